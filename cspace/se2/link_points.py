"""Link points: a point in the overlap of two slabs' FREE components, deep inside it where it can be.

The slab graph joins FREE component i of one slab to component j of the next where the two
overlap with an interior; the point it keeps is where a path may change slabs (turn in place),
so it is taken deep inside the overlap (:func:`deep_point`: more than the regions' link depth
from its boundary) where the overlap allows, else anywhere inside it (:func:`inner_point`: a
thin rail). :func:`deep_in_both` finds one without the overlay, where one component's own deep
point lies that deep in the other: on a large map two neighbouring slabs' main components are
nearly the same polygon of thousands of vertices, whose intersection costs ~10 ms.
"""
from __future__ import annotations


def deep_point(geom, depth: float) -> tuple[float, float] | None:
    """A point of ``geom`` (shapely, polygonal) farther than ``depth`` from its boundary, or None:
    the centre of the largest inscribed circle of its largest part.

    >>> import shapely
    >>> x, y = deep_point(shapely.box(0, 0, 2, 1), 0.1)
    >>> bool(0.4 < x < 1.6 and abs(y - 0.5) < 1e-9), deep_point(shapely.box(0, 0, 2, 1e-9), 0.1)
    (True, None)
    """
    import shapely

    parts = [p for p in shapely.get_parts(geom) if p.geom_type == "Polygon" and p.area > 0.0]
    for p in sorted(parts, key=lambda q: -q.area):
        x0, y0, x1, y1 = p.bounds  # a coarse circle is enough: any point deep inside will do
        mic = shapely.maximum_inscribed_circle(p, tolerance=0.02 * max(x1 - x0, y1 - y0))
        (cx, cy), _ = shapely.get_coordinates(mic).tolist()
        if p.boundary.distance(shapely.Point(cx, cy)) > depth and shapely.intersects_xy(p, cx, cy):
            return float(cx), float(cy)
    return None


def inner_point(geom) -> tuple[float, float] | None:
    """A point inside ``geom`` (shapely, polygonal) of positive area, however thin: the
    representative point of its largest part; None if it has no area.

    >>> import shapely
    >>> x, y = inner_point(shapely.box(0, 5, 3, 5 + 1e-9))
    >>> 0 < x < 3 and 5 < y < 5 + 1e-9, inner_point(shapely.LineString([(0, 0), (1, 1)]))
    (True, None)
    """
    import shapely

    parts = [p for p in shapely.get_parts(geom) if p.geom_type == "Polygon" and p.area > 0.0]
    if not parts:
        return None
    pt = max(parts, key=lambda q: q.area).representative_point()
    return float(pt.x), float(pt.y)


def deep_in_both(r1, i: int, r2, j: int, depth: float, kept: dict) -> tuple[float, float] | None:
    """A point farther than ``depth`` from the boundaries of both ``r1.components[i]`` and
    ``r2.components[j]`` (so inside their overlap, that far from its boundary): the first one's
    :func:`deep_point` (kept in ``kept`` by region and component), where the second holds it that
    deep; None otherwise (the caller intersects them).

    >>> import shapely
    >>> from types import SimpleNamespace as NS
    >>> a, b = NS(a=0.0, b=1.0, components=[shapely.box(0, 0, 4, 2)]), NS(components=[shapely.box(0.5, 0, 5, 2)])
    >>> x, y = deep_in_both(a, 0, b, 0, 0.1, {})
    >>> bool(0.6 < x < 3.9 and 0.1 < y < 1.9), deep_in_both(a, 0, NS(components=[shapely.box(3.9, 0, 9, 2)]), 0, 0.1, {})
    (True, None)
    """
    import shapely

    key = (r1.a, r1.b, i)
    if key not in kept:
        kept[key] = deep_point(r1.components[i], depth)
    pt = kept[key]
    other = r2.components[j]
    if pt is None or not shapely.intersects_xy(other, *pt) or other.boundary.distance(shapely.Point(pt)) <= depth:
        return None
    return pt
