"""The car motion check as the planners call it: CarCSpace.car_motion_test (one compiled call per
motion, the join of the curve's end to the goal pose certified in it where one slab's segment
test does: cspace/compiled/_carmotion.c, join_end) and the adapter's memory of free motions
(planners.adapters.car.CarSpace.motion_free), against the pure path (the oracle) and the
independent shapely sweep.
"""
from __future__ import annotations

import glob
import math
import os
import random

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import SCENARIOS, load_script
from cspace.car.curves import dubins_segments, reeds_shepp_segments
from cspace.car.motion import ARC_CHUNK, FLOOR_REL, MAX_HULLS, CarCSpace
from cspace.compiled import fastpath, motions
from cspace.io.load import load_scenario
from cspace.kernel.polygons.rotation import wrap_angle

oracle = load_script("sweep_oracle")
compiled = pytest.mark.skipif(not fastpath.compiled(), reason="the compiled fast path is not built (or CSPACE_PURE=1)")
CAR_FILES = sorted(glob.glob(os.path.join(SCENARIOS, "car", "*.toml")))
_scenes: dict = {}


def scene(name):
    if name not in _scenes:
        sc = load_scenario(os.path.join(SCENARIOS, "car", name))
        cs = CarCSpace.from_scenario(sc)
        with fastpath.disabled():
            pure = CarCSpace.from_scenario(sc)
        _scenes[name] = (sc, cs, pure)
    return _scenes[name]


def pairs(sc, cs, n: int, seed: int) -> list:
    """Pose pairs as a planner asks them: free poses, the second near the first (half the time
    within a turning radius or two), or anywhere."""
    rng = random.Random(seed)
    xmin, xmax, ymin, ymax = sc.bounds
    r = sc.turning_radius
    out = []
    while len(out) < n:
        a = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        if not cs.is_free(a):
            continue
        d, turn = rng.uniform(0.02, 2.5) * r, rng.uniform(-1.5, 1.5)
        b = (a[0] + d * math.cos(a[2] + turn), a[1] + d * math.sin(a[2] + turn), wrap_angle(a[2] + rng.uniform(-2, 2)))
        if len(out) % 3 == 2:
            b = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        out.append((a, b))
    return out


def joined(cs, a, b, kind, radius) -> int:
    """The compiled motion asked to join (slabs built as asked): its code."""
    motion = motions.car_motion(motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK))
    grids = [None] * cs.slabs
    while True:
        r = motion(grids, *a, *b, float(radius), kind == "dubins", 1e6 * cs.extent, 128 * math.pi * radius, True)[0]
        if r >= -1:
            return r
        grids[-2 - r] = cs.slab(-2 - r)._fast


@compiled
@pytest.mark.parametrize("name", ["parking.toml", pytest.param("garage_reverse.toml", marks=pytest.mark.slow),
                                  pytest.param("maze.toml", marks=pytest.mark.slow)])
def test_the_motion_test_answers_as_the_pure_path(name):
    """On a scene's random motions: the planners' motion test (compiled, joined in C where it can
    be) answers as the pure path does on the Python segments; both joins are exercised; the
    curves it calls free pass the shapely sweep."""
    sc, cs, pure = scene(name)
    kind, r = sc.space, sc.turning_radius
    test = cs.car_motion_test(kind, r)
    seg = dubins_segments if kind == "dubins" else reeds_shepp_segments
    codes, judged = [], []
    for a, b in pairs(sc, cs, 60, seed=3):
        want = pure.curve_free(a, seg(a, b, r), r, q1=b)
        assert test(a, b) == want == cs.car_motion_free(a, b, kind, r), (a, b)
        code = joined(cs, a, b, kind, r)
        codes.append(code)
        if code == 2:  # the chain and the join certified in C: the pure path says free
            assert want, (a, b)
            if len(judged) < 4:
                judged.append((a, b))
        if code == 0:
            assert not want, (a, b)
    assert codes.count(2) >= 5 and codes.count(0) >= 5
    for a, b in judged:
        j = oracle.car_sweep_check(sc, np.array([a, b]), lambda p, q: seg(p, q, r), r)
        assert not (j["collides"] or j["out_of_bounds"]), (a, b, j)


@compiled
def test_a_join_across_slabs_or_the_wrap_is_left_to_the_caller():
    """The end of a chain joined to a goal whose heading lies in another slab (or across ±π):
    the compiled call certifies the chain and hands the join back (1), and the motion test
    still answers as the pure path."""
    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    cs = CarCSpace((0, 10, 0, 10), [sq], [box], slabs=16)
    with fastpath.disabled():
        pure = CarCSpace((0, 10, 0, 10), [sq], [box], slabs=16)
    w = 2 * math.pi / 16
    test = cs.car_motion_test("reeds-shepp", 1.0)
    for th in (-math.pi + w, -math.pi, math.pi - 1e-15):  # a slab boundary, the wrap from both sides
        a, b = (1.0, 1.5, th), (2.0, 1.5, th)
        c = joined(cs, a, b, "reeds-shepp", 1.0)
        assert c in (1, 2)
        assert test(a, b) == pure.car_motion_free(a, b, "reeds-shepp", 1.0) is True


_off = st.floats(-0.3, 0.3)


@compiled
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(["parking.toml", "parallel_tight.toml", "garage_reverse.toml"]),
       st.tuples(_off, _off, _off), st.tuples(_off, _off, _off), st.booleans())
def test_hypothesis_grazing_motions_near_the_queries(name, d0, d1, to_goal):
    """Motions from the start (or the goal) of the tight scenes to poses nearby: grazing the
    parked cars and the walls. Where the compiled call certifies chain and join (2), the pure
    path says free; the motion test's answer is always the pure path's."""
    sc, cs, pure = scene(name)
    q = sc.all_queries()[0]
    s, g = tuple(map(float, q.start)), tuple(map(float, q.goal))
    a = tuple(float(v + w) for v, w in zip(s if not to_goal else g, d0))
    b = tuple(float(v + w) for v, w in zip(g if to_goal else s, d1))
    if not (cs.is_free(a) and cs.is_free(b)):
        return
    r = sc.turning_radius
    want = pure.curve_free(a, reeds_shepp_segments(a, b, r), r, q1=b)
    if joined(cs, a, b, "reeds-shepp", r) == 2:
        assert want, (a, b)
    assert cs.car_motion_test("reeds-shepp", r)(a, b) == want, (a, b)


def test_free_motions_are_remembered_and_collisions_are_not():
    """The adapter's memory: a motion certified free is answered again without a check; one in
    collision is checked each time; keys with a zero are never kept (0.0 == -0.0); the path
    check still refuses a path with a colliding motion among remembered free ones."""
    from planners.adapters.car import CarSpace

    sc, cs, _ = scene("parking.toml")
    car = CarSpace(cs, "reeds-shepp", sc.turning_radius)
    calls = []
    real = cs.car_motion_test("reeds-shepp", sc.turning_radius)
    car._test = lambda a, b: calls.append((a, b)) or real(a, b)
    s = (2.0, 2.2, 0.05)  # in the lane (no zero: such keys are not kept)
    free = (2.5, 2.25, 0.06)
    assert car.motion_free(s, free) and car.motion_free(s, free) and len(calls) == 1
    hit = (4.5, 0.5, 0.1)  # inside the parked car ahead of the gap: not free
    assert not car.motion_free(s, hit) and not car.motion_free(s, hit) and len(calls) == 3
    zero = (2.5, 2.2, 0.0)
    car.motion_free(s, zero), car.motion_free(s, zero)
    assert len(calls) == 5 and all(0.0 not in a + b for a, b in car._free)
    ok, why = car.verify(np.array([s, free, hit]), s, hit)
    assert not ok and "1" in why


def test_the_last_length_is_remembered_for_that_path_only():
    """A path measured twice (when found, when returned) is measured once; another path, or the
    same numbers with a signed zero (0.0 == -0.0, another curve: a heading of ±π), is measured
    afresh: the length is always the one a fresh adapter gives."""
    from planners.adapters.car import CarSpace

    sc, cs, _ = scene("parking.toml")
    car, fresh = (CarSpace(cs, "reeds-shepp", sc.turning_radius) for _ in range(2))
    a = np.array([[2.0, 2.2, 0.05], [2.5, 2.25, 0.06], [3.0, 2.3, 1.0]])
    b = np.array([[2.0, 2.2, 0.05], [2.5, 2.25, 0.06], [3.0, 2.3, -math.pi]])
    c = np.array([[2.0, 2.2, 0.0], [2.5, 2.25, 0.06], [3.0, 2.3, math.pi]])
    for p in (a, a, b, a, c, c * np.array([1, 1, -1]), c):
        assert car.length(p) == fresh.length(p)
        fresh._last_length = (None, 0.0)


def test_a_new_planning_run_starts_with_nothing_remembered():
    """What the adapter remembers (free motions, the last length) belongs to one planning run: a
    run repeated on the same adapter (a benchmark's rounds) checks its motions again."""
    from planners.adapters.car import CarSpace
    from planners.adapters.glue import ompl_available

    if not ompl_available():
        pytest.skip("OMPL is not installed")
    sc, cs, _ = scene("parking.toml")
    car = CarSpace(cs, "reeds-shepp", sc.turning_radius)
    a, b = (2.0, 2.2, 0.05), (2.5, 2.25, 0.06)
    assert car.motion_free(a, b) and car._free and car.length(np.array([a, b])) > 0
    from planners.adapters.glue import make_setup

    keep = make_setup(car, "RRTConnect", 0)  # a new run: its validator
    assert not car._free and car._last_length == (None, 0.0) and keep[3] is not None
    assert car.motion_free(a, b) and car._free
    car.forget()  # auto's direct curve, before any validator: a new run too
    assert not car._free


def robot_clearance(sc, q) -> float:
    """The distance from the robot at pose q to the obstacles (shapely: an independent oracle)."""
    from shapely import affinity

    placed = [affinity.translate(affinity.rotate(p, q[2], origin=(0, 0), use_radians=True), q[0], q[1])
              for p in oracle.robot_pieces(sc)]
    return min(p.distance(o.to_shapely()) for p in placed for o in sc.obstacles)


@compiled
def test_a_join_by_rounding_at_one_heading_near_an_obstacle_is_decided_in_c():
    """The usual join (the curve's end differs from the goal pose by rounding of x and y, the same
    heading) where the slab's hull is too coarse (near an obstacle: its segment test fails): the
    compiled call certifies it (2) wherever the robot there has clearance, as the pure path's
    exact translational test does (was: 1, the join left to that test, ~0.4 ms a motion: 3 to 31
    times in 6 of the loading dock's first 10 seeds of `plan`, shortening included). Motions into
    the bay and past the truck."""
    sc, cs, pure = scene("loading_dock.toml")
    r = sc.turning_radius
    g = tuple(map(float, sc.all_queries()[0].goal))
    motion = motions.car_motion(motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK))
    grids = [cs.slab(k)._fast for k in range(cs.slabs)]
    rng = random.Random(5)
    coarse = 0
    for i in range(400):
        if i % 2:  # up the bay towards the goal, the sides 0.15 away
            b = (g[0] + rng.uniform(-0.14, 0.14), g[1] + rng.uniform(-1.5, 0.0), g[2] + rng.uniform(-0.1, 0.1))
        else:  # along the truck's south side, a few cm from it
            b = (rng.uniform(1.0, 3.0), rng.uniform(2.05, 2.14), rng.uniform(-0.05, 0.05))
        a = (b[0] - rng.uniform(0.3, 1.5) * math.cos(b[2]), b[1] - rng.uniform(0.3, 1.5) * math.sin(b[2]),
             wrap_angle(b[2] + rng.uniform(-0.2, 0.2)))
        if not (cs.is_free(a) and cs.is_free(b)):
            continue
        code, *p = motion(grids, *a, *b, r, False, 1e6 * cs.extent, 128 * math.pi * r, True)
        if code not in (1, 2) or tuple(p) == b or p[2] != b[2]:
            continue  # not free, or no join, or a join that turns (not this test's)
        if cs.slab(cs._slab_index(b[2])).segment_free(tuple(p[:2]), b[:2]):
            continue  # the slab's test certifies it: not the coarse case
        coarse += 1
        want = pure.motion_free(tuple(p), b)  # the exact join
        if code == 2:
            assert want, (a, b)
        else:  # left to the exact path: only where the robot (nearly) touches an obstacle
            assert not (want and robot_clearance(sc, b) > 1e-9), ("a join with clearance left to the exact path", a, b)
    assert coarse >= 20, coarse


@compiled
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.floats(1.2, 3.0), st.sampled_from([0.0, 1e-15, 1e-13, 1e-12, 1e-11, 1e-9, 1e-6, -1e-13, -1e-9]),
       st.floats(0.2, 1.2), st.floats(-0.06, 0.0), st.floats(-1e-3, 1e-3))
def test_hypothesis_joins_at_poses_touching_an_obstacle(x, gap, back, dy, dth):
    """Goal poses at or within a hair of the loading dock's truck (its south side y = 2.5, the van
    0.35 from its axle to its side: heading 0 touches at y = 2.15), reached from behind: where the
    compiled call certifies chain and join (2) the pure path says free, and the motion test's
    answer is always the pure path's (never a false "free" at a touching pose)."""
    sc, cs, pure = scene("loading_dock.toml")
    r = sc.turning_radius
    b = (x, 2.5 - 0.35 - gap, 0.0 if dth < 0 else dth)
    a = (x - back, b[1] + dy, 0.0)
    want = pure.curve_free(a, reeds_shepp_segments(a, b, r), r, q1=b) if pure.is_free(a) and pure.is_free(b) else False
    if joined(cs, a, b, "reeds-shepp", r) == 2:
        assert want, (a, b)
    assert cs.car_motion_test("reeds-shepp", r)(a, b) == want, (a, b)
