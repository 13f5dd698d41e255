"""Exact certification of the vectorised angular merge (:mod:`cspace.kernel.minkowski.sorted_keys`).

Float filters first, exact answers in doubt: the turns of many edge pairs at once
(:func:`turns_cols`), whether consecutive merged edges are in angular order and which
are parallel (:func:`parallel_pairs`: exact integer products, the stage-A filter,
error-free products, rationals last), and the strict convexity of the rounded sum,
repaired to the hull of its vertices (:func:`certify_cols`).
"""
from __future__ import annotations

import numpy as np

from ..polygons.polygon import lowest_first
from ..polygons.predicates import CCW_ERRBOUND_A, cross_diff_cols, cross_diff_sign, error_free_cross_sign, lower_half, sum_error


def turns_cols(ux, uy, vx, vy, a, b, c, d) -> np.ndarray:
    """Vectorised :func:`cspace.kernel.minkowski.scalar._turn`: exact signs of u x v for float edges u = b - a, v = d - c."""
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        # Three fresh arrays, the rest in place: at 10^4 vertices and more, each fresh
        # array costs more in page faults than its arithmetic.
        left = np.multiply(ux, vy)
        right = np.multiply(uy, vx)
        det = np.subtract(left, right)
        bound = np.abs(left, out=left)
        bound += np.abs(right, out=right)
        bound *= CCW_ERRBOUND_A
        ok = (bound > 1e-280) & (bound < np.inf)
        sign = (ok & (det > bound)).astype(np.int8) - (ok & (np.negative(det, out=right) > bound)).astype(np.int8)
    doubt = np.flatnonzero(sign == 0)
    if len(doubt):
        sign[doubt] = cross_diff_cols(a[doubt, 0], a[doubt, 1], b[doubt, 0], b[doubt, 1],
                                      c[doubt, 0], c[doubt, 1], d[doubt, 0], d[doubt, 1])
    return sign



def parallel_pairs(ux, uy, half, integral, order, edged, rot, sizes, w1, w2) -> np.ndarray | None:
    """Which consecutive merged edges are parallel (to be fused); None if out of order.

    Within a half-plane, edge t+1 must not turn clockwise of edge t: u x v >= 0,
    decided exactly. For integer input, products below 2^53 are exact; for floats the
    stage-A filter decides; in doubt, Dekker's error-free products, rationals last.
    """
    same = half[:-1] == half[1:]
    left = np.multiply(ux[:-1], uy[1:], out=w1[:-1])  # w1, w2: scratch
    right = np.multiply(uy[:-1], ux[1:], out=w2[:-1])
    if integral and max(max_abs(left), max_abs(right)) < 2.0**53:
        # Integer products below 2^53 are exact (a true product of 2^53 or more cannot
        # round below 2^53) and so is their difference's sign: all are sure at once.
        det = np.subtract(left, right, out=left)
        if (same & (det < 0)).any():
            return None
        return same & (det == 0)
    if integral:
        # Integer products below 2^53 are exact (a true product of 2^53 + 1 or more
        # cannot round below 2^53), and the one rounding of their difference keeps
        # its sign; pairs with a larger product go to the exact tests below.
        big = 2.0**53
        sure = (left < big) & (left > -big) & (right < big) & (right > -big)
        det = np.subtract(left, right, out=left)
    else:  # the stage-A bound, computed in place over the products (one fresh array)
        det = np.subtract(left, right)
        bound = np.abs(left, out=left)
        bound += np.abs(right, out=right)
        bound *= CCW_ERRBOUND_A
        sure = (bound > 1e-280) & (bound < np.inf) & (np.abs(det, out=right) > bound)
    if (same & sure & (det < 0)).any():
        return None
    fused = same & (~sure | (det == 0))  # parallel, or in doubt: decided exactly below
    doubt = np.flatnonzero(same & ~sure)
    if len(doubt):
        sign = _error_free_signs(ux, uy, doubt)
        ends = np.cumsum(sizes)
        first = ends - sizes
        edged = [np.roll(p, -k, axis=0) for p, k in zip(edged, rot)]  # lowest first
        X = np.concatenate([p[:, 0] for p in edged])
        Y = np.concatenate([p[:, 1] for p in edged])
        exact_edge = _diff_is_exact_cols(X, first, ends) & _diff_is_exact_cols(Y, first, ends)
        sign[~(exact_edge[order[doubt]] & exact_edge[order[doubt + 1]])] = 2
        rest = np.flatnonzero(sign == 2)
        if len(rest):
            sign[rest] = [_exact_pair(edged, first, order[doubt[r]], order[doubt[r] + 1])
                          for r in rest]
        if (sign < 0).any():
            return None
        fused[doubt] = sign == 0  # parallel, same direction: no vertex between them
    return fused


def max_abs(u: np.ndarray) -> float:
    # The ufunc reductions themselves: ndarray.max() adds a Python-level wrapper.
    return max(float(np.maximum.reduce(u, axis=None)), -float(np.minimum.reduce(u, axis=None)))


def _error_free_signs(ux: np.ndarray, uy: np.ndarray, doubt: np.ndarray) -> np.ndarray:
    """Exact signs of ux[t]*uy[t+1] - uy[t]*ux[t+1] where floats get them without error, else 2.

    :func:`cspace.kernel.polygons.predicates.error_free_cross_sign` on the edge vectors (as differences
    from the origin, which are exact). The edges themselves must be exact differences
    of the input vertices, which the caller checks.
    """
    z = np.zeros(len(doubt))
    return error_free_cross_sign(z, z, ux[doubt], uy[doubt], z, z, ux[doubt + 1], uy[doubt + 1])


def _diff_is_exact_cols(x: np.ndarray, first: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Whether each cyclic difference fl(x[i+1] - x[i]) within each operand is exact.

    Knuth's TwoSum: the rounding error of b + (-a) is computed exactly; zero means exact.
    """
    b = np.empty_like(x)
    b[:-1] = x[1:]
    b[ends - 1] = x[first]
    na = -x
    return sum_error(b, na, b + na) == 0.0


def _exact_pair(edged: list, ends: np.ndarray, s: int, t: int) -> int:
    """Exact sign of edge s x edge t, edges numbered across the concatenated operands."""
    def ends_of(g):
        i = int(np.searchsorted(ends, g, side="right")) - 1
        p = edged[i]
        j = g - ends[i]
        return p[j], p[(j + 1) % len(p)]
    a, b = ends_of(int(s))
    c, d = ends_of(int(t))
    return cross_diff_sign(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])



class _Cyclic:
    """``p`` shifted cyclically by ``k`` rows, read only at the indices asked for
    (the exact fallback of :func:`turns_cols` reads a few): no shifted copy is made."""

    def __init__(self, p: np.ndarray, k: int):
        self.p, self.k = p, k

    def __getitem__(self, key):
        rows, col = key
        return self.p[(rows + self.k) % len(self.p), col]


def certify_cols(out: np.ndarray, exact: bool) -> np.ndarray:
    """Vectorised :func:`cspace.kernel.minkowski.scalar._certify_small`; skipped when the sums were exact integers.

    Rounded sums of a strictly convex polygon are still in angular order around its
    interior, so a vertex whose exact turn is not left lies inside its neighbours'
    chord and is removed (never two neighbours in one round, so each removal is
    decided on vertices that stay); rounds repeat until every turn is left, which is
    the hull of the rounded vertices (as a Graham scan of angularly sorted points).
    """
    if exact or len(out) < 3:
        return out
    for _ in range(len(out)):
        n = len(out)
        e = np.empty((n + 1, 2))  # e[i]: the edge into vertex i; e[i + 1]: the edge out of it
        np.subtract(out[1:], out[:-1], out=e[1:n])
        e[0] = e[n] = out[0] - out[-1]
        turn = turns_cols(e[:-1, 0], e[:-1, 1], e[1:, 0], e[1:, 1], _Cyclic(out, -1), out, out, _Cyclic(out, 1))
        bad = turn <= 0
        if not bad.any():
            # Every turn is left, so the edge directions sweep 2 pi once per winding and
            # cross from the lower half-plane into the upper one once per winding.
            h = lower_half(e[1:, 0], e[1:, 1])
            if np.count_nonzero(h[:-1] & ~h[1:]) + bool(h[-1] and not h[0]) == 1:
                return lowest_first(out)
            break  # it winds more than once: the hull of its vertices
        drop = bad.copy()
        drop[1:] &= ~bad[:-1]  # keep a bad vertex whose predecessor is being removed
        if drop[0] and drop[-1]:
            drop[-1] = False
        out = out[~drop]
        if len(out) < 3:
            break
    from ..polygons.hull import convex_hull

    return convex_hull(out)
