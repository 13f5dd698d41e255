"""Ctrl-C where Python code cannot take it (planners.cli.interrupt): inside an import, and
inside a callback. Each case runs in a child interpreter that sends itself SIGINT at the
exact spot, so the timing is certain; without the module's handling, each one fails."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from conftest import ROOT


HARNESS = """
import signal, sys, time
from planners.cli import interrupt
assert interrupt.install()
{body}
try:
    {action}
    for _ in range(2000):  # 2 s for the held Ctrl-C to come back
        time.sleep(0.001)
    print("not interrupted")
except KeyboardInterrupt:
    print("interrupted", interrupt.came(), getattr(sys.modules.get("slow_module"), "DONE", None))
"""


def run(tmp_path, body: str, action: str, module: str = "") -> subprocess.CompletedProcess:
    if module:
        (tmp_path / "slow_module.py").write_text(textwrap.dedent(module))
    code = HARNESS.format(body=textwrap.dedent(body), action=action)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, str(tmp_path)]))
    return subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=60)


def test_a_ctrl_c_inside_an_import_waits_until_the_import_returns(tmp_path):
    """The module's body goes on after the signal (DONE is set); the KeyboardInterrupt
    comes when the import returns, at the importing line."""
    module = """
        import signal, time
        signal.raise_signal(signal.SIGINT)
        for _ in range(20):  # Python code after the signal: Python's own handler raises here
            time.sleep(0.001)
        DONE = True
    """
    out = run(tmp_path, "", "import slow_module; print('after the import line')", module)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "interrupted True True\n"


def test_a_ctrl_c_inside_a_nested_import_waits_for_the_outermost(tmp_path):
    """An import inside an import (a C extension importing numpy does this) returning is
    still inside the outer one: the Ctrl-C waits for the outer import to return."""
    (tmp_path / "inner_module.py").write_text("import signal\nsignal.raise_signal(signal.SIGINT)\nX = 1\n")
    module = """
        import time
        import inner_module
        for _ in range(20):
            time.sleep(0.001)
        DONE = inner_module.X == 1
    """
    out = run(tmp_path, "", "import slow_module", module)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "interrupted True True\n"


def test_a_second_ctrl_c_while_one_is_held_raises_at_once(tmp_path):
    """An import that does not return (a program run from an import) can still be stopped."""
    module = """
        import signal, time
        signal.raise_signal(signal.SIGINT)
        for _ in range(20):
            time.sleep(0.001)
        signal.raise_signal(signal.SIGINT)
        for _ in range(20):
            time.sleep(0.001)
        DONE = True
    """
    out = run(tmp_path, "", "import slow_module", module)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "interrupted True None\n"  # inside the module's body


def test_a_held_ctrl_c_goes_to_the_handler_current_when_the_import_returns(tmp_path):
    """Planning sets its own SIGINT handler (it stops OMPL's planners cleanly): a Ctrl-C held
    through an import is delivered to that handler, not raised past it."""
    module = """
        import signal
        signal.raise_signal(signal.SIGINT)
        signal.signal(signal.SIGINT, lambda *_: print("planner's handler"))
        DONE = True
    """
    out = run(tmp_path, "", "import slow_module", module)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "planner's handler\nnot interrupted\n"


# A finaliser that sends SIGINT and runs Python code after it: Python's handler runs inside it.
FINALISED = """
    class Finalised:
        def __del__(self):
            signal.raise_signal(signal.SIGINT)
            for _ in range(20):
                time.sleep(0.001)
"""


def test_a_ctrl_c_lost_in_a_callback_comes_back_silently(tmp_path):
    """A KeyboardInterrupt raised inside __del__ is 'Exception ignored' in Python, and the run
    would go on; here it is re-delivered, with nothing on stderr."""
    out = run(tmp_path, FINALISED, "x = Finalised(); del x")
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "interrupted True None\n"


def test_a_ctrl_c_lost_in_a_callback_during_an_import_waits_for_the_import(tmp_path):
    module = """
        import __main__, time
        x = __main__.Finalised()
        del x
        for _ in range(20):
            time.sleep(0.001)
        DONE = True
    """
    out = run(tmp_path, FINALISED, "import slow_module", module)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "interrupted True True\n"


def test_other_unraisable_errors_still_reach_the_previous_hook(tmp_path):
    body = """
        class Finalised:
            def __del__(self):
                raise ValueError("from a finaliser")
    """
    out = run(tmp_path, body, "x = Finalised(); del x")
    assert out.stdout == "not interrupted\n"
    assert "Exception ignored in" in out.stderr and "ValueError: from a finaliser" in out.stderr


def test_under_a_profiler_a_ctrl_c_in_an_import_raises_at_once(tmp_path):
    body = """
        sys.setprofile(lambda *_: None)
    """
    module = """
        import signal, time
        signal.raise_signal(signal.SIGINT)
        for _ in range(20):
            time.sleep(0.001)
        DONE = True
    """
    out = run(tmp_path, body, "import slow_module; print('imported')", module)
    assert out.stdout == "interrupted True None\n"  # as Python's own handler: inside the module's body


def test_release_drops_a_held_ctrl_c_and_ignores_later_ones(tmp_path):
    module = """
        import signal
        signal.raise_signal(signal.SIGINT)
        from planners.cli import interrupt
        interrupt.release()  # the exit code is known before the import returns
    """
    out = run(tmp_path, "", "import slow_module; signal.raise_signal(signal.SIGINT)", module)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    assert out.stdout == "not interrupted\n"


# numpy 1.26's import_array(), as a C extension runs it: a KeyboardInterrupt inside the import is
# printed with its traceback, and an ImportError raised in its place (the flake CI once met).
LIBRARY = """
import signal, sys, time, traceback
class Finder:
    def find_spec(self, name, path=None, target=None):
        if name != "cspace.io.load":
            return None
        sys.meta_path.remove(self)
        try:
            signal.raise_signal(signal.SIGINT)
            for _ in range(20):
                time.sleep(0.001)
        except KeyboardInterrupt:
            traceback.print_exc()
            raise ImportError("numpy.core.multiarray failed to import")
        return None
sys.meta_path.insert(0, Finder())
"""


@pytest.mark.parametrize("entry", ["-m planners", "console"])
def test_the_command_holds_a_ctrl_c_that_lands_inside_a_librarys_import(tmp_path, entry):
    """End to end: SIGINT lands inside an import whose library would print the interrupt's
    traceback and raise ImportError; the command answers 'interrupted', 130, and nothing else."""
    (tmp_path / "library_import.py").write_text(LIBRARY)
    run_it = ("runpy.run_module('planners', run_name='__main__', alter_sys=True)" if entry == "-m planners"
              else "from planners.cli import console; console()")
    scenario = os.path.join(ROOT, "scenarios", "basic.toml")
    code = f"import library_import, runpy, sys; sys.argv = ['cspace', 'plan', {scenario!r}]; {run_it}"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([ROOT, str(tmp_path)]))
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=120)
    assert (out.returncode, out.stderr) == (130, "interrupted\n"), out.stderr[-2000:]


def test_sigterm_is_taken_as_ctrl_c_inside_an_import_too(tmp_path):
    # SIGTERM (how batch systems end a job) goes the same way as Ctrl-C, held through an import,
    # and the command's exit code says which came: 143
    out = run(tmp_path, "import os", "import slow_module", module="""
        import os, signal, time
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.05)
        DONE = True
        """)
    assert out.stdout.split() == ["interrupted", "True", "True"], out.stderr[-2000:]
    code = ("from planners.cli import interrupt; import os, signal, time\n"
            "assert interrupt.install()\n"
            "try:\n    os.kill(os.getpid(), signal.SIGTERM); time.sleep(1)\n"
            "except KeyboardInterrupt:\n    print(interrupt.exit_code())\n")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.stdout.strip() == "143", r.stderr[-2000:]
