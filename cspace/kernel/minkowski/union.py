"""The union of polygons by GEOS, checked, with a robust retry.

GEOS's floating-point overlay (OverlayNG) is fast and almost always right, but not
always: unions of polygons with nearly coincident edges can drop part of an input
(found by this project's property tests: five valid comb sums whose ``union_all``
lost 18 of 124 units of area; compare libgeos/geos#1344). A wrong union here would be
a silent wrong answer downstream (a Minkowski sum with a bite out of it, a free space
with a phantom corridor), so every union is checked against its inputs:

- the union's area lies between the largest input's and the sum of the inputs';
- every vertex and every edge midpoint of every input lies in the union, or within
  ``TOL`` x the coordinate scale of it (an input the union lost a part of shows it by
  a sample of its boundary left outside);
- every vertex and every edge midpoint of the union lies on an input's edge, within
  ``TOL`` (a true union's boundary is made of pieces of the inputs' edges: a chord
  across a gap, or a hole bitten out of an input, has samples off them all).

This is a detector of GEOS's failures, not a proof of the union (a region lost or
gained whose boundary runs entirely along other inputs' edges could pass it). When it
fires, the union is taken again with snap rounding (``grid_size`` a power of two, 2^-42 of the coordinate
scale: GEOS's fixed-precision overlay, robust by construction, about five times
slower) and checked again; if that fails too, :class:`UnionError` is raised rather
than a wrong region returned.
"""
from __future__ import annotations

import math

import numpy as np

TOL = 2.0**-40  # relative distance within which a sampled point counts as in the union
AREA_TOL = 1e-9  # relative slack of the area bounds
GRID_BITS = 42  # snap-rounding grid: 2^-GRID_BITS of the coordinate scale


class UnionError(ArithmeticError):
    """GEOS returned a union that fails its check, with and without snap rounding."""


def union(polys, first=None):
    """The union of shapely polygons (an array or a list), checked against its inputs.
    ``first``: the union as the caller computed it (e.g. in groups, which is faster),
    checked and kept when it passes.

    >>> import shapely
    >>> sq = [shapely.box(0, 0, 2, 2), shapely.box(1, 1, 3, 3)]
    >>> union(sq).area
    7.0
    """
    import shapely

    polys = np.asarray(polys, dtype=object).ravel()
    polys = polys[~shapely.is_empty(polys)] if len(polys) else polys
    if len(polys) == 0:
        return shapely.Polygon()
    if len(polys) == 1 and first is None:
        return polys[0]
    region = shapely.union_all(polys) if first is None else first
    if faithful(region, polys):
        return region
    scale = float(np.abs(shapely.get_coordinates(polys)).max()) or 1.0
    grid = math.ldexp(1.0, math.frexp(scale)[1] - GRID_BITS)
    region = shapely.union_all(polys, grid_size=grid)
    if faithful(region, polys, slack=grid):
        return region
    raise UnionError(f"GEOS {shapely.geos_version_string}: the union of {len(polys)} polygons failed its check "
                     "(its area out of bounds, an input not covered, or its boundary off the inputs' edges), "
                     "with and without snap rounding")


def faithful(region, polys, slack: float = 0.0) -> bool:
    """Does ``region`` pass the union's check against ``polys`` (see the module docstring)?
    ``slack``: extra distance allowed (the snap-rounding grid).

    >>> import shapely
    >>> a, b = shapely.box(0, 0, 2, 2), shapely.box(1, 1, 3, 3)
    >>> faithful(shapely.union(a, b), [a, b]), faithful(a, [a, b]), faithful(shapely.box(0, 0, 3, 3), [a, b])
    (True, False, False)
    """
    import shapely

    polys = np.asarray(polys, dtype=object)
    areas = shapely.area(polys)
    area = float(shapely.area(region))
    if not (float(areas.max()) * (1.0 - AREA_TOL) <= area <= float(areas.sum()) * (1.0 + AREA_TOL)):
        return False
    pts, edges = _samples(polys)
    tol = TOL * float(np.abs(pts).max()) + slack
    # The inputs in the union: their samples in it, or within tol of it (rounded nodes).
    shapely.prepare(region)
    out = pts[~shapely.intersects_xy(region, pts[:, 0], pts[:, 1])]
    if len(out) and not shapely.dwithin(region, shapely.points(out), tol).all():  # (prepared: indexed)
        return False
    # The union's boundary along the inputs' edges: its vertices and edge midpoints each
    # on one, within tol (a true union's boundary is made of pieces of the inputs' edges).
    # Most are an input's vertex or edge midpoint to the bit; the rest are measured.
    own, _ = _samples(np.array([region], dtype=object))
    rest = own[~np.isin(own[:, 0] + 1j * own[:, 1], pts[:, 0] + 1j * pts[:, 1])]
    return _on_edges(rest, edges, tol)


def _on_edges(p: np.ndarray, edges: np.ndarray, tol: float) -> bool:
    """Is every point within ``tol`` of one of the segments ``edges`` (K, 2, 2)? The
    segments whose boxes (widened by tol) hold the point are measured, in blocks of
    about 2^18 (point, segment) pairs; many points against many segments go through an
    STRtree of the segments instead."""
    if len(p) * len(edges) > 1 << 22:
        import shapely

        near = shapely.STRtree(shapely.linestrings(edges)).query(shapely.points(p), predicate="dwithin", distance=tol)
        return len(np.unique(near[0])) == len(p)
    lo, hi = edges.min(axis=1) - tol, edges.max(axis=1) + tol
    step = max(1, (1 << 18) // max(len(edges), 1))
    for s in range(0, len(p), step):
        q = p[s:s + step]
        box = ((q[:, None, 0] >= lo[:, 0]) & (q[:, None, 0] <= hi[:, 0]) &
               (q[:, None, 1] >= lo[:, 1]) & (q[:, None, 1] <= hi[:, 1]))
        i, k = np.nonzero(box)
        a, d = edges[k, 0], edges[k, 1] - edges[k, 0]
        w = q[i] - a
        t = np.clip((w * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), np.finfo(float).tiny), 0.0, 1.0)
        close = np.zeros(len(q), dtype=bool)
        close[i[np.hypot(w[:, 0] - t * d[:, 0], w[:, 1] - t * d[:, 1]) <= tol]] = True
        if not close.all():
            return False
    return True


def _samples(polys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The vertices and edge midpoints of every ring of the polygons, as (N, 2) rows, and
    the edges (K, 2, 2)."""
    import shapely

    xy, ring = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(polys)), return_index=True)
    same = ring[1:] == ring[:-1]  # rings are closed: consecutive rows of one ring are its edges
    edges = np.stack((xy[:-1][same], xy[1:][same]), axis=1)
    return np.concatenate((xy, 0.5 * (edges[:, 0] + edges[:, 1]))), edges
