"""Fast clearance of many points, and a cheap certified bound on a segment's clearance.

The planners' clearance objective asks for the clearance of every state it adds (once per
state) and for a value of every motion it weighs (hundreds per added state under RRTstar).
:class:`PointClearance` answers the first: the exact float distance from a point to the
nearest convex piece, through a uniform grid whose cells each keep, on first use, only the
edges of the pieces that can be nearest to some point of the cell. :func:`disc_bound` answers
the second from the two ends' clearances and the segment's length alone (no geometry).

Why the cells' edges suffice: for a cell of centre m and half-diagonal h, the nearest
vertex v of any piece gives, for every point p of the cell, dist(p, pieces) <= |p - v| <=
|m - v| + h = U; a piece whose bounding box is farther than U from the cell's box is
farther than U from every point of the cell, so it is never the nearest.
"""
from __future__ import annotations

import math

import numpy as np

CELLS_PER_PIECE = 4  # grid cells per piece (at least MIN_CELLS, at most MAX_CELLS in all)
MIN_CELLS, MAX_CELLS = 256, 1 << 14
FEW_EDGES = 24  # a cell with at most this many candidate edges is measured in a Python loop (faster than numpy)


def disc_bound(c1: float, c2: float, length: float) -> float:
    """A certified lower bound of the clearance of a segment whose ends have clearances
    ``c1`` and ``c2`` (>= 0) and whose length is ``length``: no obstacle meets the open
    disc of radius c1 about one end nor that of radius c2 about the other, so the segment
    is at least as far from obstacles as from the nearest point outside both discs (the
    discs' crossing points, or an end): 0 when the discs are apart, min(c1, c2) for a
    point, and it tends to the true clearance as the segment shortens.

    >>> disc_bound(1.0, 1.0, 0.0), round(disc_bound(1.0, 1.0, 1.0), 6), disc_bound(1.0, 1.0, 2.5)
    (1.0, 0.866025, 0.0)
    >>> disc_bound(0.5, 3.0, 2.0)  # the larger disc covers the segment up to the small one's end
    0.5
    """
    if length <= 0.0 or math.isinf(c1) or math.isinf(c2):  # a point, or no obstacles at all
        return min(c1, c2)
    if length >= c1 + c2:
        return 0.0
    a = (length * length + c1 * c1 - c2 * c2) / (2.0 * length)  # the crossing points' projection
    if a <= 0.0:
        return c1
    if a >= length:
        return c2
    return min(c1, c2, math.sqrt(max(c1 * c1 - a * a, 0.0)))


class PointClearance:
    """Float distance from a point to the nearest edge of convex ``pieces``: for a point
    outside every piece (a free state of a C-space whose pieces they are) that is its
    clearance, the distance to the nearest piece; inf without pieces. ``bounds`` is
    (xmin, xmax, ymin, ymax); points outside it are answered too (slowly:
    against every edge).

    >>> pc = PointClearance([np.array([[4., 4], [6, 4], [6, 6], [4, 6]])], (0, 10, 0, 10))
    >>> pc(1.0, 5.0), pc(7.0, 7.0) == math.hypot(1, 1)
    (3.0, True)
    """

    def __init__(self, pieces: list, bounds: tuple, cells: int | None = None):
        ps = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in pieces]
        ps = [p for p in ps if len(p)]
        self.pieces = ps
        xmin, xmax, ymin, ymax = (float(b) for b in bounds)
        n = cells if cells is not None else min(MAX_CELLS, max(MIN_CELLS, CELLS_PER_PIECE * len(ps)))
        w, hgt = max(xmax - xmin, 1e-300), max(ymax - ymin, 1e-300)
        self.nx = max(1, int(round(math.sqrt(n * w / hgt))))
        self.ny = max(1, int(round(n / self.nx)))
        self.x0, self.y0 = xmin, ymin
        self.sx, self.sy = self.nx / w, self.ny / hgt  # cells per unit
        self.cw, self.ch = w / self.nx, hgt / self.ny
        if ps:
            self.verts = np.concatenate(ps)
            self.lo = np.array([p.min(axis=0) for p in ps])
            self.hi = np.array([p.max(axis=0) for p in ps])
        self._cells: dict = {}

    def _cell(self, i: int, j: int):
        """The candidate edges of cell (i, j) (every edge for ``i = -1``), computed on first
        use: (ax, ay, dx, dy, 1/|d|^2) as five arrays, or as a list of rows when they are few."""
        if i < 0:
            keep = np.arange(len(self.pieces))
        else:
            eps = 1e-9 * (self.cw + self.ch)  # the cell widened: a point floored into it may lie ulps out
            cx0, cy0 = self.x0 + i * self.cw - eps, self.y0 + j * self.ch - eps
            cx1, cy1 = cx0 + self.cw + 2 * eps, cy0 + self.ch + 2 * eps
            mx, my, half = 0.5 * (cx0 + cx1), 0.5 * (cy0 + cy1), 0.5 * math.hypot(cx1 - cx0, cy1 - cy0)
            u = float(np.hypot(self.verts[:, 0] - mx, self.verts[:, 1] - my).min()) + half
            gx = np.maximum(np.maximum(self.lo[:, 0] - cx1, cx0 - self.hi[:, 0]), 0.0)
            gy = np.maximum(np.maximum(self.lo[:, 1] - cy1, cy0 - self.hi[:, 1]), 0.0)
            keep = np.flatnonzero(np.hypot(gx, gy) <= u * (1.0 + 1e-12))
        a = np.concatenate([self.pieces[k] for k in keep.tolist()])
        b = np.concatenate([np.roll(self.pieces[k], -1, axis=0) for k in keep.tolist()])
        d = b - a
        dd = np.einsum("ij,ij->i", d, d)
        inv = np.where(dd > 0.0, 1.0 / np.maximum(dd, np.finfo(float).tiny), 0.0)
        cols = (a[:, 0].copy(), a[:, 1].copy(), d[:, 0].copy(), d[:, 1].copy(), inv)
        entry = list(zip(*(c.tolist() for c in cols))) if len(inv) <= FEW_EDGES else cols
        self._cells[(i, j)] = entry
        return entry

    def __call__(self, x: float, y: float) -> float:
        """Distance from (x, y) to the nearest edge of the pieces (inf without pieces)."""
        if not self.pieces:
            return math.inf
        fx, fy = (x - self.x0) * self.sx, (y - self.y0) * self.sy
        if 0.0 <= fx <= self.nx and 0.0 <= fy <= self.ny:  # in the grid
            i, j = min(int(fx), self.nx - 1), min(int(fy), self.ny - 1)
        else:  # outside the bounds (NaN too): every edge
            i = j = -1
        e = self._cells.get((i, j)) or self._cell(i, j)
        if type(e) is list:  # few edges: a loop over (ax, ay, dx, dy, 1/|d|^2) rows
            best = math.inf
            for ax, ay, dx, dy, inv in e:
                px, py = x - ax, y - ay
                t = (px * dx + py * dy) * inv
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
                ex, ey = px - t * dx, py - t * dy
                dd = ex * ex + ey * ey
                if dd < best:
                    best = dd
            return math.sqrt(best)
        ax, ay, dx, dy, inv = e
        px, py = x - ax, y - ay
        t = np.minimum(np.maximum((px * dx + py * dy) * inv, 0.0), 1.0)
        return float(np.hypot(px - t * dx, py - t * dy).min())
