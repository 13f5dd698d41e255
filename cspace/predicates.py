"""Exact geometric predicates on float coordinates.

This module owns the one decision every other module rests on: which side of the
directed line a->b the point c lies on. The sign is computed with a floating-point
filter (Shewchuk's stage-A error bound) and, only when the filter cannot certify
the sign, recomputed exactly from the doubles' rational values. The answer is
therefore exact for every finite input, integer or not.

Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast
Robust Geometric Predicates", Discrete & Computational Geometry 18 (1997).
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

# Unit roundoff of IEEE double (round to nearest): eps = 2^-53.
EPS = 2.0**-53
# Shewchuk's ccwerrboundA: |fl(det) - det| <= (3 + 16 eps) eps * (|detleft| + |detright|).
CCW_ERRBOUND_A = (3.0 + 16.0 * EPS) * EPS
# Below this magnitude products may be subnormal and the relative bound no longer
# holds; such inputs go straight to the exact path.
_UNDERFLOW_GUARD = 1e-280
_INF = float("inf")


def orient2d_exact(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> int:
    """Sign of the orientation of (a, b, c) in exact rational arithmetic.

    Every finite double is a dyadic rational, so ``Fraction(x)`` is exact.

    >>> orient2d_exact(0.0, 0.0, 1.0, 0.0, 0.5, 1e-300)
    1
    """
    fax, fay = Fraction(ax), Fraction(ay)
    det = (Fraction(bx) - fax) * (Fraction(cy) - fay) - (Fraction(by) - fay) * (Fraction(cx) - fax)
    return (det > 0) - (det < 0)


def orient2d(a, b, c) -> int:
    """Exact sign of the turn a -> b -> c: +1 left (CCW), -1 right (CW), 0 collinear.

    ``a``, ``b``, ``c`` are points ``(x, y)`` with finite float coordinates.

    >>> orient2d((0, 0), (1, 0), (0, 1))
    1
    >>> orient2d((0, 0), (1, 1), (2, 2))
    0
    """
    ax, ay = float(a[0]), float(a[1])
    bx, by = float(b[0]), float(b[1])
    cx, cy = float(c[0]), float(c[1])
    return orient2d_xy(ax, ay, bx, by, cx, cy)


def orient2d_xy(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> int:
    """:func:`orient2d` on six plain floats (no tuple unpacking: the hot path).

    >>> orient2d_xy(0.0, 0.0, 1.0, 0.0, 2.0, -1.0)
    -1
    """
    # Shewchuk's form: translate so c is the origin, then one 2x2 determinant, i.e. the
    # cross product of the edge vectors c->a and c->b (filter and fallback live there).
    return cross_diff_sign(cx, cy, ax, ay, cx, cy, bx, by)


def orient2d_many(a, b, c) -> np.ndarray:
    """Vectorised :func:`orient2d` over arrays of points, shape ``(N, 2)`` each (broadcasting).

    Returns an ``int8`` array of signs. The filter runs in numpy; only the entries it
    cannot certify are recomputed exactly, one by one.

    >>> orient2d_many([[0, 0], [0, 0]], [[1, 0], [1, 1]], [[0, 1], [2, 2]]).tolist()
    [1, 0]
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    c = np.asarray(c, dtype=np.float64)
    return orient2d_cols(a[..., 0], a[..., 1], b[..., 0], b[..., 1], c[..., 0], c[..., 1])


def orient2d_cols(ax, ay, bx, by, cx, cy) -> np.ndarray:
    """:func:`orient2d_many` on coordinate columns (arrays or scalars that broadcast).

    >>> orient2d_cols(np.zeros(2), np.zeros(2), 1.0, 0.0, np.array([0.5, 0.5]), np.array([1.0, -1.0])).tolist()
    [1, -1]
    """
    # orient2d(a, b, c) = (a - c) x (b - c): the edge-vector cross product from c.
    return cross_diff_cols(cx, cy, ax, ay, cx, cy, bx, by)


def cross_sign(u, v) -> int:
    """Exact sign of the cross product ``u x v`` of two float vectors.

    ``cross(u, v) > 0`` means v is counter-clockwise of u (less than pi).

    >>> cross_sign((1e6, 1.0), (2e6, 2.0))
    0
    """
    return orient2d_xy(0.0, 0.0, float(u[0]), float(u[1]), float(v[0]), float(v[1]))


def cross_diff_exact(ax, ay, bx, by, cx, cy, dx, dy) -> int:
    """Exact sign of ``(b - a) x (d - c)`` in rational arithmetic.

    >>> cross_diff_exact(0.0, 0.0, 1e6, 1.0, 5.0, 5.0, 5.0 + 2e6, 7.0)
    0
    """
    F = Fraction
    det = (F(bx) - F(ax)) * (F(dy) - F(cy)) - (F(by) - F(ay)) * (F(dx) - F(cx))
    return (det > 0) - (det < 0)


def cross_diff_sign(ax: float, ay: float, bx: float, by: float,
                    cx: float, cy: float, dx: float, dy: float) -> int:
    """Exact sign of the cross product of two edge vectors ``(b - a) x (d - c)``.

    This is the angular comparison of the Minkowski merge: +1 when edge c->d turns
    counter-clockwise from edge a->b. It is :func:`orient2d` with four independent
    differences, so Shewchuk's stage-A bound applies unchanged (each difference and
    product is rounded once, then one subtraction).

    >>> cross_diff_sign(0.0, 0.0, 1e6, 1.0, 0.0, 0.0, 2e6, 2.0 + 2.0**-30)
    1
    """
    ux, uy, vx, vy = bx - ax, by - ay, dx - cx, dy - cy
    left = ux * vy
    right = uy * vx
    det = left - right
    detsum = abs(left) + abs(right)
    if _UNDERFLOW_GUARD < detsum < _INF:
        errbound = CCW_ERRBOUND_A * detsum
        if det > errbound:
            return 1
        if -det > errbound:
            return -1
    elif detsum == 0.0 and (ux == 0.0 or vy == 0.0) and (uy == 0.0 or vx == 0.0):
        return 0
    return cross_diff_exact(ax, ay, bx, by, cx, cy, dx, dy)


def cross_diff_cols(ax, ay, bx, by, cx, cy, dx, dy) -> np.ndarray:
    """Vectorised :func:`cross_diff_sign` over coordinate columns (``int8`` signs).

    >>> cross_diff_cols(np.zeros(2), np.zeros(2), np.ones(2), np.zeros(2),
    ...                 np.zeros(2), np.zeros(2), np.array([1.0, 1.0]), np.array([1.0, -0.0])).tolist()
    [1, 0]
    """
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        ux, uy, vx, vy = bx - ax, by - ay, dx - cx, dy - cy
        left = ux * vy
        right = uy * vx
        det = left - right
        detsum = np.abs(left) + np.abs(right)
        errbound = CCW_ERRBOUND_A * detsum
        ok = (detsum > _UNDERFLOW_GUARD) & (detsum < _INF)
        sign = (ok & (det > errbound)).astype(np.int8) - (ok & (-det > errbound)).astype(np.int8)
        certain = sign != 0
        certain |= (detsum == 0.0) & ((ux == 0.0) | (vy == 0.0)) & ((uy == 0.0) | (vx == 0.0))
    if not certain.all():
        cols = np.broadcast_arrays(ax, ay, bx, by, cx, cy, dx, dy, sign)
        sign = np.array(cols[-1], dtype=np.int8)
        for idx in zip(*np.nonzero(~np.broadcast_to(certain, sign.shape))):
            sign[idx] = cross_diff_exact(*(float(col[idx]) for col in cols[:8]))
    return sign
