"""``planner = "exact"`` for a car (planners/core/auto.py ``exact_reeds_shepp``): a Reeds–Shepp
car gets the slab graph's SE(2) path driven as certified curves (Laumond's route, alone), a
proof that the independent checker accepts, or "not decided"; no OMPL is needed for it. Every
path is judged by the independent sweep (scripts/sweep_oracle.py, shapely, along the curves).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import planners
from conftest import ROOT, SCENARIOS, load_script
from cspace.car.curves import reeds_shepp_segments
from cspace.io.load import load_scenario
from planners.core.auto import exact_reeds_shepp
from planners.core.proof_check import check_proof

oracle = load_script("sweep_oracle")
CAR = os.path.join(SCENARIOS, "car")
HIDE_OMPL = "import sys; sys.modules['ompl'] = None\n"


def sweep_free(sc, path) -> bool:
    j = oracle.car_sweep_check(sc, path, lambda a, b: reeds_shepp_segments(a, b, sc.turning_radius),
                               sc.turning_radius)
    return not j["collides"] and not j["out_of_bounds"]


@pytest.mark.parametrize("name", ["parking", "u_turn", "garage_reverse", "dead_end_alley", "u_turn_cusps"])
def test_exact_drives_a_reeds_shepp_car_along_certified_curves(name):
    path = os.path.join(CAR, name + ".toml")
    sc = load_scenario(path)
    res = planners.plan(path, planner="exact", time=20.0)
    assert res.solved and res.planner == "exact" and res.exact, res.message
    assert "Reeds-Shepp" in res.message and res.stages[-2:] == ["Reeds-Shepp curves", "simplify"]
    assert tuple(res.path[0]) == tuple(res.start) and tuple(res.path[-1]) == tuple(res.goal)
    assert sweep_free(sc, res.path), res.message
    assert len(res.curves) == len(res.path) - 1  # the path's curves, as a sampling planner's carry
    again = planners.plan(path, planner="exact", time=20.0)
    assert np.array_equal(again.path, res.path)  # deterministic


def test_exact_proves_a_reeds_shepp_car_stuck_and_the_checker_agrees():
    path = os.path.join(CAR, "tight_corner.toml")  # a Dubins scene; no SE(2) path at all
    res = planners.plan(path, planner="exact", space="reeds-shepp", time=20.0)
    assert not res.solved and res.proven_unsolvable and res.planner == "exact", res.message
    sc = load_scenario(path)
    assert check_proof(sc, res.proof, 0).valid


def test_exact_with_no_time_left_says_not_decided():
    from planners.core.plan import build_cspace, make_adapter

    sc = load_scenario(os.path.join(CAR, "parking.toml"))
    cs = build_cspace(sc)
    res = exact_reeds_shepp(sc, cs, make_adapter(sc, cs), sc.all_queries()[0], sc.path, 0.0)
    assert not res.solved and not res.proven_unsolvable and res.proof is None
    assert res.planner == "exact" and res.message.startswith("not decided within the time limit")


def test_a_dubins_car_still_asks_exact_for_a_proof_only():
    with pytest.raises(Exception) as err:
        planners.plan(os.path.join(CAR, "maze.toml"), planner="exact", time=5.0)
    assert "a Dubins car (space = \"dubins\") cannot turn in place" in str(err.value) and "more characters" not in str(err.value)


def test_without_ompl_a_reeds_shepp_car_is_planned_by_exact(tmp_path):
    out = tmp_path / "u.json"
    r = subprocess.run([sys.executable, "-c", HIDE_OMPL + "from planners.cli import console; "
                        "sys.argv = ['cspace'] + sys.argv[1:]; console()", "plan",
                        os.path.join(CAR, "u_turn.toml"), "--json", str(out)],
                       cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("note: OMPL is not installed") and len(r.stderr.strip().splitlines()) == 1
    assert "solved by exact" in r.stdout and "OMPL not installed: not shortened" in r.stdout
    doc = json.loads(out.read_text())
    sc = load_scenario(os.path.join(CAR, "u_turn.toml"))
    assert doc["solved"] and doc["curves"] and sweep_free(sc, np.array(doc["path"], dtype=float))
