"""The compiled fast path (cspace/compiled/_fast.c) against the pure-Python path, its oracle.

Every answer the C routines give must be the exact one: on random and degenerate
queries (integer scenes, segments through vertices and along edges, zero-length
segments, points on boundaries) the compiled segment and point tests, where they
decide, agree with the pure path, and the public segment test agrees everywhere.
Skipped when the extension is not built (or CSPACE_PURE=1): then there is one path.
"""
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from conftest import ROOT
from cspace import CSpace

from cspace.compiled import fastpath
from cspace.kernel.polygons.predicates import orient2d_exact

needs_c = pytest.mark.skipif(not fastpath.ENABLED, reason="compiled fast path not built (or CSPACE_PURE=1)")


def _integer_scene(seed: int) -> CSpace:
    """Integer boxes and triangles with an integer robot: every C-obstacle vertex is an
    integer, so queries on integers touch edges and vertices exactly."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for _ in range(int(rng.integers(1, 7))):
        x, y = rng.integers(0, 10, 2)
        w, h = rng.integers(1, 4, 2)
        if rng.random() < 0.5:
            obstacles.append(np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]], dtype=float))
        else:
            obstacles.append(np.array([[x, y], [x + w, y], [x, y + h]], dtype=float))
    robot = [np.array([[0., 0], [1, 0], [0, 1]])] if seed % 2 else None
    return CSpace((0, 12, 0, 12), obstacles, robot, grid_cells=int(rng.choice([16, 64, 1024])))


_SCENES = {}


def scene(seed: int) -> CSpace:
    if seed not in _SCENES:
        _SCENES[seed] = _integer_scene(seed)
    return _SCENES[seed]


coord = st.one_of(st.integers(-1, 13).map(float), st.integers(-2, 26).map(lambda v: v / 2.0),
                  st.floats(-0.5, 12.5, allow_nan=False))


@needs_c
@settings(max_examples=400, deadline=None)
@given(st.integers(0, 11), coord, coord, coord, coord)
@example(seed=0, ax=0.0, ay=0.0, bx=2.2250738585e-313, by=1.0)  # a slope that overflowed: "free", wrongly
def test_segment_matches_pure(seed, ax, ay, bx, by):
    cs = scene(seed)
    want = cs._segment_pure(ax, ay, bx, by)
    r = fastpath._fast.segment(cs._fast, ax, ay, bx, by)
    if r >= 0:
        assert (r != 0) == want
    assert cs.segment_test()(ax, ay, bx, by) == want
    assert cs.segment_free((ax, ay), (bx, by)) == want


@needs_c
@settings(max_examples=300, deadline=None)
@given(st.integers(0, 11), coord, coord)
def test_point_matches_pure(seed, x, y):
    cs = scene(seed)
    want = cs._is_free_exact(x, y)
    r = fastpath._fast.point(cs._fast, x, y)
    if r >= 0:
        assert (r == 1) == want
    r = fastpath._fast.segment(cs._fast, x, y, x, y)  # a segment of length zero
    if r >= 0:
        assert (r != 0) == want


@needs_c
@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(st.integers(-4, 4).map(float), st.floats(-1e3, 1e3, allow_nan=False),
                          st.sampled_from([1e-300, -1e-300, 1e300, 0.1, 0.3, 2.0**-60])), min_size=6, max_size=6))
def test_orient_filter_certified(v):
    s = fastpath._fast.orient(*v)
    if s != 2:
        assert s == orient2d_exact(*v)


@needs_c
def test_random_polygons_motions_match():
    """Float scene (the bundled random_polygons): 3000 random motions, short and long."""
    cs = CSpace.from_scenario(os.path.join(ROOT, "scenarios", "random_polygons.toml"))
    xmin, xmax, ymin, ymax = cs.bounds
    rng = np.random.default_rng(1)
    fast = cs.segment_test()
    for _ in range(3000):
        a = rng.uniform((xmin, ymin), (xmax, ymax))
        b = a + rng.normal(size=2) * (xmax - xmin) * rng.choice([0.01, 0.1, 0.5])
        b = np.clip(b, (xmin, ymin), (xmax, ymax))
        args = (float(a[0]), float(a[1]), float(b[0]), float(b[1]))
        assert fast(*args) == cs._segment_pure(*args), args


@needs_c
def test_nonfinite_and_out_of_bounds_go_to_python():
    cs = scene(0)
    assert fastpath._fast.segment(cs._fast, float("nan"), 1.0, 2.0, 2.0) == -1
    assert fastpath._fast.segment(cs._fast, -1.0, 1.0, 2.0, 2.0) == -1
    with pytest.raises(ValueError):
        cs.segment_free((float("nan"), 1.0), (2.0, 2.0))
    assert cs.segment_free((-1.0, 1.0), (2.0, 2.0)) is False


def test_cspace_pure_forces_the_pure_path():
    env = dict(os.environ, CSPACE_PURE="1")
    out = subprocess.run([sys.executable, "-c", "import cspace.compiled.fastpath as f; print(f.ENABLED)"],
                         env=env, capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "False"


# ---------------------------------------------------------------- SE(2)

def _se2_pair(seed: int):
    """The same integer SE(2) scene twice: compiled, and pure (every slab built pure)."""
    from cspace import SE2CSpace

    rng = np.random.default_rng(100 + seed)
    obstacles = []
    for _ in range(int(rng.integers(1, 6))):
        x, y = rng.integers(0, 10, 2)
        w, h = rng.integers(1, 4, 2)
        obstacles.append(np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]], dtype=float))
    robot = [np.array([[-2., -0.5], [2, -0.5], [2, 0.5], [-2, 0.5]])] if seed % 2 else \
        [np.array([[0., 0], [2, 0], [2, 1]]), np.array([[0., 0], [2, 1], [0, 2]])]
    fast = SE2CSpace((0, 12, 0, 12), obstacles, robot, slabs=8)
    with fastpath.disabled():
        pure = SE2CSpace((0, 12, 0, 12), obstacles, robot, slabs=8)
        for k in range(pure.slabs):
            pure.slab(k)
    return fast, pure


_SE2 = {}


def se2_pair(seed: int):
    if seed not in _SE2:
        _SE2[seed] = _se2_pair(seed)
    return _SE2[seed]


angle = st.one_of(st.sampled_from([0.0, -np.pi, np.pi / 2, -np.pi / 2, 1.0]), st.floats(-np.pi, np.pi - 1e-9))


@needs_c
@settings(max_examples=300, deadline=None)
@given(st.integers(0, 3), coord, coord, angle)
def test_se2_pose_matches_pure(seed, x, y, th):
    fast, pure = se2_pair(seed)
    assert fast._fast is not None and pure._fast is None
    assert fast.is_free((x, y, th)) == pure.is_free((x, y, th))


@needs_c
@settings(max_examples=60, deadline=None)
@given(st.integers(0, 3), coord, coord, angle, coord, coord, angle)
def test_se2_motion_matches_pure(seed, x0, y0, a0, x1, y1, a1):
    fast, pure = se2_pair(seed)
    assert fast.motion_free((x0, y0, a0), (x1, y1, a1)) == pure.motion_free((x0, y0, a0), (x1, y1, a1))


@needs_c
def test_se2_bundled_scene_matches_pure():
    """A float SE(2) scene (the bundled car maze, 8 slabs): 3000 random poses."""
    from cspace import SE2CSpace, load_scenario

    sc = load_scenario(os.path.join(ROOT, "scenarios", "se2", "car_maze.toml"))
    fast = SE2CSpace.from_scenario(sc, slabs=8)
    with fastpath.disabled():
        pure = SE2CSpace.from_scenario(sc, slabs=8)
        for k in range(pure.slabs):
            pure.slab(k)
    xmin, xmax, ymin, ymax = sc.bounds
    rng = np.random.default_rng(2)
    f, g = fast.pose_test(), pure.pose_test()
    for x, y, th in rng.uniform((xmin, ymin, -np.pi), (xmax, ymax, np.pi), (3000, 3)).tolist():
        assert f(x, y, th) == g(x, y, th), (x, y, th)


def _grids_equal(a, b) -> bool:
    return (np.array_equal(a.state, b.state) and np.array_equal(a.blocker, b.blocker)
            and np.array_equal(a._cand, b._cand) and np.array_equal(a._starts, b._starts)
            and list(a.cand_masks_list) == list(b.cand_masks_list) and a.stats() == b.stats())


def _both_routes(pieces, bounds, cells, monkeypatch):
    from cspace.translation.broadphase import GridIndex
    from cspace.translation.cellclass import CellClassifier

    c = GridIndex(pieces, bounds, cells=cells)
    monkeypatch.setattr(CellClassifier, "compiled", False)
    n = GridIndex(pieces, bounds, cells=cells)
    monkeypatch.undo()
    return c, n


@needs_c
def test_grid_handle_holds_read_only_arrays():
    # The handle holds the grid's and the pieces' arrays instead of copying them: they are
    # read-only from then on, and the handle keeps them alive after their owners are gone.
    import gc

    from cspace.compiled import _fast
    from cspace.translation.broadphase import GridIndex
    from cspace.kernel.polygons.pieces import PieceSet

    pieces = [np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]]), np.array([[1.0, 1.0], [3.0, 1.5], [2.0, 3.0]])]
    g, ps = GridIndex(pieces, (0, 10, 0, 10), cells=256), PieceSet(pieces)
    h = fastpath.grid_handle(g, ps, (0, 10, 0, 10))
    for a in (g.state, g.blocker, g._starts, g._cand, ps.offsets, ps.start):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[...] = 0
    queries = [(5.0, 5.0), (0.5, 0.5), (2.0, 2.0), (6.0 + 1e-9, 5.0)]
    before = [_fast.point(h, x, y) for x, y in queries] + [_fast.segment(h, 0.5, 5.0, 9.5, 5.0)]
    del g, ps, pieces
    gc.collect()
    [np.ones(4096) for _ in range(64)]  # fresh allocations over any freed memory
    assert [_fast.point(h, x, y) for x, y in queries] + [_fast.segment(h, 0.5, 5.0, 9.5, 5.0)] == before
    assert before[0] == 0 and before[1] == 1


@needs_c
@pytest.mark.parametrize("margin", [0.0, 0.01])
def test_compiled_classification_builds_the_same_grid(margin, monkeypatch):
    # The C route of the grid build evaluates every cell of each box with the numpy
    # route's doubles: the same states, blockers, candidates and masks, on every bundled
    # translation scene, with and without a margin (wide pieces: chord polygons).
    import dataclasses
    import glob

    from conftest import SCENARIOS
    from cspace import load_scenario

    files = sorted(glob.glob(os.path.join(SCENARIOS, "*.toml"))) + sorted(glob.glob(os.path.join(SCENARIOS, "ompl", "*.toml")))
    checked = 0
    for path in files:
        sc = load_scenario(path)
        if sc.space != "translation" or sc.name == "env2":
            continue
        xmin, xmax, ymin, ymax = sc.bounds
        if margin:
            sc = dataclasses.replace(sc, clearance=margin * max(xmax - xmin, ymax - ymin))
        cs = CSpace.from_scenario(sc)
        for cells in (None, 1 << 14):
            c, n = _both_routes(cs.pieces, cs.bounds, cells, monkeypatch)
            assert _grids_equal(c, n), (path, cells)
            checked += 1
    assert checked > 20


@needs_c
@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_compiled_classification_on_random_pieces(seed):
    # Slivers, near-axis edges, pieces crossing the bounds, a piece rounded to a point,
    # wide disks: the compiled and numpy routes build the same grid.
    import pytest as _pytest

    from cspace import convex_hull
    from cspace.kernel.polygons.disk import disk_polygon

    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(int(rng.integers(1, 30))):
        c = rng.uniform(-1, 11, 2)
        if rng.random() < 0.2:
            pieces.append(disk_polygon(tuple(c), float(rng.uniform(0.05, 3)), max_error=float(rng.choice([1e-2, 1e-4]))))
            continue
        k = int(rng.integers(3, 12))
        ang = np.sort(rng.uniform(0, 2 * np.pi, k))
        r = rng.uniform(0.05, 4.0) * np.array([1.0, rng.choice([1.0, 1e-3, 1e-9])])
        rot = rng.uniform(0, 2 * np.pi)
        pts = np.column_stack([r[0] * np.cos(ang), r[1] * np.sin(ang)])
        pts = pts @ np.array([[np.cos(rot), np.sin(rot)], [-np.sin(rot), np.cos(rot)]])
        h = convex_hull(pts + c)
        if len(h) >= 3:
            pieces.append(h)
    pieces.append(np.array([[5.0, 5.0], [5.0 + 1e-300, 5.0], [5.0, 5.0 + 1e-300]]))
    mp = _pytest.MonkeyPatch()
    try:
        c, n = _both_routes(pieces, (0, 10, 0, 10), int(rng.choice([4096, 1 << 14])), mp)
    finally:
        mp.undo()
    assert _grids_equal(c, n)


@needs_c
@pytest.mark.slow
def test_compiled_entries_leave_huge_pieces_to_the_numpy_routes(monkeypatch):
    # _fast.entries classifies pieces of up to 1024 edges whose box holds up to 2^20
    # cells and hands the others back: a 2000-gon and a triangle whose box holds ~1.4
    # million cells go through the numpy routes, next to a long strip and a wide disk; the grid equals the
    # all-numpy one, and the same again from packed vertices given by the caller.
    from cspace.kernel.polygons.disk import disk_polygon
    from cspace.kernel.polygons.pieces import PieceSet
    from cspace.translation.broadphase import GridIndex

    huge = disk_polygon((3.0, 3.0), 2.0, max_error=1e-7)
    assert len(huge) > 1024
    pieces = [huge, np.array([[1.0, 6.0], [9.5, 6.2], [5.0, 9.9]]), disk_polygon((7.0, 3.0), 1.5, max_error=1e-4),
              np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 0.5], [0.0, 0.5]])]
    cells = 1 << 22  # the last piece's box: ~2^21 cells
    c, n = _both_routes(pieces, (0, 10, 0, 10), cells, monkeypatch)
    assert _grids_equal(c, n)
    ps = PieceSet(pieces)
    g = GridIndex(pieces, (0, 10, 0, 10), cells=cells, packed=ps)
    assert _grids_equal(g, n)
    assert (n.state == 2).sum() > 1000


@needs_c
def test_compiled_path_builds_no_pure_only_structures():
    # A scene pays only for the stages it needs: with the compiled walk, the pure segment
    # walk's coarse grid, its summed-area table and the pieces' scalar lists are never built
    # by point and segment queries that C decides; the pure path builds them on first use.
    cs = CSpace.from_scenario(os.path.join(ROOT, "scenarios", "random_polygons.toml"))
    rng = np.random.default_rng(0)
    xmin, xmax, ymin, ymax = cs.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], (400, 2))
    for (ax, ay), (bx, by) in zip(pts[:-1], pts[1:]):
        cs.segment_free((ax, ay), (bx, by))
        cs.is_free((ax, ay))
    assert cs._coarse is None and cs.index._sat_rows is None
    with fastpath.disabled():
        pure = CSpace.from_scenario(os.path.join(ROOT, "scenarios", "random_polygons.toml"))
    for (ax, ay), (bx, by) in zip(pts[:-1], pts[1:]):
        assert pure.segment_free((ax, ay), (bx, by)) == cs.segment_free((ax, ay), (bx, by))
    assert pure._coarse is not None and pure.coarse.nx * pure.coarse.ny <= pure.index.nx * pure.index.ny


@needs_c
def test_nearly_vertical_segments_never_come_out_free_wrongly():
    # A segment whose x-extent is subnormal (or tiny) has a slope that overflows; the
    # compiled walk then clipped each column's rows to nothing and answered "free"
    # without testing a piece (found by hypothesis on a segment touching a triangle's
    # edge). Now it walks the column's whole y-range: never a false "free".
    checked = 0
    for seed in range(12):
        cs = scene(seed)
        for x in [float(v) for v in range(13)] + [0.5, 6.25]:
            for dx in (5e-324, 2.2250738585e-313, 1e-300, 1e-200, 1e-30):
                for y0, y1 in ((0.0, 1.0), (0.5, 3.0), (1.0, 11.0), (2.0, 2.5), (0.0, 12.0)):
                    if x + dx > 12.0:
                        continue
                    want = cs._segment_pure(x, y0, x + dx, y1)
                    r = fastpath._fast.segment(cs._fast, x, y0, x + dx, y1)
                    if r >= 0:
                        assert (r != 0) == want, (seed, x, dx, y0, y1)
                    assert cs.segment_free((x, y0), (x + dx, y1)) == want
                    checked += 1
    assert checked > 1000


def test_the_built_extension_is_the_build_of_these_sources():
    """setup.py compiles the C sources' fingerprint in; the suite must run the build of the
    sources it tests (after a pull that changed them, rebuild: pip install -e .)."""
    import importlib.util

    from cspace.compiled.fingerprint import fingerprint

    if importlib.util.find_spec("cspace.compiled._fast") is None:
        pytest.skip("the compiled fast path is not built")
    import cspace.compiled._fast as ext

    assert ext.source_hash == fingerprint(os.path.dirname(fastpath.__file__))


def test_an_extension_built_from_other_sources_is_not_run(tmp_path):
    """A copy of the package whose C source changed after the build: its fast path is off, with a
    warning and --version saying why (a car_motion taking a new argument ran stale code that
    raised TypeError mid-plan)."""
    import importlib.util
    import shutil

    if importlib.util.find_spec("cspace.compiled._fast") is None:
        pytest.skip("the compiled fast path is not built")
    src = os.path.dirname(os.path.dirname(fastpath.__file__))
    shutil.copytree(src, tmp_path / "cspace", ignore=shutil.ignore_patterns("__pycache__"))
    code = ("import warnings, cspace.compiled.fastpath as f; print(f.compiled(), f.STALE is not None)")
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "CSPACE_PURE": "0"}
    fresh = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert fresh.stdout.split() == ["True", "False"], fresh.stderr
    with open(tmp_path / "cspace" / "compiled" / "_carmotion.c", "a") as fh:
        fh.write("\n/* edited after the build */\n")
    edited = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert edited.stdout.split() == ["False", "True"] and "pip install -e ." in edited.stderr, edited.stderr
