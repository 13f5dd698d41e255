"""Without OMPL (issue 18.4): cspace and the exact planner work, `cspace plan` falls back
to exact with a note, an OMPL planner asked for by name is a clear one-line error.

OMPL is hidden by ``sys.modules['ompl'] = None`` in a fresh interpreter (an import of
it then fails as if it were not installed)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import conftest

ROOT = Path(conftest.ROOT)
BASIC = str(ROOT / "scenarios" / "basic.toml")
HIDE = "import sys; sys.modules['ompl'] = None\n"


def run(code: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", HIDE + code, *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)


def cli(*args: str) -> subprocess.CompletedProcess:
    return run("from planners.cli import console; sys.argv = ['cspace'] + sys.argv[1:]; console()", *args)


def test_cspace_and_the_exact_planner_work_without_ompl():
    r = run("import cspace, planners\n"
            "res = planners.plan(sys.argv[1], planner='exact')\n"
            "assert res.solved and 'ompl' not in [m for m in sys.modules if sys.modules[m] is not None]\n"
            "try:\n"
            "    planners.plan(sys.argv[1], planner='RRTConnect')\n"
            "except ImportError as exc:\n"
            "    print('refused:', exc)\n", BASIC)
    assert r.returncode == 0, r.stderr
    assert "refused: the sampling planners need OMPL" in r.stdout and "pip install" in r.stdout


def test_plan_falls_back_to_exact_with_a_note():
    r = cli("plan", BASIC)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("note: OMPL is not installed: planning with the exact planner instead")
    assert len(r.stderr.strip().splitlines()) == 1
    assert "solved by exact" in r.stdout


def test_an_ompl_planner_by_name_is_a_one_line_error():
    r = cli("plan", BASIC, "--planner", "rrtconnect")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert ": --planner: RRTConnect needs OMPL" in r.stderr and "pip install" in r.stderr
    b = cli("bench", BASIC, "--out", "/nonexistent-dir/x", "-q")
    assert b.returncode == 2 and len(b.stderr.strip().splitlines()) == 1 and "OMPL is not installed" in b.stderr


def test_with_ompl_nothing_is_noted():
    r = subprocess.run([sys.executable, "-m", "planners.cli", "plan", BASIC], cwd=ROOT, capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0 and r.stderr == ""


def _loaded_after(code: str) -> list[str]:
    """Heavy optional modules loaded by ``code`` in a fresh interpreter (OMPL not hidden)."""
    probe = ("import sys\n" + code + "\nprint(' '.join(m for m in ('ompl', 'matplotlib', 'tqdm', 'tomllib', 'numpy') "
             "if sys.modules.get(m) is not None))")
    r = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_imports_load_neither_ompl_nor_matplotlib_nor_tqdm():
    # Start-up (issue 23.6): the packages load their names on first use; OMPL, matplotlib
    # and tqdm only when a plan, a plot or a progress bar runs, the TOML reader with a file.
    assert _loaded_after("import cspace, planners") == []
    assert _loaded_after("import planners.cli") == []
    used = _loaded_after("import cspace, planners\nfrom cspace import CSpace, SE2CSpace, shortest_path, load_scenario\n"
                         "from planners import plan, PlanResult\nimport planners.core.routine, planners.adapters.translation, "
                         "planners.cli.plan, planners.bench")
    assert used == ["numpy"]
    assert _loaded_after(f"from cspace import load_scenario; load_scenario({BASIC!r})") == ["tomllib", "numpy"]


def test_help_imports_no_command_module():
    code = ("import sys; sys.argv = ['cspace', '--help']\nfrom planners.cli import main\n"
            "import contextlib, io\nwith contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
            "    main()\n"
            "print(sorted(m for m in sys.modules if m.startswith(('planners.', 'cspace', 'numpy'))))")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    # the dispatcher and its Ctrl-C handling (signal and sys only), no command
    assert r.stdout.strip() == "['planners.cli', 'planners.cli.command', 'planners.cli.interrupt']"
    m = subprocess.run([sys.executable, "-m", "planners", "--help"], cwd=ROOT, capture_output=True, text=True,
                       timeout=60)
    assert m.returncode == 0 and m.stdout.startswith("usage: cspace") and "plan a collision-free path" in m.stdout


def test_a_rotating_robot_plans_without_ompl_by_the_slab_graph():
    door = str(ROOT / "scenarios" / "se2" / "bar_door.toml")
    r = cli("plan", door)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("note: OMPL is not installed: planning with the exact planner instead")
    assert "solved by exact" in r.stdout and "not shortened" in r.stdout
    trap = str(ROOT / "scenarios" / "se2" / "bug_trap_l.toml")
    r = cli("plan", trap)
    assert r.returncode == 1 and "proven unsolvable" in r.stdout
