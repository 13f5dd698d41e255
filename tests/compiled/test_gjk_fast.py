"""The compiled GJK loop (``gjk`` in cspace/compiled/_fast.c) against the pure loop, its oracle.

The C loop repeats the pure loop's float operations in the same order, so everything
must match to the bit: the loop's raw result (closest points, iterations, inside flag,
simplex, extent; compared by float.hex, so even the sign of a zero counts), and
gjk_distance's answer with and without ``loop=`` (distance, points, iterations, status).
Skipped when the extension is not built (or CSPACE_PURE=1), except the pure-path test.
"""
import math
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import ROOT
from cspace.kernel.distance import gjk
from cspace.kernel.polygons.disk import disk_polygon
from cspace.kernel.distance.gjk import gjk_distance
from cspace.kernel.polygons.hull import convex_hull
from cspace.compiled import fastpath

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


@pytest.mark.slow
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
    from planners import plan

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
    from cspace.translation.clearance import path_clearance

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
    from cspace.se2.clearance import se2_path_clearance

    rng = np.random.default_rng(5)
    obstacles = [convex_hull(rng.uniform(0, 2, (8, 2)) + rng.uniform(0, 10, 2)) for _ in range(6)]
    bar = [np.array([[-1.0, -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])]
    path = np.c_[rng.uniform(0, 10, (5, 2)), rng.uniform(-3, 3, 5)]
    fast = se2_path_clearance(path, bar, obstacles, angle_step=1e-2)
    with fastpath.disabled():
        pure = se2_path_clearance(path, bar, obstacles, angle_step=1e-2)
    assert bits(tuple(fast)) == bits(tuple(pure))


# ------------------------------------------- min_clearance's compiled search (_nearest.c)


def _scene(rng, n_obstacles: int, grid: bool):
    """Random convex obstacles on both sides of a corridor, a robot of 0, 1 or 2 convex
    pieces and a path along the corridor (many pairs at nearly equal distances, so the
    search improves its best often); on ``grid``, integer coordinates (contacts, equal
    distances, repeated path points)."""
    def convex(c, r, k):
        pts = rng.uniform(-r, r, (k, 2)) + c
        return convex_hull(np.round(pts) if grid else pts)

    centres = np.c_[rng.uniform(0, 40, n_obstacles), rng.choice([-1, 1], n_obstacles) * rng.uniform(4, 12, n_obstacles)]
    obstacles = [convex(c, rng.uniform(1, 3), int(rng.integers(3, 9))) for c in centres]
    robot = [convex((0.0, 0.0), 1.0, 5), convex((0.5, 0.0), 0.5, 4)][: int(rng.integers(0, 3))]
    n = int(rng.integers(1, 30))
    path = np.c_[np.sort(rng.uniform(0, 40, n)), rng.uniform(-1, 1, n)]
    if grid:
        path = np.round(path)
        path = np.repeat(path, rng.integers(1, 3, len(path)), axis=0)  # still segments
    return obstacles, robot, path


@needs_c
@pytest.mark.parametrize("seed", range(12))
def test_path_clearance_scan_equals_the_pure_search(seed):
    # The compiled pass over losing pairs (clearance_scan), the compiled boxes and their
    # gaps leave path_clearance's answer as the pure search finds it, to the bit (distance,
    # place, obstacle point, segment): on random scenes, few and many pairs (the filtered
    # route, the tight bounds after GJK_FIRST pairs), integer ones with contacts, ties and
    # still segments, and pieces given with a closing repeat of their first vertex.
    from cspace.translation.clearance import path_clearance

    rng = np.random.default_rng(seed)
    obstacles, robot, path = _scene(rng, (8, 60, 200)[seed % 3], grid=seed % 4 == 1)
    if seed % 4 == 2:  # along a wall at one distance: ties on every segment (the tight bounds' case)
        obstacles = [o + (0.0, 40.0) for o in obstacles] + [np.array([[-5.0, -3.0], [45, 2], [45, 2.5], [-5, -2.5]])]
        path = np.c_[np.linspace(0, 40, 60), np.linspace(0, 40, 60) * 0.1 - 0.5 + 1.2]  # parallel to the wall
    if seed % 4 == 3:
        obstacles = [np.vstack([o, o[:1]]) for o in obstacles]
        robot = [np.vstack([r, r[:1]]) for r in robot]
    for moved in (path, path + rng.normal(size=path.shape) * 0.1):
        fast = path_clearance(moved, robot, obstacles)
        with fastpath.disabled():
            pure = path_clearance(moved, robot, obstacles)
        assert bits(tuple(fast)) == bits(tuple(pure)), (seed, fast, pure)


@needs_c
def test_pack_boxes_and_box_gaps_equal_numpy():
    from cspace.kernel.polygons.polygon import pack, piece_boxes

    rng = np.random.default_rng(3)
    pieces = [rng.normal(size=(int(k), 2)) * 10.0 ** rng.integers(-3, 4) for k in rng.integers(0, 9, 40)]
    pieces[5] = np.asfortranarray(pieces[5])  # strides other than (16, 8)
    pieces[7] = np.zeros((0, 2))
    xy, off, lo, hi, scale = fastpath.pack_boxes(pieces)
    pts, sizes = pack(pieces)
    lo2, hi2 = piece_boxes(pieces)
    assert bits(xy) == bits(pts) and off.tolist() == [0, *np.cumsum(sizes).tolist()]
    assert bits(lo) == bits(lo2) and bits(hi) == bits(hi2)
    assert scale == max(float(hi2.max()), -float(lo2.min()))
    # not finite float64 (n, 2) arrays: numpy's turn
    assert fastpath.pack_boxes([np.array([[0.0, np.nan]])]) is None
    assert fastpath.pack_boxes([np.array([[0, 1]])]) is None
    assert fastpath.pack_boxes([np.zeros((3, 3))]) is None
    # the distances between boxes: numpy's doubles, empty pieces' boxes (inf) included
    a, b = rng.normal(size=(30, 2)) * 5, rng.normal(size=(30, 2)) * 5
    blo, bhi = np.minimum(a, b), np.maximum(a, b)
    gap = np.maximum(np.maximum(lo[None] - bhi[:, None], blo[:, None] - hi[None]), 0.0)
    assert bits(fastpath.box_gaps(blo, bhi, lo, hi)) == bits(np.hypot(gap[..., 0], gap[..., 1]))


@needs_c
def test_clearance_scan_decisions_and_input_checks():
    # One pair, decided as Python's search decides it: a loss, a new best (its distance and
    # the obstacle's closest point), a tie (math.hypot decides: a loss), the bounds' stop,
    # a contact (left to Python); bad arguments raise (never read out of bounds), an id out
    # of range stops the scan where it stands.
    from cspace.compiled import _fast

    sq = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    placed = [np.vstack([sq, sq + 1])]  # the square at (0, 0) and at (1, 1): one segment
    xy, off = np.vstack([sq + 5]), np.array([0, 4], dtype=np.int64)
    still, lbs, q = np.zeros(1, dtype=bool), np.array([0.0]), np.array([0], dtype=np.int64)
    args = [placed, 2, still, xy, off, q, None, lbs, 1, 0, 1.0, 0.0, -1, 64, 2.0**-101, 2.0**100, 1e-9, math.hypot]

    def scan(**kw):
        names = ["placed", "npoints", "still", "xy", "off", "queue", "pairs", "lbs", "no", "pos", "best", "slack"]
        return _fast.clearance_scan(*[kw.get(n, a) for n, a in zip(names, args)], *args[12:])

    tie = math.hypot(3.0, 3.0)  # from (2, 2) to (5, 5)
    assert scan(best=1.0) == (1, 1, None)  # a loss against a best of 1
    assert scan(best=100.0) == (1, 1, (tie, 0, 5.0, 5.0))  # the new best
    assert scan(best=tie) == (1, 1, None)  # a tie loses
    assert scan(best=math.nextafter(tie, 9)) == (1, 1, (tie, 0, 5.0, 5.0))
    assert scan(lbs=np.array([2.0])) == (0, 0, None)  # the bounds stop the search
    assert scan(xy=np.vstack([sq + 2]), best=100.0) == (0, 0, None)  # touching: Python's exact test
    assert scan(queue=np.array([3], dtype=np.int64)) == (0, 0, None)  # out of range
    with pytest.raises(ZeroDivisionError):  # an error in the hypot called is raised
        _fast.clearance_scan(*args[:10], tie, *args[11:-1], lambda x, y: 1 / 0)
    with pytest.raises(ValueError):
        scan(placed=[np.zeros((3, 2))])  # 3 rows for 2 path points
    with pytest.raises(ValueError):
        scan(placed=[np.zeros((4, 2), dtype=np.int64)])  # 8-byte items, but not float64
    with pytest.raises(TypeError):
        _fast.clearance_scan(*args[:-1])
    with pytest.raises(ValueError):
        _fast.box_gaps(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((1, 2)), np.zeros((1, 2)), np.zeros(3))
