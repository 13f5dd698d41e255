"""EPA: penetration depth and direction of two overlapping convex sets, from supports.

When 0 lies inside D = A ⊕ (−B), the minimum translation that separates A and B is
the distance from the origin to D's boundary, along the normal of the nearest edge:
moving B by depth·normal leaves the two touching. EPA grows a polygon inside D
from a few support points: split the edge nearest the origin by the support point
in its normal until the support adds nothing. In 2-D D has at most |A| + |B|
vertices, so at most that many insertions; the loop is capped there, checks for
duplicate supports, and falls back to the materialised difference (the exact
angular merge of :mod:`cspace.kernel.minkowski.merge`) if the cap is reached.

Touching sets get depth 0 (never "expanded"), separated sets a clear status.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .gjk import gjk_distance
from ..polygons.polygon import as_array
from ..polygons.scaling import scaled_copies

# Support progress below this times the local scale ends the expansion.
EPA_TOL = 1e-12


class Penetration(NamedTuple):
    """Minimum translation of B out of A: ``depth`` along unit ``normal``."""

    depth: float
    normal: np.ndarray
    iterations: int
    status: str


def epa_penetration(A, B) -> Penetration:
    """Penetration depth and normal of convex A and B (vertex arrays).

    >>> p = epa_penetration([[0, 0], [2, 0], [2, 2], [0, 2]], [[1.5, 0.5], [3, 0.5], [3, 1.5], [1.5, 1.5]])
    >>> round(p.depth, 12), p.normal.tolist(), p.status
    (0.5, [1.0, 0.0], 'overlapping')
    """
    a = as_array(A, nonempty=True)
    b = as_array(B, nonempty=True)
    with np.errstate(over="ignore", invalid="ignore"):
        extent = max(float(np.abs(a - a[0]).max()), float(np.abs(b - a[0]).max()))
    rescaled = scaled_copies([a, b], extent)
    if rescaled:  # products would under- or overflow: the same sets at 2^k scale (exact)
        k, (sa, sb) = rescaled
        p = epa_penetration(sa, sb)
        with np.errstate(over="ignore"):
            return Penetration(float(np.ldexp(p.depth, -k)), p.normal, p.iterations, p.status)
    d = gjk_distance(a, b)
    if d.status == "separated":
        # The closest points are rounded in the global frame: normalise their difference
        # rather than divide by the (local-frame) distance, so the normal is a unit vector.
        v = d.point_b - d.point_a
        nv = math.hypot(v[0], v[1])
        n = v / nv if nv > 0.0 else np.array([1.0, 0.0])
        return Penetration(0.0, n, d.iterations, "separated")
    origin = a[0].copy()
    al, bl = a - origin, b - origin
    scale = max(float(np.abs(al).max()), float(np.abs(bl).max()), 1e-300)
    if d.status == "touching":
        return Penetration(0.0, _nearest_face(al, bl)[1], d.iterations, "touching")
    res = _expand(al, bl, scale)
    if res is None:  # cap reached or a degenerate start: the exact materialised answer
        depth, n = _nearest_face(al, bl)
        return Penetration(depth, n, len(a) + len(b), "overlapping")
    depth, n, it = res
    return Penetration(depth, n, it, "overlapping")


def _support_d(al: np.ndarray, bl: np.ndarray, n) -> np.ndarray:
    """Support point of D = A − B in direction n."""
    return al[int(np.argmax(al @ n))] - bl[int(np.argmin(bl @ n))]


def _expand(al: np.ndarray, bl: np.ndarray, scale: float):
    """EPA proper. Returns (depth, normal, iterations) or None to ask for the exact route."""
    dirs = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]
    poly = []
    for dx, dy in dirs:
        w = _support_d(al, bl, np.array([dx, dy]))
        if not poly or not np.array_equal(w, poly[-1]):
            poly.append(w)
    if len(poly) > 1 and np.array_equal(poly[0], poly[-1]):
        poly.pop()
    if len(poly) < 3 or _min_face(poly)[0] <= 0.0:
        return None  # origin not strictly inside the start polygon (D is thin here)
    cap = len(al) + len(bl) + 8
    for it in range(1, cap + 1):
        dist, k, n = _min_face(poly)
        w = _support_d(al, bl, n)
        if any(np.array_equal(w, p) for p in poly) or float(n @ w) - dist <= EPA_TOL * scale:
            return dist, n, it
        poly.insert(k + 1, w)
    return None


def _min_face(poly: list):
    """Nearest edge of a CCW polygon containing the origin: (distance, edge index, unit normal)."""
    best = (math.inf, -1, None)
    m = len(poly)
    for i in range(m):
        p, q = poly[i], poly[(i + 1) % m]
        ex, ey = q[0] - p[0], q[1] - p[1]
        ln = math.hypot(ex, ey)
        if ln == 0.0:
            continue
        n = np.array([ey / ln, -ex / ln]) + 0.0  # + 0.0: no negative zeros
        dist = float(n @ p)
        if dist < best[0]:
            best = (dist, i, n)
    return best


def _nearest_face(al: np.ndarray, bl: np.ndarray):
    """Depth and normal from the materialised D (exact merge), for the rare fallback."""
    from ..polygons.hull import convex_hull
    from ..minkowski.merge import minkowski_sum, reflect

    # The sets are the hulls of their vertices (supports see only the hull).
    D = minkowski_sum(convex_hull(al), reflect(convex_hull(bl)))
    if len(D) < 3:  # a flat difference: depth 0 along its normal
        e = D[-1] - D[0]
        ln = math.hypot(*e) or 1.0
        return 0.0, np.array([e[1] / ln, -e[0] / ln])
    dist, _, n = _min_face(list(D))
    return max(dist, 0.0), n
