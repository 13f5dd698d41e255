"""GJK: distance, closest points and intersection of two convex sets from their supports.

A ∩ B ≠ ∅ ⇔ 0 ∈ D = A ⊕ (−B), and the distance between A and B is the distance
from the origin to D. GJK walks a simplex (point, segment, triangle) of D towards
the origin using only the support function s_D(d) = s_A(d) − s_B(−d); D is never
built. Each step keeps the sub-simplex nearest the origin (Voronoi regions decided
by barycentric signs, as in Box2D's ``b2ShapeDistance``) and asks for the support
point in the direction of the origin.

Robustness, per the known failure modes of published GJK code:
- all work is in a local frame (both sets shifted by a vertex of A), so sets far
  from the origin (1e8) keep their precision; a frame whose coordinates are so small
  or large that their products under- or overflow is first rescaled by a power of
  two (:mod:`cspace.kernel.polygons.scaling`), exactly;
- a support pair already in the simplex ends the loop (no cycling), as does no
  progress (v·v − v·w ≤ 1e-14 · v·v), and an iteration cap;
- degenerate simplices (repeated or collinear points) are reduced, never inverted:
  no 0/0, no NaN;
- where the float distance is within its error bound of zero, the relation
  (separated / touching / overlapping) is decided exactly: the separating axis test
  over the sets' hull edges in rational arithmetic (:mod:`cspace.kernel.distance.gjk_exact`,
  whose :func:`exact_relation` is re-exported here).

The loop has an optional compiled twin (``gjk`` in cspace/compiled/_fast.c, injected as
``gjk_distance(..., loop=)``) doing the same float operations in the same order: the
same answers, bit for bit; the pure loop is its fallback and oracle.
"""
from __future__ import annotations

import math
from itertools import chain
from typing import NamedTuple

import numpy as np

from .gjk_exact import contact_relation, exact_distance, exact_relation  # noqa: F401  (re-exported)
from ..polygons.polygon import as_array
from ..polygons.scaling import SAFE_MAX, SAFE_MIN, scaled_copies

MAX_ITERATIONS = 64
# Relative progress below which the distance has converged (GJK's usual test).
REL_TOL = 1e-14
# Float distances below this times the local scale are decided exactly.
EXACT_BAND = 1e-9


class Distance(NamedTuple):
    """Separation of two convex sets. ``status``: separated, touching or overlapping."""

    distance: float
    point_a: np.ndarray
    point_b: np.ndarray
    iterations: int
    status: str


def gjk_distance(A, B, max_iterations: int = MAX_ITERATIONS, *, loop=None) -> Distance:
    """Distance and closest points of convex sets A and B (vertex arrays; points and segments too).

    ``max_iterations`` caps the loop (the default is never reached on separated or
    overlapping pairs; a capped answer is an upper bound on the distance). ``loop``: a
    compiled GJK loop (:func:`cspace.compiled.fastpath.gjk_loop`), called as ``loop(a, b,
    max_iterations)`` on the float64 vertex arrays; it returns :func:`_loop`'s result on
    the local frame, bit for bit, plus the frame's extent, or None (a coordinate not
    finite). Pairs it cannot take, and ``loop=None``, run the pure loop: same answers.

    >>> d = gjk_distance([[0, 0], [1, 0], [1, 1], [0, 1]], [[3, 0], [4, 0], [4, 1], [3, 1]])
    >>> d.distance, d.status
    (2.0, 'separated')
    >>> gjk_distance([[0, 0], [1, 0], [1, 1], [0, 1]], [[1, 0], [2, 0], [2, 1], [1, 1]]).status
    'touching'
    """
    if (fast := _compiled(A, B, max_iterations, loop)) is not None:
        return _answer_raw(*fast)
    a = as_array(A, copy=False, nonempty=True)  # only read: no copy
    b = as_array(B, copy=False, nonempty=True)
    if loop is not None and (raw := loop(a, b, max_iterations)) is not None and SAFE_MIN <= raw[7] < SAFE_MAX:
        return _answer_raw(a, b, raw)
    ox, oy = a[0].tolist()
    if len(a) + len(b) <= 80:  # Python floats (an overflow is inf, silently): cheaper when small
        al = [(x - ox, y - oy) for x, y in a.tolist()]
        bl = [(x - ox, y - oy) for x, y in b.tolist()]
        extent = _scale(al, bl)
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            la, lb = a - a[0], b - a[0]
            extent = max(float(np.abs(la).max()), float(np.abs(lb).max())) or 1.0  # as _scale
        al, bl = la.tolist(), lb.tolist()
    if not SAFE_MIN <= extent < SAFE_MAX and (rescaled := scaled_copies([a, b], extent)):
        k, (sa, sb) = rescaled  # products would under- or overflow: the same sets at 2^k scale
        d = gjk_distance(sa, sb, max_iterations, loop=loop)
        with np.errstate(over="ignore"):  # a distance beyond the double range is inf
            return Distance(float(np.ldexp(d.distance, -k)), np.ldexp(d.point_a, -k), np.ldexp(d.point_b, -k),
                            d.iterations, d.status)
    return _answer(a, b, ox, oy, extent, _gjk(al, bl, max_iterations))


def gjk_distance_below(A, B, bound: float, *, loop=None) -> Distance | None:
    """:func:`gjk_distance` of A and B, or None when the compiled ``loop`` shows the sets
    separated by at least ``bound`` (outside the exact band: the distance gjk_distance
    would return, to the bit, is not below ``bound``). A search for the nearest of many
    pairs skips building the answers of those that cannot win.

    >>> sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    >>> from cspace.compiled.fastpath import gjk_loop
    >>> far = gjk_distance_below(sq, sq + 3, 1.0, loop=gjk_loop())
    >>> far is None if gjk_loop() else far.distance == gjk_distance(sq, sq + 3).distance
    True
    >>> gjk_distance_below(sq, sq + 3, 9.0, loop=gjk_loop()).distance == gjk_distance(sq, sq + 3).distance
    True
    """
    if (fast := _compiled(A, B, MAX_ITERATIONS, loop)) is None:
        return gjk_distance(A, B, loop=loop)
    raw = fast[2]
    if not raw[5]:  # not inside: gjk_distance returns this distance unless in the exact band
        dist = math.hypot(raw[0] - raw[2], raw[1] - raw[3])
        if dist >= bound and dist > EXACT_BAND * raw[7]:
            return None
    return _answer_raw(*fast)


def witness_weights(A, B, *, loop=None) -> list[tuple[int, float]] | None:
    """A's closest point to B as weights on A's vertices, ``[(index, weight)]``: GJK's final
    simplex and its weights (the point :func:`gjk_distance` reports as ``point_a``), where
    its float loop separates A and B beyond the exact band; None where it does not (touching,
    overlapping, decided exactly, coordinates far from unit scale). A search over swept
    sets reads from them where along its motion a piece comes closest.

    >>> A, B = np.array([[0., 0], [2, 0], [2, 1], [0, 1]]), np.array([[1., 3], [3, 3], [2, 4]])
    >>> w = witness_weights(A, B)
    >>> sum(t * A[i] for i, t in w).tolist() == gjk_distance(A, B).point_a.tolist() == [1.5, 1.0]
    True
    """
    fast = _compiled(A, B, MAX_ITERATIONS, loop)
    if fast is not None:
        pax, pay, pbx, pby, _, inside, simplex, extent = fast[2]
    else:
        a, b = as_array(A, copy=False, nonempty=True), as_array(B, copy=False, nonempty=True)
        ox, oy = a[0].tolist()
        al = [(x - ox, y - oy) for x, y in a.tolist()]
        bl = [(x - ox, y - oy) for x, y in b.tolist()]
        extent = _scale(al, bl)
        if not SAFE_MIN <= extent < SAFE_MAX:
            return None
        pax, pay, pbx, pby, _, inside, simplex = _loop(al, bl, MAX_ITERATIONS)
    if inside or math.hypot(pax - pbx, pay - pby) <= EXACT_BAND * extent:
        return None
    kept, lam = _solve(list(simplex))  # the loop's last solve: the weights of point_a
    return [(int(v[0]), float(t)) for v, t in zip(kept, lam)]


def _compiled(A, B, max_iterations: int, loop):
    """``(a, b, raw)``: the compiled ``loop``'s result on plain (N, 2) float64 arrays A and B
    (a closing repeat of the first vertex dropped, as as_array does), or None where it
    does not answer (no loop, other inputs, a non-finite coordinate, an extent outside
    the safe range): gjk_distance's fast entry."""
    if loop is not None and _plain(A) and _plain(B):  # the compiled loop checks finiteness itself
        a, b = _open(A), _open(B)
        raw = loop(a, b, max_iterations)
        if raw is not None and SAFE_MIN <= raw[7] < SAFE_MAX:
            return a, b, raw
    return None


def _answer_raw(a: np.ndarray, b: np.ndarray, raw) -> Distance:
    """The Distance from the compiled loop's result on a and b (local frame at a[0])."""
    ox, oy = a[0].tolist()
    return _answer(a, b, ox, oy, raw[7], _outcome(*raw))


def _answer(a: np.ndarray, b: np.ndarray, ox: float, oy: float, extent: float, result) -> Distance:
    """The Distance from :func:`_gjk`'s result (local frame, origin (ox, oy) = a[0]): the
    exact relation where the float distance is within its error band of zero."""
    dist, pa, pb, it, inside, simplex = result
    if inside == "deep":
        p = np.array((pa[0] + ox, pa[1] + oy))
        return Distance(0.0, p, p.copy(), it, "overlapping")
    if inside or dist <= EXACT_BAND * extent:
        status = contact_relation(a.tolist(), b.tolist(), simplex) or exact_relation(a, b)
        if status != "separated":
            p = np.array((pa[0] + ox, pa[1] + oy))
            return Distance(0.0, p, p.copy(), it, status)
        if inside:  # float said overlap but exact says apart: a sliver gap, measure it exactly
            dist, pa, pb = exact_distance(a, b, a[0])
    return Distance(float(dist), np.array((pa[0] + ox, pa[1] + oy)), np.array((pb[0] + ox, pb[1] + oy)),
                    it, "separated")


def _plain(A) -> bool:
    """A non-empty (N, 2) float64 array: what as_array would pass through (bar NaN and
    infinities, which the compiled loop reports by returning None)."""
    return type(A) is np.ndarray and A.dtype == np.float64 and A.ndim == 2 and A.shape[1] == 2 and len(A) > 0


def _open(a: np.ndarray) -> np.ndarray:
    """``a`` without a closing repeat of its first vertex, as as_array gives it."""
    if len(a) > 1 and a[0, 0] == a[-1, 0] and a[0, 1] == a[-1, 1]:
        return a[:-1]
    return a


def gjk_intersects(A, B) -> bool:
    """Whether the closed convex sets A and B meet (touching counts).

    >>> gjk_intersects([[0, 0], [1, 0], [0, 1]], [[1, 0], [2, 0], [2, 1]])
    True
    """
    return gjk_distance(A, B).status != "separated"


def _scale(al: list, bl: list) -> float:
    """Largest coordinate magnitude in the local frame (1 for two points at the origin)."""
    m = max(map(abs, chain.from_iterable(al + bl)))
    return m if m > 0.0 else 1.0


def _support(pts: list, dx: float, dy: float) -> int:
    """Index of a vertex maximising (dx, dy) · p (the first of equals)."""
    best, bi = -math.inf, 0
    for i, (x, y) in enumerate(pts):
        s = x * dx + y * dy
        if s > best:
            best, bi = s, i
    return bi


def _gjk(al: list, bl: list, max_iterations: int = MAX_ITERATIONS):
    """GJK in the local frame: (distance, pa, pb, iterations, origin_inside, simplex); the
    simplex's vertices carry the indices (ia, ib) of the supporting vertices of A and B."""
    raw = _loop(al, bl, max_iterations)
    return _outcome(*raw, _scale(al, bl) if raw[5] else 1.0)


def _loop(al: list, bl: list, max_iterations: int):
    """The GJK loop (compiled as ``gjk`` in cspace/compiled/_fast.c, operation for operation):
    (pax, pay, pbx, pby, iterations, origin_inside, simplex), the closest points of A and B."""
    # Simplex vertices: (ia, ib, wx, wy) with w = a[ia] - b[ib]; weights lam.
    simplex = [(0, 0, al[0][0] - bl[0][0], al[0][1] - bl[0][1])]
    lam = [1.0]
    it = 0
    inside = False
    while it < max_iterations:
        it += 1
        simplex, lam = _solve(simplex)
        if len(simplex) == 3:
            inside = True
            break
        vx, vy = _combine(lam, simplex, 2, 3)
        vv = vx * vx + vy * vy
        if vv == 0.0:
            inside = True
            break
        ia = _support(al, -vx, -vy)
        ib = _support(bl, vx, vy)
        if (ia, ib) in [(s[0], s[1]) for s in simplex]:
            break  # the support is already in the simplex: converged (or cycling)
        wx, wy = al[ia][0] - bl[ib][0], al[ia][1] - bl[ib][1]
        if vv - (vx * wx + vy * wy) <= REL_TOL * vv:
            break  # no progress towards the origin
        simplex.append((ia, ib, wx, wy))
        lam.append(0.0)
    # Closest points: the same weights on the simplex's vertices of A and of B.
    pax, pay = _combine(lam, [al[s[0]] for s in simplex], 0, 1)
    pbx, pby = _combine(lam, [bl[s[1]] for s in simplex], 0, 1)
    return pax, pay, pbx, pby, it, inside, simplex


def _outcome(pax: float, pay: float, pbx: float, pby: float, it: int, inside: bool, simplex, extent: float):
    """:func:`_gjk`'s result from the loop's (pure or compiled); ``extent`` as :func:`_scale`."""
    if inside:
        # Certain overlap when the origin is deep inside the simplex (beyond any rounding).
        deep = len(simplex) == 3 and _depth_in_triangle(simplex) > EXACT_BAND * extent
        return 0.0, (pax, pay), (pax, pay), it, "deep" if deep else True, simplex
    return math.hypot(pax - pbx, pay - pby), (pax, pay), (pbx, pby), it, False, simplex


def _combine(lam: list, pts: list, ix: int, iy: int) -> tuple[float, float]:
    """The point sum(lam[k] * pts[k]) of coordinates (pts[k][ix], pts[k][iy])."""
    if len(lam) == 1:
        return pts[0][ix], pts[0][iy]
    p, q = pts[0], pts[1]
    x = lam[0] * p[ix] + lam[1] * q[ix]
    y = lam[0] * p[iy] + lam[1] * q[iy]
    if len(lam) == 3:
        r = pts[2]
        x += lam[2] * r[ix]
        y += lam[2] * r[iy]
    return x, y


def _solve(simplex: list):
    """Closest point of the simplex to the origin: the reduced simplex and its weights."""
    if len(simplex) == 1:
        return simplex, [1.0]
    if len(simplex) == 2:
        return _solve2(simplex[0], simplex[1])
    return _solve3(*simplex)


def _solve2(s1, s2):
    x1, y1, x2, y2 = s1[2], s1[3], s2[2], s2[3]
    ex, ey = x2 - x1, y2 - y1
    d2 = -(x1 * ex + y1 * ey)   # weight of w2 (unnormalised)
    if d2 <= 0.0:
        return [s1], [1.0]
    d1 = x2 * ex + y2 * ey      # weight of w1
    if d1 <= 0.0:
        return [s2], [1.0]
    inv = 1.0 / (d1 + d2)
    return [s1, s2], [d1 * inv, d2 * inv]


def _solve3(s1, s2, s3):
    """Voronoi regions of a triangle (Box2D's b2SolveSimplex3)."""
    x1, y1, x2, y2, x3, y3 = s1[2], s1[3], s2[2], s2[3], s3[2], s3[3]
    e12x, e12y = x2 - x1, y2 - y1
    d12_1 = x2 * e12x + y2 * e12y
    d12_2 = -(x1 * e12x + y1 * e12y)
    e13x, e13y = x3 - x1, y3 - y1
    d13_1 = x3 * e13x + y3 * e13y
    d13_2 = -(x1 * e13x + y1 * e13y)
    e23x, e23y = x3 - x2, y3 - y2
    d23_1 = x3 * e23x + y3 * e23y
    d23_2 = -(x2 * e23x + y2 * e23y)
    n123 = e12x * e13y - e12y * e13x
    d123_1 = n123 * (x2 * y3 - y2 * x3)
    d123_2 = n123 * (x3 * y1 - y3 * x1)
    d123_3 = n123 * (x1 * y2 - y1 * x2)
    if d12_2 <= 0.0 and d13_2 <= 0.0:
        return [s1], [1.0]
    if d12_1 > 0.0 and d12_2 > 0.0 and d123_3 <= 0.0:
        inv = 1.0 / (d12_1 + d12_2)
        return [s1, s2], [d12_1 * inv, d12_2 * inv]
    if d13_1 > 0.0 and d13_2 > 0.0 and d123_2 <= 0.0:
        inv = 1.0 / (d13_1 + d13_2)
        return [s1, s3], [d13_1 * inv, d13_2 * inv]
    if d12_1 <= 0.0 and d23_2 <= 0.0:
        return [s2], [1.0]
    if d13_1 <= 0.0 and d23_1 <= 0.0:
        return [s3], [1.0]
    if d23_1 > 0.0 and d23_2 > 0.0 and d123_1 <= 0.0:
        inv = 1.0 / (d23_1 + d23_2)
        return [s2, s3], [d23_1 * inv, d23_2 * inv]
    total = d123_1 + d123_2 + d123_3
    if total == 0.0 or not (d123_1 > 0.0 and d123_2 > 0.0 and d123_3 > 0.0):
        # A flat or degenerate triangle: fall back to its best edge, never divide by 0.
        cands = [_solve2(s1, s2), _solve2(s1, s3), _solve2(s2, s3)]
        return min(cands, key=lambda c: _norm2(c))
    inv = 1.0 / total
    return [s1, s2, s3], [d123_1 * inv, d123_2 * inv, d123_3 * inv]


def _depth_in_triangle(simplex: list) -> float:
    """Smallest distance from the origin to the triangle's edge lines (origin inside)."""
    (_, _, x1, y1), (_, _, x2, y2), (_, _, x3, y3) = simplex
    if (x2 - x1) * (y3 - y1) - (y2 - y1) * (x3 - x1) < 0.0:
        x2, y2, x3, y3 = x3, y3, x2, y2
    best = math.inf
    for (px, py), (qx, qy) in (((x1, y1), (x2, y2)), ((x2, y2), (x3, y3)), ((x3, y3), (x1, y1))):
        ex, ey = qx - px, qy - py
        n = math.hypot(ex, ey)
        if n == 0.0:
            return 0.0
        best = min(best, (ex * (-py) - ey * (-px)) / n)
    return best


def _norm2(c) -> float:
    vx, vy = _combine(c[1], c[0], 2, 3)
    return vx * vx + vy * vy
