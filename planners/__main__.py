"""``python -m planners``: the ``cspace`` command (same as the installed script)."""
from .cli import console

console()
