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
UNDERFLOW_GUARD = 1e-280
_INF = float("inf")


class NonFiniteError(ValueError):
    """A NaN or an infinity reached an exact predicate: it has no rational value.

    Non-finite input always ends here (the float filter certifies no sign from it),
    so the check costs nothing on finite input.
    """

    def __init__(self):
        super().__init__("coordinates must be finite (a NaN or an infinity reached the exact predicate)")


def orient2d_exact(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> int:
    """Sign of the orientation of (a, b, c) in exact rational arithmetic.

    Every finite double is a dyadic rational, so ``Fraction(x)`` is exact.

    >>> orient2d_exact(0.0, 0.0, 1.0, 0.0, 0.5, 1e-300)
    1
    """
    try:
        fax, fay = Fraction(ax), Fraction(ay)
        det = (Fraction(bx) - fax) * (Fraction(cy) - fay) - (Fraction(by) - fay) * (Fraction(cx) - fax)
    except (ValueError, OverflowError):  # Fraction(nan), Fraction(inf)
        raise NonFiniteError() from None
    return (det > 0) - (det < 0)


def orient2d(a, b, c) -> int:
    """Exact sign of the turn a -> b -> c: +1 left (CCW), -1 right (CW), 0 collinear.

    ``a``, ``b``, ``c`` are points ``(x, y)`` of finite real numbers. Exact for every
    such input: Python integers too large for a double (beyond 2^53, or beyond the
    double range) are taken as they are, in rational arithmetic, not rounded.
    Booleans, complex numbers and strings are refused (``TypeError``), NaN and
    infinities too (``ValueError``).

    >>> orient2d((0, 0), (1, 0), (0, 1))
    1
    >>> orient2d((0, 0), (1, 1), (2, 2))
    0
    >>> orient2d((0, 0), (2**53 + 1, 1), (2**53, 1))
    1
    """
    vals = _reals((a[0], a[1], b[0], b[1], c[0], c[1]))
    if vals is None:  # an integer a double cannot hold: exact from the integers themselves
        ax, ay, bx, by, cx, cy = (v if isinstance(v, int) else Fraction(v) for v in
                                  (_exact(a[0]), _exact(a[1]), _exact(b[0]), _exact(b[1]), _exact(c[0]), _exact(c[1])))
        det = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        return (det > 0) - (det < 0)
    return orient2d_xy(*vals)


def _reals(values) -> list[float] | None:
    """The values as floats, None if an integer among them is not exactly a double;
    TypeError for a boolean, complex number, string or other non-number."""
    out = []
    for v in values:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise TypeError(f"orient2d: coordinates must be real numbers, got {type(v).__name__}")
        if isinstance(v, (int, np.integer)):
            try:
                f = float(v)
            except OverflowError:
                return None
            if f != int(v):
                return None
            out.append(f)
        else:
            out.append(float(v))
    return out


def _exact(v):
    """An int as itself, a float as its exact rational value (NaN and inf refused)."""
    if isinstance(v, (int, np.integer)):
        return int(v)
    try:
        return Fraction(float(v))
    except (ValueError, OverflowError):
        raise NonFiniteError() from None


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
    return orient2d((0, 0), u, v)


def lower_half(dx, dy) -> np.ndarray:
    """Is each direction (dx, dy) in the lower half [pi, 2 pi) of the angle order,
    rather than the upper half [0, pi)? The first, exact step of every angular
    comparison (the signs of float differences are exact).

    >>> lower_half(np.array([1.0, -1.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0, 1.0])).tolist()
    [False, True, True, False]
    """
    return (dy < 0.0) | ((dy == 0.0) & (dx <= 0.0))


def cross_diff_exact(ax, ay, bx, by, cx, cy, dx, dy) -> int:
    """Exact sign of ``(b - a) x (d - c)`` in rational arithmetic.

    >>> cross_diff_exact(0.0, 0.0, 1e6, 1.0, 5.0, 5.0, 5.0 + 2e6, 7.0)
    0
    """
    # Each double is n / 2^k exactly (as_integer_ratio); over the largest 2^k they are all
    # integers, so the determinant, scaled by a positive square, is an exact Python int
    # (no gcd per operation, as Fractions would take).
    try:
        ratios = [float(v).as_integer_ratio() for v in (ax, ay, bx, by, cx, cy, dx, dy)]
    except (ValueError, OverflowError):  # nan, inf
        raise NonFiniteError() from None
    den = max(d for _, d in ratios)
    AX, AY, BX, BY, CX, CY, DX, DY = (n * (den // d) for n, d in ratios)
    det = (BX - AX) * (DY - CY) - (BY - AY) * (DX - CX)
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
    if UNDERFLOW_GUARD < detsum < _INF:
        errbound = CCW_ERRBOUND_A * detsum
        if det > errbound:
            return 1
        if -det > errbound:
            return -1
    elif detsum == 0.0 and (ux == 0.0 or vy == 0.0) and (uy == 0.0 or vx == 0.0):
        return 0
    if 2.0**-900 < detsum < 2.0**1000 and _computed_exactly(ax, ay, bx, by, cx, cy, dx, dy, ux, uy, vx, vy,
                                                            left, right):
        return 1 if det > 0 else (-1 if det < 0 else 0)  # exact operands: one rounding keeps the sign
    return cross_diff_exact(ax, ay, bx, by, cx, cy, dx, dy)


def _computed_exactly(ax, ay, bx, by, cx, cy, dx, dy, ux, uy, vx, vy, left, right) -> bool:
    """Were the four differences and two products of :func:`cross_diff_sign` exact? (scalar)"""
    return (sum_error(bx, -ax, ux) == 0.0 and sum_error(by, -ay, uy) == 0.0
            and sum_error(dx, -cx, vx) == 0.0 and sum_error(dy, -cy, vy) == 0.0
            and product_error(ux, vy, left) == 0.0 and product_error(uy, vx, right) == 0.0)


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
        # Certain: |det| above the stage-A bound, detsum clear of underflow. An infinite
        # detsum makes the bound infinite and a NaN compares False: both stay in doubt.
        certain = np.abs(det) > CCW_ERRBOUND_A * detsum
        certain &= detsum > UNDERFLOW_GUARD
        sign = np.sign(det).astype(np.int8)  # read only where certain
    if certain.all():
        return sign
    # Exact zeros: both products zero because a factor is (float differences are zero
    # exactly when the coordinates are equal), not by underflow. Touching contacts on
    # integer input are mostly these.
    with np.errstate(invalid="ignore"):
        zero = (detsum == 0.0) & ((ux == 0.0) | (vy == 0.0)) & ((uy == 0.0) | (vx == 0.0))
    certain |= zero
    if certain.all():
        return np.where(zero, np.int8(0), sign)
    if np.ndim(certain) == 0:  # all scalars: the scalar exact route
        return np.array(cross_diff_sign(ax, ay, bx, by, cx, cy, dx, dy), dtype=np.int8)
    cols = np.broadcast_arrays(ax, ay, bx, by, cx, cy, dx, dy, np.where(zero, np.int8(0), sign))
    sign = np.array(cols[-1], dtype=np.int8)
    doubt = np.nonzero(~np.broadcast_to(certain, sign.shape))
    picked = [np.asarray(col[doubt], dtype=np.float64) for col in cols[:8]]
    ef = error_free_cross_sign(*picked)
    sign[doubt] = ef  # 2 marks the entries still undecided, fixed just below
    for k in np.flatnonzero(ef == 2).tolist():
        idx = tuple(d[k] for d in doubt)
        sign[idx] = cross_diff_exact(*(float(col[k]) for col in picked))
    return sign


_SPLIT = 134217729.0  # 2^27 + 1, Dekker's splitter


def error_free_cross_sign(ax, ay, bx, by, cx, cy, dx, dy) -> np.ndarray:
    """Exact sign of ``(b - a) x (d - c)`` where floats compute it without error, else 2.

    Knuth's TwoSum tells whether each difference was exact, Dekker's TwoProduct
    whether each product was; when all six were, the one rounded subtraction keeps
    the true sign. This settles at float speed the zeros the stage-A filter cannot
    (touching contacts on integer or dyadic coordinates); what is left goes to
    rationals.

    >>> error_free_cross_sign(*(np.array([v]) for v in (0, 0, 3, 1, 0, 0, 6, 2))).tolist()
    [0]
    """
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        ux, uy, vx, vy = bx - ax, by - ay, dx - cx, dy - cy
        ok = (sum_error(bx, -ax, ux) == 0) & (sum_error(by, -ay, uy) == 0)
        ok &= (sum_error(dx, -cx, vx) == 0) & (sum_error(dy, -cy, vy) == 0)
        left, right = ux * vy, uy * vx
        ok &= (product_error(ux, vy, left) == 0) & (product_error(uy, vx, right) == 0)
        # Far from over- and underflow, where TwoProduct is itself exact: each product
        # in (2^-900, 2^1000), or zero because a factor is (a product that underflowed
        # to zero from non-zero factors would look exact and is not).
        ok &= ((np.abs(left) > 2.0**-900) | (ux == 0) | (vy == 0)) & (np.abs(left) < 2.0**1000)
        ok &= ((np.abs(right) > 2.0**-900) | (uy == 0) | (vx == 0)) & (np.abs(right) < 2.0**1000)
        ok &= np.isfinite(ux) & np.isfinite(uy) & np.isfinite(vx) & np.isfinite(vy)
        det = left - right
    return np.where(ok, np.sign(det), 2).astype(np.int8)


def sum_error(a, b, s):
    """Knuth's TwoSum error term: a + b - fl(a + b), exactly (barring overflow).

    >>> float(sum_error(np.float64(1.0), np.float64(2.0**-60), np.float64(1.0)))
    8.673617379884035e-19
    """
    bv = s - a
    av = s - bv
    return (a - av) + (b - bv)


def product_error(a, b, p):
    """Dekker's TwoProduct error term: a*b - fl(a*b), exactly (barring over/underflow).

    >>> float(product_error(np.float64(3.0), np.float64(1.0 / 3.0), np.float64(1.0)))
    -5.551115123125783e-17
    """
    t = _SPLIT * a
    ah = t - (t - a)
    al = a - ah
    t = _SPLIT * b
    bh = t - (t - b)
    bl = b - bh
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl
