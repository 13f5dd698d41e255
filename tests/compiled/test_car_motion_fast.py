"""The compiled car curve check (cspace/compiled/_carmotion.c, motions.car_curve) and the compiled
car words (cspace/compiled/_carwords.c) against the pure path (CarCSpace._curve_pure and the
Python words, the oracles) and an independent shapely sweep.

On thousands of random Dubins / Reeds–Shepp curves over the bundled car scenes
(scenarios/car/*.toml) and on random chains near thin walls: whenever the compiled call
decides, its answer is the pure path's; it never says "free" where the pure path says "not
free"; scripts/sweep_oracle.py's car_sweep_check finds no collision along curves called free;
and the motions a real plan asks give the same answers both ways.
"""
from __future__ import annotations

import glob
import math
import os
import random

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import SCENARIOS, load_script
from cspace.io.load import load_scenario
from cspace.kernel.polygons.rotation import wrap_angle
from cspace.compiled import fastpath, motions
from cspace.car.curves import dubins_segments, reeds_shepp_segments
from cspace.car.motion import ARC_CHUNK, FLOOR_REL, MAX_HULLS
from cspace.car.dubins import dubins_word, dubins_word_pure
from cspace.car.reeds_shepp import reeds_shepp_word, reeds_shepp_word_pure
from cspace.car.motion import CarCSpace

oracle = load_script("sweep_oracle")
compiled = pytest.mark.skipif(not fastpath.compiled(), reason="the compiled fast path is not built (or CSPACE_PURE=1)")

CAR_FILES = sorted(glob.glob(os.path.join(SCENARIOS, "car", "*.toml")))


@pytest.fixture(scope="module")
def scenes():
    out = {}
    for f in CAR_FILES:
        sc = load_scenario(f)
        cs = CarCSpace.from_scenario(sc)
        with fastpath.disabled():
            pure = CarCSpace.from_scenario(sc)  # its slabs and curves: the pure path
        out[os.path.basename(f)] = (sc, cs, pure)
    return out


def segments_of(sc):
    return dubins_segments if sc.space == "dubins" else reeds_shepp_segments


def compiled_answer(cs, q0, segs, radius) -> int:
    """The compiled call alone: 1 free, 0 not free, -1 undecided (the chain only, no join)."""
    f = motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK)
    grids = [None] * cs.slabs
    pose = (float(q0[0]), float(q0[1]), wrap_angle(float(q0[2])))
    while True:
        r = f(grids, pose[0], pose[1], pose[2], segs, float(radius))[0]
        if r >= -1:
            return r
        grids[-2 - r] = cs.slab(-2 - r)._fast


def random_curves(sc, cs, n: int, seed: int) -> list:
    """n pose pairs between free poses: half anywhere, half near (the planner's short steps)."""
    rng = random.Random(seed)
    xmin, xmax, ymin, ymax = sc.bounds
    r = sc.turning_radius
    free = []
    while len(free) < 400:
        q = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        if cs.is_free(q):
            free.append(q)
    out = []
    while len(out) < n:
        a = rng.choice(free)
        if len(out) % 2:
            b = rng.choice(free)
        else:
            d, turn = rng.uniform(0.05, 2.5) * r, rng.uniform(-1.2, 1.2)
            b = (a[0] + d * math.cos(a[2] + turn), a[1] + d * math.sin(a[2] + turn),
                 wrap_angle(a[2] + rng.uniform(-1.5, 1.5)))
        out.append((a, b))
    return out


def judged_colliding(sc, a, b, segs) -> bool:
    """The shapely sweep along the curve's segments (and the join to b) finds a collision."""
    j = oracle.car_sweep_check(sc, np.array([a, b]), lambda p, q: segs, sc.turning_radius)
    return bool(j["collides"] or j["out_of_bounds"])


@compiled
@pytest.mark.parametrize("name", [os.path.basename(f) for f in CAR_FILES])
@pytest.mark.slow
def test_compiled_agrees_with_pure_and_the_sweep(scenes, name):
    sc, cs, pure = scenes[name]
    seg, r = segments_of(sc), sc.turning_radius
    curves = random_curves(sc, cs, 1000, seed=7)
    decided = free = 0
    judged = []
    for a, b in curves:
        segs = seg(a, b, r)
        c = compiled_answer(cs, a, segs, r)
        p = pure._curve_pure((a[0], a[1], wrap_angle(a[2])), segs, r, None)  # the chain, as the compiled call
        if c >= 0:
            decided += 1
            assert (c == 1) == p, (a, b, segs, c, p)
        assert not (c == 1 and not p), (a, b, segs)
        full = pure.curve_free(a, segs, r, q1=b)
        assert cs.curve_free(a, segs, r, q1=b) == full  # the product's answer: compiled, else pure
        free += full
        if full and len(judged) < 40:
            judged.append((a, b, segs))
    assert decided >= 0.97 * len(curves)
    if name != "tight_corner.toml":  # a scene built to leave almost no room
        assert free >= 30
    for a, b, segs in judged:
        assert not judged_colliding(sc, a, b, segs), (a, b, segs)


# Random chains near thin walls and small triangles: halving, grazing and the straight
# segments' swept test are exercised, not only the slab grid.
_tri = st.tuples(st.floats(1, 11), st.floats(1, 11), st.floats(0.05, 1.5), st.floats(0, 6.28))
_wall = st.tuples(st.floats(1, 11), st.floats(1, 11), st.floats(0.5, 4), st.floats(0, 6.28), st.floats(1e-6, 0.05))
_seg = st.tuples(st.sampled_from("LSR"), st.floats(-4, 4).filter(lambda v: abs(v) > 1e-3))
CAR = [[-0.3, -0.25], [0.9, -0.25], [0.9, 0.25], [-0.3, 0.25]]


def _triangle(cx, cy, s, a):
    return [[cx + s * math.cos(a + k * 2.0944), cy + s * math.sin(a + k * 2.0944)] for k in range(3)]


def _thin(cx, cy, ln, a, w):
    d, n = (math.cos(a), math.sin(a)), (-math.sin(a) * w, math.cos(a) * w)
    return [[cx, cy], [cx + ln * d[0], cy + ln * d[1]], [cx + ln * d[0] + n[0], cy + ln * d[1] + n[1]],
            [cx + n[0], cy + n[1]]]


_cache: dict = {}


def _pair(obstacles):
    key = repr(obstacles)
    if key not in _cache:
        polys = [np.array(shapely.geometry.polygon.orient(shapely.Polygon(o)).exterior.coords[:-1]) for o in obstacles]
        cs = CarCSpace((0, 12, 0, 12), polys, [np.array(CAR)], slabs=16)
        with fastpath.disabled():
            pure = CarCSpace((0, 12, 0, 12), polys, [np.array(CAR)], slabs=16)
        _cache.clear()
        _cache[key] = (cs, pure, polys)
    return _cache[key]


@compiled
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(_tri, max_size=3), st.lists(_wall, min_size=1, max_size=3),
       st.lists(st.tuples(st.tuples(st.floats(2, 10), st.floats(2, 10), st.floats(-3.1, 3.1)),
                          st.lists(_seg, min_size=1, max_size=4), st.floats(0.5, 3)), min_size=1, max_size=8))
@pytest.mark.slow
def test_hypothesis_chains_near_thin_walls(tris, walls, chains):
    cs, pure, polys = _pair([_triangle(*t) for t in tris] + [_thin(*w) for w in walls])
    for q0, segs, radius in chains:
        c = compiled_answer(cs, q0, segs, radius)
        p = pure.curve_free(q0, segs, radius)
        if c >= 0:
            assert (c == 1) == p, (q0, segs, radius, c, p)
        if c == 1:  # free: dense exact poses along the chain are free
            from cspace.car.curves import curve_length, pose_along
            n = max(8, int(curve_length(segs) / 0.02))
            for t in np.linspace(0.0, 1.0, n + 1):
                assert pure.is_free(pose_along(q0, segs, radius, float(t)))


@compiled
def test_straight_segments_beyond_the_slab_grid():
    """A straight drive along a wall closer than the slab hulls' excess: the slab grid cannot
    certify it, the compiled swept test at the one angle does; through a wall thinner than the
    probe's spacing: not free, both ways."""
    wall = [[1.0, 3.0], [11.0, 3.0], [11.0, 3.2], [1.0, 3.2]]
    thin = [[6.0, 5.0], [6.0 + 1e-6, 5.0], [6.0 + 1e-6, 7.0], [6.0, 7.0]]
    cs, pure, _ = _pair([wall, thin])
    q0 = (2.0, 3.2 + 0.25 + 1e-4, 0.0)  # the car's side 1e-4 above the wall
    segs = [("S", 7.0)]
    assert compiled_answer(cs, q0, segs, 1.0) == 1 and pure.curve_free(q0, segs, 1.0)
    q1 = (4.0, 6.0, 0.0)  # drives through the thin wall at x = 6 between the probe's poses
    segs = [("S", 2.5), ("S", 2.0)]
    assert compiled_answer(cs, q1, segs, 1.0) == 0 and not pure.curve_free(q1, segs, 1.0)


@compiled
def test_a_real_plan_replayed_both_ways(scenes):
    """The curves RRTConnect asks on the parking scene (Reeds–Shepp): the same answers on the
    pure path, and the returned path passes the shapely sweep."""
    from planners import plan

    sc, _, pure = scenes["parking.toml"]
    fresh = CarCSpace.from_scenario(sc)
    asked = []
    make = fresh.car_motion_test

    def logged_test(kind, radius):  # the adapter's motion check: every motion it is asked
        inner = make(kind, radius)

        def test(q0, q1):
            r = inner(q0, q1)
            asked.append((tuple(q0), tuple(q1), kind, radius, r))
            return r

        return test

    fresh.car_motion_test = logged_test
    res = plan(sc, planner="RRTConnect", seed=1, time=10.0, cspace=fresh)
    assert res.solved and len(asked) > 50
    assert any(r for *_, r in asked) and not all(r for *_, r in asked)
    for q0, q1, kind, radius, r in asked:  # the pure path, from the Python segments
        assert kind == "reeds-shepp" and pure.curve_free(q0, reeds_shepp_segments(q0, q1, radius), radius, q1=q1) == r
    path = np.asarray(res.path)
    j = oracle.car_sweep_check(sc, path, lambda a, b: reeds_shepp_segments(a, b, sc.turning_radius),
                               sc.turning_radius)
    assert not (j["collides"] or j["out_of_bounds"]), j


@compiled
def test_words_are_the_python_words_bit_for_bit():
    rng = random.Random(3)
    special = [0.0, -0.0, 1.0, -1.0, 2.0, 4.0, math.pi, -math.pi, math.pi / 2, 1e-9, 2 * math.pi]

    def same(a, b):
        return a == b and all(math.copysign(1, u) == math.copysign(1, v) for u, v in zip(a[1], b[1]))

    for i in range(20000):
        if i % 3 == 0:
            x, y, p = (rng.choice(special) * rng.choice((1, -1)) for _ in range(3))
        else:
            s = 10 ** rng.uniform(-8, 2)
            x, y, p = rng.uniform(-s, s), rng.uniform(-s, s), rng.uniform(-7, 7)
        assert same(reeds_shepp_word(x, y, p), reeds_shepp_word_pure(x, y, p)), (x, y, p)
        d, al, be = abs(x), p % (2 * math.pi), (3 * y) % (2 * math.pi)
        if i % 5 == 0:
            be = al + rng.choice((0.0, 1e-7, -1e-7, 1e-12))
        assert same(dubins_word(d, al, be), dubins_word_pure(d, al, be)), (d, al, be)
    # Huge values: the compiled words decline, the Python words decide (and raise where they raise).
    assert motions.reeds_shepp_word(1e200, 0.0, 0.0) is None and motions.dubins_word(1e200, 0.0, 0.0) is None


@compiled
def test_errors_and_undecided(scenes):
    sc, cs, pure = scenes["parking.toml"]
    f = motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK)
    with pytest.raises(TypeError):
        f([None], 1.0, 1.0, 0.0, [("S", 1.0)], 1.0)  # not one entry per slab
    with pytest.raises(TypeError):
        f([None] * cs.slabs, 1.0)
    grids = [None] * cs.slabs
    assert f(grids, float("nan"), 1.0, 0.0, [("S", 1.0)], 1.0)[0] == -1
    assert f(grids, 1.0, 1.0, 0.0, [("X", 1.0)], 1.0)[0] == -1  # the Python path raises
    assert f(grids, 1.0, 1.0, 0.0, [("S", 1.0)], -1.0)[0] == -1
    start = tuple(sc.all_queries()[0].start)  # a free pose: the chain is read
    for c in (cs, pure):
        with pytest.raises(ValueError):
            c.curve_free(start, [("X", 1.0)], 1.0)


def test_pure_path_has_no_compiled_curve(scenes):
    sc, cs, pure = scenes["parking.toml"]
    assert motions.car_curve(pure, MAX_HULLS, FLOOR_REL, ARC_CHUNK) is None
    with fastpath.disabled():
        assert motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK) is None
        assert motions.reeds_shepp_word(2.0, 0.0, 0.0) is None and motions.dubins_word(4.0, 0.0, 0.0) is None
        assert reeds_shepp_word(2.0, 0.0, 0.0) == ("LSL", (0.0, 2.0, 0.0))


@pytest.mark.slow
def test_pure_answers_are_sweep_checked(scenes):
    """On any build (CSPACE_PURE=1 too): curves the product path calls free pass the sweep."""
    sc, cs, pure = scenes["u_turn.toml"]
    seg, r = segments_of(sc), sc.turning_radius
    n = 0
    for a, b in random_curves(sc, cs, 80, seed=5):
        segs = seg(a, b, r)
        if cs.curve_free(a, segs, r, q1=b):
            n += 1
            assert not judged_colliding(sc, a, b, segs), (a, b, segs)
    assert n > 0


def compiled_motion(cs, q0, q1, kind, radius):
    """The compiled motion alone (motions.car_motion): (r, chain's end), slabs built as asked."""
    curve = motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK)
    motion = motions.car_motion(curve)
    grids = [None] * cs.slabs
    while True:
        r, *end = motion(grids, *q0, *q1, float(radius), kind == "dubins", 1e6 * cs.extent, 64 * 2 * math.pi * radius)
        if r >= -1:
            return r, tuple(end)
        grids[-2 - r] = cs.slab(-2 - r)._fast


def _motion_pairs(sc, cs, seed):
    pairs = random_curves(sc, cs, 300, seed=seed)
    a = pairs[0][0]
    # the same pose, a hair apart (Dubins' "nearly the same pose" rule), heading ±π, reversed
    pairs += [(a, a), (a, (a[0] + 1e-9, a[1], a[2])), (a, (a[0], a[1] + 1e-7, a[2] + 1e-8)),
              ((a[0], a[1], -math.pi), (a[0] + 0.5, a[1], math.pi - 1e-15)), (pairs[1][1], pairs[1][0])]
    return pairs


@compiled
@pytest.mark.parametrize("name", [os.path.basename(f) for f in CAR_FILES])
@pytest.mark.parametrize("kind", ["dubins", "reeds-shepp"])
def test_compiled_motion_is_the_curve_of_the_python_segments(scenes, name, kind):
    """motions.car_motion computes the segments in C: the same chain end, bit for bit, and the
    same answer as the compiled curve check of the Python segments; the product's answer
    (car_motion_free) is the pure path's on the Python segments."""
    sc, cs, pure = scenes[name]
    r = sc.turning_radius
    seg = dubins_segments if kind == "dubins" else reeds_shepp_segments
    decided = 0
    for a, b in _motion_pairs(sc, cs, seed=11):
        segs = seg(a, b, r)
        got, end = compiled_motion(cs, a, b, kind, r)
        want = compiled_answer(cs, a, segs, r)
        assert got == want, (a, b, segs, got, want)
        if got >= 0:
            decided += 1
            f = motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK)
            grids = [cs.slab(k)._fast for k in range(cs.slabs)]
            assert end == tuple(f(grids, a[0], a[1], wrap_angle(a[2]), segs, r)[1:]), (a, b, segs)
        full = pure.curve_free(a, segs, r, q1=b)
        assert cs.car_motion_free(a, b, kind, r) == full == pure.car_motion_free(a, b, kind, r), (a, b, segs)
    assert decided >= 0.97 * 305


@compiled
def test_compiled_motion_declines_what_python_decides(scenes):
    """Headings past 2^20 (Python wraps them first), poses past 1e100 radii apart, segments past
    the curve check's bounds and bad arguments: -1 or an error, never an answer of its own."""
    sc, cs, pure = scenes["parking.toml"]
    start = tuple(sc.all_queries()[0].start)
    far = (start[0], start[1], start[2] + 2.0**21)
    assert compiled_motion(cs, start, far, "reeds-shepp", 1.0)[0] == -1
    assert compiled_motion(cs, start, (start[0] + 1.0, start[1], 0.0), "dubins", 1e-101)[0] == -1
    motion = motions.car_motion(motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK))
    grids = [cs.slab(k)._fast for k in range(cs.slabs)]
    # the straight 1.0 ahead exceeds a `longest` of 0.5: the Python check would refuse it
    assert motion(grids, *start, start[0] + math.cos(start[2]), start[1] + math.sin(start[2]), start[2], 1.0,
                  False, 0.5, 400.0)[0] == -1
    assert motion(grids, float("nan"), 1.0, 0.0, 2.0, 1.0, 0.0, 1.0, False, 1e9, 400.0)[0] == -1
    with pytest.raises(TypeError):
        motion(grids, 1.0)
    with pytest.raises(TypeError):
        motion([None], *start, *start, 1.0, False, 1e9, 400.0)
    with pytest.raises(ValueError):
        cs.car_motion_free(start, start, "bicycle", 1.0)
    with pytest.raises(ValueError):  # the full path words the error, as before
        cs.car_motion_free(start, (1.0, float("inf"), 0.0), "reeds-shepp", 1.0)
    # past the slab grid's headings the product still answers, by the Python path
    assert cs.car_motion_free(start, far, "reeds-shepp", sc.turning_radius) == \
        pure.curve_free(start, reeds_shepp_segments(start, far, sc.turning_radius), sc.turning_radius, q1=far)


_coord = st.one_of(st.floats(-20, 20), st.floats(-1e12, 1e12), st.sampled_from([0.0, -0.0, 6.0, 1e-300]))
_angle = st.one_of(st.floats(-7, 7), st.floats(-3e6, 3e6), st.sampled_from([0.0, -0.0, math.pi, -math.pi, 2.0**20]))


@compiled
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.tuples(_coord, _coord, _angle), st.tuples(_coord, _coord, _angle), st.sampled_from(["dubins", "reeds-shepp"]),
       st.sampled_from([0.3, 1.0, 2.5, 1e-6]), st.booleans())
def test_hypothesis_compiled_motion_never_differs(scenes, q0, q1, kind, radius, near):
    """Any poses, near and absurd: where the compiled motion decides, it is the compiled curve
    check of the Python segments (answer and chain end, bit for bit); where it declines, the
    Python segments raise or the product runs the Python path. ``near``: q0 and q1 are the
    scene's start and goal moved by a hundredth of the drawn values (free motions too)."""
    sc, cs, pure = scenes["u_turn.toml"]
    if near:
        s0, s1 = tuple(sc.all_queries()[0].start), tuple(sc.all_queries()[0].goal)
        q0 = tuple(float(v + 0.01 * math.tanh(w)) for v, w in zip(s0, q0))
        q1 = tuple(float(v + 0.01 * math.tanh(w)) for v, w in zip(s0 if radius < 1 else s1, q1))
    seg = dubins_segments if kind == "dubins" else reeds_shepp_segments
    got, end = compiled_motion(cs, q0, q1, kind, radius)
    try:
        segs = seg(q0, q1, radius)
    except ValueError:
        assert got == -1  # Python refuses these poses: the compiled call never answers them
        return
    if got >= 0:
        assert got == compiled_answer(cs, q0, segs, radius), (q0, q1, segs)
        f = motions.car_curve(cs, MAX_HULLS, FLOOR_REL, ARC_CHUNK)
        grids = [cs.slab(k)._fast for k in range(cs.slabs)]
        assert end == tuple(f(grids, q0[0], q0[1], wrap_angle(q0[2]), segs, radius)[1:]), (q0, q1, segs)
