"""The one float rotation of the project ("the robot at theta") and OMPL's angle wrap.

Every module that turns a polygon calls :func:`rotate` (or :func:`rotate_piece` for a
convex piece that must stay convex), so the same body vertex and angle always give the
same double; angles are wrapped into OMPL's SO(2) range [−π, π) by :func:`wrap_angle`.
"""
from __future__ import annotations

import math

import numpy as np

from .hull import convex_hull
from .polygon import as_array
from .predicates import orient2d_xy

TWO_PI = 2.0 * math.pi


def rotate(poly: np.ndarray, theta: float) -> np.ndarray:
    """The polygon turned by ``theta`` about the origin: the ONE float rotation of the project.

    Each vertex (x, y) becomes (x c − y s, x s + y c) with c, s = math.cos(theta),
    math.sin(theta), each product and difference rounded once (no fused multiply-add,
    no matrix product whose summation order could vary), so the same body vertex and
    angle always give the same double. Orientation (CCW) is kept.

    >>> rotate(np.array([[1.0, 0.0], [0.0, 2.0]]), math.pi / 2).round(12).tolist()
    [[0.0, 1.0], [-2.0, 0.0]]
    """
    p = as_array(poly, copy=False)
    c, s = math.cos(theta), math.sin(theta)
    x, y = p[:, 0], p[:, 1]
    out = np.empty_like(p)
    out[:, 0] = x * c - y * s
    out[:, 1] = x * s + y * c
    return out + 0.0  # no negative zeros


def rotate_piece(piece: np.ndarray, theta: float) -> np.ndarray:
    """:func:`rotate` of a convex piece, kept convex: the exact hull of the rotated vertices
    if rounding made a near-straight turn reflex (otherwise the rotated array itself).

    This is "the robot piece at theta" of the SE(2) C-space.

    >>> rotate_piece(np.array([[0., 0], [1, 0], [0, 1]]), 0.0).tolist()
    [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    """
    r = rotate(piece, theta)
    if len(r) < 3:
        return r
    # A rotated convex piece winds once; strict left turns everywhere (exact predicate) keep it convex.
    pts = r.tolist()
    (ax, ay), (bx, by) = pts[-2], pts[-1]
    for cx, cy in pts:
        if orient2d_xy(ax, ay, bx, by, cx, cy) <= 0:
            return convex_hull(r)
        ax, ay, bx, by = bx, by, cx, cy
    return r


def wrap_angle(theta: float) -> float:
    """θ in OMPL's SO(2) range [−π, π), as ``SO2StateSpace::enforceBounds`` computes it.

    >>> wrap_angle(math.pi) == -math.pi, wrap_angle(0.5), round(wrap_angle(7.0), 12)
    (True, 0.5, 0.71681469282)
    """
    if -math.pi <= theta < math.pi:
        return theta
    v = math.fmod(theta, TWO_PI)
    if v < -math.pi:
        v += TWO_PI
    elif v >= math.pi:
        v -= TWO_PI
    return v
