"""A verified triangulation of one free component F, for exact visibility queries.

F (one polygon of the bounds minus the C-obstacle union, shell counter-clockwise,
holes clockwise, so F lies left of every ring edge) is triangulated by GEOS's
constrained Delaunay triangulation, which adds no vertex. GEOS decides in floats,
so its output is not trusted: :class:`FreeMesh` keeps it only when exact checks
say it is a triangulation of F:

- every triangle is strictly counter-clockwise (exact orientation);
- every directed edge occurs once, and an edge either has a twin in the opposite
  direction (an inner edge) or is a ring edge of F with F on its left;
- every ring edge of F is such a boundary edge, and the triangles' areas add up
  to F's (so no part of F is covered twice or missed).

The first two make the triangles a locally consistent covering of F; the area
settles its degree to one. Anything else raises :class:`MeshError`, and the caller
falls back to a search that needs no mesh.

Flat ring vertices (a straight angle, which GEOS's overlay keeps where pieces met)
are dropped first when no other ring touches them: a sight line along a wall then
meets no vertex, and every vertex of the mesh is a corner of F, around which a
straight line either cannot pass (a convex corner of F) or may bend at no cost (a
reflex corner, a node of the search).
"""
from __future__ import annotations

import numpy as np

from .predicates import orient2d_cols


class MeshError(ValueError):
    """GEOS's triangulation failed an exact check (the caller falls back)."""


def _clean_ring(c: np.ndarray, shared: set) -> np.ndarray:
    """Ring ``c`` (no closing repeat) without its flat vertices (exactly collinear with
    both neighbours and between them) that no other ring touches."""
    a, b = np.roll(c, 1, axis=0), np.roll(c, -1, axis=0)
    turn = orient2d_cols(a[:, 0], a[:, 1], c[:, 0], c[:, 1], b[:, 0], b[:, 1])
    # Between its neighbours: the steps a -> c and c -> b point the same way (signs of
    # float differences are exact).
    ahead = (np.sign(c - a) == np.sign(b - c)).all(axis=1)
    flat = (turn == 0) & ahead
    if flat.any() and shared:
        flat &= np.array([tuple(v) not in shared for v in c.tolist()])
    return c[~flat]


class FreeMesh:
    """An exactly verified triangulation of the free polygon ``region`` (shapely).

    ``tri[3t:3t+3]`` holds triangle t's three vertex ids, counter-clockwise; ``nbr[3t+k]`` is
    the triangle across the edge opposite local vertex k (-1 on F's boundary) and
    ``nbk[3t+k]`` the local index, in that triangle, of its vertex opposite the edge.

    >>> import shapely
    >>> m = FreeMesh(shapely.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (1, 2), (2, 2), (2, 1)]]))
    >>> m.ntri, len(m.x)  # a square ring: 8 corners, 8 triangles
    (8, 8)
    """

    def __init__(self, region):
        import shapely

        rings = [region.exterior] + list(region.interiors)
        raw = [np.asarray(r.coords)[:-1, :2] for r in rings]
        seen: dict = {}
        for c in raw:
            for v in c.tolist():
                seen[tuple(v)] = seen.get(tuple(v), 0) + 1
        shared = {v for v, n in seen.items() if n > 1}
        clean = [_clean_ring(c, shared) for c in raw]
        if any(len(c) < 3 for c in clean):
            raise MeshError("a ring of F has fewer than 3 corners")
        self.rings = clean
        poly = shapely.Polygon(np.vstack([clean[0], clean[0][:1]]),
                               [np.vstack([c, c[:1]]) for c in clean[1:]])
        tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
        coords = shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3]
        ident: dict = {}
        for c in clean:
            for v in c.tolist():
                ident.setdefault(tuple(v), len(ident))
        nv = len(ident)
        try:
            tv = np.array([ident[v] for v in map(tuple, coords.reshape(-1, 2).tolist())], dtype=np.int64).reshape(-1, 3)
        except KeyError:
            raise MeshError("the triangulation added a vertex") from None
        xy = np.empty((nv, 2))
        xy[list(ident.values())] = list(ident.keys())
        self.x, self.y = xy[:, 0].tolist(), xy[:, 1].tolist()
        # Integer coordinates up to 2^25: every orientation determinant is exact in floats.
        self.small_int = bool((xy == np.floor(xy)).all() and (np.abs(xy) <= 2.0**25).all())
        self.xy = xy
        self._check_and_link(tv, clean, ident, float(poly.area))

    def _check_and_link(self, tv: np.ndarray, rings: list, ident: dict, area: float) -> None:
        xy = self.xy
        P = xy[tv]
        s = orient2d_cols(P[:, 0, 0], P[:, 0, 1], P[:, 1, 0], P[:, 1, 1], P[:, 2, 0], P[:, 2, 1])
        if (s == 0).any():
            raise MeshError("a flat triangle")
        tv[s < 0] = tv[s < 0][:, ::-1]
        T = len(tv)
        # Directed edge opposite local vertex k: tv[k+1] -> tv[k+2].
        src = tv[:, [1, 2, 0]].ravel()
        dst = tv[:, [2, 0, 1]].ravel()
        nv = len(xy)
        key = src * nv + dst
        order = np.argsort(key, kind="stable")
        if (np.diff(key[order]) == 0).any():
            raise MeshError("a directed edge occurs twice (overlapping triangles)")
        twin = dst * nv + src
        pos = np.searchsorted(key[order], twin)
        pos[pos >= len(key)] = 0
        has = key[order][pos] == twin
        nbr = np.where(has, order[pos] // 3, -1)
        # Local index of the far vertex in the neighbour: the edge slot of the twin.
        nbk = np.where(has, order[pos] % 3, -1)
        ring_key = np.concatenate([np.array([ident[tuple(v)] for v in c.tolist()], dtype=np.int64) * nv
                                   + np.array([ident[tuple(v)] for v in np.roll(c, -1, axis=0).tolist()],
                                              dtype=np.int64) for c in rings])
        bound = np.sort(key[~has])
        if len(bound) != len(ring_key) or (bound != np.sort(ring_key)).any():
            raise MeshError("the triangles' boundary is not F's boundary")
        with np.errstate(all="ignore"):
            a = 0.5 * ((P[:, 1, 0] - P[:, 0, 0]) * (P[:, 2, 1] - P[:, 0, 1])
                       - (P[:, 1, 1] - P[:, 0, 1]) * (P[:, 2, 0] - P[:, 0, 0]))
        total = float(np.abs(a).sum())
        if not abs(total - area) <= 1e-9 * max(area, total):
            raise MeshError("the triangles' area is not F's area")
        self.tri = tv.ravel().tolist()
        self.nbr = nbr.tolist()
        self.nbk = nbk.tolist()
        self.ntri = T
        # The triangles around each vertex (all fans of a point where rings touch).
        fan: list = [[] for _ in range(nv)]
        for t3, v in enumerate(self.tri):
            fan[v].append(t3)
        self.fan = fan  # entries 3t + k: triangle t, the vertex at local index k
        self.id = ident

    def locate(self, px: float, py: float) -> list[int]:
        """Triangles whose closure holds (px, py), exactly (empty when outside F).

        >>> import shapely
        >>> m = FreeMesh(shapely.Polygon([(0, 0), (2, 0), (2, 2), (0, 2)]))
        >>> len(m.locate(0.5, 0.2)), len(m.locate(1.0, 1.0)), m.locate(3.0, 3.0)
        (1, 2, [])
        """
        P = self.xy[np.asarray(self.tri).reshape(-1, 3)]
        inside = np.ones(len(P), dtype=bool)
        for k in range(3):
            a, b = P[:, (k + 1) % 3], P[:, (k + 2) % 3]
            near = inside.copy()
            inside[near] = orient2d_cols(a[near, 0], a[near, 1], b[near, 0], b[near, 1], px, py) >= 0
        return np.flatnonzero(inside).tolist()
