"""The compiled GJK loop (``gjk`` in cspace/spaces/_fast.c) against the pure loop, its oracle.

The C loop repeats the pure loop's float operations in the same order, so everything
must match to the bit: the loop's raw result (closest points, iterations, inside flag,
simplex, extent; compared by float.hex, so even the sign of a zero counts), and
gjk_distance's answer with and without ``loop=`` (distance, points, iterations, status).
Skipped when the extension is not built (or CSPACE_PURE=1), except the pure-path test.
"""
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cspace.kernel import gjk
from cspace.kernel.disk import disk_polygon
from cspace.kernel.gjk import gjk_distance
from cspace.kernel.hull import convex_hull
from cspace.spaces import fastpath

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
needs_c = pytest.mark.skipif(not fastpath.compiled(), reason="compiled fast path not built (or CSPACE_PURE=1)")


def bits(v):
    """v with every float as its hex string (so 0.0 and -0.0 differ), recursively."""
    if isinstance(v, float):
        return v.hex()
    if isinstance(v, (tuple, list)):
        return tuple(bits(x) for x in v)
    if isinstance(v, np.ndarray):
        return bits(v.tolist())
    return v


def pure_raw(a: np.ndarray, b: np.ndarray, max_iterations: int):
    """The pure loop's raw result and _scale on the local frame, as gjk_distance builds it."""
    ox, oy = a[0].tolist()
    al = [(x - ox, y - oy) for x, y in a.tolist()]
    bl = [(x - ox, y - oy) for x, y in b.tolist()]
    return (*gjk._loop(al, bl, max_iterations), gjk._scale(al, bl))


def check(A, B, iterations=(gjk.MAX_ITERATIONS,)):
    """Compiled and pure agree bit for bit: the raw loop and gjk_distance's answer."""
    a, b = np.asarray(A, dtype=np.float64).reshape(-1, 2), np.asarray(B, dtype=np.float64).reshape(-1, 2)
    loop = fastpath.gjk_loop()
    for it in iterations:
        with np.errstate(over="ignore", invalid="ignore"):
            finite = np.isfinite(a - a[0]).all() and np.isfinite(b - a[0]).all()
        if finite:
            assert bits(loop(a, b, it)) == bits(pure_raw(a, b, it)), (a.tolist(), b.tolist(), it)
        p = gjk_distance(a, b, it)
        c = gjk_distance(a, b, it, loop=loop)
        assert bits(tuple(c)) == bits(tuple(p)), (a.tolist(), b.tolist(), it)
    return p


def test_pure_path_without_a_loop():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    d = gjk_distance(sq, sq + (3.0, 0.0), loop=None)
    assert (d.distance, d.status, d.point_a.tolist(), d.point_b.tolist()) == (2.0, "separated", [1.0, 0.0],
                                                                            [3.0, 0.0])
    assert gjk_distance(sq, sq + (1.0, 0.0), loop=None).status == "touching"
    with fastpath.disabled():
        assert fastpath.gjk_loop() is None


@needs_c
def test_points_segments_touching_overlapping():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    cases = [
        ([[0, 0]], [[0, 0]]), ([[0, 0]], [[3, 4]]), ([[0.5, 0.5]], sq), ([[1, 0.5]], sq),
        ([[0, 0], [2, 0]], [[1, 0], [1, 1]]), ([[0, 0], [2, 0]], [[3, 0], [4, 0]]),
        ([[0, 0], [2, 0]], [[1, 1], [3, 1]]), ([[0, 0], [0, 0]], [[0, 0], [1, 0]]),
        (sq, sq), (sq, sq + (1, 0)), (sq, sq + (1, 1)), (sq, sq + (0.5, 0.25)), (sq, sq + (1 + 1e-15, 0)),
        (sq, sq * 0.5 + 0.25), (sq, sq + (3, 0)), (sq + 1e8, sq + 1e8 + (1, 0)), (sq * 1e-300, sq * 1e-300 + 2e-300),
        (sq * 1e300, sq * 1e300 + (1e300, 0)), ([[-1e308, 0]], [[1e308, 0]]),
    ]
    for A, B in cases:
        check(A, B, iterations=(0, 1, 2, 3, gjk.MAX_ITERATIONS))


@needs_c
def test_disks_against_disks():
    rng = np.random.default_rng(3)
    for _ in range(60):
        r1, r2 = rng.uniform(0.1, 3, 2)
        c1 = rng.uniform(-5, 5, 2)
        gap = rng.choice([-0.5, 0.0, 1e-12, 0.3]) * r1
        direction = rng.normal(size=2)
        c2 = c1 + direction / np.linalg.norm(direction) * (r1 + r2 + gap)
        A = disk_polygon(c1, r1, sides=int(rng.integers(8, 200)))
        B = disk_polygon(c2, r2, sides=int(rng.integers(8, 200)))
        check(A, B)
        check(A, B[:1])


@needs_c
def test_thousands_of_small_degenerate_cases():
    """Integer point sets on a tiny grid: repeated points, collinear simplices, flat triangles
    (the degenerate branch of _solve3), contacts; raw point sets and their hulls; capped loops."""
    rng = np.random.default_rng(7)
    for t in range(4000):
        span = 2 if t % 3 else 5
        A = rng.integers(-span, span + 1, (int(rng.integers(1, 7)), 2)).astype(float)
        B = rng.integers(-span, span + 1, (int(rng.integers(1, 7)), 2)).astype(float)
        if t % 4 == 0:  # collinear sets: every simplex is flat
            A[:, 1] = A[:, 0] * 2 - 1
            B[:, 1] = B[:, 0] * 2 - 1
        if t % 2:
            A, B = convex_hull(A), convex_hull(B)
        check(A, B, iterations=(1, 2, 3, gjk.MAX_ITERATIONS) if t % 10 == 0 else (gjk.MAX_ITERATIONS,))


def _near_degenerate(rng, t):
    """Slivers: nearly collinear sets at an irrational slope, touching edges, repeated points
    rounded apart, tiny sets far out: where _solve3 meets flat triangles (its fallback)."""
    n, m = rng.integers(1, 7, 2)
    kind = t % 4
    d = rng.normal(size=2)
    d /= np.linalg.norm(d)
    if kind == 0:
        A = rng.uniform(-5, 5, n)[:, None] * d + rng.normal(size=(n, 2)) * rng.choice([0, 1e-16, 1e-13])
        B = (rng.uniform(-5, 5, m)[:, None] * d + rng.normal(size=2) * rng.choice([0, 1e-15, 1e-12, 1e-9])
             + rng.normal(size=(m, 2)) * rng.choice([0, 1e-16, 1e-13]))
    elif kind == 1:
        A = rng.uniform(-3, 3, n)[:, None] * d
        B = rng.uniform(-3, 3, m)[:, None] * d + rng.choice([0, 1e-300, 5e-324])
    elif kind == 2:
        A = rng.normal(size=(n, 2))
        B = A[rng.integers(0, n, m)] * (1 + rng.normal(size=(m, 1)) * 1e-15)
    else:
        A, B = rng.uniform(-1, 1, (n, 2)) * 1e-9 + 1e6, rng.uniform(-1, 1, (m, 2)) * 1e-9 + 1e6
    return A, B


@needs_c
def test_flat_triangles_take_the_same_branch(monkeypatch):
    """The fallback of _solve3 (a flat triangle: its first best edge by _norm2, which only the
    fallback calls) is reached many times, and the compiled loop follows it to the bit. The
    kept example cycles to the cap in both loops; picking the LAST best edge on a tie
    (``<=`` for ``<``) ends it at 3 iterations instead."""
    calls = [0]
    norm2 = gjk._norm2

    def counting(c):
        calls[0] += 1
        return norm2(c)

    monkeypatch.setattr(gjk, "_norm2", counting)
    check([[1.6960842630367832, 2.1569179341836784], [0.3418966365277215, 0.4347914800196032],
           [-0.9108063407999812, -1.1582764924204039], [-0.7648139369616554, -0.9726173002705609]],
          [[0.3993262990149289, 0.5078250383588488], [0.13649715952600297, 0.17358404753996667]],
          iterations=range(1, 8))
    rng = np.random.default_rng(1)
    for t in range(6000):
        check(*_near_degenerate(rng, t))
    assert calls[0] >= 100


coords = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)


@needs_c
@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(coords, coords), min_size=1, max_size=200),
       st.lists(st.tuples(coords, coords), min_size=1, max_size=200),
       st.sampled_from([1e-3, 1.0, 1e3, 1e6]), st.sampled_from([0.0, 1.0, -1e4, 1e8]),
       st.tuples(coords, coords), st.booleans(), st.booleans())
def test_random_convex_sets_match(pa, pb, scale, offset, shift, hull, quantise):
    a = np.array(pa) * scale + offset
    b = (np.array(pb) + np.array(shift) * 2.0) * scale + offset
    if quantise:  # coarse coordinates: many ties and collinear points
        a, b = np.round(a, 1 - int(np.log10(scale))), np.round(b, 1 - int(np.log10(scale)))
    if hull:
        a, b = convex_hull(a), convex_hull(b)
    check(a, b)


@needs_c
def test_loop_input_checks():
    loop = fastpath.gjk_loop()
    ok = np.zeros((2, 2))
    for bad in (np.zeros((0, 2)), np.zeros((2, 3)), np.zeros(4), np.zeros((2, 2), dtype=np.float32)):
        with pytest.raises(ValueError):
            loop(bad, ok, 64)
        with pytest.raises(ValueError):
            loop(ok, bad, 64)
    strided = np.arange(12.0).reshape(3, 4)[:, ::2]  # not contiguous: read through its strides
    assert bits(loop(strided, ok, 64)) == bits(pure_raw(strided, ok, 64))
    assert loop(np.array([[-1e308, 0.0]]), np.array([[1e308, 0.0]]), 64) is None  # local frame overflows


# ---------------------------------------------------------------- path clearance


def _plans():
    from cspace import load_scenario
    from planners.plan import plan

    out = []
    for name, clearance in (("basic", 0.1), ("maze", 0.3), ("disks", 0.3), ("random_polygons", 1.1),
                            ("u_robot", 0.2), ("parts", 0.2)):
        sc = load_scenario(os.path.join(ROOT, "scenarios", f"{name}.toml"))
        for planner in (None, "exact"):
            r = plan(sc, planner=planner, seed=0, clearance=clearance)
            if r.solved:
                out.append((f"{name}/{planner}", r))
    return out


@needs_c
@pytest.mark.slow
def test_path_clearance_compiled_equals_pure_on_bundled_scenes():
    from cspace.spaces.clearance import path_clearance

    plans = _plans()
    assert len(plans) >= 8
    for name, r in plans:
        rob, obs = r.cspace.robot_pieces, r.cspace.obstacle_pieces
        fast = path_clearance(r.path, rob, obs)
        with fastpath.disabled():
            pure = path_clearance(r.path, rob, obs)
        assert bits(tuple(fast)) == bits(tuple(pure)), name
        assert fast.distance == r.min_clearance, name
        # a path moved by small offsets: other contacts and ties
        rng = np.random.default_rng(len(name))
        moved = r.path + rng.normal(size=r.path.shape) * 0.05
        with fastpath.disabled():
            pure = path_clearance(moved, rob, obs)
        assert bits(tuple(path_clearance(moved, rob, obs))) == bits(tuple(pure)), name


@needs_c
def test_se2_lower_bound_compiled_equals_pure():
    from cspace.spaces.clearance import se2_path_clearance

    rng = np.random.default_rng(5)
    obstacles = [convex_hull(rng.uniform(0, 2, (8, 2)) + rng.uniform(0, 10, 2)) for _ in range(6)]
    bar = [np.array([[-1.0, -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])]
    path = np.c_[rng.uniform(0, 10, (5, 2)), rng.uniform(-3, 3, 5)]
    fast = se2_path_clearance(path, bar, obstacles, angle_step=1e-2)
    with fastpath.disabled():
        pure = se2_path_clearance(path, bar, obstacles, angle_step=1e-2)
    assert bits(tuple(fast)) == bits(tuple(pure))
