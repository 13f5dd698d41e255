"""The scalar angular merge of convex polygons: exact, for the small operands of C-space pieces.

Operands are cleaned (CCW, lowest first, no repeated or collinear vertex, convexity checked
by exact turns), merged two at a time by two pointers (:func:`merge2_small`, which also
tells whether every vertex sum was exact) or k at a time (:func:`merge_small`), edges
compared by half-plane and then by the exact sign of their cross product, parallel edges
fused. :func:`certify_small` checks the rounded sum is strictly convex, else returns the
exact hull of its vertices. :func:`cspace.kernel.minkowski.merge.minkowski_sum` takes this route up
to a few dozen vertices in total, and when the vectorised route cannot certify its order.
"""
from __future__ import annotations

import numpy as np

from ..polygons.polygon import drop_collinear
from ..polygons.predicates import CCW_ERRBOUND_A, cross_diff_sign


def _turn(ux: float, uy: float, vx: float, vy: float, a, b, c, d) -> int:
    """Sign of (b - a) x (d - c), given the float edges u = b - a and v = d - c.

    The stage-A filter on the already-rounded differences; the exact product of the
    endpoints' rationals when it cannot decide.
    """
    left = ux * vy
    right = uy * vx
    det = left - right
    bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
    if det > bound and bound > 1e-280:
        return 1
    if -det > bound and bound > 1e-280:
        return -1
    return cross_diff_sign(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])



def clean_small(pts: list) -> list:
    """CCW, lowest-first, no repeated or collinear vertex; checks convexity (scalar)."""
    return clean_edges_small(pts)[0]


def clean_edges_small(pts: list) -> tuple[list, list]:
    """:func:`clean_small`, and the cleaned operand's edges from :func:`_edges_small`.

    One pass computes each vertex's turn as the cross product of its two edges (the
    stage-A filter inline, rationals only in doubt) and the lowest vertex.
    """
    out = [(p[0], p[1]) for i, p in enumerate(pts) if p != pts[i - 1]] or [tuple(pts[0])]
    n = len(out)
    if n <= 2:
        out = extremes(out)
        return out, _edges_small(out)
    pos = neg = 0
    px, py = out[-1]
    qx, qy = out[0]
    ux, uy = qx - px, qy - py
    low = 0
    for i in range(n):
        rx, ry = out[i + 1] if i + 1 < n else out[0]
        vx, vy = rx - qx, ry - qy
        left, right = ux * vy, uy * vx
        det = left - right
        bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
        if bound > 1e-280 and det > bound:
            pos += 1
        elif bound > 1e-280 and -det > bound:
            neg += 1
        else:
            t = cross_diff_sign(px, py, qx, qy, qx, qy, rx, ry)
            if t == 0:  # a collinear vertex: drop it exactly (rare), then start again
                p = drop_collinear(np.array(out, dtype=np.float64))
                if len(p) >= 3:
                    return clean_edges_small(p.tolist())
                out = extremes(out)
                return out, _edges_small(out)
            pos += t > 0
            neg += t < 0
        if qy < out[low][1] or (qy == out[low][1] and qx < out[low][0]):
            low = i
        px, py, qx, qy, ux, uy = qx, qy, rx, ry, vx, vy
    if pos and neg:
        raise ValueError("minkowski_sum: operand is not convex")
    if neg:
        out.reverse()
        low = n - 1 - low
    out = out[low:] + out[:low]
    return out, _edges_small(out)  # raises unless the edges sweep the angle once


def extremes(pts: list) -> list:
    """A point or a segment, as its one or two extreme points, lowest (then leftmost) first."""
    lo = min(pts, key=lambda v: (v[1], v[0]))
    hi = max(pts, key=lambda v: (v[1], v[0]))
    return [lo] if lo == hi else [lo, hi]



def _half(dx: float, dy: float) -> int:
    """0 for directions in [0, pi) (upper half-plane), 1 for [pi, 2 pi)."""
    return 0 if dy > 0.0 or (dy == 0.0 and dx > 0.0) else 1



def merge2_small(P: list, Q: list, EP: list | None = None, EQ: list | None = None) -> tuple[list, bool]:
    """The two-operand merge: two pointers, exact comparison, parallel edges fused.

    Returns the vertices as a flat list [x0, y0, x1, y1, ...] (cheap to hand to numpy)
    and whether every vertex sum was exact (the test of Fast2Sum: fl(s - a) == c
    and fl(s - c) == a hold together only for an exact sum).
    """
    n, m = len(P), len(Q)
    EP = _edges_small(P) if EP is None else EP
    EQ = _edges_small(Q) if EQ is None else EQ
    ne, me = len(EP), len(EQ)
    i = j = 0
    (ax, ay), (cx, cy) = P[0], Q[0]
    sx, sy = ax + cx, ay + cy
    exact = sx - ax == cx and sx - cx == ax and sy - ay == cy and sy - cy == ay
    out = [sx, sy]
    while True:
        if i < ne and j < me:
            ux, uy, hu = EP[i]
            vx, vy, hv = EQ[j]
            if hu != hv:
                s = hv - hu  # the edge in the upper half comes first
            else:  # exact sign of u x v: the stage-A filter, rationals in doubt
                left, right = ux * vy, uy * vx
                det = left - right
                bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
                if bound > 1e-280 and abs(det) > bound:
                    s = 1 if det > 0 else -1
                else:
                    a, b, c, d = P[i], P[(i + 1) % n], Q[j], Q[(j + 1) % m]
                    s = cross_diff_sign(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])
            # s > 0: P's edge comes first; s < 0: Q's; 0: parallel, fused.
            if s >= 0:
                i += 1
            if s <= 0:
                j += 1
        elif i < ne:
            i += 1
        elif j < me:
            j += 1
        if i == ne and j == me:
            return out, exact
        (ax, ay), (cx, cy) = P[i % n], Q[j % m]
        sx, sy = ax + cx, ay + cy
        if exact:
            exact = sx - ax == cx and sx - cx == ax and sy - ay == cy and sy - cy == ay
        out += (sx, sy)


def _edges_small(P: list) -> list:
    """Edge vectors of a cleaned operand with their half-plane (0 upper, 1 lower).

    From the lowest vertex of a convex polygon, the edges read upper...upper then
    lower...lower; a polygon with all turns left that returns to the upper half
    (a pentagram) winds more than once and is not convex. A point has no edge.
    """
    if len(P) < 2:
        return []
    edges = [(bx - ax, by - ay, 0 if by > ay or (by == ay and bx > ax) else 1)
             for (ax, ay), (bx, by) in zip(P, P[1:] + P[:1])]
    seen_lower = 0
    for e in edges:
        if e[2] < seen_lower:
            raise ValueError("minkowski_sum: operand is not convex (winds more than once)")
        seen_lower = e[2]
    return edges


def merge_small(polys: list) -> list:
    """The k-way angular merge, one vertex of the sum per distinct edge direction.

    ``idx[i]`` is the current vertex of operand i; the current vertex of the sum is
    the sum of those. At each step the operands whose next edge has the smallest
    angle (exactly equal angles tie) all advance together, which fuses parallel edges.
    """
    k = len(polys)
    sizes = [len(p) for p in polys]
    idx = [0] * k
    out = [(sum(p[0][0] for p in polys), sum(p[0][1] for p in polys))]
    total = sum(s if s > 1 else 0 for s in sizes)
    taken = 0
    while taken < total:
        best: list = []
        bh = 2
        for i in range(k):
            n = sizes[i]
            if n < 2 or idx[i] == n:
                continue
            p = polys[i]
            a, b = p[idx[i]], p[(idx[i] + 1) % n]
            h = _half(b[0] - a[0], b[1] - a[1])
            if h < bh:
                bh, best = h, [(i, a, b)]
            elif h == bh:
                _, c, d = best[0]
                s = cross_diff_sign(c[0], c[1], d[0], d[1], a[0], a[1], b[0], b[1])
                if s < 0:      # edge a->b is clockwise of the current best: smaller angle
                    best = [(i, a, b)]
                elif s == 0:   # parallel, same half: the same direction
                    best.append((i, a, b))
        for i, _, _ in best:
            idx[i] += 1
            taken += 1
        if taken < total:
            out.append((sum(polys[i][idx[i] % sizes[i]][0] for i in range(k)),
                        sum(polys[i][idx[i] % sizes[i]][1] for i in range(k))))
    return out


def certify_small(out: list) -> list:
    """Exact strict-convexity check of the rounded sum; repair by exact hull if needed."""
    n = len(out)
    if n < 3:  # a point or a segment, already lowest first
        return out
    for i in range(n):
        a, b, c = out[i - 1], out[i], out[(i + 1) % n]
        if _turn(b[0] - a[0], b[1] - a[1], c[0] - b[0], c[1] - b[1], a, b, b, c) <= 0:
            from ..polygons.hull import convex_hull

            return convex_hull(out).tolist()
    return out
