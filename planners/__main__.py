"""``python -m planners``: the ``cspace`` command."""
from .cli import console

console()
