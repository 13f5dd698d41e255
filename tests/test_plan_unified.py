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

from cspace import CSpace, load_scenario
from planners import bench, plan
from planners.ompl_glue import PLANNERS
from planners.spaces import TranslationSpace

ROOT = Path(__file__).resolve().parents[1]
BASIC = str(ROOT / "scenarios" / "basic.toml")


@pytest.fixture(scope="module")
def basic():
    sc = load_scenario(BASIC)
    return sc, CSpace.from_scenario(sc)


def _task(planner, budget, seed, iterations=None):
    return {"file": BASIC, "scenario": "basic", "optimum": 1.0, "planner": planner,
            "time_budget": budget, "seed": seed, "iterations": iterations}


@pytest.mark.parametrize("planner", PLANNERS)
def test_every_planner_solves_in_the_bench_where_plan_does(basic, planner):
    sc, cs = basic
    res = plan(sc, planner=planner, time=0.3, seed=0, cspace=cs)
    assert res.solved, res.message
    row = bench.run_one(_task(planner, 0.3, 0), sc, cs)
    assert row["status"] == "ok" and row["solved"], row["message"]
    assert row["length"] >= row["optimum"] and row["first_solution_s"] <= row["solve_s"] + 1e-9
    assert row["progress"] and row["progress"][0][0] == pytest.approx(row["first_solution_s"])


@pytest.mark.parametrize("planner, iterations", [("RRTConnect", 2000), ("RRT", 2000), ("RRTstar", 400),
                                                 ("KPIECE1", 2000)])
def test_bench_length_equals_plan_length_for_an_iteration_budget(basic, planner, iterations):
    sc, cs = basic
    res = plan(sc, planner=planner, time=30.0, seed=4, iterations=iterations, cspace=cs)
    row = bench.run_one(_task(planner, 30.0, 4, iterations), sc, cs)
    assert res.solved and row["solved"]
    assert row["length"] == res.length and row["length_unsimplified"] == res.length_unsimplified


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
    from planners.plan import run_planner

    sc, cs = basic
    space = TranslationSpace(cs)
    (r,) = run_planner(space, "RRTConnect", [(sc.start, sc.goal)], 1.0, 0)
    assert r.solved and tuple(r.path[0]) == sc.start and tuple(r.path[-1]) == sc.goal
    assert r.length == pytest.approx(float(np.hypot(*np.diff(r.path, axis=0).T).sum()))
    assert space.verify(r.path, sc.start, sc.goal) == (True, "exact solution")
    # The adapter refuses what is not a path from start to goal.
    assert not space.verify(r.path[::-1], sc.start, sc.goal)[0]
    assert not space.verify(np.array([sc.start, sc.goal]), sc.start, sc.goal)[0]  # through an obstacle
