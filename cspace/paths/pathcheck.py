"""Exact checks of a polygonal path against convex C-obstacle pieces, and the
degenerate pieces (points and segments) that area-based geometry cannot see.

A piece of zero area (a disk of radius below the coordinates' ulp collapses to a
point, a wall thinner than an ulp to a segment) is still a closed obstacle, but a
polygon union ignores it: the free space F built from areas would let a path run
straight through it. This module owns the two answers to that:

- :class:`Degenerate`: the zero-area pieces as points and segments, the rule for a
  path edge (its open part must miss them; an end may touch one only at a *wrap*
  point, the free tip of a segment or an isolated point strictly inside F, around
  which a path can bend) and those wrap points as extra graph nodes;
- :func:`path_violations`: an independent check of a finished path against every
  piece with exact predicates (:func:`cspace.kernel.polygons.predicates.orient2d_many`): no edge's
  open part enters a piece's interior (separating axis: an edge line of the piece
  with both ends on its closed outer side, or the edge's own line with the whole
  piece on one closed side), and the degenerate rule above.

Everything is decided by exact orientation signs, so a path is never accepted
because of rounding.
"""
from __future__ import annotations

import numpy as np

from ..kernel.polygons.polygon import as_array, collinear_extent, orientation, piece_boxes
from ..kernel.polygons.predicates import orient2d_many, orient2d_xy


def is_degenerate(piece) -> bool:
    """Exact: has the convex piece zero area (all its vertices on one line)?

    >>> is_degenerate([[0, 0], [1, 1], [2, 2]]), is_degenerate([[0, 0], [1, 0], [0, 1]])
    (True, False)
    """
    p = as_array(piece, copy=False)
    if len(p) < 3:
        return True
    return orientation(p) == 0 and _all_collinear(p)


def _all_collinear(p: np.ndarray) -> bool:
    lo, hi = p[np.lexsort((p[:, 0], p[:, 1]))[[0, -1]]]
    if (lo == hi).all():
        return True
    return not orient2d_many(lo, hi, p).any()


def split_pieces(pieces: list) -> tuple[list, list]:
    """``(proper, degenerate)``: pieces of positive area, and the others as their
    extent (one point or the two ends of a segment, :func:`collinear_extent`).

    A float area well above its rounding error settles most pieces at once; the
    rest are decided exactly.

    >>> proper, deg = split_pieces([np.array([[0., 0], [1, 0], [0, 1]]), np.array([[2., 2], [2, 2], [2, 2]])])
    >>> len(proper), deg[0].tolist()
    (1, [[2.0, 2.0]])
    """
    flat = _flat_mask(pieces)
    proper = [as_array(p, copy=False) for p, f in zip(pieces, flat) if not f]
    deg = [collinear_extent(p) for p, f in zip(pieces, flat) if f and len(p)]
    return proper, deg


def _flat_mask(pieces: list) -> list[bool]:
    """Which pieces have zero area: a float shoelace sum well above its rounding error
    settles a piece at once (all pieces in one vectorised pass), the rest are decided
    exactly (:func:`is_degenerate`)."""
    arrs = [as_array(p, copy=False) for p in pieces]
    sizes = np.array([len(p) for p in arrs], dtype=np.intp)
    out = sizes < 3
    big = np.flatnonzero(~out)
    if len(big):
        P = np.concatenate([arrs[k] for k in big.tolist()])
        n = sizes[big]
        starts = np.cumsum(n) - n
        first = np.repeat(starts, n)
        nxt = np.arange(len(P)) + 1
        nxt[starts + n - 1] = starts  # each ring closes on itself
        with np.errstate(all="ignore"):
            x, y = P[:, 0] - P[first, 0], P[:, 1] - P[first, 1]  # about each piece's first vertex
            l, r = x * y[nxt], y * x[nxt]
            area = np.add.reduceat(l - r, starts)
            size = np.add.reduceat(np.abs(l) + np.abs(r), starts)
        certain = (np.abs(area) > 1e-9 * size) & (size > 1e-280) & np.isfinite(size)
        for k in big[~certain].tolist():
            out[k] = is_degenerate(arrs[k])
    return out.tolist()


def _on_closed(px: float, py: float, c, d) -> bool:
    """Exact: is point p on the closed segment c-d (or equal to the point c = d)?"""
    if orient2d_xy(c[0], c[1], d[0], d[1], px, py) != 0:
        return False
    return min(c[0], d[0]) <= px <= max(c[0], d[0]) and min(c[1], d[1]) <= py <= max(c[1], d[1])


def open_meets(a, b, c, d) -> bool:
    """Exact: does the open segment (a, b) meet the closed segment [c, d] (a point if c = d)?

    >>> open_meets((0, 0), (2, 0), (1, 0), (1, 0)), open_meets((0, 0), (2, 0), (2, 0), (2, 5))
    (True, False)
    """
    ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
    cx, cy, dx, dy = float(c[0]), float(c[1]), float(d[0]), float(d[1])
    o1 = orient2d_xy(ax, ay, bx, by, cx, cy)
    o2 = orient2d_xy(ax, ay, bx, by, dx, dy)
    if o1 == 0 and o2 == 0:  # collinear (or c = d on the line): compare along the line
        k = 0 if ax != bx else 1
        lo_ab, hi_ab = sorted(((ax, ay)[k], (bx, by)[k]))
        lo_cd, hi_cd = sorted(((cx, cy)[k], (dx, dy)[k]))
        return lo_cd < hi_ab and hi_cd > lo_ab
    if (cx, cy) == (dx, dy):
        return False  # a point off the line
    o3 = orient2d_xy(cx, cy, dx, dy, ax, ay)
    o4 = orient2d_xy(cx, cy, dx, dy, bx, by)
    # The lines cross at one point; it is in [c, d] iff o1 o2 <= 0, and strictly
    # between a and b iff o3 o4 < 0 (o3 = 0 puts it at a, o4 = 0 at b).
    return o1 * o2 <= 0 and o3 * o4 < 0


class Degenerate:
    """The zero-area pieces of a search: the edge rule and the wrap nodes.

    ``region`` (a shapely polygon, the free component searched) decides which tips
    are strictly inside F; a tip on F's boundary or on another degenerate piece is
    no wrap point (the path cannot pass around it).
    """

    def __init__(self, extents: list, region=None):
        import shapely

        self.ext = [np.asarray(e, dtype=np.float64).reshape(-1, 2) for e in extents]
        segs = [(e[0], e[-1]) for e in self.ext]
        self.segs = segs
        lo = np.array([np.minimum(c, d) for c, d in segs]).reshape(-1, 2)
        hi = np.array([np.maximum(c, d) for c, d in segs]).reshape(-1, 2)
        self.lo, self.hi = lo, hi
        self.wraps: dict = {}  # tip (x, y) -> index of its piece
        for k, (c, d) in enumerate(segs):
            for tip in {tuple(c.tolist()), tuple(d.tolist())}:
                if region is not None and not region.contains(shapely.Point(tip)):
                    continue
                if any(_on_closed(tip[0], tip[1], *segs[j]) for j in self._near(tip, tip) if j != k):
                    continue
                self.wraps[tip] = k

    def _near(self, a, b) -> list:
        if not len(self.lo):
            return []
        x0, x1 = min(a[0], b[0]), max(a[0], b[0])
        y0, y1 = min(a[1], b[1]), max(a[1], b[1])
        m = (self.lo[:, 0] <= x1) & (self.hi[:, 0] >= x0) & (self.lo[:, 1] <= y1) & (self.hi[:, 1] >= y0)
        return np.flatnonzero(m).tolist()

    def blocks(self, a, b) -> bool:
        """Does edge a-b pass through a degenerate piece (its open part meets one, or
        an end touches one anywhere but at that piece's wrap point)?"""
        a = (float(a[0]), float(a[1]))
        b = (float(b[0]), float(b[1]))
        for k in self._near(a, b):
            c, d = self.segs[k]
            if open_meets(a, b, c, d):
                return True
            for end in (a, b):
                if _on_closed(end[0], end[1], c, d) and self.wraps.get(end) != k:
                    return True
        return False

    def contains(self, p) -> bool:
        """Is point p on a degenerate piece (so not free)?"""
        x, y = float(p[0]), float(p[1])
        return any(_on_closed(x, y, *self.segs[k]) for k in self._near((x, y), (x, y)))


def path_violations(path, pieces: list, bounds=None) -> list[tuple[int, int]]:
    """``(edge, piece)`` pairs where the path goes through a piece; empty when valid.

    An edge's open part must not enter a proper piece's interior nor meet a
    degenerate piece. A path vertex on a degenerate piece must touch it without
    crossing (its neighbours weakly on one side of the piece's line), or be a wrap
    point: a tip of that piece on no other piece and not on the bounds' boundary.

    >>> sq = np.array([[1., 1], [2, 1], [2, 2], [1, 2]])
    >>> path_violations([(0, 0), (3, 3)], [sq]), path_violations([(0, 0), (1, 1), (1, 3)], [sq])
    ([(0, 0)], [])
    >>> dot = np.array([[5., 5], [5, 5], [5, 5]])
    >>> path_violations([(0, 5), (9, 5)], [dot]), path_violations([(0, 5), (5, 5), (9, 5)], [dot])
    ([(0, 0)], [])
    """
    pts = as_array(path)
    if not np.isfinite(pts).all():
        raise ValueError("path coordinates must be finite")
    flat = _flat_mask(pieces)
    proper_idx = [k for k, f in enumerate(flat) if not f]
    deg_idx = [k for k, f in enumerate(flat) if f and len(pieces[k])]
    proper = [np.asarray(pieces[k], dtype=np.float64) for k in proper_idx]
    plo, phi = piece_boxes(proper)  # every box in two reductions
    deg = Degenerate([collinear_extent(pieces[k]) for k in deg_idx])
    out = []
    for e in range(len(pts) - 1):
        a, b = pts[e], pts[e + 1]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        near = np.flatnonzero(~((plo > hi).any(axis=1) | (phi < lo).any(axis=1)))  # boxes that meet the edge's
        for j in near.tolist():
            if _enters(a, b, proper[j]):
                out.append((e, proper_idx[j]))
        for j in deg._near(a, b):
            if open_meets(a, b, *deg.segs[j]):
                out.append((e, deg_idx[j]))
    for i, v in enumerate(pts):
        x, y = float(v[0]), float(v[1])
        for j in deg._near((x, y), (x, y)):
            c, d = deg.segs[j]
            if not _on_closed(x, y, c, d):
                continue
            inner = 0 < i < len(pts) - 1
            if inner and _is_tip(x, y, c, d) and not _on_other(x, y, j, deg, proper, bounds):
                continue  # a wrap point: the path bends around the free tip
            if inner and not (c == d).all() and _one_side(pts[i - 1], pts[i + 1], c, d):
                continue  # touches the segment from one side
            out.append((max(i - 1, 0), deg_idx[j]))
    return sorted(set(out))


def _is_tip(x: float, y: float, c, d) -> bool:
    return (x, y) == (float(c[0]), float(c[1])) or (x, y) == (float(d[0]), float(d[1]))


def _on_other(x: float, y: float, j: int, deg: Degenerate, proper: list, bounds) -> bool:
    """Is (x, y) on a piece other than degenerate piece j, or on the bounds' boundary?"""
    from ..kernel.polygons.polygon import point_in_convex

    if bounds is not None:
        xmin, xmax, ymin, ymax = map(float, bounds)
        if x in (xmin, xmax) or y in (ymin, ymax):
            return True
    if any(_on_closed(x, y, *deg.segs[k]) for k in deg._near((x, y), (x, y)) if k != j):
        return True
    for P in proper:  # (rare: only for a path vertex on a zero-area piece)
        if P[:, 0].min() <= x <= P[:, 0].max() and P[:, 1].min() <= y <= P[:, 1].max():
            if point_in_convex(P if orientation(P) > 0 else P[::-1], x, y) >= 0:
                return True
    return False


def _one_side(p, q, c, d) -> bool:
    """Are p and q weakly on one side of the line c-d?"""
    sp = orient2d_xy(float(c[0]), float(c[1]), float(d[0]), float(d[1]), float(p[0]), float(p[1]))
    sq = orient2d_xy(float(c[0]), float(c[1]), float(d[0]), float(d[1]), float(q[0]), float(q[1]))
    return sp * sq >= 0


def _enters(a, b, P: np.ndarray) -> bool:
    """Exact: does the open segment (a, b) meet the interior of convex polygon P?"""
    if orientation(P) < 0:
        P = P[::-1]
    Q = np.roll(P, -1, axis=0)
    A = np.broadcast_to(np.asarray(a, dtype=np.float64), P.shape)
    B = np.broadcast_to(np.asarray(b, dtype=np.float64), P.shape)
    sa, sb = orient2d_many(P, Q, A), orient2d_many(P, Q, B)
    real = (P != Q).any(axis=1)  # a repeated vertex is no edge (its "line" separates nothing)
    if ((sa <= 0) & (sb <= 0) & real).any():
        return False  # an edge line of P has the whole segment on its closed outer side
    s = orient2d_many(A, B, P)
    return not ((s >= 0).all() or (s <= 0).all())  # else the segment's own line separates
