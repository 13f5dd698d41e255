"""The ``cspace`` command: a thin dispatcher over subcommand modules.

Each subcommand lives in its own module, imported only when that subcommand runs,
so ``cspace plan`` never pays for matplotlib or the benchmark code. A module exposes
``register(subparsers)``, which adds its parser and sets ``run`` (``args -> exit code``).

Exit codes: 0 success, 1 not solved (or a check failed), 2 bad input, 3 internal error.
"""
from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import sys
import warnings

COMMANDS = {
    "plan": "planners.cli.plan",
    "show": "planners.cli.show",
    "bench": "planners.cli.bench",
    "stability": "planners.cli.stability",
    "generate": "planners.cli.generate",
    "import": "planners.cli.imports",
    "check-proof": "planners.cli.check_proof",
}
# Each command's one-line help, for the listing of ``cspace --help`` (and a bare
# ``cspace``), which then imports no command module, nor numpy: start-up stays short.
# tests/test_cli.py checks these are the help strings the modules register.
HELP = {
    "plan": "plan a collision-free path for a scenario",
    "show": "draw the workspace, the C-obstacles and their convex pieces",
    "bench": "error against run time for OMPL planners vs the exact shortest path",
    "stability": "run stiff and extreme cases through every layer",
    "generate": "write a random scenario (random, maze, narrow, disks, office)",
    "import": "convert a ROS map (.yaml) or an OMPL.app problem (.cfg) to a scenario",
    "check-proof": "re-check a proof that no path exists (from plan --proof)",
}


def clip(text: str, limit: int) -> str:
    """:func:`cspace.io.messages.clip`, imported when needed (it pulls in numpy).

    >>> clip("abc", 10)
    'abc'
    """
    from cspace.io.messages import clip as _clip

    return _clip(text, limit)


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one short line, exit 2, like every other input fault
        sys.stderr.write(f"error: {self.prog}: {clip(message, 240)}\n")
        sys.exit(2)


def version_line() -> str:
    """``cspace X.Y.Z (Python ..., numpy ..., shapely ..., ompl ...)``: what a bug report needs.

    The versions come from the installed packages' metadata, so OMPL is not imported.

    >>> version_line().startswith("cspace ")
    True
    """
    import platform
    from importlib import metadata

    import cspace

    deps = []
    for dist in ("numpy", "shapely", "ompl"):
        try:
            deps.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            deps.append(f"{dist} not installed")
    return f"cspace {cspace.__version__} (Python {platform.python_version()}, {', '.join(deps)})"


class _Version(argparse.Action):
    """``--version``: computed only when asked for."""

    def __init__(self, option_strings, dest, **kw):
        super().__init__(option_strings, dest, nargs=0, help="print the version (and its dependencies') and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        sys.stdout.write(version_line() + "\n")
        parser.exit(0)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    parser = _Parser(prog="cspace", description="2-D configuration-space motion planning",
                     epilog="Run `cspace COMMAND --help` for a command's options. A bare `cspace` prints this "
                            "help and exits with status 0.")
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name, module in COMMANDS.items():
        if name != only:  # listed only: its one-line help, its module not imported
            if importlib.util.find_spec(module) is not None:
                sub.add_parser(name, help=HELP[name], add_help=False)
            continue
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as exc:
            if exc.name != module:
                raise
            continue
        mod.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv:  # a bare `cspace`: what it can do, not an error
        build_parser().print_help(sys.stdout)
        return 0
    first = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(first if first in COMMANDS else None)
    args = parser.parse_args(argv)
    from cspace.io.scenario import ScenarioError

    try:
        with warnings.catch_warnings():
            if not getattr(args, "verbose", False):  # numpy/matplotlib chatter is not for the terminal
                warnings.simplefilter("ignore")
            code = args.run(args)
    except ScenarioError as exc:
        sys.stderr.write(f"error: {exc}\n")
        code = 2
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        code = 130
    except BrokenPipeError:  # the reader went away (`cspace ... | head`): stop quietly
        _silence_stdout()
        code = 141  # 128 + SIGPIPE, as a shell reports a process killed by it
    except Exception as exc:  # a bug, not bad input: still one line unless --verbose
        if getattr(args, "verbose", False):
            raise
        sys.stderr.write(f"internal error: {type(exc).__name__}: {clip(str(exc), 240)} "
                         "(run with --verbose for the traceback)\n")
        code = 3
    return code


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot raise again."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # not a real file: just replace it
        sys.stdout = open(os.devnull, "w")
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


def console() -> None:
    """Entry point of the installed ``cspace`` script.

    OMPL's bindings print a ``nanobind: leaked ...`` report at interpreter exit; a
    command-line user should not see it, so the process ends with ``os._exit`` once
    its output is flushed (unless ``--verbose`` asks to see everything).
    """
    code = main()
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()
        code = 141
    sys.stderr.flush()
    if "ompl" in sys.modules and "--verbose" not in sys.argv and "-v" not in sys.argv:
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    console()
