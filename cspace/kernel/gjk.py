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
  two (:mod:`cspace.kernel.scaling`), exactly;
- a support pair already in the simplex ends the loop (no cycling), as does no
  progress (v·v − v·w ≤ 1e-14 · v·v), and an iteration cap;
- degenerate simplices (repeated or collinear points) are reduced, never inverted:
  no 0/0, no NaN;
- where the float distance is within its error bound of zero, the relation
  (separated / touching / overlapping) is decided exactly: the separating axis test
  over the sets' hull edges in rational arithmetic.
"""
from __future__ import annotations

import math
from fractions import Fraction
from itertools import chain
from typing import NamedTuple

import numpy as np

from .polygon import as_array
from .predicates import orient2d_cols, orient2d_xy
from .scaling import SAFE_MAX, SAFE_MIN, scaled_copies

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


def gjk_distance(A, B, max_iterations: int = MAX_ITERATIONS) -> Distance:
    """Distance and closest points of convex sets A and B (vertex arrays; points and segments too).

    ``max_iterations`` caps the loop (the default is never reached on separated or
    overlapping pairs; a capped answer is an upper bound on the distance).

    >>> d = gjk_distance([[0, 0], [1, 0], [1, 1], [0, 1]], [[3, 0], [4, 0], [4, 1], [3, 1]])
    >>> d.distance, d.status
    (2.0, 'separated')
    >>> gjk_distance([[0, 0], [1, 0], [1, 1], [0, 1]], [[1, 0], [2, 0], [2, 1], [1, 1]]).status
    'touching'
    """
    a = as_array(A, nonempty=True)
    b = as_array(B, nonempty=True)
    origin = a[0].copy()
    ox, oy = origin.tolist()
    if len(a) + len(b) <= 80:  # Python floats (an overflow is inf, silently): cheaper when small
        al = [(x - ox, y - oy) for x, y in a.tolist()]
        bl = [(x - ox, y - oy) for x, y in b.tolist()]
        extent = _scale(al, bl)
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            la, lb = a - origin, b - origin
            extent = max(float(np.abs(la).max()), float(np.abs(lb).max())) or 1.0  # as _scale
        al, bl = la.tolist(), lb.tolist()
    if not SAFE_MIN <= extent < SAFE_MAX and (rescaled := scaled_copies([a, b], extent)):
        k, (sa, sb) = rescaled  # products would under- or overflow: the same sets at 2^k scale
        d = gjk_distance(sa, sb, max_iterations)
        with np.errstate(over="ignore"):  # a distance beyond the double range is inf
            return Distance(float(np.ldexp(d.distance, -k)), np.ldexp(d.point_a, -k), np.ldexp(d.point_b, -k),
                            d.iterations, d.status)
    dist, pa, pb, it, inside, simplex = _gjk(al, bl, max_iterations)
    if inside == "deep":
        p = np.array((pa[0] + ox, pa[1] + oy))
        return Distance(0.0, p, p.copy(), it, "overlapping")
    if inside or dist <= EXACT_BAND * extent:
        status = _contact_relation(a.tolist(), b.tolist(), simplex) or exact_relation(a, b)
        if status != "separated":
            p = np.array((pa[0] + ox, pa[1] + oy))
            return Distance(0.0, p, p.copy(), it, status)
        if inside:  # float said overlap but exact says apart: a sliver gap, measure it exactly
            dist, pa, pb = _exact_distance(a, b, origin)
    return Distance(float(dist), np.array((pa[0] + ox, pa[1] + oy)), np.array((pb[0] + ox, pb[1] + oy)),
                    it, "separated")


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
    """The GJK loop in the local frame.

    Returns (distance, pa, pb, iterations, origin_inside, simplex); the simplex's
    vertices carry the indices (ia, ib) of the supporting vertices of A and B."""
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
    if inside:
        # Certain overlap when the origin is deep inside the simplex (beyond any rounding).
        deep = len(simplex) == 3 and _depth_in_triangle(simplex) > EXACT_BAND * _scale(al, bl)
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


def _contact_relation(A: list, B: list, simplex: list) -> str | None:
    """The exact relation proved by one line near GJK's contact, or None if none is found.

    Candidates are the lines of the edges at the supporting vertices of GJK's final
    simplex. A line L weakly separates when A lies on one closed side and B on the
    other (exact signs). Then A and B meet iff their traces on L overlap; the traces
    are the vertices exactly on L, ordered along L by their (x, y) order, so the
    overlap test is exact too. For touching convex polygons such a line always exists
    along an edge at a contact vertex; when none is found the caller runs the full
    separating-axis test.
    """
    lines = set()
    for P, idx in ((A, {s[0] for s in simplex}), (B, {s[1] for s in simplex})):
        n = len(P)
        if n < 2:
            continue
        for i in idx:
            for j in ((i - 1) % n, (i + 1) % n):
                p, q = P[i], P[j]
                if p != q:
                    lines.add((tuple(p), tuple(q)) if tuple(p) < tuple(q) else (tuple(q), tuple(p)))
    for (x0, y0), (x1, y1) in lines:
        sa = _side_of(A, x0, y0, x1, y1)
        if sa is None:
            continue
        sb = _side_of(B, x0, y0, x1, y1)
        if sb is None or sa[0] * sb[0] > 0:
            continue
        on_a, on_b = sa[1], sb[1]
        if not on_a or not on_b:
            return "separated"  # a strict gap on one side of L
        lo_a, hi_a = min(on_a), max(on_a)  # points exactly on L: (x, y) order is the order along L
        lo_b, hi_b = min(on_b), max(on_b)
        return "touching" if max(lo_a, lo_b) <= min(hi_a, hi_b) else "separated"
    return None


def _side_of(P: list, x0: float, y0: float, x1: float, y1: float):
    """(+1 or -1, points on the line) if P lies on one closed side of line (x0,y0)->(x1,y1),
    else None (exact signs)."""
    side = 0
    on = []
    for x, y in P:
        s = orient2d_xy(x0, y0, x1, y1, x, y)
        if s == 0:
            on.append((x, y))
        elif side == 0:
            side = s
        elif s != side:
            return None
    return (side or 1), on


def _norm2(c) -> float:
    vx, vy = _combine(c[1], c[0], 2, 3)
    return vx * vx + vy * vy


# ---------------------------------------------------------------- exact decisions


def exact_relation(A, B) -> str:
    """'separated', 'touching' or 'overlapping', decided in exact rational arithmetic.

    Separating axis test over the hull edges of both sets (and, for a point or a
    segment, the segment's direction and the axis joining the two sets): separated
    if some axis separates strictly, touching if one separates only weakly (the sets
    meet but no interior point of one is interior to the other's side), else
    overlapping.

    >>> exact_relation([[0, 0], [1, 0], [0, 1]], [[1, 0], [2, 0], [1, 1]])
    'touching'
    """
    from .hull import convex_hull

    ga = _as_hull(as_array(A, nonempty=True), convex_hull)
    gb = _as_hull(as_array(B, nonempty=True), convex_hull)
    if len(ga) >= 3 and len(gb) >= 3:
        return _relation_polygons(ga, gb)
    ha = [(Fraction(x), Fraction(y)) for x, y in ga.tolist()]
    hb = [(Fraction(x), Fraction(y)) for x, y in gb.tolist()]
    weak = False
    for ax in _axes(ha, hb):
        pa = [ax[0] * x + ax[1] * y for x, y in ha]
        pb = [ax[0] * x + ax[1] * y for x, y in hb]
        lo_a, hi_a, lo_b, hi_b = min(pa), max(pa), min(pb), max(pb)
        if hi_a < lo_b or hi_b < lo_a:
            return "separated"
        if hi_a == lo_b or hi_b == lo_a:
            weak = True
    return "touching" if weak else "overlapping"


def _as_hull(p: np.ndarray, convex_hull) -> np.ndarray:
    """p itself if it is already a strictly convex CCW polygon (the usual case: C-space
    pieces), else its exact hull. Strict left turns everywhere and edge directions that
    cross from the lower to the upper half-plane exactly once mean p winds once."""
    n = len(p)
    if 3 <= n <= 64:
        pts = p.tolist()
        ups = 0
        for i in range(n):
            (ax, ay), (bx, by), (cx, cy) = pts[i - 2], pts[i - 1], pts[i]
            if orient2d_xy(ax, ay, bx, by, cx, cy) <= 0:
                break
            lower_before = by < ay or (by == ay and bx < ax)
            upper_after = cy > by or (cy == by and cx > bx)
            ups += lower_before and upper_after
        else:
            if ups == 1:
                return p
    return convex_hull(p)


def _relation_polygons(ga: np.ndarray, gb: np.ndarray) -> str:
    """Separating axis test for two convex polygons (CCW hulls) with the exact predicate.

    An edge of A separates iff every vertex of B lies right of its directed line
    (orient2d < 0), weakly iff on or right of it; the same with A and B swapped.
    Disjoint compact convex polygons always have a strictly separating edge line,
    so no strict separator and a weak one means the sets touch. An edge is dropped
    as soon as one vertex of the other set lies strictly left of it.
    """
    if len(ga) * len(gb) > 144:  # large: all edge-vertex signs at once (one filter pass)
        return _relation_polygons_cols(ga, gb)
    weak = False
    for g, h in ((ga.tolist(), gb.tolist()), (gb.tolist(), ga.tolist())):
        for i in range(len(g)):
            (x0, y0), (x1, y1) = g[i - 1], g[i]
            on_line = False
            for x, y in h:
                s = orient2d_xy(x0, y0, x1, y1, x, y)
                if s > 0:
                    break
                on_line = on_line or s == 0
            else:
                if not on_line:
                    return "separated"
                weak = True
    return "touching" if weak else "overlapping"


def _relation_polygons_cols(ga: np.ndarray, gb: np.ndarray) -> str:
    """:func:`_relation_polygons` with the signs of every edge-vertex pair in one array."""
    weak = False
    for g, h in ((ga, gb), (gb, ga)):
        e0 = np.roll(g, 1, axis=0)[:, None, :]
        e1 = g[:, None, :]
        s = orient2d_cols(e0[..., 0], e0[..., 1], e1[..., 0], e1[..., 1], h[None, :, 0], h[None, :, 1])
        outside = (s <= 0).all(axis=1)
        if (outside & (s < 0).all(axis=1)).any():
            return "separated"
        weak = weak or bool(outside.any())
    return "touching" if weak else "overlapping"


def _axes(ha: list, hb: list) -> list:
    axes = []
    for h in (ha, hb):
        n = len(h)
        for i in range(n if n > 2 else n - 1):
            (x0, y0), (x1, y1) = h[i], h[(i + 1) % n]
            axes.append((y1 - y0, x0 - x1))
            if n < 3:
                axes.append((x1 - x0, y1 - y0))
    if len(ha) < 3 or len(hb) < 3:
        axes.append((hb[0][0] - ha[0][0], hb[0][1] - ha[0][1]))
    axes = [a for a in axes if a != (0, 0)]
    return axes or [(Fraction(1), Fraction(0))]  # two equal points: any axis separates weakly


def _exact_distance(a: np.ndarray, b: np.ndarray, origin: np.ndarray):
    """Distance of disjoint sets by brute force over vertex-edge pairs (the rare sliver case)."""
    best = (math.inf, None, None)
    for P, Q, swap in ((a, b, False), (b, a, True)):
        for p in P:
            for i in range(len(Q)):
                q0, q1 = Q[i], Q[(i + 1) % len(Q)] if len(Q) > 1 else Q[i]
                c = _closest_on_segment(p, q0, q1)
                d = math.hypot(p[0] - c[0], p[1] - c[1])
                if d < best[0]:
                    best = (d, c, p) if swap else (d, p, c)
    d, pa, pb = best
    return d, tuple(np.asarray(pa) - origin), tuple(np.asarray(pb) - origin)


def _closest_on_segment(p, q0, q1):
    ex, ey = q1[0] - q0[0], q1[1] - q0[1]
    ee = ex * ex + ey * ey
    if ee == 0.0:
        return q0
    t = min(1.0, max(0.0, ((p[0] - q0[0]) * ex + (p[1] - q0[1]) * ey) / ee))
    return (q0[0] + t * ex, q0[1] + t * ey)
