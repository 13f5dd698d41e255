"""The clearance objective (issue 39, item 7): its state clearance against shapely, its motion
bound against the true clearance of the swept robot, its cost against what OMPL reports, a
plan under it, and the hint of a plan under it that fails. (Its speed: scripts/bench_objective.py.)"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import shapely
import shapely.affinity

from conftest import SCENARIOS
from cspace import CSpace, load_scenario
from cspace.translation.point_clearance import PointClearance, disc_bound

BUG_TRAP = os.path.join(SCENARIOS, "bug_trap.toml")
BASIC = os.path.join(SCENARIOS, "basic.toml")


def _oracle(obstacles, robot, x, y):
    """The robot placed at (x, y): its distance to the obstacles, 0 when it meets them."""
    placed = shapely.affinity.translate(robot, x, y)
    return 0.0 if placed.intersects(obstacles) else placed.distance(obstacles)


@pytest.fixture(scope="module")
def bug_trap():
    pytest.importorskip("ompl")
    import tomllib

    from planners.core.plan import make_adapter

    sc = load_scenario(BUG_TRAP)
    cs = CSpace.from_scenario(sc)
    with open(BUG_TRAP, "rb") as f:
        raw = tomllib.load(f)
    obstacles = shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", [])) for o in raw["obstacles"]])
    robot = shapely.Polygon(raw["robot"]["polygon"])
    return sc, cs, make_adapter(sc, cs), obstacles, robot


def _states(adapter, points):
    space = adapter.state_space()
    out = []
    for p in points:
        s = space.allocState()
        adapter.set_state(s, (float(p[0]), float(p[1])))
        out.append(s)
    return space, out


def test_state_clearance_is_the_robots_distance_to_the_obstacles(bug_trap):
    """On random states: the objective's clearance of a state equals the distance between the
    robot placed there and the obstacles (shapely), 0 where they meet."""
    from planners.adapters.objectives import clearance_functions

    sc, cs, adapter, obstacles, robot = bug_trap
    state, _ = clearance_functions(adapter)
    rng = np.random.default_rng(7)
    pts = rng.uniform(0.0, 20.0, (400, 2))
    space, states = _states(adapter, pts)  # (the space kept alive with its states)
    free = 0
    for p, s in zip(pts, states):
        want = _oracle(obstacles, robot, *p)
        assert state(s) == pytest.approx(want, abs=1e-9), p
        assert state(s) == pytest.approx(want, abs=1e-9)  # the second read comes from the cache
        free += want > 0
    assert 100 < free < 400  # both kinds of states were met


def test_point_clearance_matches_shapely_on_many_pieces():
    """PointClearance's cells keep the nearest piece: random convex pieces, points everywhere
    (outside the bounds too), the distance to the nearest edge (shapely)."""
    rng = np.random.default_rng(3)
    pieces = []
    for _ in range(60):
        c = rng.uniform(0, 50, 2)
        ang = np.sort(rng.uniform(0, 2 * np.pi, 6))
        pts = c + np.column_stack([np.cos(ang), np.sin(ang)]) * rng.uniform(0.2, 2.0)
        pieces.append(np.asarray(shapely.MultiPoint(pts).convex_hull.exterior.coords)[:-1])
    pc = PointClearance(pieces, (0, 50, 0, 50))
    edges = shapely.union_all([shapely.Polygon(p).boundary for p in pieces])
    for x, y in rng.uniform(-5, 55, (600, 2)):
        assert pc(float(x), float(y)) == pytest.approx(shapely.Point(x, y).distance(edges), abs=1e-12)
    assert PointClearance([], (0, 1, 0, 1))(0.5, 0.5) == math.inf


def test_disc_bound_is_a_lower_bound_and_tight_at_the_discs_crossing():
    """Point obstacles at random: the bound from the ends' clearances and the length never
    exceeds the segment's true distance to them; an obstacle at the discs' crossing makes it exact."""
    rng = np.random.default_rng(11)
    for _ in range(2000):
        obs = rng.uniform(0, 10, (rng.integers(1, 6), 2))
        a, b = rng.uniform(0, 10, 2), rng.uniform(0, 10, 2)
        c1 = float(np.hypot(*(obs - a).T).min())
        c2 = float(np.hypot(*(obs - b).T).min())
        true = shapely.LineString([a, b]).distance(shapely.MultiPoint(obs))
        assert disc_bound(c1, c2, float(np.hypot(*(b - a)))) <= true + 1e-12
    h = math.sqrt(0.75)  # ends (0, 0) and (1, 0), an obstacle at (0.5, h): both clearances 1, the segment's h
    assert disc_bound(1.0, 1.0, 1.0) == pytest.approx(h, rel=1e-15)
    assert disc_bound(2.0, 3.0, 0.0) == 2.0 and disc_bound(1.0, 1.0, 2.0) == 0.0
    assert disc_bound(math.inf, math.inf, 5.0) == math.inf


def test_motion_value_is_the_disc_bound_and_below_the_swept_robots_clearance(bug_trap):
    """A motion's value: disc_bound of the oracle's clearances of its ends, never more than the
    distance from the robot swept along it (the hull of its two placements) to the obstacles."""
    from planners.adapters.objectives import clearance_functions

    sc, cs, adapter, obstacles, robot = bug_trap
    _, motion = clearance_functions(adapter)
    rng = np.random.default_rng(5)
    checked = 0
    while checked < 150:
        a = rng.uniform(0, 20, 2)
        b = a + rng.normal(0, 1.5, 2)
        if not cs.segment_free(tuple(a), tuple(b)):
            continue
        space, (sa, sb) = _states(adapter, [a, b])
        got = motion(sa, sb)
        want = disc_bound(_oracle(obstacles, robot, *a), _oracle(obstacles, robot, *b), float(np.hypot(*(b - a))))
        assert got == pytest.approx(want, abs=1e-9)
        swept = shapely.union_all([shapely.affinity.translate(robot, *a), shapely.affinity.translate(robot, *b)]).convex_hull
        assert got <= swept.distance(obstacles) + 1e-9
        checked += 1


def test_plan_under_the_clearance_objective_is_free_and_its_cost_is_what_ompl_reports():
    """RRTstar under the objective solves a small scene; every segment of the path is free;
    OMPL's cost of its path, read as a clearance (softmin_value: −σ·ln(cost)), lies within
    σ·ln(n) below path_clearance_bound of the same n motions, which is at most the path's exact
    min_clearance."""
    pytest.importorskip("ompl")
    from planners import plan
    from planners.adapters.glue import make_setup, set_query, termination
    from planners.adapters.objectives import make_objective, path_clearance_bound, softmin_sigma, softmin_value
    from planners.core.plan import make_adapter

    res = plan(BASIC, planner="RRTstar", time=60.0, seed=2, objective="clearance", iterations=1500)
    assert res.solved and res.objective == "clearance"
    sc = load_scenario(BASIC)
    cs = CSpace.from_scenario(sc)
    adapter = make_adapter(sc, cs)
    assert all(cs.segment_free(tuple(p), tuple(q)) for p, q in zip(res.path[:-1], res.path[1:]))
    assert 0.0 < path_clearance_bound(adapter, res.path) <= res.min_clearance + 1e-9

    held = make_setup(adapter, "RRTstar", 2)
    ss = held[0]
    obj = make_objective("clearance", ss.getSpaceInformation(), adapter)
    ss.setOptimizationObjective(obj)
    set_query(ss, adapter, sc.start, sc.goal)
    ss.solve(termination(60.0, 1500)[0])
    assert ss.haveExactSolutionPath()
    path = ss.getSolutionPath()
    pts = adapter.path_array(path)
    sigma = softmin_sigma(adapter)
    reported, bound = softmin_value(path.cost(obj).value(), sigma), path_clearance_bound(adapter, pts)
    assert bound - sigma * math.log(len(pts) - 1) - 1e-12 <= reported <= bound + 1e-12
    assert reported > 0.0
    # the cost is the sum of the motions' exp(-c / sigma), as OMPL adds them
    from planners.adapters.objectives import clearance_functions

    _, motion = clearance_functions(adapter)
    space, st = _states(adapter, pts)
    total = sum(math.exp(-motion(a, b) / sigma) for a, b in zip(st, st[1:]))
    assert path.cost(obj).value() == pytest.approx(total, rel=1e-12)


def test_failure_hint_under_the_clearance_objective_does_not_send_to_the_exact_planner():
    """A plan under --objective clearance that fails suggests what fits the objective: the exact
    planner refuses every objective but length, so it is not named (it still is under length)."""
    pytest.importorskip("ompl")
    from planners import plan

    res = plan(BUG_TRAP, planner="RRTstar", time=60.0, seed=1, objective="clearance", iterations=3)
    assert not res.solved
    assert "exact" not in res.message and "--time" in res.message, res.message
    base = plan(BUG_TRAP, planner="RRTstar", time=60.0, seed=1, iterations=3)
    assert not base.solved and "--planner exact" in base.message  # the oracle: the length hint names it


def test_cli_failure_under_the_clearance_objective(capsys):
    pytest.importorskip("ompl")
    from planners.cli import main

    code = main(["plan", BUG_TRAP, "--planner", "RRTstar", "--objective", "clearance", "--time", "0.001"])
    out = capsys.readouterr()
    text = out.out + out.err
    assert code == 1 and "NOT solved" in text and "--time" in text, text
    assert "exact" not in text, text


def test_compiled_motion_cost_is_the_python_one_to_the_bit(bug_trap):
    """The compiled disc bound (cspace/compiled/_disccost.c) against the Python objective's motion
    cost: the same doubles on random motions (repeated states, zero-length motions, ends inside
    C-obstacles), with a table small enough to start over many times."""
    from cspace.compiled import fastpath
    from planners.adapters import objectives

    if not fastpath.compiled():
        pytest.skip("the compiled fast path is not built")
    sc, cs, adapter, obstacles, robot = bug_trap
    sigma = objectives.softmin_sigma(adapter)
    inv = 1.0 / sigma
    state, motion = objectives.clearance_functions(adapter)

    def py_cost(a, b):  # the pure objective's cost: exp((-c) * inv), c the Python disc bound
        return math.exp(-motion(a, b) * inv)

    def raw(x, y):
        return state((x, y))

    calls = []

    def counted(x, y):
        calls.append((x, y))
        return raw(x, y)

    c_cost = fastpath.disc_cost(math.ldexp(1.0, -adapter.k), sigma, float, counted, slots_log2=4)
    rng = np.random.default_rng(11)
    pts = [tuple(p) for p in rng.uniform(-1, 21, (60, 2))]  # some outside the bounds, some blocked
    space, states = _states(adapter, pts)
    raws = [(float(s[0]), float(s[1])) for s in states]
    n = 0
    for _ in range(3000):
        i, j = rng.integers(0, len(raws), 2)
        a, b = raws[i], raws[j] if rng.random() < 0.9 else raws[i]
        assert c_cost(a, b) == py_cost(a, b), (a, b)
        n += 1
    assert {c for c in calls} <= set(raws) and len(calls) > len(raws)  # the 16-slot table started over
    assert any(raw(*p) == 0.0 for p in raws) and any(raw(*p) > 0.0 for p in raws)
    # a plan under the objective takes the compiled cost where built, the same path as the pure one
    from planners import plan

    r = plan(BASIC, planner="RRTstar", seed=4, iterations=400, time=60.0, objective="clearance")
    with fastpath.disabled():
        p = plan(BASIC, planner="RRTstar", seed=4, iterations=400, time=60.0, objective="clearance")
    assert r.solved and np.array_equal(r.path, p.path)
