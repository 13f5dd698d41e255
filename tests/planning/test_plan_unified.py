"""One planning routine: ``cspace plan``, ``planners.plan()`` and every bench run agree.

The bench once re-implemented the planning steps and drifted (anytime planners were
reported as never solving); these tests hold the two to the same answers.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import conftest
from cspace import CSpace, load_scenario
from planners import bench, plan
from planners.core import routine
from planners.adapters.glue import PLANNERS
from planners.adapters.translation import TranslationSpace

ROOT = Path(conftest.ROOT)
BASIC = str(ROOT / "scenarios" / "basic.toml")


@pytest.fixture(scope="module")
def basic():
    sc = load_scenario(BASIC)
    return sc, CSpace.from_scenario(sc)


def _task(planner, budget, seed, iterations=None):
    return {"file": BASIC, "scenario": "basic", "optimum": 1.0, "planner": planner,
            "time_budget": budget, "seed": seed, "iterations": iterations}


# Iterations that solve basic.toml (an iteration of the RRT* family costs about 1 ms).
ITERATIONS = {"RRTstar": 600, "InformedRRTstar": 600, "SORRTstar": 600, "PRM": 300, "PRMstar": 300,
              "FMT": 300, "BFMT": 300}


@pytest.mark.parametrize("planner", PLANNERS)
def test_every_planner_solves_in_the_bench_where_plan_does_with_the_same_length(basic, planner):
    # An iteration budget (and a time limit far away) makes both runs independent of the
    # machine's load: the bench must solve where plan() does, with the same path length
    # (PRM and PRMstar check for a solution on a thread of their own: same success only).
    sc, cs = basic
    n = ITERATIONS.get(planner, 3000)
    res = plan(sc, planner=planner, time=30.0, seed=0, iterations=n, cspace=cs)
    assert res.solved, res.message
    row = bench.run_one(_task(planner, 30.0, 0, n), sc, cs)
    assert row["status"] == "ok" and row["solved"], row["message"]
    assert row["length"] >= row["optimum"] and row["first_solution_s"] <= row["solve_s"] + 1e-9
    if planner not in ("PRM", "PRMstar"):
        assert row["length"] == res.length and row["length_unsimplified"] == res.length_unsimplified


@pytest.mark.parametrize("planner", sorted(routine.SLICED))
@pytest.mark.slow
def test_anytime_planners_solve_in_time_slices(basic, planner):
    # The slices are what the old bench got wrong (0 % success for RRTstar, PRMstar, BITstar).
    from planners.adapters.glue import planner_name

    sc, cs = basic
    row = bench.run_one(_task(planner_name(planner), 1.0, 0), sc, cs)
    assert row["status"] == "ok" and row["solved"], row["message"]
    assert row["progress"] and row["progress"][0][0] == pytest.approx(row["first_solution_s"])
    costs = [c for _, c in row["progress"]]
    assert costs == sorted(costs, reverse=True)  # the best cost never gets worse
    assert row["length_unsimplified"] == pytest.approx(costs[-1], abs=1e-8)


def test_bench_row_equals_the_cli_plan_in_fresh_processes(tmp_path):
    # Same seed and iteration budget: the bench's child and `cspace plan` give the same length.
    out = tmp_path / "p.json"
    subprocess.run([sys.executable, "-m", "planners.cli", "plan", BASIC, "--planner", "RRTstar", "--seed", "2",
                    "--iterations", "300", "--time", "30", "--json", str(out)], cwd=ROOT, check=True,
                   capture_output=True, timeout=60)
    cli = json.loads(out.read_text())
    task = bench.make_tasks([{"file": BASIC, "scenario": "basic", "optimum": 1.0}], ["RRTstar"], [30.0], 3, 300)[2]
    row = bench.isolated_run(task, limit=60)
    assert cli["solved"] and row["solved"] and row["length"] == cli["length"]


def test_the_routine_only_needs_the_adapter(basic):
    # run_planner on the adapter directly (what SE(2) will reuse): verified, from start to goal.
    from planners.core.plan import run_planner

    sc, cs = basic
    space = TranslationSpace(cs)
    (r,) = run_planner(space, "RRTConnect", [(sc.start, sc.goal)], 1.0, 0)
    assert r.solved and tuple(r.path[0]) == sc.start and tuple(r.path[-1]) == sc.goal
    assert r.length == pytest.approx(float(np.hypot(*np.diff(r.path, axis=0).T).sum()))
    assert space.verify(r.path, sc.start, sc.goal) == (True, "exact solution")
    # The adapter refuses what is not a path from start to goal.
    assert not space.verify(r.path[::-1], sc.start, sc.goal)[0]
    assert not space.verify(np.array([sc.start, sc.goal]), sc.start, sc.goal)[0]  # through an obstacle
