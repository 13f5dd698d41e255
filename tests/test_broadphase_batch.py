"""The grid's batched classification equals the piece-by-piece one, cell for cell.

The reference below is the per-piece loop the grid used before its pieces were
classified in blocks: every cell state, blocker, candidate list and edge mask must
come out the same on the bundled scenes (and on a scene with wide pieces).
"""
import glob
import os

import numpy as np
import pytest

from conftest import SCENARIOS
from cspace.spaces.broadphase import BLOCKED, MIXED, GridIndex
from cspace.spaces.cspace import CSpace
from cspace.kernel.disk import disk_polygon


def reference(g: GridIndex, pieces):
    state = np.zeros(g.nx * g.ny, dtype=np.int8)
    blocker = np.full(g.nx * g.ny, -1, dtype=np.int64)
    cand = {}
    for k, p in enumerate(pieces):
        cells, inside, masks = g._classify(p)
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
              disk_polygon((7.0, 6.0), 1.0, max_error=1e-2)]
    assert len(pieces[0]) > 62 and len(pieces[2]) <= 62
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
