"""Convex hull of a point set, decided with the exact orientation predicate.

Andrew's monotone chain: sort the points lexicographically, then build the lower
and upper chains, popping every vertex that does not make a strict left turn.
Because each turn is decided by :func:`cspace.kernel.predicates.orient2d_xy` (exact for
all finite doubles), the hull never keeps a collinear vertex and never drops an
extreme point, however close to collinear the input is.
"""
from __future__ import annotations

import numpy as np

from .polygon import as_array, lowest_first
from .predicates import orient2d_xy


def convex_hull(points) -> np.ndarray:
    """Vertices of the convex hull: CCW, no repeated or collinear vertex, lowest (then leftmost) first.

    Degenerate input gives a degenerate hull: one point, or a segment's two endpoints.

    >>> convex_hull([[0, 0], [2, 0], [1, 0], [2, 2], [0, 2], [1, 1]]).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    >>> convex_hull([[3, 3], [1, 1], [2, 2]]).tolist()
    [[1.0, 1.0], [3.0, 3.0]]
    """
    p = as_array(points)
    if len(p) == 0:
        return p.reshape(0, 2)
    pts = _sorted_unique(p)  # lexicographic (x, then y) and without repeats
    if len(pts) <= 2:
        return lowest_first(np.array(pts, dtype=np.float64).reshape(-1, 2))
    lower = _chain(pts)
    upper = _chain(pts[::-1])
    hull = lower[:-1] + upper[:-1]
    if len(hull) < 2:  # all points equal cannot happen after unique; keep the guard
        hull = lower[:1]
    return lowest_first(np.array(hull, dtype=np.float64))


def _sorted_unique(p: np.ndarray) -> list:
    """The distinct points of p as a list of pairs, sorted by x then y."""
    if len(p) <= 64:  # a Python sort of a few tuples beats numpy's per-call overhead
        return sorted(set(map(tuple, p.tolist())))
    q = p[np.lexsort((p[:, 1], p[:, 0]))]
    keep = np.ones(len(q), dtype=bool)
    keep[1:] = (q[1:] != q[:-1]).any(axis=1)
    return q[keep].tolist()


def _chain(pts: list) -> list:
    """One monotone chain: keep only strict left turns (exact)."""
    out: list = []
    for x, y in pts:
        while len(out) >= 2:
            (ax, ay), (bx, by) = out[-2], out[-1]
            if orient2d_xy(ax, ay, bx, by, x, y) > 0:
                break
            out.pop()
        out.append((x, y))
    return out
