"""Safety margins: the convex shapes the robot is inflated by before its C-space is built.

A clearance D asks that the robot, swept along the path, stay at least D away from
every obstacle. The robot R is replaced by R ⊕ M, where M contains the disk of radius
D: then a reference point q is free (q + R ⊕ M touches no obstacle, obstacles being
closed) only if every point within D of q + R is outside every obstacle, that is
dist(q + R, O) > D. M is the circumscribed regular polygon of :mod:`cspace.kernel.polygons.disk`
(error at most ``disk_tolerance · D`` outside the disk, never inside it), optionally
summed with an anisotropic convex polygon (body frame, containing the origin: longer
ahead than aside, say). Each convex robot piece is summed with the margin in the same
k-way merge as the obstacle piece (``obstacle ⊕ −piece ⊕ −margin``), so a margin adds
edges to each sum but no extra pass.

The disk polygon is turned by MARGIN_PHASE (the golden section) of a side's angle.
Turned or not it is the circumscribed regular polygon; turned, none of its edges is
parallel, even to rounding, to an axis (boxes, grid maps) or to an edge of a disk
polygon with its side count (every disk of one tolerance has the same count). A
near-parallel pair of edges is an exact comparison in each sum's merge, and its
rounded sum vertex often a non-convex turn that the exact hull must repair: on
disks_cluttered.toml, unturned, that repair was most of the margin's build time.

A disk margin is rotation-invariant up to its polygon; in SE(2) the margin is summed
with each body-frame robot piece, so an anisotropic margin turns with the robot.
"""
from __future__ import annotations

import numpy as np

from ..polygons.disk import DEFAULT_RELATIVE_ERROR, disk_polygon, disk_sides

MARGIN_PHASE = 0.3819660112501051  # (3 - sqrt 5) / 2 of a side: see the module docstring


def margin_shapes(clearance: float = 0.0, polygon=None, disk_tolerance: float = DEFAULT_RELATIVE_ERROR,
                  theta: float = 0.0, *, inner: bool = False) -> list[np.ndarray]:
    """The convex margin operands: the disk polygon of radius ``clearance`` (if positive)
    and the anisotropic ``polygon`` (if given, turned by ``theta``), CCW, around the origin.
    ``inner``: the disk's polygon inscribed in it instead (same sides and phase), for a proof
    that no path keeps the clearance (it must hold for the disk as written).

    An empty list means no margin: the C-space is built exactly as without one.

    >>> margin_shapes(0.0)
    []
    >>> [len(m) for m in margin_shapes(0.5, disk_tolerance=1e-3)]
    [71]
    >>> margin_shapes(0.0, [[-1., -0.5], [2, -0.5], [2, 0.5], [-1, 0.5]])[0].tolist()
    [[-1.0, -0.5], [2.0, -0.5], [2.0, 0.5], [-1.0, 0.5]]
    """
    out = []
    d = float(clearance)
    if not d >= 0.0 or d != d or d == float("inf"):
        raise ValueError(f"margin_shapes: clearance must be a finite number >= 0, got {clearance!r}")
    if d > 0.0:
        n = disk_sides(d, disk_tolerance * d)
        if inner:
            from ..polygons.disk import disk_inner_polygon

            m = disk_inner_polygon((0.0, 0.0), d, n, phase=MARGIN_PHASE)
            if len(m):
                out.append(m)
        else:
            out.append(disk_polygon((0.0, 0.0), d, sides=n, phase=MARGIN_PHASE))
    if polygon is not None:
        p = np.asarray(polygon, dtype=np.float64).reshape(-1, 2)
        if theta:
            from ..polygons.rotation import rotate

            p = rotate(p, theta)
        out.append(p)
    return out


def inflated_pieces(robot_pieces: list, margin: list) -> list[np.ndarray]:
    """Each convex robot piece summed with the margin operands in one merge (the margin alone
    for a point robot); the pieces themselves without a margin.

    >>> sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    >>> inflated_pieces([sq], [sq])[0].tolist()
    [[-2.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]]
    >>> len(inflated_pieces([], [sq])[0]), inflated_pieces([sq], [])[0] is sq
    (4, True)
    """
    if not margin:
        return list(robot_pieces)
    from .merge import minkowski_sum

    if robot_pieces:
        return [minkowski_sum(p, *margin) for p in robot_pieces]
    return [minkowski_sum(*margin) if len(margin) > 1 else np.asarray(margin[0], dtype=np.float64)]


def margin_error(clearance: float, disk_tolerance: float = DEFAULT_RELATIVE_ERROR) -> float:
    """How much more than ``clearance`` a path may be kept away: the disk polygon's error.

    >>> round(margin_error(1.0, 1e-3), 6) <= 1e-3
    True
    """
    from ..polygons.disk import disk_error

    d = float(clearance)
    return disk_error(d, disk_sides(d, disk_tolerance * d)) if d > 0 else 0.0


def check_margin_polygon(p: np.ndarray) -> str | None:
    """Why a (normalised, CCW) polygon cannot be a margin, or None: it must be convex and
    contain the origin (closed), so that the inflated robot contains the robot.

    >>> check_margin_polygon(np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])) is None
    True
    >>> check_margin_polygon(np.array([[1., 1], [2, 1], [2, 2], [1, 2]]))
    'must contain the origin (the reference point) so that the inflated robot contains the robot'
    """
    from ..polygons.polygon import is_convex, point_in_convex

    if not is_convex(p):
        return "must be convex (it is summed with each convex robot piece)"
    if point_in_convex(p, 0.0, 0.0) < 0:
        return "must contain the origin (the reference point) so that the inflated robot contains the robot"
    return None
