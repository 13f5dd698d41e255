"""Convex hull of a point set, decided with the exact orientation predicate.

Andrew's monotone chain: sort the points lexicographically, then build the lower
and upper chains, popping every vertex that does not make a strict left turn.
Because each turn is decided by :func:`cspace.kernel.polygons.predicates.orient2d_xy` (exact for
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


def ring_hulls(points: np.ndarray, sizes) -> list[np.ndarray]:
    """``[convex_hull(ring) for ring in rings]`` for rings stored one after another
    (``sizes`` points each) that are convex up to rounding, such as rounded Minkowski
    sums: many rings at once, in numpy.

    Each ring is peeled: every vertex that does not turn strictly left (exact) between
    its live neighbours is dropped, until none is left; what remains turns strictly
    left everywhere, and if its edges turn around once it is a convex polygon with
    vertices among the points. It is the hull when every dropped point lies in it
    (checked exactly against each of its edges); a ring where that fails, or that peels
    to fewer than 3 vertices, gets :func:`convex_hull` instead. So the answer is :func:`convex_hull`'s, array for array.

    >>> sq = [[0., 0], [1, 0], [1, 1], [0, 1]]
    >>> [h.tolist() for h in ring_hulls(np.array(sq + [[2., 0], [3, 0], [3, 1], [2.5, 0.5], [2, 1]]), [4, 5])]
    [[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], [[2.0, 0.0], [3.0, 0.0], [3.0, 1.0], [2.0, 1.0]]]
    """
    from .polygon import ring_neighbours
    from .predicates import lower_half, orient2d_many

    p = np.asarray(points, dtype=np.float64)
    sizes = np.asarray(sizes, dtype=np.intp)
    ring = np.repeat(np.arange(len(sizes)), sizes)
    alive = np.ones(len(p), dtype=bool)
    while True:
        idx = np.flatnonzero(alive)
        prv, nxt = ring_neighbours(np.bincount(ring[idx], minlength=len(sizes)))
        turn = orient2d_many(p[idx[prv]], p[idx], p[idx[nxt]])
        drop = idx[turn <= 0]
        if not drop.size:
            break
        alive[drop] = False
    live = np.bincount(ring[alive], minlength=len(sizes))
    ok = live >= 3
    idx = np.flatnonzero(alive)
    before, after = ring_neighbours(live)
    nxt = idx[after]
    # Strict left turns everywhere make a convex polygon only if the edges turn around
    # once (a pentagram turns left everywhere, twice around): the edge directions then
    # change half-plane (exact signs of float differences) exactly twice.
    d = p[nxt] - p[idx]
    half = lower_half(d[:, 0], d[:, 1])
    change = half != half[before]
    ok &= np.bincount(ring[idx][change], minlength=len(sizes)) == 2
    # Every dropped point against every edge of its ring's peeled polygon: on or left.
    gone = np.flatnonzero(~alive & ok[ring])
    if gone.size:
        ends = np.cumsum(live)
        first = ends - live
        reps = live[ring[gone]]
        g = np.repeat(gone, reps)
        e = np.repeat(first[ring[gone]], reps) + (np.arange(len(g)) - np.repeat(np.cumsum(reps) - reps, reps))
        side = orient2d_many(p[idx[e]], p[nxt[e]], p[g])
        ok &= np.bincount(ring[g[side < 0]], minlength=len(sizes)) == 0
    out = []
    cut = np.cumsum(sizes) - sizes
    live_cut = np.cumsum(live) - live
    for r in range(len(sizes)):
        if ok[r]:
            out.append(lowest_first(p[idx[live_cut[r]:live_cut[r] + live[r]]]))
        else:
            out.append(convex_hull(p[cut[r]:cut[r] + sizes[r]]))
    return out
