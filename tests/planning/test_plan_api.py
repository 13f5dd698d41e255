"""planners.plan through the Python API: verified paths, determinism, stages, multi-query."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import shapely

import planners
from cspace import load_scenario

from conftest import OMPL_SCENES

U_ROBOT = """
name = "u-robot"
[bounds]
xmin = 0
xmax = 20
ymin = 0
ymax = 20
[robot]
polygon = [[-1, -1], [1, -1], [1, 1], [0.6, 1], [0.6, -0.6], [-0.6, -0.6], [-0.6, 1], [-1, 1]]
[[obstacles]]
polygon = [[8, 0], [12, 0], [12, 12], [8, 12]]
[[obstacles]]
polygon = [[2, 15], [18, 15], [18, 16], [2, 16]]
holes = []
[start]
x = 3
y = 3
[goal]
x = 17
y = 3
"""


def swept_overlaps_obstacles(sc, path) -> bool:
    """Independent check: does the robot swept along any segment overlap an obstacle's interior?"""
    obstacles = shapely.union_all([o.to_shapely() for o in sc.obstacles])
    for a, b in zip(path[:-1], path[1:]):
        for part in sc.robot or []:
            swept = shapely.MultiPoint(np.vstack([part.polygon + a, part.polygon + b])).convex_hull
            if swept.intersection(obstacles).area > 1e-12 * max(1.0, obstacles.area):
                return True
        if not sc.robot and shapely.LineString([a, b]).crosses(obstacles):
            return True
    return False


def test_plan_nonconvex_robot_gives_a_verified_path(write_toml):
    path = write_toml(U_ROBOT)
    res = planners.plan(path, seed=1, time=2.0)
    assert res.solved and res.exact
    sc = load_scenario(path)
    assert tuple(res.path[0]) == sc.start and tuple(res.path[-1]) == sc.goal
    xmin, xmax, ymin, ymax = sc.bounds
    assert np.all((res.path[:, 0] >= xmin) & (res.path[:, 0] <= xmax))
    assert np.all((res.path[:, 1] >= ymin) & (res.path[:, 1] <= ymax))
    assert not swept_overlaps_obstacles(sc, res.path)
    assert res.length == pytest.approx(np.hypot(*np.diff(res.path, axis=0).T).sum())
    assert {"load", "cspace", "solve", "simplify", "verify", "total"} <= set(res.timings)
    assert "minkowski" in res.stages and "decompose_robot" in res.stages
    assert res.checks["states"] > 0 and res.checks["motions"] > 0


def test_same_seed_same_path_in_one_process(write_toml):
    path = write_toml(U_ROBOT)
    a = planners.plan(path, seed=7)
    b = planners.plan(path, seed=7)
    assert a.solved and np.array_equal(a.path, b.path)


def test_scenario_object_and_planner_names_are_case_insensitive(write_toml):
    sc = load_scenario(write_toml(U_ROBOT))
    res = planners.plan(sc, planner="rrt", seed=2, time=2.0)
    assert res.planner == "RRT" and res.solved


@pytest.mark.parametrize("iterations", [0, -3, 2.5, True])
def test_iterations_must_be_a_positive_integer(write_toml, iterations):
    from cspace import ScenarioError

    with pytest.raises(ScenarioError, match="iterations: must be a positive integer"):
        planners.plan(write_toml(U_ROBOT), iterations=iterations)


def test_unsolvable_returns_not_solved_within_the_limit(write_toml):
    import time

    text = U_ROBOT.replace("[[8, 0], [12, 0], [12, 12], [8, 12]]", "[[8, 0], [12, 0], [12, 20], [8, 20]]")
    t = time.perf_counter()
    res = planners.plan(write_toml(text), time=0.3)
    assert not res.solved and math.isinf(res.length) and len(res.path) == 0
    assert time.perf_counter() - t < 0.3 + 1.0


def test_multi_query_circles_meets_ompls_own_bar():
    # OMPL's 2denvs test: >= 95 of the 100 circle queries at 1 s each, mean simplified length < 100
    res = planners.plan(os.path.join(OMPL_SCENES, "circles.toml"), time=1.0, all_queries=True)
    solved = [q for q in res.queries if q.solved]
    assert len(res.queries) == 100
    assert len(solved) >= 95
    assert sum(q.length for q in solved) / len(solved) < 100
    d = res.as_dict()
    assert len(d["queries"]) == 100 and "queries" not in d["queries"][0]


def test_point_robot_stages_skip_the_sum():
    res = planners.plan(os.path.join(OMPL_SCENES, "env1.toml"), seed=0)
    assert res.solved
    ran = {s["stage"]: s["ran"] for s in res.cspace_report["stages"]}
    assert ran["minkowski"] is False and ran["decompose_robot"] is False


HOSTILE_ARGUMENTS = [("slabs", 10**9), ("slabs", 3), ("slabs", 4097), ("slabs", True), ("slabs", 2.0),
                     ("time", -1), ("time", math.nan), ("time", math.inf), ("time", 1e300),
                     ("seed", -1), ("seed", 2**40), ("iterations", 0), ("iterations", True),
                     ("clearance", -1.0), ("clearance", math.inf), ("objective", "x")]


@pytest.mark.parametrize("field,value", HOSTILE_ARGUMENTS)
def test_hostile_plan_arguments_are_refused_before_any_work(field, value):
    """Every bound the command line keeps holds for the Python call too: an argument out of range
    is one ScenarioError naming plan() and the argument, raised before the C-space is built (the
    CLI refused --slabs 1e9; plan(slabs=10**9) built slabs without end)."""
    from cspace.io.load import ScenarioError

    scene = os.path.join(os.path.dirname(__file__), "..", "..", "scenarios", "se2", "bar_door.toml")
    with pytest.raises(ScenarioError) as exc:
        planners.plan(scene, **{field: value})
    assert str(exc.value).startswith(f"plan(): {field}:"), str(exc.value)


def test_the_se2_cspace_bounds_its_slabs_as_a_file_does():
    from cspace.io.scenario.schema import MAX_SLABS
    from cspace.se2.cspace import SE2CSpace

    sc = load_scenario(os.path.join(os.path.dirname(__file__), "..", "..", "scenarios", "se2", "bar_door.toml"))
    with pytest.raises(ValueError, match=f"from 4 to {MAX_SLABS}"):
        SE2CSpace.from_scenario(sc, slabs=MAX_SLABS + 1)
