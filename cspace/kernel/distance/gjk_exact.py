"""GJK's exact decisions: the relation (separated / touching / overlapping) of two convex
sets where the float distance is within its error bound of zero, and the distance of a
sliver gap the float loop mistook for an overlap.

:func:`cspace.kernel.distance.gjk.gjk_distance` calls these (and re-exports :func:`exact_relation`):
first :func:`contact_relation`, one exact line near GJK's contact, else the full
separating axis test of :func:`exact_relation`, in exact signs and rationals.
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ..polygons.arrays import as_array
from ..polygons.predicates import orient2d_cols, orient2d_xy


def contact_relation(A: list, B: list, simplex: list) -> str | None:
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
    from ..polygons.hull import convex_hull

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


def exact_distance(a: np.ndarray, b: np.ndarray, origin: np.ndarray):
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
