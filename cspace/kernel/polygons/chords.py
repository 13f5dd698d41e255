"""Chord polygons: a convex polygon of many edges, approximated from inside and outside
by a few of its own vertices.

The hull of a subset of a convex polygon's vertices lies inside it; each chord of that
hull, pushed outward by its sagitta (how far the polygon's arc beyond it reaches), has
the whole polygon on its inner side. So a few chords bound a polygon of many edges
from both sides, within the sagittas. The grid broad phase classifies pieces of more
than 62 edges (a margin's rounded corners, disks) this way
(:mod:`cspace.translation.cellclass`).
"""
from __future__ import annotations

import numpy as np


def chord_polygons(Q: np.ndarray, sizes: np.ndarray, long_edge: float, tolerance: float):
    """Convex pieces (padded vertices ``Q``, (K, E, 2); counts ``sizes``) as chord polygons:
    eight vertices and both ends of every edge longer than ``long_edge`` (in the L1 norm),
    then, while a chord's sagitta exceeds ``tolerance``, the vertex halfway along the arc it
    cuts off. Returns the chord polygons (padded), their vertex counts, and each chord's
    sagitta.

    The hull of a subset of a convex piece's vertices lies inside the piece, so a cell
    inside it is inside the piece; a chord's line pushed out by its sagitta (the
    largest n . v - c over the vertices of the arc it cuts off; the piece being convex,
    every other vertex lies on its inner side, up to a rounding far below the grid's
    margin) has the whole piece on its inner side, so a cell beyond it is separated
    from the piece. Cells between the two are MIXED, which only costs the narrow phase a
    test: a piece of 75 edges (a margin's rounded corners) is classified at the cost of a
    dozen, its band of MIXED cells at most 2 x ``tolerance`` wider (the grid's build asks
    for a quarter of a cell).

    >>> sq = np.array([[[0., 0], [1, 0], [1, 1], [0, 1]]])
    >>> R, n, sag = chord_polygons(sq, np.array([4]), long_edge=0.5, tolerance=0.1)
    >>> int(n[0]), sag[0].tolist()  # every edge long: the square itself, nothing cut off
    (4, [0.0, 0.0, 0.0, 0.0])
    >>> t = np.linspace(0, 2 * np.pi, 72, endpoint=False)
    >>> disk = np.stack([10 * np.cos(t), 10 * np.sin(t)], axis=1)[None]
    >>> R, n, sag = chord_polygons(disk, np.array([72]), long_edge=5.0, tolerance=0.1)
    >>> int(n[0]) < 72, bool(sag.max() <= 0.1)
    (True, True)
    """
    K, E, _ = Q.shape
    ar = np.arange(K)[:, None]  # row index for gathers (cheaper than take_along_axis)
    slot = np.arange(E)
    valid = slot[None, :] < sizes[:, None]
    nxt = np.where(slot[None, :] + 1 < sizes[:, None], slot[None, :] + 1, 0)
    e = Q[ar, nxt] - Q
    long = valid & (np.abs(e[:, :, 0]) + np.abs(e[:, :, 1]) > long_edge)
    prev = (slot[None, :] - 1) % sizes[:, None]
    eighth = slot[None, :] % np.maximum(sizes[:, None] // 8, 1) == 0  # eight vertices to start from
    keep = valid & (long | long[ar, prev] | eighth)
    limit = tolerance
    rr, vv = np.nonzero(valid)  # row-major: (piece, vertex) pairs, each piece's in order
    while True:
        n = keep.sum(axis=1)
        C = int(n.max())
        order = np.argsort(~keep, axis=1, kind="stable")[:, :C]  # kept slots first, in order
        R = Q[ar, order]
        cc = np.arange(C)[None, :]
        ok = cc < n[:, None]
        rn = np.where(cc + 1 < n[:, None], cc + 1, 0)
        d = R[ar, rn] - R
        nrm = np.stack([d[:, :, 1], -d[:, :, 0]], axis=2)
        with np.errstate(invalid="ignore", divide="ignore"):
            nrm /= np.hypot(nrm[:, :, 0], nrm[:, :, 1])[:, :, None]
            c = nrm[:, :, 0] * R[:, :, 0] + nrm[:, :, 1] * R[:, :, 1]
            # Each vertex against the chord whose arc holds it (the last kept slot at
            # or before it; slot 0 is always kept): n . v - c, its largest per chord.
            cid = (np.cumsum(keep, axis=1) - 1)[rr, vv]
            reach = nrm[rr, cid, 0] * Q[rr, vv, 0]
            reach += nrm[rr, cid, 1] * Q[rr, vv, 1]
            reach -= c[rr, cid]
        key = rr * C + cid  # non-decreasing: one run per chord
        first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        sag = np.full(K * C, -np.inf)
        sag[key[first]] = np.maximum.reduceat(reach, first)  # NaN (a degenerate chord) stays NaN
        sag = np.maximum(sag.reshape(K, C), 0.0)
        sag[~ok] = 0.0
        # Chords cutting off too much: add the middle vertex of the arc each spans.
        a = order
        b = order[ar, rn]
        span = (b - a) % sizes[:, None]
        bad = ok & (sag > limit) & (span > 1)
        if not bad.any():
            return R, n.astype(np.int64), sag
        rows, cols = np.nonzero(bad)
        mid = (a[rows, cols] + span[rows, cols] // 2) % sizes[rows]
        keep[rows, mid] = True
