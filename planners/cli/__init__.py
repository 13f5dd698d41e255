"""The ``cspace`` command: :mod:`~planners.cli.command` dispatches to one module per subcommand
(``plan``, ``show``, ``bench``, ``stability``, ``generate``, ``import``), each imported only when
its subcommand runs."""
from __future__ import annotations

from .command import COMMANDS, HELP, build_parser, clip, console, main, version_line  # noqa: F401
