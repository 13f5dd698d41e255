"""Errors the command line reports as one line: ``error: FILE: FIELD: what is wrong``."""
from __future__ import annotations

from cspace.io.load import ScenarioError


class InputError(ScenarioError):
    """A fault in an input other than the scenario's own fields (an option, an output path).

    Same shape as :class:`cspace.ScenarioError`, so the CLI reports both alike.
    """
