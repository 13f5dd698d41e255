"""Issue 39, "the second hour": defects where two features meet, each pinned by a test that
failed before its fix (-v with an internal error, negative numbers in options, planning without
OMPL, a scene that claimed "unsolvable" without a proof)."""
from __future__ import annotations

import glob
import json
import os
import subprocess
import sys
import warnings

import pytest

import planners
from conftest import ROOT, SCENARIOS
from cspace.io.load import load_scenario

CLI = "from planners.cli import console; sys.argv = ['cspace'] + sys.argv[1:]; console()"
HIDE_OMPL = "import sys; sys.modules['ompl'] = None\n"
FOOTPRINT = "-0.2,-0.15;0.2,-0.15;0.2,0.15;-0.2,0.15"  # about its reference point: starts with a minus
OFFICE = os.path.join(SCENARIOS, "maps", "office.yaml")


def run(prelude: str, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "import sys\n" + prelude + CLI, *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)


# ---------------------------------------------------------------- item 2: --verbose keeps exit 3

BOOM = ("import planners.core.plan as P\n"
        "def boom(*a, **k): raise RuntimeError('planted fault')\n"
        "P.plan = boom\n")


@pytest.mark.parametrize("verbose", [False, True])
def test_an_internal_error_exits_3_with_or_without_verbose(verbose):
    r = run(BOOM, "plan", os.path.join(SCENARIOS, "basic.toml"), *(["-v"] if verbose else []))
    assert r.returncode == 3, (r.returncode, r.stderr)  # 1 would say "not solved"
    if verbose:  # the whole traceback, for the bug report
        assert "Traceback (most recent call last)" in r.stderr and "RuntimeError: planted fault" in r.stderr
    else:
        assert r.stderr.strip().splitlines() == [
            "internal error: RuntimeError: planted fault (run with --verbose for the traceback)"]


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(SCENARIOS, "se2", "*.toml")))[:3]
                         + sorted(glob.glob(os.path.join(SCENARIOS, "car", "*.toml")))[:2], ids=os.path.basename)
def test_verbose_summarises_rotating_and_car_plans(path):
    r = run("", "plan", path, "-v", "--time", "2")
    assert r.returncode in (0, 1), r.stderr
    assert "Traceback" not in r.stderr and "stages:" in r.stdout


# ---------------------------------------------------------------- item 3: negative numbers as values

@pytest.mark.parametrize("command", ["plan", "import", "show"])
def test_negative_numbers_are_values_in_every_command(command, tmp_path):
    out = {"plan": ["--json", str(tmp_path / "o.json")], "import": ["--out", str(tmp_path / "o.toml")],
           "show": ["--json", str(tmp_path / "o.json")]}[command]
    for form in (["--polygon", FOOTPRINT], [f"--polygon={FOOTPRINT}"]):
        r = run("", command, OFFICE, *form, "--start", "0.5,0.5", "--goal", "9.5,6.5", *out)
        assert r.returncode == 0, r.stderr
    # a negative start: refused by the map's geometry (outside it), not by the option parser
    r = run("", command, OFFICE, "--polygon", FOOTPRINT, "--start", "-1,0.5", "--goal", "9.5,6.5", *out)
    assert r.returncode == 2 and "expected one argument" not in r.stderr and "--start" not in r.stderr.split(":")[0]
    assert "start" in r.stderr


def test_negative_angles_reach_the_planner(tmp_path):
    j = tmp_path / "o.json"
    r = run("", "plan", OFFICE, "--space", "se2", "--polygon", FOOTPRINT, "--start", "0.5,0.5,-1.5",
            "--goal", "9.5,6.5,-0.5", "--json", str(j))
    assert r.returncode == 0, r.stderr
    path = json.loads(j.read_text())["path"]
    assert path[0] == [0.5, 0.5, -1.5] and path[-1] == [9.5, 6.5, -0.5]
    s = run("", "show", os.path.join(SCENARIOS, "se2", "bar_door.toml"), "--theta", "-1.57",
            "--plot", str(tmp_path / "s.png"))
    assert s.returncode == 0, s.stderr and (tmp_path / "s.png").stat().st_size > 0


def test_an_option_name_is_still_an_option():
    # the wider rule takes "-1,2" and "-.5" as values; "-v" and "--json" stay options
    r = run("", "plan", os.path.join(SCENARIOS, "basic.toml"), "--time", "-v")
    assert r.returncode == 2 and "--time: expected one argument" in r.stderr


# ---------------------------------------------------------------- item 5: without OMPL

@pytest.mark.slow
def test_stability_skips_the_cases_that_need_ompl(tmp_path):
    j = tmp_path / "st.json"
    r = run(HIDE_OMPL, "stability", "--json", str(j), timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr
    assert "FAIL" not in r.stdout and "note: skipped 1 case(s) that need OMPL" in r.stdout
    data = json.loads(j.read_text())
    assert data["passed"] and data["skipped"] == ["plan_rrtconnect_o1e8"]
    assert all("CRASH" not in c["result"] for c in data["cases"])


def test_the_api_falls_back_to_exact_as_the_command_does():
    code = ("import warnings, planners\n"
            "with warnings.catch_warnings(record=True) as w:\n"
            "    warnings.simplefilter('always')\n"
            "    res = planners.plan(sys.argv[1])\n"
            "print(res.solved, res.planner, len(w), str(w[0].message))\n"
            "try:\n"
            "    planners.plan(sys.argv[1], planner='RRTConnect')\n"
            "except ImportError as exc:\n"
            "    print('named:', type(exc).__name__)\n")
    r = subprocess.run([sys.executable, "-c", HIDE_OMPL + code, os.path.join(SCENARIOS, "basic.toml")], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    first, second = r.stdout.splitlines()
    assert first.startswith("True exact 1 OMPL is not installed: planning with the exact planner instead")
    assert "pip install" in first
    assert second == "named: OMPLNotInstalled"  # a planner asked for by name is still refused


def test_with_ompl_the_api_warns_of_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert planners.plan(os.path.join(SCENARIOS, "basic.toml")).planner == "RRTConnect"


def test_a_dubins_car_without_ompl_says_once_that_it_needs_ompl():
    # (a Reeds-Shepp car is planned by exact without OMPL: tests/car/test_exact_car.py)
    r = run(HIDE_OMPL, "plan", os.path.join(SCENARIOS, "car", "maze.toml"))
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 2 and lines[0].startswith("note: OMPL is not installed") and "pip install" in lines[0]
    assert "a car's path needs OMPL's sampling planners (not installed)" in lines[1]
    assert "RRTConnect" not in lines[1] and "more characters" not in lines[1]


# ---------------------------------------------------------------- item 6 and 13: proofs, not failures

EVERY = sorted(f for f in glob.glob(os.path.join(SCENARIOS, "*.toml")) + glob.glob(os.path.join(SCENARIOS, "*", "*.toml"))
               if os.path.basename(f) != "robot.toml")  # maps/robot.toml is a robot, not a scene
UNSOLVABLE = [f for f in EVERY if load_scenario(f).expect == "unsolvable"]


def test_the_unsolvable_scenes_are_all_found():
    names = {os.path.relpath(f, SCENARIOS) for f in UNSOLVABLE}
    assert {"car/tight_corner.toml", "se2/wide_square.toml", "se2/bug_trap_l.toml"} <= names


@pytest.mark.parametrize("path", UNSOLVABLE, ids=lambda f: os.path.relpath(f, SCENARIOS))
def test_every_unsolvable_scene_carries_a_proof_that_checks(path, tmp_path):
    """``expect = "unsolvable"`` is a claim: the exact planner proves it, and for a rotating robot
    or a car the proof file passes the independent checker."""
    sc = load_scenario(path)
    proof = tmp_path / "proof.json"
    r = run("", "plan", path, "--planner", "exact", "--proof", str(proof))
    assert r.returncode == 1 and "proven unsolvable" in r.stdout, r.stdout + r.stderr
    if sc.rotates:
        c = run("", "check-proof", path, str(proof))
        assert c.returncode == 0 and c.stdout.startswith("proof valid"), c.stdout + c.stderr


@pytest.mark.parametrize("path", [f for f in UNSOLVABLE if load_scenario(f).rotates],
                         ids=lambda f: os.path.relpath(f, SCENARIOS))
def test_impossible_rotating_scenes_are_proven_before_sampling(path):
    """Item 6: the default planner does not spend its budget first (RRTConnect, 5-10 s)."""
    sc = load_scenario(path)
    res = planners.plan(sc, planner="RRTConnect", time=10.0)
    assert not res.solved and res.message.startswith("proven unsolvable before sampling"), res.message
    assert res.timings["total"] < 2.0


def test_the_tight_corner_defeats_a_freely_rotating_robot_too():
    """The van cannot turn the corner by any rigid motion, so the car's claim does not rest on its
    turning radius: the same proof holds in SE(2) and with reverse gear."""
    for space in ("se2", "reeds-shepp"):
        res = planners.plan(os.path.join(SCENARIOS, "car", "tight_corner.toml"), space=space, planner="exact")
        assert not res.solved and res.message.startswith("proven unsolvable"), (space, res.message)
