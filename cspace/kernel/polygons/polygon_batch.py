"""Many small polygons validated and normalised at once (the loader's fast route).

A scene of 90 000 triangles spent ~1.6 ms per obstacle in the loader, almost all of it
numpy's and GEOS's per-call overhead on three vertices. Here the polygons of one vertex
count are stacked into an ``(M, n, 2)`` block and the loader's per-polygon work is done
on the block, with the same arithmetic:

- the turn at every vertex, exactly (:func:`cspace.kernel.polygons.predicates.orient2d_many`);
- GEOS's validity (``shapely.is_valid`` on the block's polygons, one call);
- the orientation (the exact turn at the lowest, then leftmost vertex), the reversal of
  clockwise rings, and the rotation to start at that vertex;
- convexity (:func:`cspace.kernel.polygons.polygon.is_convex`'s test: turns of one sign, turning 2 pi).

Only polygons for which this equals the scalar route are decided here: no repeated
vertex, no zero turn (so ``drop_repeats`` and ``drop_collinear`` would change nothing,
at least 3 distinct vertices are present and the orientation is the turn at the lowest
vertex), magnitudes where GEOS runs unscaled, and GEOS-valid. Every other polygon comes
back ``None``: the caller's scalar route decides it, and words its error.
"""
from __future__ import annotations

import math

import numpy as np

from .predicates import orient2d_many
from .scaling import SAFE_MAX, SAFE_MIN


def normalize_many(polygons: list[np.ndarray]) -> list[tuple[np.ndarray, bool] | None]:
    """Per polygon: ``(normalize(p, ccw=True), is_convex(...))``, or None where the scalar
    route must decide (see the module's notes). The arrays are rows of one block.

    >>> out = normalize_many([np.array([[0., 0], [0, 1], [1, 0]]), np.array([[0., 0], [1, 0], [2, 0], [0, 1]])])
    >>> out[0][0].tolist(), out[0][1], out[1]
    ([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], True, None)
    """
    out: list = [None] * len(polygons)
    groups: dict[int, list[int]] = {}
    for i, p in enumerate(polygons):
        if p.ndim == 2 and p.shape[1] == 2 and len(p) >= 3:
            groups.setdefault(len(p), []).append(i)
    for n, idx in groups.items():
        for i, value in zip(idx, _normalize_block(np.stack([polygons[i] for i in idx]))):
            out[i] = value
    return out


def _normalize_block(A: np.ndarray) -> list:
    """:func:`normalize_many` for an ``(M, n, 2)`` block of polygons of n vertices."""
    import shapely

    M, n = A.shape[0], A.shape[1]
    prev, nxt = np.roll(A, 1, axis=1), np.roll(A, -1, axis=1)
    repeat = (A == prev).all(axis=2).any(axis=1)
    turn = orient2d_many(prev.reshape(-1, 2), A.reshape(-1, 2), nxt.reshape(-1, 2)).reshape(M, n)
    magnitude = np.abs(A).max(axis=(1, 2))
    ok = ~repeat & (turn != 0).all(axis=1) & (magnitude >= SAFE_MIN) & (magnitude < SAFE_MAX)
    # Simple without asking GEOS when star-shaped about the vertex mean (see _star_shaped);
    # GEOS's validity test is quadratic on stars (their spikes' envelopes all overlap).
    ask = ok & ~_star_shaped(A, turn)
    if ask.any():
        ok[ask] = shapely.is_valid(shapely.polygons(A[ask]))
    # The lowest (then leftmost) vertex, as polygon.lowest_index picks it.
    y = A[:, :, 1]
    x_low = np.where(y == y.min(axis=1)[:, None], A[:, :, 0], np.inf)
    low = np.argmin(x_low, axis=1)
    ccw = np.take_along_axis(turn, low[:, None], axis=1)[:, 0] > 0
    # Clockwise rings are reversed (p[::-1]): the lowest vertex moves to n - 1 - low.
    start = np.where(ccw, low, n - 1 - low)
    step = np.arange(n)
    order = np.where(ccw[:, None], (start[:, None] + step) % n, (n - 1 - (start[:, None] + step) % n))
    B = np.take_along_axis(A, order[:, :, None], axis=1)
    # is_convex: every turn of one sign, and the boundary turning once (2 pi) in all.
    one_sign = (turn > 0).all(axis=1) | (turn < 0).all(axis=1)
    e = np.roll(B, -1, axis=1) - B  # on the normalised rings, as is_convex(normalize(p)) sees them
    ang = np.arctan2(e[:, :, 1], e[:, :, 0])
    d = np.diff(np.concatenate([ang, ang[:, :1]], axis=1), axis=1)
    d = (d + math.pi) % (2 * math.pi) - math.pi
    convex = one_sign & (np.abs(np.abs(d.sum(axis=1)) - 2 * math.pi) < 1.0)
    return [(B[k], bool(convex[k])) if ok[k] else None for k in range(M)]


def _star_shaped(A: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Per polygon of the ``(M, n, 2)`` block: certainly simple, by one exact argument.

    With c the (rounded) mean of the vertices: if every triangle (c, v_i, v_i+1) turns
    strictly the same way (exact predicate) and the angles they subtend add up to one
    turn, the rays from c through the vertices come in strictly monotone order over a
    single turn. Each edge then lies in its own wedge between two consecutive rays,
    touching the rays only at its ends and never passing through c; wedges of
    non-adjacent edges share only c, adjacent ones only the ray through their common
    vertex. So edges meet only at shared vertices and no vertex repeats: the polygon is
    simple. (The angles are summed in floats; the sum is an exact multiple of 2 pi up
    to n roundings, so |sum - 2 pi| < 1 decides the number of turns.)

    >>> sq = np.array([[[0., 0], [2, 0], [2, 2], [0, 2]], [[0., 0], [2, 2], [2, 0], [0, 2]]])
    >>> _star_shaped(sq, np.ones((2, 4))).tolist()
    [True, False]
    """
    M, n = A.shape[0], A.shape[1]
    c = np.broadcast_to(A.mean(axis=1)[:, None, :], A.shape)
    nxt = np.roll(A, -1, axis=1)
    wedge = orient2d_many(c.reshape(-1, 2), A.reshape(-1, 2), nxt.reshape(-1, 2)).reshape(M, n)
    same = (wedge > 0).all(axis=1) | (wedge < 0).all(axis=1)
    u, w = A - c, nxt - c
    ang = np.abs(np.arctan2(u[:, :, 0] * w[:, :, 1] - u[:, :, 1] * w[:, :, 0],
                            u[:, :, 0] * w[:, :, 0] + u[:, :, 1] * w[:, :, 1]))
    return same & (np.abs(ang.sum(axis=1) - 2 * math.pi) < 1.0)
