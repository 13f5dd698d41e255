"""A short path through a verified triangulation of F: A* over the triangles, then the funnel.

The exact shortest path (:mod:`cspace.paths.visibility`) settles reflex corners, and each
settlement walks the triangles its corner sees: on a large open map (a warehouse's aisles)
that is most of the mesh, hundreds of times per query. When any certified path will do (the
exact SE(2) planner's translations, which OMPL's simplifier shortens afterwards), a cheaper
one is enough:

1. **Channel**: A* over the triangles of :class:`cspace.paths.freemesh.FreeMesh`, a
   triangle entered at the midpoint of the edge it was entered by, moves costing the
   Euclidean distance between those points and the heuristic the distance to the goal
   (consistent: the triangle inequality). The result is a sequence of distinct triangles,
   each sharing an edge (a *portal*) with the next: a sleeve inside F.
2. **Funnel** (Lee and Preparata's funnel, in Mononen's form): the shortest path inside the
   sleeve, bending only at portal ends. The funnel's sides are rays from its apex through
   portal ends, and every decision is the exact sign of orient(apex, X, Y) on mesh vertices
   and the two end points: no point is constructed, so the path's corners are input points.

The path is the shortest within its sleeve, not always within F (another sleeve may be
shorter). The caller checks it against the pieces exactly (:func:`cspace.paths.shortest.shortest_path`
does), so a fault here can cost time, never a colliding path.
"""
from __future__ import annotations

import heapq
import math
import time

from ..kernel.polygons.predicates import orient2d_xy as orient

_INF = math.inf


def channel(mesh, sx: float, sy: float, gx: float, gy: float, deadline: float | None = None) -> list[int] | None:
    """Triangles from one holding (sx, sy) to one holding (gx, gy), each sharing an edge with the
    next (None when the goal is not reached, or past ``deadline``, a ``time.perf_counter`` value).

    >>> import shapely
    >>> from cspace.paths.freemesh import FreeMesh
    >>> m = FreeMesh(shapely.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (1, 3), (3, 3), (3, 1)]]))
    >>> c = channel(m, 0.5, 0.5, 3.5, 3.5)
    >>> len(c) >= 2 and all(b in m.nbr[3 * a:3 * a + 3] for a, b in zip(c, c[1:]))
    True
    """
    X, Y, tri, nbr = mesh.x, mesh.y, mesh.tri, mesh.nbr
    goal = set(mesh.locate(gx, gy))
    starts = mesh.locate(sx, sy)
    if not goal or not starts:
        return None
    parent: dict = {}
    best: dict = {}
    heap = []
    for t in starts:  # entered at the start point itself
        best[t] = 0.0
        heap.append((math.hypot(gx - sx, gy - sy), 0.0, t, -1, sx, sy))
    heapq.heapify(heap)
    done = set()
    pops = 0
    while heap:
        _f, gv, t, par, px, py = heapq.heappop(heap)
        if t in done:
            continue
        done.add(t)
        parent[t] = par
        if t in goal:
            out = [t]
            while parent[out[-1]] >= 0:
                out.append(parent[out[-1]])
            return out[::-1]
        pops += 1
        if deadline is not None and pops % 256 == 0 and time.perf_counter() > deadline:
            return None
        b = 3 * t
        for k in range(3):
            u = nbr[b + k]
            if u < 0 or u in done:
                continue
            v, w = tri[b + (k + 1) % 3], tri[b + (k + 2) % 3]  # the shared edge
            mx, my = 0.5 * (X[v] + X[w]), 0.5 * (Y[v] + Y[w])
            gu = gv + math.hypot(mx - px, my - py)
            if gu < best.get(u, _INF):
                best[u] = gu
                heapq.heappush(heap, (gu + math.hypot(gx - mx, gy - my), gu, u, t, mx, my))
    return None


def portals(mesh, tris: list[int]) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """The shared edges of consecutive triangles, each as (left end, right end) seen when
    crossing it from the earlier triangle into the later one.

    >>> import shapely
    >>> from cspace.paths.freemesh import FreeMesh
    >>> m = FreeMesh(shapely.Polygon([(0, 0), (2, 0), (2, 2), (0, 2)]))
    >>> t = m.locate(1.5, 0.5)[0]
    >>> u = next(n for n in m.nbr[3 * t:3 * t + 3] if n >= 0)
    >>> portals(m, [t, u])  # the diagonal, crossed from the triangle at (1.5, 0.5)
    [((0.0, 0.0), (2.0, 2.0))]
    """
    X, Y, tri, nbr = mesh.x, mesh.y, mesh.tri, mesh.nbr
    out = []
    for a, b in zip(tris, tris[1:]):
        k = nbr[3 * a:3 * a + 3].index(b)
        right, left = tri[3 * a + (k + 1) % 3], tri[3 * a + (k + 2) % 3]  # a is CCW: its edge runs right -> left
        out.append(((X[left], Y[left]), (X[right], Y[right])))
    return out


def funnel(start: tuple[float, float], goal: tuple[float, float], gates: list) -> list[tuple[float, float]]:
    """The shortest path from ``start`` to ``goal`` through the portals ``gates`` ((left, right)
    pairs, in order), as its corners: start, the portal ends it bends at, goal.

    >>> funnel((0.0, 0.0), (4.0, 0.0), [((2.0, 1.0), (2.0, -1.0))])  # a wide gate: straight through
    [(0.0, 0.0), (4.0, 0.0)]
    >>> funnel((0.0, 0.0), (4.0, 0.0), [((2.0, 3.0), (2.0, 1.0))])  # a gate above the line: bend at its right end
    [(0.0, 0.0), (2.0, 1.0), (4.0, 0.0)]
    """
    gates = [(start, start)] + list(gates) + [(goal, goal)]
    path = [start]
    apex = left = right = start
    i_left = i_right = 0
    i = 1
    while i < len(gates):
        gl, gr = gates[i]
        # the right side moves in (toward the left) when the new right end is not right of it
        if orient(*apex, *right, *gr) >= 0:
            if apex in (right, left) or orient(*apex, *left, *gr) < 0:
                right, i_right = gr, i  # tighter, and still right of the left side (if it has one)
            else:  # it crosses the left side: the path bends at the left end
                path.append(left)
                apex, right, i_right = left, left, i_left
                i = i_left + 1
                continue
        if orient(*apex, *left, *gl) <= 0:
            if apex in (left, right) or orient(*apex, *right, *gl) > 0:
                left, i_left = gl, i
            else:  # it crosses the right side: the path bends at the right end
                path.append(right)
                apex, left, i_left = right, right, i_right
                i = i_right + 1
                continue
        i += 1
    if path[-1] != goal:
        path.append(goal)
    return path


def channel_path(mesh, start: tuple[float, float], goal: tuple[float, float],
                 deadline: float | None = None) -> list[tuple[float, float]] | None:
    """A short path from ``start`` to ``goal`` inside the meshed F: :func:`channel`, then
    :func:`funnel` through its portals (None when no channel was found).

    >>> import shapely
    >>> from cspace.paths.freemesh import FreeMesh
    >>> m = FreeMesh(shapely.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (1, 3), (3, 3), (3, 1)]]))
    >>> channel_path(m, (0.5, 2.0), (3.5, 2.0)) in ([(0.5, 2.0), (1.0, 3.0), (3.0, 3.0), (3.5, 2.0)],
    ...                                            [(0.5, 2.0), (1.0, 1.0), (3.0, 1.0), (3.5, 2.0)])
    True
    """
    tris = channel(mesh, start[0], start[1], goal[0], goal[1], deadline)
    if tris is None:
        return None
    return funnel(tuple(start), tuple(goal), portals(mesh, tris))
