"""The "slab hull": one convex polygon holding a piece through an arc of angles.

This module owns the convex superset of a rotating piece (the rotation itself is
:func:`cspace.kernel.polygons.rotation.rotate`) (note se2-rotation.md, section 1):

- a vertex v turning through [a, b] (Δ = b − a < π, m the middle) traces an arc
  that lies in the triangle of its chord and its two end tangents, T(v) = conv{R_a v,
  R_b v, R_m v / cos(Δ/2)} (the tangents meet on the bisector at r / cos(Δ/2));
- a convex piece is the hull of its vertices, so R_θ P ⊆ H = conv ⋃ T(v_i) for every θ
  in [a, b]. H exceeds the hull of the two end poses by at most r·sin²(Δ/2)/cos(Δ/2);
- the computed H is then enlarged by a square [−δ, δ]² (the angular merge of
  :func:`cspace.kernel.minkowski.merge.minkowski_sum`) that covers every rounding on the way: see
  :func:`slab_pad`.

The SO(2) angle is OMPL's: a value in [−π, π), other values wrapped as OMPL's
``SO2StateSpace::enforceBounds`` does. The circle is cut into K equal slabs.
"""
from __future__ import annotations

import math

import numpy as np

from ..minkowski.merge import minkowski_sum
from ..polygons.hull import convex_hull
from ..polygons.polygon import as_array
from ..polygons.rotation import TWO_PI, rotate, rotate_piece, wrap_angle
from ..polygons.predicates import orient2d_xy
from ..minkowski.union import union as checked_union

# Every slab's hull interval is widened by this much on both sides, so an angle within
# rounding of a slab boundary (the slab index, the wrap, OMPL's interpolation) is still
# inside the interval of the slab it is assigned to: 64 ulps of π, about 2.8e-14 rad.
ANGLE_SLACK = 64.0 * math.ulp(math.pi)
# Relative pad of the slab hull, as a multiple of the coordinates' magnitude: 2^-44 is
# 512 units of roundoff (see slab_pad for the ~20 it must cover).
_PAD_REL = 2.0**-44
# Absolute floor of the pad (far above the smallest normal double, far below any scene).
_PAD_ABS = 2.0**-900


def slab_range(k: int, K: int) -> tuple[float, float]:
    """The angles slab k of K covers: [−π + k·2π/K, −π + (k+1)·2π/K] (computed in floats).

    >>> slab_range(0, 4) == (-math.pi, -math.pi / 2)
    True
    """
    if not (K >= 1 and 0 <= k < K):
        raise ValueError(f"slab_range: need 0 <= k < K, got k={k}, K={K}")
    w = TWO_PI / K
    return -math.pi + k * w, (math.pi if k == K - 1 else -math.pi + (k + 1) * w)


def slab_of(theta: float, K: int) -> int:
    """The slab holding θ (wrapped into [−π, π) first).

    The float index may be off by one within rounding of a boundary; the answer is
    checked against :func:`slab_range` widened by :data:`ANGLE_SLACK` (the interval
    the slab's hull is built for) and moved to the neighbour if needed, so the slab
    returned always covers θ.

    >>> slab_of(0.0, 4), slab_of(-math.pi, 4), slab_of(math.pi, 4), slab_of(3.0, 4)
    (2, 0, 0, 3)
    """
    t = wrap_angle(float(theta))
    if t != t:
        raise ValueError("slab_of: theta is NaN")
    k = min(max(int(math.floor((t + math.pi) * (K / TWO_PI))), 0), K - 1)
    for cand in (k, k - 1, k + 1):
        if 0 <= cand < K:
            a, b = slab_range(cand, K)
            if a - ANGLE_SLACK <= t <= b + ANGLE_SLACK:
                return cand
    raise AssertionError(f"slab_of: no slab covers {t!r}")  # pragma: no cover (cannot happen)


def slab_pad(magnitude: float) -> float:
    """δ, the pad of a slab hull whose coordinates (and those it is summed with) are ≤ ``magnitude``.

    δ = 2^-44 · magnitude (+ 2^-900), i.e. 512 units of roundoff u = 2^-53. It covers,
    with a wide margin, the gap between the computed hull and the exact set:
    math.cos/sin (< 1 ulp, ≤ u per factor), the rounded angles m = (a + b)/2 and Δ/2
    and cos(Δ/2) and the division (a few u·r), the rotation products and sums (≤ 3u·r);
    the rounding of the enlarged hull's own vertices (≤ 2u·(r + δ)); and, once H is
    summed with obstacle pieces of magnitude S, the rounding of the C-space's vertex
    sums on both sides of a comparison (≤ 2·2u·(r + S)) and of the interpolated
    positions along a motion (≤ 2u·S). In all about 20u·(r + S).

    >>> slab_pad(1.0) == 2.0**-44 + 2.0**-900
    True
    """
    return _PAD_REL * float(magnitude) + _PAD_ABS


def slab_hull(piece: np.ndarray, a: float, b: float, *, scale: float = 0.0) -> np.ndarray:
    """A convex CCW polygon H holding R_θ(piece) for every θ in [a, b] (0 ≤ b − a ≤ π/2).

    For ``b == a`` it is :func:`rotate_piece` (``rotate(piece, a)``, hull-repaired only if
    rounding bent it): translation is the zero-width case. Otherwise it is
    conv ⋃ T(v) over the vertices (see the module docstring) summed with the square
    [−δ, δ]², δ = :func:`slab_pad` of max(r / cos(Δ/2), ``scale``) where r is the largest
    vertex radius and ``scale`` the magnitude of the coordinates H will be summed
    with (the obstacles, the positions of a motion). With that pad H holds the
    exactly rotated piece and also :func:`rotate` of it at every float θ in [a, b].

    >>> sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    >>> H = slab_hull(sq, 0.0, math.pi / 2)
    >>> H[H[:, 1].argmax()].round(9).tolist()  # the tangents of (1, 1) and (-1, 1) meet at (0, 2)
    [0.0, 2.0]
    """
    pts, d = slab_points(piece, a, b, scale=scale)
    if d == 0.0:
        return pts
    square = np.array([[-d, -d], [d, -d], [d, d], [-d, d]])
    return minkowski_sum(convex_hull(pts), square)


def slab_points(piece: np.ndarray, a: float, b: float, *, scale: float = 0.0) -> tuple[np.ndarray, float]:
    """(points, δ): :func:`slab_hull` (same arguments) is the convex hull of the points summed with
    the square [−δ, δ]² (δ = 0, the points a convex polygon: ``b == a``). For a caller that needs
    no polygon, only a distance: GJK's from the points' hull, less δ√2, bounds the hull's from below.

    >>> pts, d = slab_points(np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]]), 0.0, math.pi / 2)
    >>> len(pts), 0.0 < d < 1e-12
    (12, True)
    """
    p = as_array(piece, copy=False)
    a, b = float(a), float(b)
    if not (b >= a and b - a <= 0.5 * math.pi + 4 * ANGLE_SLACK):
        raise ValueError(f"slab_hull: need 0 <= b - a <= pi/2, got [{a!r}, {b!r}]")
    if b == a:
        return rotate_piece(p, a), 0.0
    half = 0.5 * (b - a)
    m = a + half
    apex = rotate(p, m) / math.cos(half)  # the end tangents meet at R_m v / cos(Δ/2)
    pts = np.concatenate([rotate(p, a), rotate(p, b), apex])
    r = float(np.abs(apex).max()) * math.sqrt(2.0)
    return pts, slab_pad(max(r, float(scale)))


def slab_inner(piece: np.ndarray, a: float, b: float, pad: float) -> np.ndarray:
    """A convex polygon inside rotate_piece(piece, θ) for every θ in [a, b] ((0, 2) if none).

    Write θ = m + φ, |φ| <= h (m the middle, h the half-width). R_θ P = R_m R_φ P and
    R_φ P = ∩_e {x : (R_φ n_e)·x <= c_e} over P's edges (outward normal n_e, offset
    c_e). For one edge and x = |x|(cos α, sin α) relative to n_e, (R_φ n_e)·x =
    |x| cos(φ − α) is largest over the interval at an end, or at φ = α if α is in it.
    So J = ∩_φ R_φ P holds the two end half-planes (φ = ±h) of every edge and, on the
    wedge |α| <= h, |x| <= c_e; the chord half-plane n_e·x <= c_e cos h implies the
    latter there (|x| cos h <= |x| cos α = n_e·x), and for c_e < 0 it empties the wedge,
    where the end half-planes alone might not. Every offset is lowered by 4·pad·|n_e|
    (``pad`` = the slab pad: it covers the rounding of the turned normals, of the float
    clipping, of the final rotation and of the C-space sums), and the result is R_m J.
    This is the SE(2) C-space's certified-blocked set: an obstacle meeting it meets the
    robot at every angle of the slab.

    >>> sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    >>> J = slab_inner(sq, -0.1, 0.1, 1e-12)
    >>> bool(0.99 < J[:, 0].max() < 1.0), len(J)
    (True, 12)
    """
    p = as_array(piece, copy=False)
    half = 0.5 * (float(b) - float(a))
    m = float(a) + half
    ch, sh = math.cos(half), math.sin(half)
    box = 2.0 * float(np.hypot(p[:, 0], p[:, 1]).max())  # the clipping's rounding stays ~u·r
    poly = [(-box, -box), (box, -box), (box, box), (-box, box)]
    for nx, ny, c, ln in edge_planes(p):
        low = 4.0 * pad * ln
        for ux, uy, off in ((nx * ch - ny * sh, nx * sh + ny * ch, c - low),
                            (nx * ch + ny * sh, -nx * sh + ny * ch, c - low),
                            (nx, ny, c * ch - low)):
            poly = _clip_halfplane(poly, ux, uy, off)
        if len(poly) < 3:
            return np.zeros((0, 2))
    j = convex_hull(np.array(poly))
    return rotate_piece(j, m) if len(j) >= 3 else np.zeros((0, 2))


def robot_radius(pieces: list[np.ndarray]) -> float:
    """Largest distance of a robot vertex from the reference point (0 for a point robot).

    >>> robot_radius([np.array([[0., 0], [3, 4], [0, 1]])])
    5.0
    """
    return max((float(np.hypot(p[:, 0], p[:, 1]).max()) for p in pieces if len(p)), default=0.0)


def default_slabs(robot_radius: float, extent: float, gap: float | None = None) -> tuple[int, str]:
    """K, the number of slabs, and a one-line reason.

    In a slab of width Δ = 2π/K a robot point at radius r sweeps a chord of about
    r·Δ, so the slab C-obstacles are thicker than the C-obstacle at one angle by up
    to about r·Δ (plus r·Δ²/4, the hull's excess over the two end poses), and the
    inner (certified blocked) ones thinner by about as much. States in that band
    take the exact test (~20x a grid lookup) and motions through it are refined, so
    the validity cost grows with r·Δ / g, g the scene's typical gap: K is the
    smallest power of two with r·2π/K <= g/8 (measured on the bundled scenes: an
    exact-test share of a few per cent of uniform states). Each slab costs a
    translational C-space build plus an inner grid (~50-200 ms on the bundled
    scenes), paid lazily on first use, so K is clamped to [16, 64]: beyond 64 the
    build time dominates a planning run while the band is already a small
    fraction of the gaps. Tightness (the hull excess, ~r·Δ²/4) is then below 1 %
    of r. ``gap`` defaults to extent / 8 and is capped there.

    >>> default_slabs(1.0, 10.0)[0], default_slabs(0.1, 10.0)[0], default_slabs(5.0, 10.0)[0]
    (64, 16, 64)
    """
    g = extent / 8.0 if gap is None or not gap > 0.0 else min(gap, extent / 8.0)
    if robot_radius <= 0.0:
        return 1, "K = 1: a point robot does not turn"
    need = TWO_PI * robot_radius / (g / 8.0)
    k = 16
    while k < need and k < 64:
        k *= 2
    delta = TWO_PI / k
    chord = 2.0 * robot_radius * math.sin(0.5 * delta)
    excess = math.sin(0.5 * delta) ** 2 / math.cos(0.5 * delta)
    return k, (f"K = {k}: robot radius {robot_radius:.3g}, a slab of {math.degrees(delta):.3g} deg moves its "
               f"farthest point by {chord:.3g} ({100 * chord / g:.2g} % of the typical gap {g:.3g}); "
               f"hull excess over the end poses <= {100 * excess:.2g} % of the radius")


def typical_gap(pieces: list[np.ndarray], extent: float) -> float:
    """Median distance from an obstacle piece to its nearest other piece (shapely),
    ignoring touching pieces (parts of one decomposed obstacle); extent / 8 if none."""
    if len(pieces) < 2:
        return extent / 8.0
    import shapely

    geoms = [shapely.Polygon(p) for p in pieces[:400]]
    tree = shapely.STRtree(geoms)
    gaps = []
    for i, g in enumerate(geoms):
        j, d = tree.query_nearest(g, exclusive=True, return_distance=True, all_matches=False)
        if len(d) and d[0] > 0.0:
            gaps.append(float(d[0]))
    return float(np.median(gaps)) if gaps else extent / 8.0


def inscribed_radius(robot_parts: list[np.ndarray]) -> float:
    """Radius of a disk about the origin inside the union of the robot parts, rounded down.

    0 if the origin is in no part. Computed as the distance from the origin to the
    boundary of the union (shapely), then shrunk by 2^-40 relative: the disk of that
    radius is certainly inside (the union's rounding and the distance's are far
    smaller). The parts may be non-convex (simple polygons).

    >>> inscribed_radius([np.array([[-1., -1], [1, -1], [1, 2], [-1, 2]])]) < 1.0
    True
    >>> round(inscribed_radius([np.array([[-1., -1], [1, -1], [1, 2], [-1, 2]])]), 9)
    1.0
    >>> inscribed_radius([np.array([[1., 1], [2, 1], [2, 2]])])
    0.0
    """
    import shapely
    from shapely.geometry import Point, Polygon

    polys = [Polygon(as_array(p)) for p in robot_parts if len(p) >= 3]
    if not polys:
        return 0.0
    union = checked_union(polys)
    origin = Point(0.0, 0.0)
    if not union.covers(origin):
        return 0.0
    d = float(union.boundary.distance(origin))
    scale = max(float(np.abs(as_array(p)).max()) for p in robot_parts if len(p))
    d -= 2.0**-40 * scale  # the rounding of the union and the distance, with room to spare
    return max(d, 0.0)


def inscribed_polygon(radius: float, n: int = 32) -> np.ndarray:
    """A regular n-gon inside the disk of ``radius`` about the origin (CCW, vertices at
    radius·(1 − 1e-12), so rounding never puts one outside).

    >>> P = inscribed_polygon(2.0, 8)
    >>> len(P), bool((np.hypot(P[:, 0], P[:, 1]) < 2.0).all())
    (8, True)
    """
    if radius <= 0.0:
        return np.zeros((0, 2))
    if n < 3:
        raise ValueError("inscribed_polygon: need n >= 3")
    rr = float(radius) * (1.0 - 1e-12)
    ang = np.arange(n) * (TWO_PI / n)
    return np.column_stack([rr * np.cos(ang), rr * np.sin(ang)]) + 0.0


def edge_planes(p: np.ndarray) -> list[tuple[float, float, float, float]]:
    """Per edge of a CCW polygon: outward normal (dy, −dx), offset n·start, and |n|."""
    pts = p.tolist()
    out = []
    px, py = pts[-1]
    for qx, qy in pts:
        nx, ny = qy - py, px - qx
        out.append((nx, ny, nx * px + ny * py, math.hypot(nx, ny)))
        px, py = qx, qy
    return out


def _clip_halfplane(poly: list, nx: float, ny: float, c: float) -> list:
    """The part of a convex polygon (list of points) where n·x <= c, in floats
    (Sutherland–Hodgman on one edge; the caller's margins cover the rounding)."""
    out = []
    k = len(poly)
    for t in range(k):
        px, py = poly[t - 1]
        qx, qy = poly[t]
        fp, fq = nx * px + ny * py - c, nx * qx + ny * qy - c
        if fq <= 0.0:
            if fp > 0.0:
                s = fp / (fp - fq)
                out.append((px + (qx - px) * s, py + (qy - py) * s))
            out.append((qx, qy))
        elif fp <= 0.0:
            s = fp / (fp - fq)
            out.append((px + (qx - px) * s, py + (qy - py) * s))
    return out
