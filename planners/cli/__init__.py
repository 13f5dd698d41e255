"""The ``cspace`` command: :mod:`~planners.cli.command` dispatches to one module per subcommand
(``plan``, ``show``, ``bench``, ``stability``, ``generate``, ``import``), each imported only when
its subcommand runs.

This package's own import is nearly empty (its names load on first use, PEP 562), so that
:func:`console`, the installed script's entry point, handles Ctrl-C from its first moment:
even while the command's modules load, Ctrl-C prints ``interrupted`` and exits with 130.
"""
from __future__ import annotations

import importlib
import sys

_NAMES = ("COMMANDS", "HELP", "build_parser", "clip", "main", "version_line")
__all__ = [*_NAMES, "console"]


def console() -> None:
    """Entry point of the installed ``cspace`` script, ``python -m planners`` and
    ``python -m planners.cli``: :func:`planners.cli.command.console`, Ctrl-C included."""
    try:
        from .command import console as run

        run()
    except KeyboardInterrupt:  # before the command's own handler is in place
        sys.stderr.write("interrupted\n")
        raise SystemExit(130) from None


def __getattr__(name: str):
    if name in _NAMES:
        value = getattr(importlib.import_module(".command", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
