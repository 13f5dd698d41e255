"""Broad phase for point and segment queries: a uniform grid with a precomputed occupancy.

This module owns the question "which convex pieces can a query near (x, y) touch?".
The grid covers the bounds; each cell is classified once, at build time:

- ``FREE``: no piece meets the closed cell, so every state in it is free;
- ``BLOCKED``: the closed cell lies inside one (closed, convex) piece, so every
  state in it collides;
- ``MIXED``: otherwise; the cell keeps the list of pieces that may meet it.

The classification is conservative: a cell is called FREE or BLOCKED only when the
float test is certified with a margin far larger than its rounding error; anything
in doubt is MIXED and goes to the exact narrow phase. A point query in a FREE or
BLOCKED cell therefore costs a few arithmetic operations, which is what makes a
Python validity checker affordable inside OMPL.
"""
from __future__ import annotations

import math
from array import array
from functools import cached_property

import numpy as np

from ..kernel.polygons.pieces import PieceSet
from ..kernel.polygons.polygon import piece_boxes
from ..compiled import fastpath
from .cellclass import MASK_EDGES, WIDE_MASK, CellClassifier  # noqa: F401  (the masks: part of the grid's API)

FREE, MIXED, BLOCKED = 0, 1, 2

# Relative margin for the certified cell classification: far above the rounding
# error of the few float operations used (about 1e-15 of the scene's scale).
_MARGIN = 1e-9


# The default grid: cells per piece and the fewest cells, on the pure path and on the
# compiled one (see GridIndex).
CELLS_PER_PIECE, MIN_CELLS = 256, 1 << 12
CELLS_PER_PIECE_COMPILED, MIN_CELLS_COMPILED = 32, 1 << 11

# Most (piece, cell) pairs the build classifies, before the grid is coarsened.
_PAIR_BUDGET = float(1 << 22)

def _ints(a: np.ndarray) -> array:
    """An int64 numpy array as an ``array.array('q')`` (one buffer copy).

    >>> _ints(np.array([3, -1])).tolist()
    [3, -1]
    """
    out = array("q")
    out.frombytes(np.ascontiguousarray(a, dtype=np.int64).tobytes())
    return out


def _box_shares(lo: np.ndarray, hi: np.ndarray, xmin: float, xmax: float, ymin: float, ymax: float) -> np.ndarray:
    """Fraction of the bounds covered by each piece's bounding box (clipped to the bounds).

    >>> _box_shares(np.array([[-1., 0]]), np.array([[1., 2]]), 0.0, 2.0, 0.0, 2.0).tolist()
    [0.5]
    """
    bw = np.minimum(hi[:, 0], xmax) - np.maximum(lo[:, 0], xmin)
    bh = np.minimum(hi[:, 1], ymax) - np.maximum(lo[:, 1], ymin)
    return np.maximum(bw, 0.0) * np.maximum(bh, 0.0) / ((xmax - xmin) * (ymax - ymin))


class GridIndex(CellClassifier):
    """Uniform grid over ``bounds`` classifying cells against convex ``pieces``.

    ``cells`` sets the cell count (default: from the pieces); ``shape`` = (nx, ny)
    fixes the columns and rows instead, to share another grid's cells; ``packed``: the
    pieces as a :class:`cspace.kernel.polygons.pieces.PieceSet` when the caller has one (its boxes
    and packed vertices are used, not computed again).

    >>> g = GridIndex([np.array([[-1., -1], [2, -1], [2, 2], [-1, 2]])], (0, 4, 0, 4), cells=16)
    >>> int(g.state_at(3.5, 3.5)), int(g.state_at(0.5, 0.5))
    (0, 2)
    """

    def __init__(self, pieces: list[np.ndarray], bounds, cells: int | None = None,
                 shape: tuple[int, int] | None = None, packed: PieceSet | None = None):
        self._frame(pieces, bounds, cells, shape, packed)
        n, nx, ny = len(pieces), self.nx, self.ny
        if not n:  # nothing to classify: every cell FREE
            cp = cm = np.zeros(0, np.int64)
            state, blocker = np.zeros(nx * ny, np.int8), np.full(nx * ny, -1, np.int64)
            starts = np.zeros(nx * ny + 1, np.int64)
            self._counts = (nx * ny, 0, 0)
        elif fastpath.compiled() and self.compiled:  # the same arrays, assembled in C
            cc, cp, cm, inside = self._classify_all(pieces, packed)
            state, blocker = np.empty(nx * ny, np.int8), np.empty(nx * ny, np.int64)
            starts, cand, masks = np.empty(nx * ny + 1, np.int64), np.empty(len(cc), np.int64), np.empty(len(cc), np.int64)
            self._counts = fastpath.assemble(cc, cp, cm, inside, n, state, blocker, starts, cand, masks)
            cp, cm = cand[: int(starts[-1])], masks[: int(starts[-1])]
        else:
            state, blocker, cp, cm, starts = self._assembled(*self._classify_all(pieces), n)
            self._counts = None
        self.state = state
        self.blocker = blocker
        self._cand = cp
        self._starts = starts
        self._masks = cm
        # Compact copies for the scalar hot path: indexing bytes or an array.array yields
        # a Python int as cheaply as a list does, and they are built by one copy of the
        # buffer instead of one Python object per cell (a million cells: ~1 ms, not ~50).
        # The state bytes serve every point test; the other copies only the Python narrow
        # phase, so they are made when it first runs (with the compiled path, rarely).
        self.state_list = state.astype(np.uint8).tobytes()
        self._rows = None
        self._sat_rows = None

    @classmethod
    def blocked_cells(cls, pieces: list[np.ndarray], bounds, shape: tuple[int, int],
                      packed: PieceSet | None = None) -> np.ndarray:
        """The cells ``GridIndex(pieces, bounds, shape=shape, packed=packed)`` calls BLOCKED, as
        a bool per cell (flat, row-major), without the rest of the grid (blockers,
        candidates, masks): the same frame and classification, fewer arrays. (The SE(2)
        slabs' inner grids: only their BLOCKED cells are read.)

        >>> sq = [np.array([[-1., -1], [2, -1], [2, 2], [-1, 2]])]
        >>> g = GridIndex(sq, (0, 4, 0, 4), shape=(4, 4))
        >>> bool((GridIndex.blocked_cells(sq, (0, 4, 0, 4), (4, 4)) == (g.state == BLOCKED)).all())
        True
        """
        g = cls.__new__(cls)
        g._frame(pieces, bounds, None, shape, packed)
        out = np.zeros(g.nx * g.ny, dtype=bool)
        if len(pieces):
            cc, _, _, inside = g._classify_all(pieces, packed)
            out[cc[inside]] = True
        return out

    def _frame(self, pieces: list[np.ndarray], bounds, cells: int | None, shape: tuple[int, int] | None,
               packed: PieceSet | None) -> None:
        """The grid's frame (columns and rows, cells, local origin, margin) and the pieces'
        boxes, as the classification reads them."""
        xmin, xmax, ymin, ymax = map(float, bounds)
        self.bounds = (xmin, xmax, ymin, ymax)
        n = len(pieces)
        w, h = xmax - xmin, ymax - ymin
        # each piece's box, in one pass
        self._lo, self._hi = (packed.lo, packed.hi) if packed is not None else piece_boxes(pieces)
        if cells is None:
            # Pure path: about 256 cells per piece, at least 64 x 64, measured on the bundled scenes
            # (plans of RRTConnect, compiled and pure paths), 1024 per piece and at least
            # 256 x 256 classified 2-4x longer for no faster query: a MIXED cell costs
            # the compiled narrow phase less than the Python call around it, and a
            # segment walks fewer cells. With the compiled narrow phase, 32 per piece and
            # at least 2048 cells plan as fast or faster than 64 and 4096 (RRTConnect, 10
            # interleaved seeds, wall time with the build, on 14 bundled scenes: 0.89-0.99x
            # on the small ones, where the build is a third of the plan; maze, ompl/normal
            # and ompl/thin within 3 %, ompl/env2 and ompl/thick within 1 % over 4 seeds),
            # and build faster; on the pure path 128 plans 15-25 % slower than 256 (maze,
            # office, ompl/normal), a MIXED cell costing a Python call there.
            per, least = (CELLS_PER_PIECE_COMPILED, MIN_CELLS_COMPILED) if fastpath.compiled() else (CELLS_PER_PIECE, MIN_CELLS)
            cells = int(min(max(per * n, least), 1 << 20)) if n else 1  # no piece: one FREE cell
            # Large, overlapping pieces (comb sums) would each cover a big share of that
            # grid: cap the (piece, cell) pairs the classification visits at ~2^22.
            # (Each share is at most 1: with n * cells within the budget, so is cover * cells.)
            cover = sum(_box_shares(self._lo, self._hi, xmin, xmax, ymin, ymax).tolist()) if n * cells > _PAIR_BUDGET else 0.0
            if cover * cells > _PAIR_BUDGET:
                cells = max(int(_PAIR_BUDGET / cover), 1 << 12)
        nx = max(1, min(4096, int(round(math.sqrt(cells * w / h)))))
        ny = max(1, min(4096, int(round(cells / nx))))
        if shape is not None:  # the same cells as another grid (the SE(2) inner grid)
            nx, ny = int(shape[0]), int(shape[1])
        self.nx, self.ny = nx, ny
        self.x0, self.y0 = xmin, ymin
        self.cw, self.ch = w / nx, h / ny
        self.inv_w, self.inv_h = nx / w, ny / h
        # Classification runs in a local frame centred on the bounds, so its rounding
        # error scales with the scene's extent; the shift itself may round by up to
        # an ulp of the largest coordinate, which the margin also covers.
        self.ox, self.oy = 0.5 * (xmin + xmax), 0.5 * (ymin + ymax)
        # The largest |coordinate| of the bounds and the pieces: over boxes [lo, hi] it is
        # max(hi, -lo) (an empty piece's box, lo = inf and hi = -inf, adds nothing).
        top = [float(max(self._hi.max(), -self._lo.min()))] if n else []
        big = max([abs(xmin), abs(xmax), abs(ymin), abs(ymax)] + top)
        self.margin = _MARGIN * max(w, h) + 64.0 * 2.0**-53 * big

    def _assembled(self, cc, cp, cm, inside, n: int):
        """The grid's arrays from its classified (cell, piece, mask, inside) entries:
        ``(state, blocker, candidates, masks, starts)`` (numpy; ``_fast.assemble`` in C)."""
        nx, ny = self.nx, self.ny
        state = np.zeros(nx * ny, dtype=np.int8)
        blocker = np.full(nx * ny, -1, dtype=np.int64)
        if cc.size:
            # A cell inside a piece is BLOCKED, its blocker the last such piece.
            blk = cc[inside]
            state[blk] = BLOCKED
            np.maximum.at(blocker, blk, cp[inside])
            cc, cp, cm = cc[~inside], cp[~inside], cm[~inside]
        if cc.size:
            # A cell touched by any piece but not wholly inside one is MIXED; its
            # candidates in piece order.
            order = np.argsort(cc * n + cp)  # by cell, then piece: (cell, piece) pairs are unique
            cc, cp, cm = cc[order], cp[order], cm[order]
            touched = np.zeros(nx * ny, dtype=bool)
            touched[cc] = True
            state[touched & (state != BLOCKED)] = MIXED
            starts = np.zeros(nx * ny + 1, dtype=np.int64)  # cc is sorted: counts, summed
            np.cumsum(np.bincount(cc, minlength=nx * ny), out=starts[1:])
        else:
            cp = np.zeros(0, dtype=np.int64)
            cm = np.zeros(0, dtype=np.int64)
            starts = np.zeros(nx * ny + 1, dtype=np.int64)
        return state, blocker, cp, cm, starts

    @cached_property
    def blocker_list(self) -> array:
        """``blocker`` as an array.array (the pure path's scalar reads), made on first use."""
        return _ints(self.blocker)

    @cached_property
    def _cand_list(self) -> array:
        return _ints(self._cand)

    @cached_property
    def _starts_list(self) -> array:
        return _ints(self._starts)

    @cached_property
    def cand_masks_list(self) -> array:
        """For each candidate (cell, piece): a bit mask of the piece's edges whose line may
        pass within the margin of the cell (bit e: edge from vertex e-1 to e). Every other
        edge has the whole widened cell strictly on its inner side, so a point located in
        the cell needs no test against it. (Pieces of more than MASK_EDGES edges:
        WIDE_MASK, see edge_mask.)"""
        return _ints(self._masks)

    @property
    def _sat(self) -> list[array]:
        """Summed-area table of non-FREE cells: the count in any block of cells in O(1),
        read as sat[j][i] (one array.array per row). Built on first use: only the pure
        segment walk reads it (the compiled one walks the cells itself)."""
        if self._sat_rows is None:
            busy = (self.state != FREE).reshape(self.ny, self.nx).astype(np.int64)
            sat = np.zeros((self.ny + 1, self.nx + 1), dtype=np.int64)
            np.cumsum(busy, axis=0, out=sat[1:, 1:])
            np.cumsum(sat[1:, 1:], axis=1, out=sat[1:, 1:])
            self._sat_rows = [_ints(r) for r in sat]
        return self._sat_rows

    def state_rows(self) -> list[bytes]:
        """The point test's view of the grid (built once, shared by every test made):
        one bytes row per grid row (FREE 0, MIXED 1, BLOCKED 2), each with a border
        cell (3) after the last column, and a border row after the last row."""
        if self._rows is None:
            nx, ny, flat = self.nx, self.ny, self.state_list
            border = bytes([3])
            self._rows = [flat[r * nx:(r + 1) * nx] + border for r in range(ny)] + [border * (nx + 1)]
        return self._rows

    # -- build -------------------------------------------------------------------

    # -- queries -----------------------------------------------------------------

    def cell_of(self, x: float, y: float) -> int:
        """Flat index of the cell holding (x, y) (clamped to the grid)."""
        i = math.floor((x - self.x0) * self.inv_w)
        j = math.floor((y - self.y0) * self.inv_h)
        i = 0 if i < 0 else (self.nx - 1 if i >= self.nx else i)
        j = 0 if j < 0 else (self.ny - 1 if j >= self.ny else j)
        return j * self.nx + i

    def state_at(self, x: float, y: float) -> int:
        """FREE, MIXED or BLOCKED for the cell holding (x, y)."""
        return self.state_list[self.cell_of(x, y)]

    def candidates(self, cell: int) -> np.ndarray:
        """Pieces that may meet a MIXED cell."""
        return self._cand[self._starts[cell] : self._starts[cell + 1]]

    def candidates_of(self, cells: np.ndarray) -> np.ndarray:
        """Distinct pieces that may meet any of ``cells`` (one vectorised gather)."""
        s, e = self._starts[cells], self._starts[cells + 1]
        counts = e - s
        total = int(counts.sum())
        if total == 0:
            return np.zeros(0, dtype=np.int64)
        idx = np.repeat(s - (np.cumsum(counts) - counts), counts) + np.arange(total)
        return np.unique(self._cand[idx])

    def segment_candidates(self, ax: float, ay: float, bx: float, by: float, on_blocker=None):
        """Pieces the closed segment a-b may meet: ``(blockers, candidates)`` as sets.

        The segment is halved recursively; a piece of it whose cell bounding box
        (widened by the margin) holds no non-FREE cell is free and dropped, in O(1)
        through the summed-area table. Pieces of at most 2 x 2 cells are leaves:
        their BLOCKED cells contribute their blocking piece, their MIXED cells their
        candidate pieces. The caller tests the original segment exactly against
        both sets, so the halving only has to be conservative, never exact.
        ``on_blocker(k)``, if given, is called on each new blocking piece as soon as
        it is found (nearest ``a`` first); when it returns True the walk stops and
        ``None`` is returned (the caller found a hit).
        """
        m, x0, y0, iw, ih = self.margin, self.x0, self.y0, self.inv_w, self.inv_h
        nx1, ny1 = self.nx - 1, self.ny - 1
        sat, state, nx = self._sat, self.state_list, self.nx
        blockers: set[int] = set()
        cands: set[int] = set()
        stack = [(ax, ay, bx, by)]
        while stack:
            px, py, qx, qy = stack.pop()
            i0 = math.floor(((px if px < qx else qx) - m - x0) * iw)
            i1 = math.floor(((qx if px < qx else px) + m - x0) * iw)
            j0 = math.floor(((py if py < qy else qy) - m - y0) * ih)
            j1 = math.floor(((qy if py < qy else py) + m - y0) * ih)
            i0 = 0 if i0 < 0 else i0
            j0 = 0 if j0 < 0 else j0
            i1 = nx1 if i1 > nx1 else i1
            j1 = ny1 if j1 > ny1 else j1
            if i1 < i0 or j1 < j0:
                continue
            if sat[j1 + 1][i1 + 1] - sat[j0][i1 + 1] - sat[j1 + 1][i0] + sat[j0][i0] == 0:
                continue  # every cell near this piece of the segment is FREE
            # A leaf: at most 2 x 2 cells, or a piece shorter than a cell (the margin may
            # span many cells when the scene is tiny against its coordinates, and halving
            # cannot shrink the widened box then), or one floats can no longer halve.
            if ((i1 - i0) < 2 and (j1 - j0) < 2) or (abs(qx - px) * iw < 1.0 and abs(qy - py) * ih < 1.0):
                for j in range(j0, j1 + 1):
                    for i in range(i0, i1 + 1):
                        c = j * nx + i
                        st = state[c]
                        if st == BLOCKED:
                            k = self.blocker_list[c]
                            if k not in blockers:
                                blockers.add(k)
                                if on_blocker is not None and on_blocker(k):
                                    return None
                        elif st == MIXED:
                            cands.update(self._cand_list[self._starts_list[c]:self._starts_list[c + 1]])
                continue
            mx, my = 0.5 * (px + qx), 0.5 * (py + qy)
            if (mx == px and my == py) or (mx == qx and my == qy):
                stack.append((px, py, px, py))  # cannot halve: one more pass as a leaf
                stack.append((qx, qy, qx, qy))
                continue
            stack.append((mx, my, qx, qy))
            stack.append((px, py, mx, my))
        return blockers, cands

    def stats(self) -> dict:
        """Cell counts by class, for reports."""
        free, mixed, blocked = self._counts or np.bincount(self.state, minlength=3).tolist()[:3]
        return {"cells": int(self.nx * self.ny), "grid": [int(self.nx), int(self.ny)],
                "free": free, "blocked": blocked, "mixed": mixed}
