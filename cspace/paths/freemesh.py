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

from ..kernel.polygons.predicates import orient2d_cols


class MeshError(ValueError):
    """GEOS's triangulation failed an exact check (the caller falls back)."""


def ring_turns(region) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """All ring vertices of a polygon at once: ``(C, prev, nxt, turn, ring)``: the
    vertices (shell, then holes; no closing repeats), each one's ring neighbours as
    indices into C, the exact turn prev -> v -> next (+1 left, -1 right, 0 straight)
    and the ring index.

    >>> C, prev, nxt, turn, ring = ring_turns(__import__("shapely").box(0, 0, 1, 1))
    >>> len(C), turn.tolist()
    (4, [1, 1, 1, 1])
    """
    import shapely

    xy, idx = shapely.get_coordinates(shapely.get_rings(region), return_index=True)
    sizes = np.bincount(idx)
    ends = np.cumsum(sizes)
    keep = np.ones(len(xy), dtype=bool)
    keep[ends - 1] = False  # the closing repeats
    C = xy[keep]
    ring = idx[keep]
    n = sizes - 1
    first = np.repeat(ends - sizes - np.arange(len(sizes)), n)  # each ring's first index in C
    pos = np.arange(len(C)) - first
    nn = np.repeat(n, n)
    prev = first + (pos - 1) % nn
    nxt = first + (pos + 1) % nn
    turn = orient2d_cols(C[prev, 0], C[prev, 1], C[:, 0], C[:, 1], C[nxt, 0], C[nxt, 1])
    return C, prev, nxt, turn, ring


def _triangulate(poly) -> np.ndarray:
    """GEOS's constrained triangulation as (T, 3, 2) corners. GEOS's ear clipper can fail
    on a valid polygon with many holes ("Unable to find a convex corner") depending on
    where its rings start: the same polygon is then retried normalised, then with every
    ring started one vertex later (deterministic; the result is checked exactly anyway)."""
    import shapely

    def rotated(p):
        def r(c):
            c = np.asarray(c.coords)[:-1]
            c = np.roll(c, -1, axis=0)
            return np.vstack([c, c[:1]])
        return shapely.Polygon(r(p.exterior), [r(h) for h in p.interiors])

    err = None
    for attempt in (lambda: poly, lambda: shapely.normalize(poly), lambda: rotated(poly)):
        try:
            tris = shapely.get_parts(shapely.constrained_delaunay_triangles(attempt()))
        except shapely.errors.GEOSException as exc:
            err = exc
            continue
        return shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3]
    raise MeshError(f"GEOS could not triangulate F ({err})")


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

        C, prev, nxt, turn, ring = ring_turns(region)
        # Flat: collinear with both neighbours and between them (the steps prev -> v and
        # v -> next point the same way; signs of float differences are exact), and no
        # other ring touches it.
        flat = (turn == 0) & (np.sign(C - C[prev]) == np.sign(C[nxt] - C)).all(axis=1)
        if flat.any():
            order = np.lexsort((C[:, 1], C[:, 0]))
            dup = np.zeros(len(C), dtype=bool)
            same = (C[order[1:]] == C[order[:-1]]).all(axis=1)
            dup[order[1:][same]] = True
            dup[order[:-1][same]] = True
            flat &= ~dup
        # Integer coordinates up to 2^25 on every ring (the dropped flat vertices too: they
        # are the corners' ring neighbours in the tangency tests): every orientation
        # determinant of them is exact in floats.
        self.small_int = bool((C == np.floor(C)).all() and (np.abs(C) <= 2.0**25).all())
        C, ring = C[~flat], ring[~flat]
        sizes = np.bincount(ring, minlength=int(ring.max()) + 1)
        if (sizes < 3).any():
            raise MeshError("a ring of F has fewer than 3 corners")
        starts = np.cumsum(sizes) - sizes
        nxt = np.arange(len(C)) + 1
        nxt[starts + sizes - 1] = starts  # each ring closes on itself
        if flat.any():
            clean = np.split(C, starts[1:])
            poly = shapely.Polygon(np.vstack([clean[0], clean[0][:1]]), [np.vstack([c, c[:1]]) for c in clean[1:]])
        else:
            poly = region
        coords = _triangulate(poly)
        ident: dict = {}
        for v in map(tuple, C.tolist()):
            ident.setdefault(v, len(ident))  # a point where rings touch gets one id
        vid = np.array([ident[v] for v in map(tuple, C.tolist())], dtype=np.int64)
        try:
            tv = np.array([ident[v] for v in map(tuple, coords.reshape(-1, 2).tolist())], dtype=np.int64).reshape(-1, 3)
        except KeyError:
            raise MeshError("the triangulation added a vertex") from None
        xy = np.empty((len(ident), 2))
        xy[vid] = C
        self.x, self.y = xy[:, 0].tolist(), xy[:, 1].tolist()
        self.xy = xy
        self.id = ident
        self._check_and_link(tv, vid * len(xy) + vid[nxt], float(poly.area))

    def _check_and_link(self, tv: np.ndarray, ring_key: np.ndarray, area: float) -> None:
        """The exact checks (see the module notes), then the neighbour tables.
        ``ring_key``: F's ring edges a -> b as ``id(a) * nv + id(b)``."""
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
        # The triangles around each vertex (all fans of a point where rings touch), as
        # entries 3t + k: triangle t, the vertex at local index k.
        flat_tv = tv.ravel()
        by_vertex = np.argsort(flat_tv, kind="stable")
        cuts = np.searchsorted(flat_tv[by_vertex], np.arange(nv + 1))
        self._fan_order, self._fan_cuts = by_vertex.tolist(), cuts.tolist()

    def fan(self, v: int) -> list[int]:
        """Entries 3t + k of the triangles around vertex v (k: v's local index in t).

        >>> import shapely
        >>> m = FreeMesh(shapely.Polygon([(0, 0), (2, 0), (2, 2), (0, 2)]))
        >>> sorted(len(m.fan(v)) for v in range(4))
        [1, 1, 2, 2]
        """
        return self._fan_order[self._fan_cuts[v]:self._fan_cuts[v + 1]]

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
