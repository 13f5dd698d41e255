"""The float filter of the SE(2) exact pose test: one (obstacle piece, turned robot piece) pair.

:meth:`cspace.se2.cspace.SE2CSpace.pose_test` decides a pose that its slab's grids leave
open by testing the reference point against each nearby pair's sum O ⊕ −R'. Most pairs
are decided here, in floats, by separating axes with a margin far above their rounding;
only a pair this filter leaves unsure goes to the exact test of the computed sum.
"""
from __future__ import annotations

import math


def pair_filter(o_edges: list, o_pts: list, r_pts: list, r_axes: list, x: float, y: float, margin: float) -> int:
    """Float filter for "is (x, y) in O ⊕ −R'" (R' the robot piece at θ: rotated vertices
    ``r_pts``; ``r_axes`` the outward normals of −R' with a vertex of R' on each edge and
    the normal's length): +1 outside, −1 inside, 0 unsure.

    The sum's edge normals are O's and −R''s. For each such n, g(n) = n·p − h_O(n) −
    h_{−R'}(n) > 0 puts p outside (for ANY direction n); g(n) < 0 for every edge normal
    puts it inside. Decisions are taken only with |g| > margin·|n|, the margin (the
    slab pad, 512 units of roundoff of the magnitudes) far above the float error of g,
    of the turned normals, and of the rounded vertices of the computed sum, so a
    decided answer is also the exact test's answer.

    >>> sq = [(1.0, 0.0, 6.0, 1.0), (0.0, 1.0, 6.0, 1.0), (-1.0, 0.0, -4.0, 1.0), (0.0, -1.0, -4.0, 1.0)]
    >>> corners = [(4.0, 4.0), (6.0, 4.0), (6.0, 6.0), (4.0, 6.0)]
    >>> dot = [(0.0, 0.0)]  # a point robot: no axes of its own
    >>> pair_filter(sq, corners, dot, [], 5.0, 5.0, 1e-9), pair_filter(sq, corners, dot, [], 8.0, 5.0, 1e-9)
    (-1, 1)
    """
    inside = True
    for nx, ny, off, ln in o_edges:  # O's normals: h_{−R'}(n) = −min over r of n·r
        lo = math.inf
        for rx, ry in r_pts:
            v = nx * rx + ny * ry
            if v < lo:
                lo = v
        g = nx * x + ny * y - off + lo
        m = margin * ln
        if g > m:
            return 1
        if g >= -m:
            inside = False
    for nx, ny, rx, ry, ln in r_axes:  # −R''s normals: h_{−R'}(n) = n·(−r_e), h_O(n) = max n·o
        hi = -math.inf
        for ox, oy in o_pts:
            v = nx * ox + ny * oy
            if v > hi:
                hi = v
        g = nx * x + ny * y - hi + (nx * rx + ny * ry)
        m = margin * ln
        if g > m:
            return 1
        if g >= -m:
            inside = False
    return -1 if inside else 0


