"""The H-representation of convex polygons: half-planes, support functions, erosion.

A convex polygon is the intersection of its edges' half-planes n_i · x <= c_i, with
n_i the outward normal (dy, -dx) of edge i (not normalised, so exact on integers).
Its support function h_P(d) = max_{p in P} d · p is attained at a vertex.

Erosion A ⊖ B = {c : c + B ⊆ A} is the intersection of A's half-planes, each moved
inward by B's support in its normal: n_i · c <= c_i − h_B(n_i). It is *not*
A ⊕ (−B) (that is the set of c where c + B meets A, the C-obstacle). The edges of
the result are a subset of A's edges, so it has at most |A| vertices. It is computed
in exact rational arithmetic (Fractions of the doubles) by clipping, then rounded
once to floats.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from .polygon import as_array, as_point, normalize


def halfplanes(polygon) -> tuple[np.ndarray, np.ndarray]:
    """Outward edge normals and offsets of a convex polygon: P = {x : N x <= c}.

    Normals are (dy, -dx) of each CCW edge, unnormalised.

    >>> n, c = halfplanes([[0, 0], [2, 0], [2, 1], [0, 1]])
    >>> n.tolist(), c.tolist()
    ([[0.0, -2.0], [1.0, 0.0], [0.0, 2.0], [-1.0, 0.0]], [0.0, 2.0, 2.0, 0.0])
    """
    p = normalize(as_array(polygon, nonempty=True))
    e = np.roll(p, -1, axis=0) - p
    normals = np.column_stack([e[:, 1], -e[:, 0]]) + 0.0  # + 0.0: no negative zeros
    offsets = np.einsum("ij,ij->i", normals, p)
    return normals, offsets


def support(polygon, d) -> float:
    """The support function h_P(d) = max over P of d · p.

    >>> support([[0, 0], [2, 0], [0, 1]], (1, 1))
    2.0
    """
    p = as_array(polygon, nonempty=True)
    return float((p @ np.array(as_point(d))).max())


def support_point(polygon, d) -> np.ndarray:
    """A vertex of P attaining the support function in direction d.

    >>> support_point([[0, 0], [2, 0], [0, 1]], (0, 1)).tolist()
    [0.0, 1.0]
    """
    p = as_array(polygon, nonempty=True)
    return p[int(np.argmax(p @ np.array(as_point(d))))].copy()


def erode(A, B) -> np.ndarray:
    """A ⊖ B = {c : c + B ⊆ A} for convex A and B, as a CCW array; (0, 2) if B does not fit.

    A point or a segment comes back when B fits only just (no room to move in some
    direction). Exact before the final rounding to floats.

    >>> erode([[0, 0], [4, 0], [4, 3], [0, 3]], [[0, 0], [1, 0], [1, 1], [0, 1]]).tolist()
    [[0.0, 0.0], [3.0, 0.0], [3.0, 2.0], [0.0, 2.0]]
    >>> erode([[0, 0], [1, 0], [0, 1]], [[0, 0], [2, 0], [0, 2]]).shape
    (0, 2)
    """
    verts = erode_exact(A, B)
    if not verts:
        return np.zeros((0, 2))
    try:
        out = np.array([[float(x), float(y)] for x, y in verts], dtype=np.float64)
    except OverflowError:  # the exact vertex is beyond the double range
        raise ValueError("erode: the result's coordinates overflow the double range") from None
    return normalize(out) if len(out) >= 3 else out


def erode_exact(A, B) -> list[tuple[Fraction, Fraction]]:
    """:func:`erode` in exact rationals: the vertices as ``(Fraction, Fraction)`` pairs, CCW.

    >>> erode_exact([[0, 0], [2, 0], [0, 2]], [[0, 0], [1, 0], [0, 1]])
    [(Fraction(0, 1), Fraction(0, 1)), (Fraction(1, 1), Fraction(0, 1)), (Fraction(0, 1), Fraction(1, 1))]
    """
    a = normalize(A)
    b = as_array(B)
    if len(a) < 3 or len(b) == 0:
        raise ValueError("erode: A must be a proper convex polygon and B non-empty")
    if not np.isfinite(b).all():  # (A's coordinates went through the exact predicate in normalize)
        raise ValueError("erode: coordinates must be finite")
    fa = [(Fraction(x), Fraction(y)) for x, y in a.tolist()]
    fb = [(Fraction(x), Fraction(y)) for x, y in b.tolist()]
    # Start from A − b0 (c + b0 ∈ A is necessary), then clip by every shifted half-plane.
    b0x, b0y = fb[0]
    poly = [(x - b0x, y - b0y) for x, y in fa]
    n = len(fa)
    for i in range(n):
        (px, py), (qx, qy) = fa[i], fa[(i + 1) % n]
        nx, ny = qy - py, px - qx
        c = nx * px + ny * py - max(nx * x + ny * y for x, y in fb)
        poly = _clip(poly, nx, ny, c)
        if not poly:
            return []
    return poly


def _clip(poly: list, nx: Fraction, ny: Fraction, c: Fraction) -> list:
    """Keep the part of a convex polygon (or point or segment) where n · x <= c, exactly."""
    m = len(poly)
    s = [c - (nx * x + ny * y) for x, y in poly]  # >= 0 inside
    if all(v >= 0 for v in s):
        return poly
    out: list = []
    for i in range(m):
        j = (i + 1) % m
        if s[i] >= 0:
            out.append(poly[i])
        if (s[i] > 0 and s[j] < 0) or (s[i] < 0 and s[j] > 0):
            t = s[i] / (s[i] - s[j])
            (x0, y0), (x1, y1) = poly[i], poly[j]
            out.append((x0 + t * (x1 - x0), y0 + t * (y1 - y0)))
        if m == 1:
            break
    # Drop repeats that clipping through a vertex can leave.
    clean = [p for k, p in enumerate(out) if p != out[k - 1]] if len(out) > 1 else out
    return clean
