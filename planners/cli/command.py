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
import re
import sys
import traceback
import warnings

from . import interrupt

COMMANDS = {
    "plan": "planners.cli.plan",
    "show": "planners.cli.show",
    "bench": "planners.cli.bench",
    "stability": "planners.cli.stability",
    "generate": "planners.cli.generate",
    "import": "planners.cli.imports",
    "check-proof": "planners.cli.check_proof",
    "view": "planners.cli.view",
    "recheck": "planners.cli.recheck",
}
# Each command's one-line help, for the listing of ``cspace --help`` (and a bare
# ``cspace``), which then imports no command module, nor numpy: start-up stays short.
# tests/cli/test_cli.py checks these are the help strings the modules register.
HELP = {
    "plan": "plan a collision-free path for a scenario",
    "show": "draw the workspace, the C-obstacles and their convex pieces",
    "bench": "error against run time for OMPL planners vs the exact shortest path",
    "stability": "run stiff and extreme cases through every layer",
    "generate": "write a random scenario (random, maze, narrow, disks, office)",
    "import": "convert a ROS map (.yaml), an OMPL.app problem (.cfg), an SVG drawing (.svg) or a MovingAI map "
              "(.map) to a scenario",
    "check-proof": "re-check a proof that no path exists (from plan --proof)",
    "view": "plan a scenario and write one offline, interactive HTML page of the plan",
    "recheck": "re-check the paths of a Bench-MR results file exactly (any planner's)",
}


def clip(text: str, limit: int) -> str:
    """:func:`cspace.io.scenario.messages.clip`, imported when needed (it pulls in numpy).

    >>> clip("abc", 10)
    'abc'
    """
    from cspace.io.scenario.messages import clip as _clip

    return _clip(text, limit)


# A value that starts with a minus and a digit is a value, not an option: footprints about
# their reference point start with one (``--polygon "-0.2,-0.15;..."``, ``--start -1,2``,
# ``--theta -1.57``). argparse's own rule accepts a lone number only; no option of ours
# looks like a number, so the wider rule is unambiguous (``--start=-1,2`` works as well).
NEGATIVE_VALUE = re.compile(r"^-\.?\d")


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)
        self._negative_number_matcher = NEGATIVE_VALUE  # argparse's hook for this rule

    def error(self, message):  # one short line, exit 2, like every other input fault
        sys.stderr.write(f"error: {self.prog}: {clip(message, 240)}\n")
        sys.exit(2)


def version_line() -> str:
    """``cspace X.Y.Z (Python ..., numpy ..., shapely ..., ompl ...; compiled fast path: on)``: what a
    bug report needs (the last part says whether the compiled routines run, or the pure path).

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
    return f"cspace {cspace.__version__} (Python {platform.python_version()}, {', '.join(deps)}; {fast_path()})"


def fast_path() -> str:
    """Whether the compiled routines of :mod:`cspace.compiled.fastpath` are in use, and why not.

    >>> fast_path().startswith(("compiled fast path: on", "pure Python path"))
    True
    """
    from cspace.compiled import fastpath

    if fastpath.compiled():
        return "compiled fast path: on"
    if os.environ.get("CSPACE_PURE", "") not in ("", "0"):
        return "pure Python path: CSPACE_PURE is set; slower"
    if fastpath.STALE:
        return f"pure Python path: the compiled extension is {fastpath.STALE}; slower"
    return "pure Python path: not compiled at install (no C compiler?); slower"


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
        show_defaults(sub.choices[name])
    return parser


def show_defaults(parser: argparse.ArgumentParser) -> None:
    """Say each option's default in its help where the help does not already: a number, a
    word or a path (not a switch's False, nor None, which means "not given").

    >>> p = argparse.ArgumentParser()
    >>> _ = p.add_argument("--runs", type=int, default=10, help="runs")
    >>> _ = p.add_argument("--quiet", action="store_true", help="less output")
    >>> show_defaults(p)
    >>> [a.help for a in p._actions[1:]]
    ['runs (default: 10)', 'less output']
    """
    for action in parser._actions:
        d = action.default
        if d is None or d is False or d is argparse.SUPPRESS or not action.option_strings or action.help is None:
            continue
        if "default" not in action.help:
            action.help += f" (default: {d})"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv:  # a bare `cspace`: what it can do, not an error
        build_parser().print_help(sys.stdout)
        return 0
    first = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(first if first in COMMANDS else None)
    args = parser.parse_args(argv)
    from cspace.io.load import ScenarioError

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
        code = interrupt.exit_code()
    except BrokenPipeError:  # the reader went away (`cspace ... | head`): stop quietly
        _silence_stdout()
        code = 141  # 128 + SIGPIPE, as a shell reports a process killed by it
    except Exception as exc:  # a bug, not bad input: still one line unless --verbose
        if interrupt.came():  # Ctrl-C, which a library turned into another error
            sys.stderr.write("interrupted\n")
            return interrupt.exit_code()
        if getattr(args, "verbose", False):  # the traceback, and still "internal error", not "not solved"
            traceback.print_exc()
            return 3
        hint = "run with --verbose for the traceback" if hasattr(args, "verbose") else "a bug: please report it"
        sys.stderr.write(f"internal error: {type(exc).__name__}: {clip(str(exc), 240)} ({hint})\n")
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

    Ctrl-C at any moment is ``interrupted`` and exit 130, also while the parser and the
    command's modules load (outside :func:`main`'s handler) and when a library turned it
    into another error. A Ctrl-C that lands inside an import is held until the import
    returns, and one lost in a callback comes back (:mod:`planners.cli.interrupt`); once
    the exit code is known, a late Ctrl-C is ignored. An
    interrupted run also ends with ``os._exit``: Python would otherwise re-raise SIGINT at
    exit if a library's C code let the KeyboardInterrupt through (exit -2, not 130).
    """
    interrupt.install()  # KeyboardInterrupt, held while an import runs (planners.cli.interrupt)
    try:
        code = main()
        try:
            sys.stdout.flush()
        except BrokenPipeError:
            _silence_stdout()
            code = 141
    except Exception:
        if not interrupt.came():
            raise
        code = _interrupted()
    except KeyboardInterrupt:
        code = _interrupted()
    interrupt.release()
    if interrupt.came():  # (a normal end flushed stdout above)
        try:
            sys.stdout.flush()
        except (BrokenPipeError, ValueError):
            _silence_stdout()
    sys.stderr.flush()
    if interrupt.came() or ("ompl" in sys.modules and "--verbose" not in sys.argv and "-v" not in sys.argv):
        output = sys.modules.get("planners.output")
        if output is not None:  # what os._exit skips: the atexit removal of our temporaries
            output.clean_stale()
        os._exit(code)
    sys.exit(code)


def _interrupted() -> int:
    sys.stderr.write("interrupted\n")
    return interrupt.exit_code()


if __name__ == "__main__":  # pragma: no cover
    console()
