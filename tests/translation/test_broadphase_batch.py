"""The grid's batched classification equals the piece-by-piece one, cell for cell.

The reference below is the per-piece loop the grid used before its pieces were
classified in blocks: every cell state, blocker, candidate list and edge mask must
come out the same on the bundled scenes (and on a scene with wide pieces). Pieces
wider than MASK_EDGES are classified through their chord polygons (one piece at a
time in the reference, with WIDE_MASK as mask); that route is checked on its own
below against the full per-piece test and shapely: never a kept cell dropped, never
a cell called inside that is not, and not many more MIXED cells.
"""
import glob
import os

import numpy as np
import pytest
import shapely

from conftest import SCENARIOS
from cspace.translation.broadphase import BLOCKED, MASK_EDGES, MIXED, WIDE_MASK, GridIndex
from cspace.translation.cspace import CSpace
from cspace.kernel.polygons.disk import disk_polygon
from cspace.kernel.minkowski.merge import minkowski_sum


def per_piece(g: GridIndex, pieces, k):
    """One piece's (cells, inside, masks) as the grid classifies it on its own."""
    if len(pieces[k]) <= MASK_EDGES:
        return g._classify(pieces[k])
    _, cells, inside, masks = g._classify_many(pieces, [k])
    return cells, inside, masks


def reference(g: GridIndex, pieces):
    state = np.zeros(g.nx * g.ny, dtype=np.int8)
    blocker = np.full(g.nx * g.ny, -1, dtype=np.int64)
    cand = {}
    for k, p in enumerate(pieces):
        cells, inside, masks = per_piece(g, pieces, k)
        state[cells[inside]] = BLOCKED
        blocker[cells[inside]] = k
        for c, m in zip(cells[~inside].tolist(), masks[~inside].tolist()):
            cand.setdefault(c, []).append((k, int(m)))
    for c in cand:
        if state[c] != BLOCKED:
            state[c] = MIXED
    return state, blocker, cand


FILES = sorted(glob.glob(os.path.join(SCENARIOS, "*.toml")))


@pytest.mark.parametrize("path", FILES, ids=os.path.basename)
def test_batched_classification_equals_per_piece(path):
    cs = CSpace.from_scenario(path, grid_cells=1 << 14)
    g = cs.index
    state, blocker, cand = reference(g, cs.pieces)
    assert np.array_equal(g.state, state)
    assert np.array_equal(g.blocker, blocker)
    for c in range(g.nx * g.ny):
        got = list(zip(g._cand_list[g._starts_list[c]:g._starts_list[c + 1]],
                       g.cand_masks_list[g._starts_list[c]:g._starts_list[c + 1]]))
        assert got == cand.get(c, []) or state[c] == BLOCKED and not got, c


def test_wide_and_narrow_pieces_together():
    pieces = [disk_polygon((3.0, 3.0), 2.0, max_error=1e-5), np.array([[1.0, 1.0], [5.0, 1.5], [4.0, 6.0]]),
              disk_polygon((7.0, 6.0), 1.0, max_error=1e-2), disk_polygon((8.0, 2.0), 1.5, max_error=1e-4)]
    assert len(pieces[0]) > MASK_EDGES and len(pieces[2]) <= MASK_EDGES and len(pieces[3]) > MASK_EDGES
    g = GridIndex(pieces, (0, 10, 0, 10), cells=4096)
    state, blocker, cand = reference(g, pieces)
    assert np.array_equal(g.state, state) and np.array_equal(g.blocker, blocker)
    for c in range(g.nx * g.ny):
        got = list(zip(g._cand_list[g._starts_list[c]:g._starts_list[c + 1]],
                       g.cand_masks_list[g._starts_list[c]:g._starts_list[c + 1]]))
        assert got == cand.get(c, []) or state[c] == BLOCKED and not got


@pytest.mark.parametrize("seed", range(5))
def test_row_scan_equals_per_piece_on_wide_boxes(seed):
    # Boxes many cells wide go through the row scan (bisection on the same float
    # expression): long thin slivers, near-horizontal and near-vertical edges, big
    # blocks, pieces crossing the bounds, a piece rounded to a point.
    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(40):
        c = rng.uniform(-1, 11, 2)
        k = int(rng.integers(3, 12))
        ang = np.sort(rng.uniform(0, 2 * np.pi, k))
        r = rng.uniform(0.05, 4.0) * np.array([1.0, rng.choice([1.0, 1e-3, 1e-9])])
        rot = rng.uniform(0, 2 * np.pi) if rng.random() < 0.7 else rng.choice([0.0, np.pi / 2, 1e-13])
        pts = np.column_stack([r[0] * np.cos(ang), r[1] * np.sin(ang)])
        pts = pts @ np.array([[np.cos(rot), np.sin(rot)], [-np.sin(rot), np.cos(rot)]])
        from cspace import convex_hull

        h = convex_hull(pts + c)
        if len(h) >= 3:
            pieces.append(h)
    pieces.append(np.array([[5.0, 5.0], [5.0 + 1e-300, 5.0], [5.0, 5.0 + 1e-300]]))  # rounds to a point
    g = GridIndex(pieces, (0, 10, 0, 10), cells=int(rng.choice([4096, 1 << 14, 1 << 16])))
    state, blocker, cand = reference(g, pieces)
    assert np.array_equal(g.state, state) and np.array_equal(g.blocker, blocker)
    for c in np.flatnonzero(state == MIXED).tolist():
        got = list(zip(g._cand_list[g._starts_list[c]:g._starts_list[c + 1]],
                       g.cand_masks_list[g._starts_list[c]:g._starts_list[c + 1]]))
        assert got == cand.get(c, [])
    assert (state == BLOCKED).sum() > 100  # the scan's inside runs were exercised


def wide_pieces(rng):
    """Convex pieces of more than MASK_EDGES edges: big and small disks, a margin's
    rounded rectangles and triangles (long edges between arcs), thin rounded slivers,
    pieces crossing the bounds."""
    out = []
    for _ in range(12):
        c = rng.uniform(-1, 11, 2)
        kind = rng.integers(0, 3)
        if kind == 0:
            out.append(disk_polygon(tuple(c), float(rng.uniform(0.05, 4.0)), max_error=float(rng.choice([1e-3, 1e-5]))))
            continue
        w, h = rng.uniform(0.01, 5.0, 2)
        core = (np.array([[0, 0], [w, 0], [w, h], [0, h]]) if kind == 1
                else np.array([[0, 0], [w, 0.3 * h], [0.2 * w, h]]))
        r = float(rng.uniform(0.02, 1.0))
        out.append(minkowski_sum(core + c, disk_polygon((0.0, 0.0), r, max_error=1e-3 * r)))
    return [p for p in out if len(p) > MASK_EDGES]


@pytest.mark.parametrize("seed", range(6))
def test_chord_route_is_conservative_and_tight(seed):
    rng = np.random.default_rng(seed)
    pieces = wide_pieces(rng)
    g = GridIndex(pieces, (0, 10, 0, 10), cells=int(rng.choice([4096, 1 << 14])))
    ref_band = ours_band = 0
    for k, p in enumerate(pieces):
        full_cells, full_inside, _ = g._classify(p)  # every edge of the piece: the reference
        _, cells, inside, masks = g._classify_many(pieces, [k])
        assert (masks == WIDE_MASK).all()
        kept, ours = set(full_cells.tolist()), set(cells.tolist())
        assert kept <= ours  # never a cell dropped that may meet the piece
        assert set(cells[inside].tolist()) <= set(full_cells[full_inside].tolist())
        # Independently: each cell called inside lies in the closed piece (shapely), and
        # each cell dropped lies apart from it.
        poly = shapely.Polygon(p)
        i, j = cells % g.nx, cells // g.nx
        boxes = shapely.box(g.x0 + i * g.cw, g.y0 + j * g.ch, g.x0 + (i + 1) * g.cw, g.y0 + (j + 1) * g.ch)
        assert shapely.covers(poly, boxes[inside]).all()
        i0, i1 = int(max(np.floor((p[:, 0].min() - g.x0) * g.inv_w), 0)), int(min(np.floor((p[:, 0].max() - g.x0) * g.inv_w), g.nx - 1))
        j0, j1 = int(max(np.floor((p[:, 1].min() - g.y0) * g.inv_h), 0)), int(min(np.floor((p[:, 1].max() - g.y0) * g.inv_h), g.ny - 1))
        ii, jj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
        box_cells = (jj * g.nx + ii).ravel()
        dropped = np.array(sorted(set(box_cells.tolist()) - ours), dtype=np.int64)
        if dropped.size:
            di, dj = dropped % g.nx, dropped // g.nx
            far = shapely.box(g.x0 + di * g.cw, g.y0 + dj * g.ch, g.x0 + (di + 1) * g.cw, g.y0 + (dj + 1) * g.ch)
            assert not shapely.intersects(poly, far).any()
        ref_band += int((~full_inside).sum())
        ours_band += int((~inside).sum())
    # The chord polygons cost a band of MIXED cells a fraction of a cell wider.
    assert ours_band <= 1.5 * ref_band + 8 * len(pieces), (ours_band, ref_band)


def test_wide_masks_on_demand_equal_the_build_masks():
    # The mask a point test computes for a wide piece's cell is the one the full
    # per-piece classification gives that (cell, piece).
    rng = np.random.default_rng(7)
    pieces = wide_pieces(rng)
    g = GridIndex(pieces, (0, 10, 0, 10), cells=4096)
    checked = 0
    for k, p in enumerate(pieces):
        cells, inside, masks = g._classify(p)
        for c, m in zip(cells[~inside].tolist()[:40], masks[~inside].tolist()[:40]):
            assert g.edge_mask(p, c) == int(m)
            checked += 1
    assert checked > 100


def test_points_near_wide_pieces_match_the_exact_test():
    # A margin's pieces and disk obstacles: the point test (compiled, or the pure narrow
    # phase with masks computed on demand) equals the exact test and shapely.
    rng = np.random.default_rng(3)
    obstacles = [disk_polygon((3.0, 3.0), 1.5, max_error=1e-4), np.array([[6.0, 1.0], [9.0, 1.0], [9.0, 2.0], [6.0, 2.0]]),
                 np.array([[5.0, 5.0], [8.0, 6.0], [6.0, 8.5]])]
    robot = [np.array([[-0.2, -0.1], [0.2, -0.1], [0.0, 0.25]])]
    cs = CSpace((0, 10, 0, 10), obstacles, robot, margin=[disk_polygon((0.0, 0.0), 0.3, max_error=3e-4)])
    assert any(len(p) > MASK_EDGES for p in cs.pieces)
    union = shapely.union_all([shapely.Polygon(p) for p in cs.pieces])
    # points on a fine lattice near the boundaries, and random ones
    pts = np.vstack([rng.uniform(0, 10, (3000, 2)),
                     np.concatenate([p + rng.normal(0, 0.01, p.shape) for p in cs.pieces])])
    test = cs.point_test()
    got = np.array([test(float(x), float(y)) for x, y in pts])
    exact = np.array([cs._is_free_exact(float(x), float(y)) for x, y in pts])
    assert (got == exact).all()
    far = shapely.distance(union, shapely.points(pts)) > 1e-9
    inside = shapely.contains(union, shapely.points(pts))
    assert (got[far] == True).all() and (got[inside] == False).all()  # noqa: E712
