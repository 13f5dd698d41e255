"""Linear-time tracing of a grid's blocked cells to polygons (issue 36: noisy maps).

``blocked[Y, X]`` is the unit square [X, X+1] x [Y, Y+1] (rows bottom-up). Every
boundary edge between a blocked and a free cell is oriented with the blocked cell on
its left; with no two blocked cells touching at a corner only (see
:func:`cspace.io.importers.occupancy.fill_corner_touches`) every grid point has at most one edge
leaving it, so "the edge after this one" is a permutation of the edges and its
cycles are the rings (exteriors counter-clockwise, holes clockwise). The cycles are
ordered by pointer doubling, collinear points dropped, and each hole given to its
blocked component's exterior through the blocked runs of the rows (a run's two ends
lie on rings of one component, and a hole's leftmost free cell is the right end of a
run whose left end is on a ring further left). All of it numpy passes: O(n log n)
for n boundary edges, no polygon overlay (GEOS's union of many small boxes, and its
hole assignment in one polygon with thousands of holes, were quadratic).

A grid with many vertices is split (halving its longer side) into regions of at most
``max_vertices`` traced vertices, each traced on its own: their union is still
exactly the blocked cells, and every later step (simplification, growth) works on one
region's polygons at a time, so its cost stays linear in the map's size.
"""
from __future__ import annotations

import numpy as np

REGION_VERTICES = 4096  # the most traced vertices in one region (a map with fewer is one region)
MIN_REGION = 16  # cells: a region is not split below this side


def corner_points(blocked: np.ndarray) -> np.ndarray:
    """(h+1, w+1) bool: the grid points where the blocked cells' boundary turns (the traced
    vertices). A point with 1 or 3 of its 4 cells blocked is a corner; 2 on a diagonal
    (a corner touch) counts too.

    >>> int(corner_points(np.array([[1, 1], [0, 1]], dtype=bool)).sum())
    6
    """
    p = np.pad(blocked, 1).astype(np.int8)
    a, b, c, d = p[:-1, :-1], p[:-1, 1:], p[1:, :-1], p[1:, 1:]
    s = a + b + c + d
    return (s == 1) | (s == 3) | ((s == 2) & (a == d))


def regions(blocked: np.ndarray, max_vertices: int = REGION_VERTICES) -> list[tuple[int, int, int, int]]:
    """The grid split into (y0, y1, x0, x1) cell rectangles of at most ``max_vertices``
    corner points each (halving the longer side; never below :data:`MIN_REGION` cells).

    >>> regions(np.ones((4, 4), dtype=bool))
    [(0, 4, 0, 4)]
    """
    c = corner_points(blocked)
    if int(np.count_nonzero(c)) <= max_vertices:  # the whole grid is one region: no prefix sums
        return [(0, blocked.shape[0], 0, blocked.shape[1])]
    s = np.zeros((c.shape[0] + 1, c.shape[1] + 1), dtype=np.int64)
    s[1:, 1:] = c.cumsum(0, dtype=np.int64).cumsum(1)

    def count(y0, y1, x0, x1):  # corner points of cells [y0, y1) x [x0, x1): its (y1-y0+1) x (x1-x0+1) points
        return int(s[y1 + 1, x1 + 1] - s[y0, x1 + 1] - s[y1 + 1, x0] + s[y0, x0])

    out, todo = [], [(0, blocked.shape[0], 0, blocked.shape[1])]
    while todo:
        y0, y1, x0, x1 = todo.pop()
        if count(y0, y1, x0, x1) <= max_vertices or max(y1 - y0, x1 - x0) <= MIN_REGION:
            out.append((y0, y1, x0, x1))
        elif y1 - y0 >= x1 - x0:
            m = (y0 + y1) // 2
            todo += [(m, y1, x0, x1), (y0, m, x0, x1)]
        else:
            m = (x0 + x1) // 2
            todo += [(y0, y1, m, x1), (y0, y1, x0, m)]
    return out


def _components(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    """Connected-component labels (the smallest member) of ``n`` nodes joined by pairs (a, b)."""
    lab = np.arange(n)
    while True:
        la, lb = lab[a], lab[b]
        if np.array_equal(la, lb):
            return lab
        m = np.minimum(la, lb)
        np.minimum.at(lab, la, m)  # hook each root to the smaller label
        np.minimum.at(lab, lb, m)
        while True:  # shortcut to the roots
            nxt = lab[lab]
            if np.array_equal(nxt, lab):
                break
            lab = nxt


def trace_rings(blocked: np.ndarray):
    """The boundary rings of the blocked cells: (coords (m, 2) float, ring (m,) int,
    component (r,) int, area (r,) float) with each ring's corner points in order (not
    repeated), its blocked component and its signed area (> 0 an exterior).

    >>> xy, ring, comp, area = trace_rings(np.array([[1, 1], [0, 1]], dtype=bool))
    >>> len(xy), area.tolist()
    (6, [3.0])
    """
    h, w = blocked.shape
    p = np.zeros((h + 2, w + 2), dtype=bool)
    p[1:-1, 1:-1] = blocked
    W = w + 3  # grid points per row of the padded grid (points X = 0 .. w + 2)
    inner = p[1:-1, 1:-1]
    # The four kinds of edge, each: its blocked cell (Y, X) in padded units, start and end points.
    kinds = (
        (inner & ~p[:-2, 1:-1], (0, 0), (0, 1)),    # bottom: (X, Y) -> (X+1, Y)
        (inner & ~p[1:-1, 2:], (0, 1), (1, 1)),     # right: (X+1, Y) -> (X+1, Y+1)
        (inner & ~p[2:, 1:-1], (1, 1), (1, 0)),     # top: (X+1, Y+1) -> (X, Y+1)
        (inner & ~p[1:-1, :-2], (1, 0), (0, 0)),    # left: (X, Y+1) -> (X, Y)
    )
    start, end, cell, kind = [], [], [], []
    for k, (mask, (sy, sx), (ey, ex)) in enumerate(kinds):
        flat = np.flatnonzero(mask)  # (one pass over the grid, faster than a 2-D nonzero)
        ys, xs = flat // w + 1, flat % w + 1
        start.append((ys + sy) * W + xs + sx)
        end.append((ys + ey) * W + xs + ex)
        cell.append(ys * (w + 2) + xs)
        kind.append(np.full(len(ys), k, dtype=np.int8))
    start, end, cell, kind = (np.concatenate(v) for v in (start, end, cell, kind))
    n = len(start)
    if n == 0:
        return np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0)
    out_at = np.full((h + 3) * W, -1, dtype=np.int32 if n < 2**31 else np.int64)  # (half the bytes to fill)
    out_at[start] = np.arange(n)
    if np.count_nonzero(out_at >= 0) != n:  # two edges leave one point
        raise ValueError("blocked cells touch at a corner only: fill_corner_touches first")
    nxt = out_at[end].astype(np.int64)
    # Ring labels (the smallest edge of each cycle) and each edge's distance to its ring's
    # last edge, by pointer doubling: O(n log n).
    lab, jump = np.arange(n), nxt.copy()
    for _ in range(int(n).bit_length() + 1):  # 2^k >= n: the minimum over the whole cycle
        lab = np.minimum(lab, lab[jump])
        jump = jump[jump]
    succ = np.where(nxt == lab, np.arange(n), nxt)  # cut each cycle before its head
    dist = (succ != np.arange(n)).astype(np.int64)
    while True:
        more = dist[succ]
        if not more.any():
            break
        dist += more
        succ = succ[succ]
    order = np.lexsort((-dist, lab))
    prev = np.empty(n, dtype=np.int64)
    prev[nxt] = np.arange(n)
    turn = kind != kind[prev]  # the edge starts at a corner
    keep = order[turn[order]]
    ring_lab = lab[keep]
    heads, ring = np.unique(ring_lab, return_inverse=True)
    xy = np.column_stack((start[keep] % W, start[keep] // W)).astype(float) - 1.0
    # Signed areas (shoelace) per ring.
    first = np.flatnonzero(np.r_[True, ring[1:] != ring[:-1]])
    nxt_pt = np.arange(len(keep)) + 1
    last = np.r_[first[1:], len(keep)] - 1
    nxt_pt[last] = first
    cross = xy[:, 0] * xy[nxt_pt, 1] - xy[nxt_pt, 0] * xy[:, 1]
    area = np.add.reduceat(cross, first) / 2.0
    # Components: a row's blocked run joins the rings of its two ends.
    ring_of_edge = np.empty(n, dtype=np.int64)
    ring_of_edge[:] = np.searchsorted(heads, lab)
    right = np.full(p.size, -1, dtype=np.int64)
    left = np.full(p.size, -1, dtype=np.int64)
    right[cell[kind == 1]] = ring_of_edge[kind == 1]
    left[cell[kind == 3]] = ring_of_edge[kind == 3]
    lc, rc = np.flatnonzero(left >= 0), np.flatnonzero(right >= 0)  # row-major: run starts and ends pair up
    comp = _components(left[lc], right[rc], len(heads))
    return xy, ring, comp, area


def staircase_polygons(blocked: np.ndarray, offset=(0, 0)):
    """The exact union of the blocked cells as an array of shapely Polygons (integer
    vertices, collinear points dropped), shifted by ``offset`` = (x, y) cells.

    >>> [p.area for p in staircase_polygons(np.array([[1, 1, 1], [1, 0, 1], [1, 1, 1]], dtype=bool))]
    [8.0]
    """
    import shapely

    xy, ring, comp, area = trace_rings(blocked)
    if len(xy) == 0:
        return np.array([], dtype=object)
    xy = xy + np.asarray(offset, dtype=float)
    # Rings ordered by component, the exterior (positive area) first.
    rorder = np.lexsort((area < 0, comp))
    rank = np.empty(len(rorder), dtype=np.int64)
    rank[rorder] = np.arange(len(rorder))
    porder = np.argsort(rank[ring], kind="stable")
    rings = shapely.linearrings(xy[porder], indices=rank[ring][porder])
    _, poly_index = np.unique(comp[rorder], return_inverse=True)
    return shapely.polygons(rings, indices=poly_index)


def largest_error(result, exact, bound: float | None = None) -> float:
    """The largest distance from a vertex of ``result`` to ``exact`` (0 when they are the
    same object), for a ``result`` that covers ``exact``: its vertices are on or outside
    ``exact``, so the distance is to ``exact``'s boundary, found in a tree of its segments
    (O(n log n); the distance to a polygon of n vertices from each of n points was quadratic).
    ``bound``, if given, is a distance no vertex should exceed: the search is cut there (faster),
    and repeated without it for any vertex found farther.

    >>> import shapely
    >>> largest_error(shapely.box(-1, 0, 2, 1), shapely.box(0, 0, 1, 1))
    1.0
    """
    import shapely

    if result is exact or result.is_empty or exact.is_empty:
        return 0.0
    xy, idx = shapely.get_coordinates(shapely.get_rings(flat_parts(exact)),
                                      return_index=True)
    same = idx[1:] == idx[:-1]
    segs = shapely.linestrings(np.stack((xy[:-1][same], xy[1:][same]), axis=1))
    tree = shapely.STRtree(segs)
    pts = shapely.points(shapely.get_coordinates(result))
    if bound is not None:
        found, dist = tree.query_nearest(pts, return_distance=True, all_matches=False, max_distance=bound)
        if len(np.unique(found[0])) == len(pts):
            return float(dist.max()) if len(dist) else 0.0
    _, dist = tree.query_nearest(pts, return_distance=True, all_matches=False)
    return float(dist.max()) if len(dist) else 0.0


def flat_parts(geom) -> np.ndarray:
    """The single geometries of a geometry, collections and multi-geometries opened (to any depth).

    >>> import shapely
    >>> g = shapely.GeometryCollection([shapely.MultiPolygon([shapely.box(0, 0, 1, 1)]), shapely.box(2, 2, 3, 3)])
    >>> len(flat_parts(g))
    2
    """
    import shapely

    parts = shapely.get_parts(geom)
    while len(parts) and (shapely.get_num_geometries(parts) != 1).any() | (shapely.get_type_id(parts) >= 4).any():
        parts = shapely.get_parts(parts)
    return parts
