"""Polygons as (N, 2) float64 arrays: conversion, orientation, clean-up, convexity,
and convex pieces packed one after another (:class:`PackedPieces`).

This module owns the polygon currency of the package. A polygon is an ``(N, 2)``
float64 array of vertices, counter-clockwise, without the closing repeat. Every
decision about turns is made with the exact predicate of :mod:`cspace.kernel.polygons.predicates`,
so a cleaned polygon never keeps a collinear vertex and never loses a real one.
"""
from __future__ import annotations

import math

import numpy as np

from .arrays import as_array, as_point  # noqa: F401  (the input gate, re-exported here)
from .predicates import lower_half, orient2d_many, orient2d_xy


def signed_area(polygon) -> float:
    """Signed area (shoelace, computed about the first vertex): > 0 for CCW.

    >>> signed_area([[0, 0], [2, 0], [0, 2]])
    2.0
    """
    return _shoelace(as_array(polygon, copy=False))


def _shoelace(p: np.ndarray) -> float:
    """:func:`signed_area` of an (N, 2) float64 array, about its first vertex."""
    if len(p) < 3:
        return 0.0
    x = p[:, 0] - p[0, 0]
    y = p[:, 1] - p[0, 1]
    # Sum of x_i y_{i+1} - y_i x_{i+1}; the wrap-around term is zero (x_0 = y_0 = 0).
    return 0.5 * float((x[:-1] * y[1:]).sum() - (y[:-1] * x[1:]).sum())


def prev_next(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each vertex's predecessor and successor rows along the ring, as new arrays.

    >>> [a.tolist() for a in prev_next(np.array([[0., 0], [1, 0], [0, 1]]))]
    [[[0.0, 1.0], [0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]]
    """
    return np.concatenate((p[-1:], p[:-1])), np.concatenate((p[1:], p[:1]))


def is_ccw(polygon) -> bool:
    """True when the polygon runs counter-clockwise, decided exactly (:func:`orientation`).

    >>> is_ccw([[0, 0], [0, 1], [1, 0]])
    False
    """
    return orientation(as_array(polygon, copy=False)) > 0


def orientation(p: np.ndarray) -> int:
    """Exact orientation of a simple polygon: +1 CCW, -1 CW, 0 for no area.

    The turn at the lowest (then leftmost) vertex, taken between its nearest
    neighbours that differ from it and are not collinear with it: that vertex is an
    extreme point, so the turn there is the orientation of the whole boundary. One
    exact predicate, right at every scale, where the shoelace sum underflows to 0
    (coordinates near 1e-160), overflows to inf or NaN (near 1e160) or rounds to the
    wrong sign (a sliver).

    >>> orientation(np.array([[0., 0], [2, 0], [0, 1]])), orientation(np.array([[0., 0], [0, 1], [2, 0]]))
    (1, -1)
    >>> orientation(np.array([[0., 0], [2, 0], [0, 1]]) * 1e-200)
    1
    """
    n = len(p)
    if n < 3:
        return 0
    k = lowest_index(p)
    bx, by = p[k].tolist()
    for step in range(1, n):  # the next vertex along the ring that is not v itself
        cx, cy = p[(k + step) % n].tolist()
        if cx != bx or cy != by:
            break
    else:
        return 0
    for back in range(1, n):  # the previous one, not v and not collinear with v -> c
        ax, ay = p[(k - back) % n].tolist()
        t = orient2d_xy(ax, ay, bx, by, cx, cy)
        if t:
            return t
    return 0


def drop_repeats(p: np.ndarray) -> np.ndarray:
    """Remove consecutive duplicate vertices (cyclically).

    >>> drop_repeats(np.array([[0., 0], [0, 0], [1, 0], [0, 1], [0, 0]])).tolist()
    [[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]
    """
    if len(p) < 2:
        return p
    prev = np.concatenate((p[-1:], p[:-1]))
    keep = (p[:, 0] != prev[:, 0]) | (p[:, 1] != prev[:, 1])
    if keep.all():
        return p
    if not keep.any():  # all the same point
        return p[:1]
    return p[keep]


def drop_collinear(p: np.ndarray) -> np.ndarray:
    """Remove every vertex whose two neighbours are exactly collinear with it.

    Repeats until stable, since removing one vertex can make its neighbour collinear
    (a spike folding back on itself).

    >>> drop_collinear(np.array([[0., 0], [1, 0], [2, 0], [2, 2]])).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]
    """
    while len(p) >= 3:
        prev, nxt = prev_next(p)
        turn = orient2d_many(prev, p, nxt)
        keep = turn != 0
        if keep.all():
            break
        if not keep.any():
            return p[:0]
        # Remove collinear vertices whose predecessor stays, so that both neighbours a
        # removal was decided on are still there: every removal is then exact.
        drop = np.zeros(len(p), dtype=bool)
        for i in np.flatnonzero(~keep):
            drop[i] = not drop[i - 1]
        if drop[0] and drop[-1]:
            drop[-1] = False
        p = p[~drop]
        p = drop_repeats(p)
    return p


def normalize(polygon, *, ccw: bool = True) -> np.ndarray:
    """Clean a polygon: drop repeats, spikes and collinear vertices, orient CCW (or CW).

    The cycle starts at the lowest (then leftmost) vertex. The result may have
    fewer than 3 vertices (a degenerate polygon); callers that need a proper
    polygon check ``len``.

    >>> normalize([[0, 0], [0, 2], [0, 1], [2, 0], [1, 0]]).tolist()
    [[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]]
    """
    p = drop_collinear(drop_repeats(as_array(polygon)))
    if len(p) >= 3 and (orientation(p) > 0) != ccw:
        p = p[::-1].copy()
    return lowest_first(p)


def collinear_extent(points) -> np.ndarray:
    """The point or segment that collinear points span: its one or two extreme
    points, lowest (then leftmost) first. ``ValueError`` if they are not collinear
    (exact test): a "polygon" of zero area that is not a point or a segment is not
    simple.

    >>> collinear_extent([[2, 2], [0, 0], [1, 1], [0, 0]]).tolist()
    [[0.0, 0.0], [2.0, 2.0]]
    >>> collinear_extent([[1, 1], [1, 1]]).tolist()
    [[1.0, 1.0]]
    """
    p = as_array(points)
    if len(p) == 0:
        return p
    order = np.lexsort((p[:, 0], p[:, 1]))  # by y, then x: along any line, its two ends
    lo, hi = p[order[0]], p[order[-1]]
    if (lo == hi).all():
        return lo.reshape(1, 2)
    if (orient2d_many(lo, hi, p) != 0).any():
        raise ValueError("not a simple polygon: no area, yet its vertices are not collinear")
    return np.array([lo, hi])


def pack(pieces: list) -> tuple[np.ndarray, np.ndarray]:
    """The pieces' vertices one piece after another, ``(M, 2)`` float64, and each
    piece's vertex count (what :class:`cspace.kernel.polygons.pieces.PieceSet` stores).

    >>> pts, sizes = pack([np.array([[0., 1], [2, 0], [1, 3]]), np.zeros((0, 2)), np.array([[5., 5], [6, 7]])])
    >>> pts.shape, sizes.tolist()
    ((5, 2), [3, 0, 2])
    """
    n = len(pieces)
    sizes = np.fromiter((len(p) for p in pieces), np.int64, n)
    full = np.flatnonzero(sizes > 0)
    if not len(full):
        return np.zeros((0, 2)), sizes
    pts = np.concatenate([pieces[k] for k in full.tolist()] if len(full) < n else pieces).reshape(-1, 2)
    return pts.astype(np.float64, copy=False), sizes


def piece_boxes(pieces: list, packing: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Each piece's bounding box, ``(lo, hi)`` as two ``(n, 2)`` arrays, in one pass over
    all the vertices (what ``p.min(axis=0)``, ``p.max(axis=0)`` give piece by piece; an
    empty piece gets lo = +inf, hi = -inf). ``packing``: the pieces' :func:`pack`, when
    the caller has it.

    >>> lo, hi = piece_boxes([np.array([[0., 1], [2, 0], [1, 3]]), np.zeros((0, 2)), np.array([[5., 5], [6, 7]])])
    >>> lo.tolist(), hi.tolist()
    ([[0.0, 0.0], [inf, inf], [5.0, 5.0]], [[2.0, 3.0], [-inf, -inf], [6.0, 7.0]])
    """
    if packing is None and len(pieces) == 1 and len(pieces[0]):  # one piece (a robot, often): its reductions
        p = np.asarray(pieces[0], dtype=np.float64).reshape(-1, 2)
        return np.minimum.reduce(p, axis=0)[None], np.maximum.reduce(p, axis=0)[None]
    pts, sizes = pack(pieces) if packing is None else packing
    n = len(sizes)
    if n and sizes.min() > 0:  # no empty piece (the common case): the reductions' own arrays
        starts = np.zeros(n, dtype=np.int64)
        np.cumsum(sizes[:-1], out=starts[1:])
        return packed_boxes(pts, starts)
    lo, hi = np.full((n, 2), np.inf), np.full((n, 2), -np.inf)
    full = np.flatnonzero(sizes > 0)
    if len(full):
        lo[full], hi[full] = packed_boxes(pts, np.cumsum(sizes[full]) - sizes[full])
    return lo, hi


def packed_boxes(pts: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boxes ``(lo, hi)`` of non-empty pieces stored one after another in ``pts``,
    piece k from row ``starts[k]``: two reductions over all the vertices.

    >>> lo, hi = packed_boxes(np.array([[0., 1], [2, 0], [5, 5], [6, 7]]), np.array([0, 2]))
    >>> lo.tolist(), hi.tolist()
    ([[0.0, 0.0], [5.0, 5.0]], [[2.0, 1.0], [6.0, 7.0]])
    """
    return np.minimum.reduceat(pts, starts, axis=0), np.maximum.reduceat(pts, starts, axis=0)


def ring_neighbours(sizes) -> tuple[np.ndarray, np.ndarray]:
    """For rings of the given sizes stored one after another, each vertex's
    predecessor and successor along its own ring (indices into the concatenation).

    >>> [a.tolist() for a in ring_neighbours([3, 2])]
    [[2, 0, 1, 4, 3], [1, 2, 0, 4, 3]]
    """
    sizes = np.asarray(sizes, dtype=np.intp)
    ends = np.cumsum(sizes)
    starts = ends - sizes
    pos = np.arange(int(ends[-1]) if len(ends) else 0)
    prev, nxt = pos - 1, pos + 1
    some = sizes > 0
    prev[starts[some]] = ends[some] - 1  # a ring's first vertex follows its last
    nxt[ends[some] - 1] = starts[some]
    return prev, nxt


class PackedPieces:
    """Convex pieces stored one after another: their vertices, each vertex's ring
    neighbours, each edge's half-plane (:func:`cspace.kernel.polygons.predicates.lower_half`), and
    ``ok``: is the piece canonical, i.e. strictly convex (exact left turns) and CCW
    from its lowest (then leftmost) vertex, so that its edges come in angular order.
    The batched angular merges rely on that order; a piece that is not ``ok``
    (including points and segments, stored as a dummy triangle) must go elsewhere.

    >>> PackedPieces([np.array([[0., 0], [1, 0], [0, 1]]), np.array([[1., 1], [0, 0], [1, 0]])]).ok.tolist()
    [True, False]
    """

    def __init__(self, pieces: list):
        self.sizes = np.array([len(p) for p in pieces])
        self.ok = self.sizes >= 3
        if not self.ok.all():  # points, segments, malformed: a dummy triangle, not ok
            pieces = [p if len(p) >= 3 else np.zeros((3, 2)) for p in pieces]
            self.sizes = np.array([len(p) for p in pieces])
        self.pts = np.concatenate(pieces).reshape(-1, 2)
        self.starts = np.cumsum(self.sizes) - self.sizes
        self.piece = np.repeat(np.arange(len(pieces)), self.sizes)
        self.local = np.arange(len(self.pts)) - self.starts[self.piece]
        self.prv, self.nxt = ring_neighbours(self.sizes)
        e = self.pts[self.nxt] - self.pts
        self.half = lower_half(e[:, 0], e[:, 1])
        # Canonical: strictly convex (exact left turns), lowest-then-leftmost first, and
        # the halves read upper...lower once (winding once).
        V = self.pts
        bad = orient2d_many(V[self.prv], V, V[self.nxt]) <= 0
        bad |= (V[:, 1] < V[self.starts[self.piece], 1]) | (
            (V[:, 1] == V[self.starts[self.piece], 1]) & (V[:, 0] < V[self.starts[self.piece], 0]))
        bad |= (self.local > 0) & (self.half < self.half[self.prv])
        self.ok &= np.bincount(self.piece[bad], minlength=len(pieces)) == 0


def lowest_first(p: np.ndarray) -> np.ndarray:
    """Rotate the vertex cycle to start at the lowest vertex (then leftmost).

    >>> lowest_first(np.array([[1., 1], [0, 0], [1, 0]])).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]
    """
    if len(p) == 0:
        return p
    i = lowest_index(p)
    return np.concatenate((p[i:], p[:i])) if i else p


def lowest_index(p: np.ndarray) -> int:
    """Index of the lowest (then leftmost) vertex of a non-empty ``(N, 2)`` array.

    >>> lowest_index(np.array([[1., 0], [2, 1], [0, 0]]))
    2
    """
    y = p[:, 1]
    low = np.flatnonzero(y == y.min())
    if len(low) == 1:
        return int(low[0])
    if len(low):  # ties: the leftmost
        return int(low[np.argmin(p[low, 0])])
    return int(np.lexsort((p[:, 0], p[:, 1]))[0])  # NaN coordinates: sorted last


def is_convex(polygon, *, strict: bool = False) -> bool:
    """Exact convexity test of a closed polygon given in either orientation.

    Convex means every turn has the same sign (or is straight) and the boundary
    winds around exactly once. ``strict=True`` also rejects collinear vertices.

    >>> is_convex([[0, 0], [2, 0], [2, 2], [0, 2]])
    True
    >>> is_convex([[0, 0], [2, 0], [1, 1], [2, 2], [0, 2]])
    False
    """
    p = drop_repeats(as_array(polygon, copy=False))
    if len(p) < 3:
        return not strict
    prev, nxt = prev_next(p)
    turn = orient2d_many(prev, p, nxt)
    if strict and (turn == 0).any():
        return False
    if (turn > 0).any() and (turn < 0).any():
        return False
    if not turn.any():
        return not strict  # all collinear: a segment, convex but degenerate
    # Same-sign turns can still wind twice (a pentagram): total turning must be 2 pi.
    e = nxt - p
    ang = np.arctan2(e[:, 1], e[:, 0])
    d = np.diff(np.append(ang, ang[0]))
    d = (d + math.pi) % (2 * math.pi) - math.pi
    return bool(abs(abs(d.sum()) - 2 * math.pi) < 1.0)


def invalid_reason(shell, holes=()) -> str | None:
    """GEOS's reason why the polygon (shell and holes) is not valid, or None if it is.

    GEOS's arithmetic multiplies coordinates: at extreme magnitudes (a triangle 1e-300
    wide) it underflows and calls a fine polygon self-intersecting, so it runs on an
    exact power-of-two copy near 1 (the reason's coordinates are then that copy's).
    Coordinates must be finite (GEOS would warn about NaN).

    >>> invalid_reason([[0, 0], [2, 2], [2, 0], [0, 2]]), invalid_reason(np.array([[0, 0], [1, 0], [0, 1]]) * 1e-300)
    ('Self-intersection[1 1]', None)
    """
    import shapely

    from .scaling import scaled_copies

    rings = [as_array(shell, copy=False)] + [as_array(h, copy=False) for h in holes]
    rescaled = scaled_copies(rings, max(float(np.abs(r).max()) for r in rings if len(r)))
    if rescaled:
        rings = rescaled[1]
    geom = shapely.Polygon(rings[0], rings[1:])
    # GEOS's reason for a degenerate ring whose coordinates span ~2^1000 (1 and subnormals,
    # even after the rescaling) overflows inside its own arithmetic; the verdict stands.
    with np.errstate(over="ignore", invalid="ignore"):
        return None if shapely.is_valid(geom) else shapely.is_valid_reason(geom)


def is_simple(polygon) -> bool:
    """True when the closed polygon has non-zero area and does not cross itself.

    >>> is_simple([[0, 0], [2, 2], [2, 0], [0, 2]])
    False
    """
    import shapely

    try:
        p = as_array(polygon)
    except ValueError:  # NaN, inf, a wrong shape: not a simple polygon (a predicate answers, it does not raise)
        return False
    if len(p) < 3 or not np.isfinite(p).all():  # GEOS would warn about NaN; not simple anyway
        return False
    # Area decided exactly (a float area underflows to 0 for coordinates near 1e-160).
    return invalid_reason(p) is None and len(normalize(p)) >= 3


def point_in_convex(p: np.ndarray, x: float, y: float) -> int:
    """Locate point (x, y) against CCW convex polygon ``p`` exactly.

    Returns +1 inside, 0 on the boundary, -1 outside.

    >>> point_in_convex(np.array([[0., 0], [2, 0], [0, 2]]), 1.0, 1.0)
    0
    """
    n = len(p)
    res = 1
    for i in range(n):
        ax, ay = p[i]
        bx, by = p[(i + 1) % n]
        s = orient2d_xy(ax, ay, bx, by, x, y)
        if s < 0:
            return -1
        if s == 0:
            res = 0
    return res
