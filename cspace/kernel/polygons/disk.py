"""Disks as polygons: the circumscribed regular polygon with a bounded error.

A disk of radius r is replaced by the regular N-gon that contains it. Its vertices
are at distance R = r / cos(pi / N) from the centre, so the polygon lies within the
annulus r <= |x - c| <= R and the largest distance from the polygon to the disk is
R - r = r (1 / cos(pi / N) - 1). N is the smallest count (at least ``MIN_SIDES``)
that keeps this error within the requested tolerance.
"""
from __future__ import annotations

import math

import numpy as np

MIN_SIDES = 8
MAX_SIDES = 1 << 17
# Default largest distance from the polygon to the true disk, relative to r.
DEFAULT_RELATIVE_ERROR = 1e-3


def disk_sides(radius: float, max_error: float | None = None) -> int:
    """Fewest sides of a circumscribed regular polygon within ``max_error`` of the disk.

    ``max_error`` defaults to ``DEFAULT_RELATIVE_ERROR * radius``.

    >>> disk_sides(1.0, 1e-3)
    71
    """
    if radius <= 0.0:
        return MIN_SIDES
    tol = DEFAULT_RELATIVE_ERROR * radius if max_error is None else max_error
    # r (sec(pi/N) - 1) <= tol  <=>  cos(pi/N) >= r / (r + tol)
    half_step = math.acos(min(radius / (radius + tol), 1.0))
    if half_step == 0.0:  # a tolerance too small to show against r (or one that underflowed)
        return MAX_SIDES
    n = math.ceil(math.pi / half_step)
    return int(min(max(n, MIN_SIDES), MAX_SIDES))


def disk_polygon(center, radius: float, max_error: float | None = None, sides: int | None = None,
                 phase: float = 0.0) -> np.ndarray:
    """CCW regular polygon that contains the disk, within ``max_error`` of it.

    The first vertex is the lowest one. Vertex radius is inflated by a few ulps so
    that rounding can never cut into the disk. ``phase`` turns the polygon about the
    centre by that fraction of a side's angle (0: an edge at the bottom).

    >>> p = disk_polygon((0, 0), 1.0, sides=4)
    >>> bool(np.all(np.hypot(p[:, 0], p[:, 1]) >= 2 ** 0.5))
    True
    """
    n = sides or disk_sides(radius, max_error)
    circum = radius / math.cos(math.pi / n) * (1.0 + 8.0 * 2.0**-53)
    # Start half a step after straight down so that an edge, not a vertex, is lowest
    # for even n; then rotate the cycle so the lowest vertex comes first.
    ang = -math.pi / 2 + math.pi / n + 2.0 * math.pi * np.arange(n) / n
    if phase:
        ang = ang + 2.0 * math.pi * phase / n
    cx, cy = float(center[0]), float(center[1])
    pts = np.column_stack([cx + circum * np.cos(ang), cy + circum * np.sin(ang)])
    i = int(np.lexsort((pts[:, 0], pts[:, 1]))[0])
    return np.roll(pts, -i, axis=0)


def disk_error(radius: float, sides: int) -> float:
    """Largest distance from the circumscribed ``sides``-gon to the disk.

    >>> round(disk_error(1.0, 4), 6)
    0.414214
    """
    return radius * (1.0 / math.cos(math.pi / sides) - 1.0)


def disk_inner_polygon(center, radius: float, sides: int, phase: float = 0.0) -> np.ndarray:
    """CCW regular ``sides``-gon INSIDE the disk: the vertices of :func:`disk_polygon`'s
    circumscribed polygon (the same angles) brought onto a circle a little smaller than the
    disk, so that rounding never puts one outside it. What a proof that no path exists
    reasons about (less obstacle, a smaller robot: the proof holds for the disk itself);
    its distance to the disk is at most r (1 − cos(π/N)) plus the rounding shrink.

    Shrink: cos and sin err by an ulp of 1, the product and the sum with the centre by an ulp
    of the result, so every vertex lies within r (1 − s) + 2^-50 r + 4 ulp(|c| + r) of the
    centre; s r = 2^-46 r + 16 ulp(|c| + r) keeps it strictly inside.

    >>> p = disk_inner_polygon((3.0, -2.0), 1.0, 16)
    >>> bool(np.all(np.hypot(p[:, 0] - 3.0, p[:, 1] + 2.0) < 1.0)), len(p)
    (True, 16)
    >>> bool(np.all(np.hypot(p[:, 0] - 3.0, p[:, 1] + 2.0) > 1.0 - 1e-12))
    True
    """
    n = int(sides)
    cx, cy = float(center[0]), float(center[1])
    r = float(radius)
    m = max(abs(cx), abs(cy)) + r
    inner = r - (2.0**-46 * r + 16.0 * math.ulp(m))
    if not inner > 0.0:
        return np.zeros((0, 2))
    ang = -math.pi / 2 + math.pi / n + 2.0 * math.pi * np.arange(n) / n
    if phase:
        ang = ang + 2.0 * math.pi * phase / n
    pts = np.column_stack([cx + inner * np.cos(ang), cy + inner * np.sin(ang)])
    from .hull import convex_hull  # exact: rounded points of a tiny disk far off stay a convex CCW ring

    hull = convex_hull(pts)
    return hull if len(hull) >= 3 else np.zeros((0, 2))
