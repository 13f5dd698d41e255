"""Without OMPL (issue 18.4): cspace and the exact planner work, `cspace plan` falls back
to exact with a note, an OMPL planner asked for by name is a clear one-line error.

OMPL is hidden by ``sys.modules['ompl'] = None`` in a fresh interpreter (an import of
it then fails as if it were not installed)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
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
