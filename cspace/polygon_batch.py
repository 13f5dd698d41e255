"""Many small polygons validated and normalised at once (the loader's fast route).

A scene of 90 000 triangles spent ~1.6 ms per obstacle in the loader, almost all of it
numpy's and GEOS's per-call overhead on three vertices. Here the polygons of one vertex
count are stacked into an ``(M, n, 2)`` block and the loader's per-polygon work is done
on the block, with the same arithmetic:

- the turn at every vertex, exactly (:func:`cspace.predicates.orient2d_many`);
- GEOS's validity (``shapely.is_valid`` on the block's polygons, one call);
- the orientation (the exact turn at the lowest, then leftmost vertex), the reversal of
  clockwise rings, and the rotation to start at that vertex;
- convexity (:func:`cspace.polygon.is_convex`'s test: turns of one sign, turning 2 pi).

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
    if ok.any():
        ok[ok] = shapely.is_valid(shapely.polygons(A[ok]))
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
    e = nxt - A
    ang = np.arctan2(e[:, :, 1], e[:, :, 0])
    d = np.diff(np.concatenate([ang, ang[:, :1]], axis=1), axis=1)
    d = (d + math.pi) % (2 * math.pi) - math.pi
    convex = one_sign & (np.abs(np.abs(d.sum(axis=1)) - 2 * math.pi) < 1.0)
    return [(B[k], bool(convex[k])) if ok[k] else None for k in range(M)]
