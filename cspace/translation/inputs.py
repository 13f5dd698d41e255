"""What the public API accepts, turned into the package's currency.

This module owns the conversions at the edge of :class:`cspace.CSpace`: obstacles and
robots given as vertex arrays (either orientation, closing repeat or not) or as
shapely Polygons / MultiPolygons become counter-clockwise, cleaned ``(N, 2)`` float64
shells with clockwise holes; query arguments become one point or an ``(N, 2)`` batch.
Every fault is a ``ValueError`` that names the argument, raised before GEOS or the
exact predicates see the input (so no GEOS message or warning reaches the user).
"""
from __future__ import annotations

import numpy as np

from ..kernel.polygons.polygon import as_array, invalid_reason, normalize


def _is_geometry(x) -> bool:
    return hasattr(x, "geom_type") and hasattr(x, "is_empty")


def _polygons_of(item, what: str) -> list:
    """The shapely Polygons of a Polygon, MultiPolygon or collection of polygons."""
    import shapely

    if item.is_empty:
        raise ValueError(f"{what}: an empty geometry")
    if item.geom_type == "Polygon":
        return [item]
    parts = list(shapely.get_parts(item))
    if item.geom_type in ("MultiPolygon", "GeometryCollection") and all(p.geom_type == "Polygon" for p in parts):
        return parts
    raise ValueError(f"{what}: a {item.geom_type} is not an area (give a Polygon or MultiPolygon)")


def _shell_and_holes(shell, holes: list, what: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """Normalised shell (CCW) and holes (CW), checked finite and simple (the array gate's
    faults are re-raised naming the argument)."""
    try:
        ext = as_array(shell)
        hs = [as_array(h) for h in holes]
    except (ValueError, TypeError) as exc:
        raise type(exc)(f"{what}: {exc}") from None
    if len(ext) < 3:
        raise ValueError(f"{what}: a polygon needs at least 3 vertices, got {len(ext)}")
    ext_n = normalize(ext, ccw=True)
    if len(ext_n) < 3:
        raise ValueError(f"{what}: the polygon has zero area")
    reason = invalid_reason(ext, hs)
    if reason:
        raise ValueError(f"{what}: not a simple polygon ({reason})")
    return ext_n, [normalize(h, ccw=False) for h in hs]


def obstacle_shapes(obstacles, holes=None) -> tuple[list[np.ndarray], list[list[np.ndarray]], list[int]]:
    """(shells, holes per shell, index of the input obstacle of each shell).

    ``obstacles`` is a list whose items are vertex arrays or shapely Polygons /
    MultiPolygons (a MultiPolygon gives several shells with the same index), or one
    shapely geometry for all of them. ``holes[i]``, if given, are the holes of array
    item ``i``; a shapely Polygon brings its own.

    >>> import shapely
    >>> shells, holes, owner = obstacle_shapes([[[0, 0], [0, 1], [1, 0]], shapely.box(2, 2, 3, 3)])
    >>> [s.tolist()[0] for s in shells], owner
    ([[0.0, 0.0], [2.0, 2.0]], [0, 1])
    """
    if obstacles is None:
        return [], [], []
    items = _polygons_of(obstacles, "obstacles") if _is_geometry(obstacles) else list(obstacles)
    holes = list(holes) if holes is not None else [[] for _ in items]
    if len(holes) != len(items):
        raise ValueError(f"obstacle_holes: {len(holes)} lists for {len(items)} obstacles")
    shells, out_holes, owner = [], [], []
    for i, (item, hs) in enumerate(zip(items, holes)):
        what = f"obstacles[{i}]"
        if _is_geometry(item):
            polys = _polygons_of(item, what)
            if hs and (len(polys) > 1 or len(polys[0].interiors)):
                raise ValueError(f"obstacle_holes[{i}]: the shapely geometry has its own holes; give them once")
            parts = [(p.exterior, list(p.interiors) or list(hs)) for p in polys]
        else:
            parts = [(item, list(hs or []))]
        for shell, hh in parts:
            s, h = _shell_and_holes(shell, hh, what)
            shells.append(s)
            out_holes.append(h)
            owner.append(i)
    return shells, out_holes, owner


def robot_parts(robot) -> list[np.ndarray]:
    """The robot's parts as normalised CCW arrays: a list of arrays or shapely polygons,
    or one shapely Polygon / MultiPolygon. Robot parts have no holes.

    >>> import shapely
    >>> [len(p) for p in robot_parts(shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(2, 0, 3, 1)]))]
    [4, 4]
    """
    if robot is None:
        return []
    items = _polygons_of(robot, "robot") if _is_geometry(robot) else list(robot)
    parts = []
    for i, item in enumerate(items):
        what = f"robot[{i}]"
        polys = _polygons_of(item, what) if _is_geometry(item) else [item]
        for p in polys:
            if _is_geometry(p) and len(p.interiors):
                raise ValueError(f"{what}: a robot part has no holes")
            parts.append(_shell_and_holes(p.exterior if _is_geometry(p) else p, [], what)[0])
    return parts


def query_points(q, dims: int, what: str) -> np.ndarray:
    """``q`` as an ``(N, dims)`` float64 batch of finite points, else a ValueError.

    A translation C-space's states are ``(x, y)``: three numbers (a pose with theta)
    are refused rather than read as (x, y), since the orientation is fixed when the
    C-space is built.

    >>> query_points([[0, 1], [2, 3]], 2, "is_free").shape
    (2, 2)
    >>> query_points((1, 2, 0.5), 2, "is_free")
    Traceback (most recent call last):
    ValueError: is_free: (x, y, theta) given to a translation C-space; its orientation is fixed when it is built: give (x, y)
    """
    a = np.asarray(q, dtype=np.float64)
    if a.ndim == 1:
        a = a.reshape(1, -1)
    if a.ndim != 2 or a.shape[-1] != dims:
        if a.ndim == 2 and a.shape[-1] == 3 and dims == 2:
            raise ValueError(f"{what}: (x, y, theta) given to a translation C-space; its orientation is fixed "
                             f"when it is built: give (x, y)")
        raise ValueError(f"{what}: expected a point (x, y) or an (N, 2) array of points, got shape {np.shape(q)}")
    if not np.isfinite(a).all():
        raise ValueError(f"{what}: coordinates must be finite, got {a[~np.isfinite(a).all(axis=1)][0].tolist()}")
    return a
