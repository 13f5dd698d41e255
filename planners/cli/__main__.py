"""``python -m planners.cli``: the ``cspace`` command, as ``python -m planners``."""
from . import console

console()
