"""How path_clearance measures a path's min clearance (issue 21): the segment-to-polygon
distance, the pruning bounds that leave GJK few pairs without changing the answer, the reach
filter of the broad phase, the closest position it reports; the objectives' edge distance;
the lower bound of a rotating robot's path. Against shapely: the robot swept along the path
(tests/helpers/oracles.py) or placed where the answer says.

Margins and the clearance of planned paths: tests/translation/test_clearance.py."""
import math

import numpy as np
import pytest
import shapely

from cspace.compiled import fastpath
from cspace.translation.cspace import CSpace
from oracles import swept_clearance


# ------------------------------------------------------------------ the pruning bound of path_clearance

def _random_convex(rng, center, radius, k):
    from cspace import convex_hull

    ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    pts = np.column_stack([np.cos(ang), np.sin(ang)]) * radius * rng.uniform(0.3, 1.0, (k, 1)) + center
    return convex_hull(pts)


@pytest.mark.parametrize("seed", range(8))
def test_segment_polygon_distance_matches_shapely(seed):
    from cspace.translation.clearance import _segment_polygon_distance

    rng = np.random.default_rng(seed)
    polys = [_random_convex(rng, rng.uniform(0, 10, 2), rng.uniform(0.2, 3), int(rng.integers(3, 9))) for _ in range(60)]
    polys = [p for p in polys if len(p) >= 3]
    E = max(len(p) for p in polys)
    P = np.array([np.vstack([p, np.repeat(p[:1], E - len(p), axis=0)]) for p in polys])
    a = rng.uniform(-2, 12, (len(polys), 2))
    b = np.where(rng.random((len(polys), 1)) < 0.2, a, rng.uniform(-2, 12, (len(polys), 2)))  # some points
    got = _segment_polygon_distance(a, b, P)
    truth = [shapely.Polygon(p).distance(shapely.LineString([x, y]) if (x != y).any() else shapely.Point(x))
             for p, x, y in zip(polys, a, b)]
    assert np.allclose(got, truth, rtol=1e-12, atol=1e-12)
    assert (got == 0).any() and (got > 0).any()


@pytest.mark.parametrize("seed", range(6))
def test_tighter_bounds_change_nothing_but_the_work(seed, monkeypatch):
    # path_clearance with the segment-to-C-obstacle bounds equals the box-bound search
    # (same distance, place and segment), on random robots, obstacles and paths, some
    # of them touching; and it runs GJK on fewer pairs.
    import cspace.translation.clearance as cl

    rng = np.random.default_rng(seed)
    obstacles = [_random_convex(rng, rng.uniform(0, 20, 2), rng.uniform(0.5, 3), int(rng.integers(3, 9))) for _ in range(25)]
    robot = [_random_convex(rng, (0.0, 0.0), 0.6, 5), _random_convex(rng, (0.3, 0.0), 0.4, 4)] if seed % 3 else []
    path = rng.uniform(0, 20, (int(rng.integers(2, 40)), 2))
    if seed % 2:  # a path along an obstacle's edge: many nearly equal distances, a touch
        o = obstacles[0]
        path = np.vstack([path[:3], o, path[-2:]])
    calls = []
    real, real_below = cl.gjk_distance, cl.gjk_distance_below
    monkeypatch.setattr(cl, "gjk_distance", lambda *x, **k: calls.append(1) or real(*x, **k))
    monkeypatch.setattr(cl, "gjk_distance_below", lambda *x, **k: calls.append(1) or real_below(*x, **k))
    fast = cl.path_clearance(path, robot, obstacles)
    n_fast = len(calls)
    monkeypatch.setattr(cl, "_tighter_bounds", lambda lbs, *rest: lbs)
    monkeypatch.setattr(cl, "TIE", 0.0)
    calls.clear()
    slow = cl.path_clearance(path, robot, obstacles)  # every pair the box bounds cannot rule out
    scale = max(np.abs(path).max(), max(np.abs(o).max() for o in obstacles))
    assert slow.distance <= fast.distance <= slow.distance + 2.0**-44 * scale
    assert (fast.distance == 0.0) == (slow.distance == 0.0)
    assert n_fast <= len(calls)
    # and the answer is the swept robot's distance (shapely)
    assert fast.distance == pytest.approx(swept_clearance(path, robot, obstacles), rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_few_pairs_skip_the_reach_filter_with_the_same_answer(seed, monkeypatch):
    # Up to FEW_PAIRS (sweep, obstacle) pairs the broad phase keeps every pair; beyond, it
    # drops those farther than the nearest piece's far corner. The search's stop rule never
    # reaches a dropped pair, so both give the same result, to the bit (distance, place,
    # obstacle point, segment), on random scenes, some touching.
    import cspace.translation.clearance as cl

    rng = np.random.default_rng(100 + seed)
    obstacles = [_random_convex(rng, rng.uniform(0, 20, 2), rng.uniform(0.5, 3), int(rng.integers(3, 9))) for _ in range(25)]
    robot = [_random_convex(rng, (0.0, 0.0), 0.6, 5), _random_convex(rng, (0.3, 0.0), 0.4, 4)] if seed % 3 else []
    path = rng.uniform(0, 20, (int(rng.integers(2, 12)), 2))
    if seed % 2:
        path = np.vstack([path[:3], obstacles[0], path[-2:]])
    assert len(path) * max(1, len(robot)) * len(obstacles) <= cl.FEW_PAIRS  # the all-pairs route
    every = cl.path_clearance(path, robot, obstacles)
    monkeypatch.setattr(cl, "FEW_PAIRS", 0)  # the filtered route
    filtered = cl.path_clearance(path, robot, obstacles)
    assert tuple(every) == tuple(filtered)
    assert every.distance == pytest.approx(swept_clearance(path, robot, obstacles), rel=1e-9, abs=1e-12)


def test_piece_boxes_of_one_piece_and_of_empty_ones():
    # piece_boxes' one-piece branch and its general one give the same boxes; an empty
    # piece keeps its (inf, -inf) box beside non-empty ones.
    from cspace.kernel.polygons.polygon import piece_boxes

    p = np.array([[0.5, -1.0], [2.0, 0.25], [-3.0, 4.0]])
    lo, hi = piece_boxes([p])
    lo2, hi2 = piece_boxes([p, p])
    assert lo.tolist() == [lo2[0].tolist()] == [[-3.0, -1.0]] and hi.tolist() == [hi2[0].tolist()] == [[2.0, 4.0]]
    lo3, hi3 = piece_boxes([p, np.zeros((0, 2))])
    assert lo3[1].tolist() == [np.inf, np.inf] and hi3[1].tolist() == [-np.inf, -np.inf]


@pytest.mark.parametrize("seed", range(8))
def test_closest_position_holds_the_distance(seed):
    # Where the robot comes closest (read off GJK's witness on the swept set, or the
    # segment's point nearest the C-obstacle where GJK decides exactly): on the reported
    # segment, and the robot placed there is at the reported distance from the obstacle,
    # whose reported point is that far from it (shapely). Some paths touch an obstacle.
    from cspace.translation.clearance import path_clearance

    rng = np.random.default_rng(50 + seed)
    obstacles = [_random_convex(rng, rng.uniform(0, 20, 2), rng.uniform(0.5, 3), int(rng.integers(3, 9))) for _ in range(12)]
    robot = [_random_convex(rng, (0.0, 0.0), 0.6, 5), _random_convex(rng, (0.3, 0.0), 0.4, 4)] if seed % 4 else []
    path = rng.uniform(0, 20, (int(rng.integers(2, 12)), 2))
    if seed % 3 == 0:  # along an obstacle's boundary: distance 0
        path = np.vstack([path[:2], obstacles[0], path[-1:]])
    c = path_clearance(path, robot, obstacles)
    a, b = path[c.segment], path[c.segment + 1]
    where, q = np.array(c.where), shapely.Point(c.obstacle_point)
    assert shapely.LineString([a, b]).distance(shapely.Point(where)) <= 1e-12 * (1 + np.abs(path).max())
    placed = shapely.union_all([shapely.Polygon(r + where) for r in robot]) if robot else shapely.Point(where)
    nearest = min(shapely.Polygon(o).distance(placed) for o in obstacles)
    assert nearest == pytest.approx(c.distance, rel=1e-9, abs=1e-9)
    assert placed.distance(q) == pytest.approx(c.distance, rel=1e-9, abs=1e-9)
    assert c.distance == pytest.approx(swept_clearance(path, robot, obstacles), rel=1e-9, abs=1e-12)


def test_tighter_bounds_prune_a_margin_path():
    # An exact path with a margin hugs the inflated obstacles along many short segments at
    # nearly the same distance: the box bounds leave GJK hundreds of pairs, the tight ones few.
    import os

    import cspace.translation.clearance as cl
    from conftest import SCENARIOS
    from planners import plan

    res = plan(os.path.join(SCENARIOS, "clearance.toml"), planner="exact")
    assert res.solved and len(res.path) > 20
    sc = res.scenario_data
    cs = CSpace.from_scenario(sc)
    calls = []
    real, real_below = cl.gjk_distance, cl.gjk_distance_below
    cl_gjk = lambda *x, **k: calls.append(1) or real(*x, **k)  # noqa: E731
    cl_below = lambda *x, **k: calls.append(1) or real_below(*x, **k)  # noqa: E731
    mp = pytest.MonkeyPatch()
    mp.setattr(cl, "gjk_distance", cl_gjk)
    mp.setattr(cl, "gjk_distance_below", cl_below)
    try:  # counted on the pure path, where each measured pair is a call (the compiled one measures the same)
        mp.setattr(fastpath, "_fast", None)
        fast = cl.path_clearance(res.path, cs.robot_pieces, cs.obstacle_pieces)
        n_fast = len(calls)
        mp.setattr(cl, "_tighter_bounds", lambda lbs, *rest: lbs)
        mp.setattr(cl, "TIE", 0.0)
        calls.clear()
        slow = cl.path_clearance(res.path, cs.robot_pieces, cs.obstacle_pieces)
    finally:
        mp.undo()
    assert fast.distance == res.min_clearance
    assert fast.distance == pytest.approx(slow.distance, rel=1e-12)
    # After GJK_FIRST pairs on box bounds, the tight bounds leave GJK one or two; box bounds
    # alone leave it dozens more.
    assert n_fast <= cl.GJK_FIRST + 2 and len(calls) >= cl.GJK_FIRST + 30, (n_fast, len(calls))


# ------------------------------------------------------------------ other measures of clearance

def test_edge_distance_matches_shapely():
    """The objectives' clearance of a state or a motion: distance to the nearest C-obstacle edge."""
    from cspace.translation.clearance import EdgeDistance

    rng = np.random.default_rng(0)
    pieces = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]]), np.array([[1., 7], [3, 7], [2, 9]])]
    ed = EdgeDistance(pieces)
    edges = shapely.union_all([shapely.Polygon(p).boundary for p in pieces])
    for _ in range(300):
        a, b = rng.uniform(0, 10, 2), rng.uniform(0, 10, 2)
        assert ed.segment(*a, *b) == pytest.approx(shapely.LineString([a, b]).distance(edges), abs=1e-12)
        assert ed.point(*a) == pytest.approx(shapely.Point(a).distance(edges), abs=1e-12)
    assert EdgeDistance([]).segment(0, 0, 1, 1) == math.inf


def test_se2_lower_bound_never_exceeds_the_truth():
    from cspace.se2.clearance import se2_path_clearance
    from cspace.se2.motion import interpolate
    from cspace.kernel.polygons.rotation import rotate

    rng = np.random.default_rng(3)
    obstacles = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]]), np.array([[1., 7], [3, 7], [2, 9]])]
    union = shapely.union_all([shapely.Polygon(o) for o in obstacles])
    bar = np.array([[-1., -0.15], [1, -0.15], [1, 0.15], [-1, 0.15]])
    free = [np.array([[2., 2, 0], [2, 2, 1.5], [8, 2, -1]]), np.array([[8., 1.5, 3], [8.5, 3, -3], [8.5, 8, 0.5]])]
    paths = free + [np.column_stack([rng.uniform(1, 9, (3, 2)), rng.uniform(-math.pi, math.pi, 3)])
                    for _ in range(4)]
    for k, path in enumerate(paths):
        c = se2_path_clearance(path, [bar], obstacles)
        if k < len(free):
            assert c.distance > 0.5  # these keep away: the bound is not trivially 0
        sampled = min(shapely.Polygon(rotate(bar, q[2]) + q[:2]).distance(union)
                      for a, b in zip(path[:-1], path[1:]) for t in np.linspace(0, 1, 400)
                      for q in [np.array(interpolate(a, b, t))])
        assert c.bound == "lower"
        assert c.distance <= sampled + 1e-12
        # ... and close to it: within about r * ANGLE_STEP plus the sampling's own gap.
        assert c.distance >= sampled - 0.05
