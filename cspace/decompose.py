"""Convex decomposition of simple polygons, holes included.

Hertel–Mehlhorn over a constrained Delaunay triangulation: triangulate (GEOS, via
``shapely.constrained_delaunay_triangles``; it adds no Steiner points, so every
triangle corner is an input vertex), then remove diagonals while both polygons
they separate merge into a convex one. Every diagonal left is *essential* (its
removal would create a reflex corner), each reflex vertex holds at most two of
them, so a polygon without holes with r reflex vertices gets at most 2r + 1
pieces, within 4x of the optimum. Convexity of a merge is decided exactly
(:func:`cspace.predicates.orient2d_xy`).

Which diagonals survive depends on the order they are tried in. Longer diagonals
are tried first (removing them merges big triangles early), and for small polygons
a few more orders are tried and the one with the fewest pieces kept: cheap, and it
finds the optimum on most hand-sized shapes (L, U, combs, rooms). A convex input
without holes is returned as it is, never triangulated.
"""
from __future__ import annotations

import numpy as np

from .polygon import as_array, drop_collinear, is_convex, normalize
from .predicates import orient2d_xy

# Polygons with at most this many vertices get extra diagonal orders tried.
_SMALL = 64
_EXTRA_ORDERS = 6


def convex_decompose(polygon, holes=None) -> list[np.ndarray]:
    """Split a simple polygon (with optional holes) into convex CCW pieces.

    The pieces' union is the polygon, their interiors are disjoint, and every
    piece vertex is an input vertex. ``polygon`` may also be a shapely Polygon
    (its interiors are then the holes).

    >>> pieces = convex_decompose([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    >>> len(pieces), sorted(len(p) for p in pieces)
    (2, [4, 4])
    >>> len(convex_decompose([[0, 0], [1, 0], [0, 1]]))
    1
    """
    if hasattr(polygon, "geom_type") and polygon.geom_type == "Polygon" and holes is None:
        holes = [as_array(r) for r in polygon.interiors]
    shell = normalize(polygon)
    hole_list = [normalize(h, ccw=False) for h in (holes or [])]
    if not hole_list and is_convex(shell):
        return [shell]
    tris, pts = _triangulate(shell, hole_list)
    best = None
    orders = [None] + (list(range(_EXTRA_ORDERS)) if len(pts) <= _SMALL else [])
    for seed in orders:
        pieces = _hertel_mehlhorn(tris, pts, seed)
        if best is None or len(pieces) < len(best):
            best = pieces
    return [_finish(pts, cyc) for cyc in best]


def _triangulate(shell: np.ndarray, holes: list) -> tuple[list, np.ndarray]:
    """CCW index triangles of the polygon, over the array of its distinct vertices."""
    import shapely

    poly = shapely.Polygon(shell, holes)
    tri = shapely.constrained_delaunay_triangles(poly)
    pts = np.concatenate([shell] + holes) if holes else shell
    index = {(x, y): i for i, (x, y) in enumerate(pts.tolist())}
    tris = []
    for g in shapely.get_parts(tri):
        c = np.asarray(g.exterior.coords)[:3].tolist()
        try:
            ids = [index[(x, y)] for x, y in c]
        except KeyError:  # never expected: GEOS's CDT uses the input vertices only
            raise ValueError("convex_decompose: triangulation introduced a new vertex") from None
        a, b, d = (pts[i] for i in ids)
        turn = orient2d_xy(*a, *b, *d)
        if turn == 0:
            continue  # a zero-area sliver: covers nothing
        tris.append(ids if turn > 0 else ids[::-1])
    return tris, pts


def _hertel_mehlhorn(tris: list, pts: np.ndarray, seed) -> list[list[int]]:
    """Merge triangles across inessential diagonals; return the pieces as index cycles."""
    pieces = {k: list(t) for k, t in enumerate(tris)}
    owner: dict = {}  # directed edge (u, v) -> piece holding it
    for k, t in pieces.items():
        for i in range(3):
            owner[(t[i], t[(i + 1) % 3])] = k
    diagonals = [(u, v) for (u, v) in owner if u < v and (v, u) in owner]
    if seed is None:
        d = pts[[u for u, _ in diagonals]] - pts[[v for _, v in diagonals]] if diagonals else np.zeros((0, 2))
        order = np.argsort(-np.hypot(d[:, 0], d[:, 1]), kind="stable")
    else:
        order = np.random.default_rng(seed).permutation(len(diagonals))
    for idx in order:
        u, v = diagonals[idx]
        a, b = owner.get((u, v)), owner.get((v, u))
        if a is None or b is None or a == b:
            continue
        merged = _merge(pieces[a], pieces[b], u, v, pts)
        if merged is None:
            continue
        del pieces[b]
        pieces[a] = merged
        n = len(merged)
        for i in range(n):
            owner[(merged[i], merged[(i + 1) % n])] = a
        owner.pop((u, v), None)
        owner.pop((v, u), None)
    return list(pieces.values())


def _merge(p: list, q: list, u: int, v: int, pts: np.ndarray) -> list | None:
    """p holds edge u->v, q holds v->u; their union if it is convex at u and at v."""
    i = p.index(u)
    p_rot = p[i:] + p[:i]          # u, v, ..., (back to u)
    j = q.index(v)
    q_rot = q[j:] + q[:j]          # v, u, ..., (back to v)
    merged = p_rot[1:] + q_rot[1:]  # v ... (p's path to u) u ... (q's path to v)
    # Corners to check: u (between p's last and q's first after u) and v.
    n = len(merged)
    for corner in (u, v):
        k = merged.index(corner)
        a, b, c = pts[merged[k - 1]], pts[corner], pts[merged[(k + 1) % n]]
        if orient2d_xy(a[0], a[1], b[0], b[1], c[0], c[1]) < 0:
            return None
    return merged


def _finish(pts: np.ndarray, cycle: list[int]) -> np.ndarray:
    """A piece as a CCW array starting at its lowest vertex, collinear corners dropped."""
    return normalize(drop_collinear(pts[cycle]))
