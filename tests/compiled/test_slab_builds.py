"""The batched slab builds (cspace/se2/slab_build.py) against the slab-by-slab route.

On the compiled path ``SE2CSpace.slab(k)`` builds k's whole run of slabs at once (hulls, inner
sets, one pair-sum call, ``CSpace.from_sums``); on the pure path (the oracle) each slab is a
``CSpace`` of its own. Both must give the same slabs: the same pieces, pairs, grids, inner
BLOCKED cells and combined grids, and so the same pose and segment answers. The batched
pieces (slab hulls, inner sets, blocked cells, ``from_sums``) are also checked one by one
against the functions they stand for, on both paths.
"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import ROOT
from cspace import CSpace, SE2CSpace, load_scenario
from cspace.kernel.polygons.hull import convex_hull
from cspace.kernel.minkowski.merge import reflect
from cspace.kernel.slabs.slab import slab_hull, slab_inner, slab_range
from cspace.compiled import fastpath
from cspace.translation.broadphase import BLOCKED, GridIndex
from cspace.translation.build import pair_sums
from cspace.se2.slab_build import build_slabs, slab_hulls, slab_inners, slab_run

needs_c = pytest.mark.skipif(not fastpath.ENABLED, reason="compiled fast path not built (or CSPACE_PURE=1)")
CAR = np.array([[-0.6, -0.25], [0.5, -0.25], [0.7, -0.1], [0.7, 0.1], [0.5, 0.25], [-0.6, 0.25]])


def convex(rng, centre, radius, integer=False) -> np.ndarray:
    """A random convex polygon (the hull of random points about ``centre``), at least a triangle."""
    radius = max(radius, 2.0) if integer else radius  # rounded to integers, a smaller one may stay flat
    for _ in range(100):
        pts = centre + rng.uniform(-radius, radius, (int(rng.integers(3, 9)), 2))
        if integer:
            pts = np.round(pts)
        h = convex_hull(pts)
        if len(h) >= 3:
            return h
    return np.round(centre) + np.array([[0., 0], [1, 0], [0, 1]])


def scene(seed: int):
    """(bounds, obstacles, robot parts) of a random scene: float or integer coordinates,
    robots with the reference point inside, outside (no inner set), several parts, a car."""
    rng = np.random.default_rng(seed)
    integer = seed % 3 == 0
    obstacles = [convex(rng, rng.uniform(1, 19, 2), rng.uniform(0.3, 3), integer) for _ in range(int(rng.integers(0, 25)))]
    kind = seed % 4
    if kind == 0:
        robot = [CAR]
    elif kind == 1:
        robot = [convex(rng, np.zeros(2), 1.0)]
    elif kind == 2:  # away from the reference point: an empty inner set at some angles
        robot = [convex(rng, np.array([1.5, 0.0]), 0.4)]
    else:
        robot = [convex(rng, np.array([-0.5, 0.0]), 0.6), convex(rng, np.array([0.6, 0.2]), 0.5)]
    return (0.0, 20.0, 0.0, 20.0), obstacles, robot


def pair(make):
    """The same SE(2) C-space twice: compiled (batched runs) and pure (slab by slab), every slab built."""
    fast = make()
    for k in range(fast.slabs):
        fast.slab(k)
    with fastpath.disabled():
        pure = make()
        for k in range(pure.slabs):
            pure.slab(k)
    return fast, pure


def grids_equal(a: GridIndex, b: GridIndex) -> bool:
    return (np.array_equal(a.state, b.state) and np.array_equal(a.blocker, b.blocker)
            and np.array_equal(a._cand, b._cand) and np.array_equal(a._starts, b._starts)
            and list(a.cand_masks_list) == list(b.cand_masks_list) and a.stats() == b.stats()
            and (a.nx, a.ny, a.x0, a.y0, a.inv_w, a.inv_h, a.margin) == (b.nx, b.ny, b.x0, b.y0, b.inv_w, b.inv_h, b.margin))


def assert_same_slabs(a: SE2CSpace, b: SE2CSpace) -> None:
    assert a.slabs == b.slabs
    for k in range(a.slabs):
        x, y = a.slab(k), b.slab(k)
        assert len(x.robot_pieces) == len(y.robot_pieces)
        assert all(np.array_equal(p, q) for p, q in zip(x.robot_pieces, y.robot_pieces)), k  # the slab hulls
        assert len(x.pieces) == len(y.pieces), k
        assert all(np.array_equal(p, q) for p, q in zip(x.pieces, y.pieces)), k
        assert x.piece_pairs == y.piece_pairs and np.array_equal(x.piece_obstacle, y.piece_obstacle), k
        assert grids_equal(x.index, y.index), k
        i, j = a._inner[k], b._inner[k]
        assert (i is False) == (j is False), k
        if i is not False:
            assert np.array_equal(i, j), k
        assert a._grids[k][:5] == b._grids[k][:5], k  # the combined grid's rows and frame
        strip = lambda st: [dict(s.as_dict(), seconds=0.0) for s in st]  # noqa: E731
        assert strip(x.stages) == strip(y.stages), k
    ra, rb = a.report(), b.report()
    assert [(d["slab"], d["pieces"], d["inner_pieces"]) for d in ra["slabs_built"]] == \
        [(d["slab"], d["pieces"], d["inner_pieces"]) for d in rb["slabs_built"]]


def assert_same_answers(a: SE2CSpace, b: SE2CSpace, seed: int, n: int = 400) -> None:
    """Poses (x, y, θ) and each slab's segments, from uniform draws and near obstacle vertices."""
    rng = np.random.default_rng(seed)
    xmin, xmax, ymin, ymax = a.bounds
    pts = rng.uniform((xmin - 1, ymin - 1), (xmax + 1, ymax + 1), (n, 2))
    if a.obstacle_pieces:
        verts = np.concatenate(a.obstacle_pieces)
        pts[: n // 2] = verts[rng.integers(0, len(verts), n // 2)] + rng.normal(0, 0.7, (n // 2, 2))
    th = rng.uniform(-math.pi, math.pi, n)
    fa, fb = a.pose_test(), b.pose_test()
    for (x, y), t in zip(pts.tolist(), th.tolist()):
        assert fa(x, y, t) == fb(x, y, t), (x, y, t)
    for k in range(a.slabs):
        sa, sb = a.slab(k), b.slab(k)
        for (x0, y0), (x1, y1) in zip(pts[: 20].tolist(), np.roll(pts, 7, axis=0)[: 20].tolist()):
            assert sa.segment_free((x0, y0), (x1, y1)) == sb.segment_free((x0, y0), (x1, y1)), (k, x0, y0, x1, y1)
            assert sa.is_free((x0, y0)) == sb.is_free((x0, y0))


# ---------------------------------------------------------------- batched pieces, one by one


polygon_seeds = st.integers(0, 10**6)


@settings(max_examples=60, deadline=None)
@given(polygon_seeds, st.integers(4, 70), st.floats(0.0, 1e3))
def test_slab_hulls_are_slab_hull(seed, K, scale):
    rng = np.random.default_rng(seed)
    pieces = [convex(rng, rng.uniform(-2, 2, 2), rng.uniform(0.01, 3)) for _ in range(int(rng.integers(1, 4)))]
    lo = [slab_range(k, K)[0] for k in range(K)]
    hi = [slab_range(k, K)[1] for k in range(K)]
    got = slab_hulls(pieces, lo, hi, scale)
    for k in range(K):
        for p, h in zip(pieces, got[k]):
            assert np.array_equal(h, slab_hull(p, lo[k], hi[k], scale=scale)), (k, p)


@settings(max_examples=60, deadline=None)
@given(polygon_seeds, st.integers(4, 70), st.sampled_from([0.0, 1e-12, 2.0**-44 * 30, 1e-3]))
def test_slab_inners_are_slab_inner(seed, K, pad):
    rng = np.random.default_rng(seed)
    # about the origin, beside it, far from it (the inner set empties at wide slabs)
    pieces = [convex(rng, rng.uniform(-1.5, 1.5, 2), rng.uniform(0.05, 2)) for _ in range(int(rng.integers(1, 4)))]
    lo = [slab_range(k, K)[0] - 1e-14 for k in range(K)]
    hi = [slab_range(k, K)[1] + 1e-14 for k in range(K)]
    got = slab_inners(pieces, lo, hi, pad)
    for k in range(K):
        for p, j in zip(pieces, got[k]):
            want = slab_inner(p, lo[k], hi[k], pad)
            assert j.shape == want.shape and np.array_equal(j, want), (k, p)


def test_slab_hulls_and_inners_of_degenerate_slabs():
    sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    lo, hi = [0.3, 0.0], [0.3, math.pi / 2]  # zero width: rotate_piece; a quarter turn
    for h, a, b in zip(slab_hulls([sq], lo, hi, 1.0), lo, hi):
        assert np.array_equal(h[0], slab_hull(sq, a, b, scale=1.0))
    with pytest.raises(ValueError):
        slab_hulls([sq], [0.0], [2.0], 1.0)  # wider than a quarter turn: slab_hull's error
    assert slab_inners([], [0.0], [0.1], 1e-12) == [[]]


def test_slab_run():
    assert slab_run(0, 64, 80) == range(0, 64)
    assert slab_run(63, 64, 1 << 12) == range(60, 64)
    assert slab_run(7, 10, 1 << 30) == range(7, 8)
    for K in (4, 10, 64, 100):
        for pairs in (1, 300, 5000, 1 << 20):
            runs = {tuple(slab_run(k, K, pairs)) for k in range(K)}
            assert sorted(k for r in runs for k in r) == list(range(K))  # a partition of the slabs
            assert all(k in slab_run(k, K, pairs) for k in range(K))


@settings(max_examples=40, deadline=None)
@given(polygon_seeds, st.integers(1, 30))
def test_blocked_cells_are_the_grids_blocked_cells(seed, n):
    rng = np.random.default_rng(seed)
    pieces = [convex(rng, rng.uniform(0, 10, 2), rng.uniform(0.2, 4), seed % 2 == 0) for _ in range(n)]
    shape = (int(rng.integers(1, 70)), int(rng.integers(1, 70)))
    g = GridIndex(pieces, (0, 10, 0, 10), shape=shape)
    assert np.array_equal(GridIndex.blocked_cells(pieces, (0, 10, 0, 10), shape), g.state == BLOCKED)
    with fastpath.disabled():
        assert np.array_equal(GridIndex.blocked_cells(pieces, (0, 10, 0, 10), shape), g.state == BLOCKED)
    assert not GridIndex.blocked_cells([], (0, 10, 0, 10), shape).any()


@settings(max_examples=40, deadline=None)
@given(polygon_seeds)
def test_from_sums_is_the_cspace(seed):
    bounds, obstacles, robot = scene(seed)
    neg = [reflect(r) for r in robot]
    for pure in (False, True):
        ctx = fastpath.disabled() if pure else _nothing()
        with ctx:
            a = CSpace(bounds, obstacles, robot, normalized=True, grid_cells=1024)
            b = CSpace.from_sums(bounds, obstacles, robot, pair_sums(obstacles, neg), grid_cells=1024)
        assert all(np.array_equal(p, q) for p, q in zip(a.pieces, b.pieces)) and len(a.pieces) == len(b.pieces)
        assert a.piece_pairs == b.piece_pairs and np.array_equal(a.piece_obstacle, b.piece_obstacle)
        assert grids_equal(a.index, b.index)
        strip = lambda st: [dict(s.as_dict(), seconds=0.0) for s in st]  # noqa: E731
        assert strip(a.stages) == strip(b.stages)
        assert (a._fast is None) == (b._fast is None) == (pure or not fastpath.ENABLED)
        rng = np.random.default_rng(seed)
        for x, y in rng.uniform(-1, 21, (50, 2)).tolist():
            assert a.is_free((x, y)) == b.is_free((x, y))


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_from_sums_checks_its_input():
    sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    with pytest.raises(ValueError):
        CSpace.from_sums((0, 4, 0, 4), [sq], [sq], [])
    with pytest.raises(ValueError):
        CSpace.from_sums((0, 4, 0, 4), [sq], [], [])
    with pytest.raises(ValueError, match="2\\^400"):  # checked unless the caller says it checked
        CSpace.from_sums((0, 4, 0, 4), [sq * 2.0**401], [-sq], pair_sums([sq * 2.0**401], [sq]))


@needs_c
def test_the_batched_slabs_check_the_range_once_for_all():
    """build_slabs hands from_sums checked=True: its own one check must see what the
    per-slab checks saw (here bounds past the supported range)."""
    from cspace.se2.slab_build import build_slabs

    sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    with pytest.raises(ValueError, match="2\\^400"):
        build_slabs((0.0, 2.0**401, 0.0, 4.0), [sq + 2], [sq - 0.5], [0.0, 0.1], [0.1, 0.2], scale=1.0, pad=1e-9,
                    grid_cells=64)


# ---------------------------------------------------------------- whole C-spaces: batched against pure


@pytest.mark.slow
@needs_c
@settings(max_examples=25, deadline=None)
@given(polygon_seeds, st.sampled_from([4, 8, 13, 16]))
def test_random_scenes_batched_equal_pure(seed, K):
    bounds, obstacles, robot = scene(seed)
    fast, pure = pair(lambda: SE2CSpace(bounds, obstacles, robot, slabs=K))
    assert_same_slabs(fast, pure)
    assert_same_answers(fast, pure, seed, n=150)


@needs_c
@pytest.mark.parametrize("seed", range(8))
def test_random_scenes_answers(seed):
    bounds, obstacles, robot = scene(seed)
    fast, pure = pair(lambda: SE2CSpace(bounds, obstacles, robot, slabs=16))
    assert_same_slabs(fast, pure)
    assert_same_answers(fast, pure, seed)


@needs_c
@pytest.mark.parametrize("name,robot", [("se2/car_maze.toml", None), ("maze.toml", None), ("maze.toml", CAR),
                                        ("u_robot.toml", None), ("se2/bug_trap.toml", None)])
def test_bundled_scenes_batched_equal_pure(name, robot):
    sc = load_scenario(os.path.join(ROOT, "scenarios", name), space="se2")
    if robot is None:
        make = lambda: SE2CSpace.from_scenario(sc, slabs=16)  # noqa: E731
    else:
        make = lambda: SE2CSpace(sc.bounds, [o.polygon for o in sc.obstacles], [robot],  # noqa: E731
                                 obstacle_holes=[o.holes for o in sc.obstacles], slabs=16)
    fast, pure = pair(make)
    assert_same_slabs(fast, pure)
    assert_same_answers(fast, pure, 5)


@needs_c
def test_margin_and_empty_scenes_batched_equal_pure():
    sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    bar = np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])
    disk = np.array([[0.2 * math.cos(t), 0.2 * math.sin(t)] for t in np.linspace(0, 2 * math.pi, 13)[:-1]])
    for make in (lambda: SE2CSpace((0, 10, 0, 10), [sq], [bar], slabs=8, margin=[disk]),
                 lambda: SE2CSpace((0, 10, 0, 10), [], [bar], slabs=8),
                 lambda: SE2CSpace((0, 10, 0, 10), [sq, sq + 0.5], [bar], slabs=8, grid_cells=100)):
        fast, pure = pair(make)
        assert_same_slabs(fast, pure)
        assert_same_answers(fast, pure, 1, n=200)


@needs_c
def test_runs_of_a_big_scene_and_lazy_slabs(monkeypatch):
    """A scene too big for one run builds the run holding the slab asked for, no more."""
    from cspace.se2 import slab_build

    bounds, obstacles, robot = scene(4)
    monkeypatch.setattr(slab_build, "SLAB_BATCH_PAIRS", 4 * len(obstacles) * 2 * len(robot))
    fast = SE2CSpace(bounds, obstacles, robot, slabs=16)
    fast.slab(5)
    assert [k for k in range(16) if fast._outer[k] is not None] == [4, 5, 6, 7]
    for k in range(16):
        fast.slab(k)
    with fastpath.disabled():
        pure = SE2CSpace(bounds, obstacles, robot, slabs=16)
        for k in range(16):
            pure.slab(k)
    assert_same_slabs(fast, pure)


def test_build_slabs_directly():
    """build_slabs on either path: the pure slab-by-slab route's C-spaces and inner cells."""
    bounds, obstacles, robot = scene(1)
    with fastpath.disabled():
        ref = SE2CSpace(bounds, obstacles, robot, slabs=8)
        for k in range(8):
            ref.slab(k)
    for pure in (False, True):
        with (fastpath.disabled() if pure else _nothing()):
            got = build_slabs(ref.bounds, ref.obstacle_pieces, ref.robot_pieces, ref._lo, ref._hi, scale=ref.scale,
                              pad=ref.pad, grid_cells=1 << 12)
        assert len(got) == 8
        for k, (outer, inner, n_inner, _, _) in enumerate(got):
            want = ref.slab(k)
            assert len(outer.pieces) == len(want.pieces)
            assert all(np.array_equal(p, q) for p, q in zip(outer.pieces, want.pieces))
            assert grids_equal(outer.index, want.index)
            assert (inner is False) == (ref._inner[k] is False)
            if inner is not False:
                assert np.array_equal(inner, ref._inner[k])
