"""Exact visibility in a triangulated free space, and the shortest-path search built on it.

Visibility from a point P (Bungiu, Hemmer, Hershberger, Huang and Kröller's
*triangular expansion*): start in the triangles around P; a window (a triangle edge
that is not F's boundary) seen from P through a cone is crossed into the next
triangle, whose far vertex z splits the cone in two, and so on until the cone meets
F's boundary or closes. A vertex is seen iff it lies in the closed cone that reaches
its triangle. The cones' sides are rays from P, each along s·(X − P) for a vertex X
of F (s = ±1: a tangent wedge's side may run away from X), so every decision is the
exact sign of orient(P, X, Y) on input points: no point is ever constructed.

Touching is allowed (the path is the infimum over free paths), so the cones are
closed; a cone that shrinks to a single ray is not followed past the vertex it
grazes. That loses no shortest path: a straight line can only pass a corner of F
that is reflex (a node of the graph: the path may bend there at no cost) or a
straight angle (removed from the mesh by :mod:`cspace.paths.freemesh`).

The search (:func:`mesh_astar`) is A* over the reduced visibility graph (Euclidean
heuristic, consistent): a node's edges are computed only when the node is settled,
and only inside its two tangent wedges (the directions whose line through the node
does not cut into the obstacle's corner); the far end is kept when the line is
tangent there too. Every edge pushed is visible by construction, so each node is
settled once, with its true distance.
"""
from __future__ import annotations

import heapq
import math
from typing import Callable

from ..kernel.polygons.predicates import CCW_ERRBOUND_A, orient2d_xy
from .astar import astar

_INF = math.inf
_TINY = CCW_ERRBOUND_A * 1e-280  # below, products may be subnormal: the exact predicate decides
_INT_LIMIT = 2.0**25  # integers up to this size: every orientation determinant is exact in floats


def _small_int(*vals: float) -> bool:
    """Are all values integers of magnitude at most 2^25 (so orientation is exact in floats)?"""
    return all(v == math.floor(v) and abs(v) <= _INT_LIMIT for v in vals)


def _orient(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> int:
    """Exact sign of orient(P, A, B): Shewchuk's stage-A filter, else the exact predicate."""
    left = (ax - px) * (by - py)
    right = (ay - py) * (bx - px)
    det = left - right
    detsum = abs(left) + abs(right)
    if 1e-280 < detsum < _INF:  # (as predicates.cross_diff_sign)
        err = CCW_ERRBOUND_A * detsum
        if det > err:
            return 1
        if det < -err:
            return -1
    return orient2d_xy(px, py, ax, ay, bx, by)


def _orient_int(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> int:
    """orient(P, A, B) when every coordinate is an integer of magnitude <= 2^25: exact in floats."""
    d = (ax - px) * (by - py) - (ay - py) * (bx - px)
    return (d > 0) - (d < 0)


def _meet(px, py, c1, c2, o=_orient):
    """The intersection of two closed cones at P (each under pi), or None when empty.

    A cone is ``(rx, ry, rs, lx, ly, ls)``: its right side along rs·(R − P), its left
    side along ls·(L − P). The right side of the intersection is the right side of
    one cone that lies in the other; likewise the left.
    """
    r = None
    if _dir_in(px, py, c1[0], c1[1], c1[2], c2, o):
        r = c1[:3]
    elif _dir_in(px, py, c2[0], c2[1], c2[2], c1, o):
        r = c2[:3]
    if r is None:
        return None
    if _dir_in(px, py, c1[3], c1[4], c1[5], c2, o):
        return r + c1[3:]
    if _dir_in(px, py, c2[3], c2[4], c2[5], c1, o):
        return r + c2[3:]
    return None


def _dir_in(px, py, x, y, s, c, o=_orient) -> bool:
    """Is the direction s·((x, y) − P) in the closed cone c?"""
    return s * c[2] * o(px, py, c[0], c[1], x, y) >= 0 and s * c[5] * o(px, py, x, y, c[3], c[4]) >= 0


def _width(px, py, c, o=_orient) -> int:
    """Sign of the cone's opening (0: a single ray)."""
    return c[2] * c[5] * o(px, py, c[0], c[1], c[3], c[4])


def visible_from(mesh, px: float, py: float, starts: list, wedges: list | None,
                 is_node: list, goal=None, goal_tris=frozenset()) -> tuple[list, bool, int]:
    """Mesh vertices seen from P = (px, py), and whether the goal point is seen.

    ``starts``: entries 3t + k of the triangles whose closure holds P, k the local index
    of P when it is a vertex of t (else any k: P is then inside t or on an edge). Only
    directions in one of the closed ``wedges`` count (``None``: all). Only vertices
    with ``is_node[v]`` are reported. Returns (vertices, goal seen, triangles visited).

    >>> import shapely
    >>> from cspace.paths.freemesh import FreeMesh
    >>> m = FreeMesh(shapely.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (1, 3), (3, 3), (3, 1)]]))
    >>> v, _, _ = visible_from(m, 0.5, 2.0, [3 * t for t in m.locate(0.5, 2.0)], None, [True] * len(m.x))
    >>> sorted((m.x[i], m.y[i]) for i in v)  # the hole hides (3, 1) and (3, 3)
    [(0.0, 0.0), (0.0, 4.0), (1.0, 1.0), (1.0, 3.0)]
    """
    X, Y, tri, nbr, nbk = mesh.x, mesh.y, mesh.tri, mesh.nbr, mesh.nbk
    exact = mesh.small_int and _small_int(px, py)
    o = _orient_int if exact else _orient  # (for the goal, which may be off the integers: _orient)
    seen: set = set()
    goal_seen = False
    gx, gy = goal if goal is not None else (0.0, 0.0)
    stack = []
    visited = 0
    for e in starts:
        t, k = divmod(e, 3)
        b = 3 * t
        v0, v1, v2 = tri[b], tri[b + 1], tri[b + 2]
        if (X[tri[e]], Y[tri[e]]) == (px, py):
            windows = [k]  # P is the vertex k: the one window is the opposite edge
        else:  # inside t or on an edge of it: every edge P is not on
            windows = [j for j, (u, w) in enumerate(((v1, v2), (v2, v0), (v0, v1))) if o(px, py, X[u], Y[u], X[w], Y[w]) > 0]
        visited += 1
        for j in windows:
            u, w = tri[b + (j + 1) % 3], tri[b + (j + 2) % 3]
            cone = (X[u], Y[u], 1, X[w], Y[w], 1)  # from P, u is on the right, w on the left
            for wedge in (wedges or (None,)):
                c = cone if wedge is None else _meet(px, py, cone, wedge, o)
                if c is None:
                    continue
                for q in (u, w):
                    if is_node[q] and q not in seen and _pt_in(px, py, X[q], Y[q], c, o):
                        seen.add(q)
                if goal is not None and t in goal_tris and not goal_seen and _pt_in(px, py, gx, gy, c, _orient):
                    goal_seen = True
                if nbr[b + j] >= 0 and _width(px, py, c, o) > 0:
                    stack.append((nbr[b + j], nbk[b + j]) + c)
    err, tiny = CCW_ERRBOUND_A, _TINY
    while stack:
        t, k, rx, ry, rs, lx, ly, ls = stack.pop()
        visited += 1
        b = 3 * t
        z = tri[b + k]
        zx, zy = X[z], Y[z]
        # zr = rs * orient(P, R, z) >= 0: z on the left of (or on) the right side; zl =
        # ls * orient(P, z, L) >= 0: z on the right of (or on) the left side. Inline
        # stage-A filters (``_orient``); integer scenes below 2^25 are exact in floats.
        left, right = (rx - px) * (zy - py), (ry - py) * (zx - px)
        d = left - right
        e = err * (abs(left) + abs(right))
        if d > e > tiny:
            zr = rs
        elif -d > e > tiny:
            zr = -rs
        elif exact:
            zr = rs * ((d > 0) - (d < 0))
        else:
            zr = rs * orient2d_xy(px, py, rx, ry, zx, zy)
        left, right = (zx - px) * (ly - py), (zy - py) * (lx - px)
        d = left - right
        e = err * (abs(left) + abs(right))
        if d > e > tiny:
            zl = ls
        elif -d > e > tiny:
            zl = -ls
        elif exact:
            zl = ls * ((d > 0) - (d < 0))
        else:
            zl = ls * orient2d_xy(px, py, zx, zy, lx, ly)
        if zr >= 0 and zl >= 0 and is_node[z]:
            seen.add(z)
        if goal is not None and t in goal_tris and not goal_seen:
            if rs * _orient(px, py, rx, ry, gx, gy) >= 0 and ls * _orient(px, py, gx, gy, lx, ly) >= 0:
                goal_seen = True
        # The window entered is the edge opposite z, u (left) -> w (right) as seen from P;
        # (w, z) is the edge opposite u (slot k+1), (z, u) the edge opposite w (slot k+2).
        kr, kl = b + (k + 1) % 3, b + (k + 2) % 3
        if zr < 0:  # z right of the cone: all of it leaves through (z, u)
            if nbr[kl] >= 0:
                stack.append((nbr[kl], nbk[kl], rx, ry, rs, lx, ly, ls))
        elif zl < 0:  # z left of the cone: all of it leaves through (w, z)
            if nbr[kr] >= 0:
                stack.append((nbr[kr], nbk[kr], rx, ry, rs, lx, ly, ls))
        else:  # z splits the cone; a part of zero width is not followed
            if zr > 0 and nbr[kr] >= 0:
                stack.append((nbr[kr], nbk[kr], rx, ry, rs, zx, zy, 1))
            if zl > 0 and nbr[kl] >= 0:
                stack.append((nbr[kl], nbk[kl], zx, zy, 1, lx, ly, ls))
    return list(seen), goal_seen, visited


def _pt_in(px, py, qx, qy, c, o=_orient) -> bool:
    """Is the point Q in the closed cone c at P?"""
    return c[2] * o(px, py, c[0], c[1], qx, qy) >= 0 and c[5] * o(px, py, qx, qy, c[3], c[4]) >= 0


def tangent_wedges(vx: float, vy: float, ax: float, ay: float, bx: float, by: float) -> list:
    """The two closed cones of directions at reflex corner v (ring a -> v -> b, F on
    the left) whose line through v does not cut into the obstacle's corner: from
    b − v to v − a, and from v − b to a − v.

    >>> tangent_wedges(0.0, 1.0, 0.0, 0.0, 1.0, 1.0)  # square corner: up-right and down-left quadrants
    [(1.0, 1.0, 1, 0.0, 0.0, -1), (1.0, 1.0, -1, 0.0, 0.0, 1)]
    """
    return [(bx, by, 1, ax, ay, -1), (bx, by, -1, ax, ay, 1)]


def taut(vx, vy, px, py, ax, ay, bx, by, wedges: list, o=_orient) -> list:
    """The tangent wedges at corner v cut to the closed half-plane, beside the line from
    the parent p through v, that holds the obstacle's corner: a path p -> v -> w that
    turns away from the corner is shortened by cutting it, so v -> w is on no shortest
    path to w (whichever optimal parent v has: the argument only uses that p -> v is
    tangent at v). Straight on (w on the line) is kept.

    >>> # corner of the square [0, 1]^2 at v = (0, 1), reached from p = (-1, 2): only the
    >>> # down-left wedge wraps the square; the up-right one turns away from it
    >>> taut(0.0, 1.0, -1.0, 2.0, 0.0, 0.0, 1.0, 1.0, tangent_wedges(0.0, 1.0, 0.0, 0.0, 1.0, 1.0))
    [(1.0, 1.0, -1, 0.0, 0.0, 1)]
    """
    side = o(px, py, vx, vy, ax, ay) or o(px, py, vx, vy, bx, by)  # the corner's side of line p -> v
    if side == 0:
        return wedges
    # Directions d with side * cross(v - p, d) >= 0, a cone of angle pi at v: its right
    # side along side * (v - p) = -side * (p - v), its left side along side * (p - v).
    half = (px, py, -side, px, py, side)
    return [c for c in (_meet(vx, vy, w, half, o) for w in wedges) if c is not None]


def mesh_astar(mesh, pts, nbrs: list, deadline: float | None = None,
               on_progress: Callable[[int, int, float], None] | None = None, every: int = 64) -> tuple:
    """A* from node 0 (start) to node 1 (goal) over nodes ``pts`` (then the reflex
    corners, with their ring neighbours ``nbrs``), edges computed on settling.

    Returns ``(path as node indices or None, length, counts)``; ``counts["stopped"]``
    says why a search ended early.
    """
    n = len(pts)
    P = [tuple(v) for v in pts.tolist()]
    gx, gy = P[1]
    h = [math.hypot(x - gx, y - gy) for x, y in P]
    at: dict = {}  # mesh vertex -> nodes there (a point where rings touch has several)
    for i in range(2, n):
        at.setdefault(mesh.id[P[i]], []).append(i)
    is_node = [False] * len(mesh.x)
    for vid in at:
        is_node[vid] = True
    goal_tris = frozenset(mesh.locate(gx, gy))
    start_tris = mesh.locate(*P[0])
    counts = {"triangles": mesh.ntri, "triangles_visited": 0, "edges_found": 0}
    if not start_tris or not goal_tris:
        raise ValueError("start or goal outside the mesh")
    closed = [False] * n
    g_best = [_INF] * n  # tentative: every pushed edge is visible, so only a cheaper one is pushed again
    g_best[0] = 0.0

    def expand(v: int, gv: float, par: int, heap: list) -> None:
        vx, vy = P[v]
        o = _orient_int if mesh.small_int and _small_int(vx, vy) else _orient
        if v == 0:
            starts, wedges = [3 * t for t in start_tris], None
        else:
            (ax, ay), (bx, by) = nbrs[v - 2]
            starts, wedges = mesh.fan(mesh.id[P[v]]), tangent_wedges(vx, vy, ax, ay, bx, by)
            px, py = P[par]
            wedges = taut(vx, vy, px, py, ax, ay, bx, by, wedges, o)
        seen, goal_seen, visited = visible_from(mesh, vx, vy, starts, wedges, is_node, P[1], goal_tris)
        counts["triangles_visited"] += visited
        cand = [w for q in seen for w in at[q] if not closed[w]]
        if goal_seen and not closed[1]:
            cand.append(1)
        for w in cand:
            wx, wy = P[w]
            if w >= 2:  # tangent at the far end too: w's ring neighbours weakly on one side
                (ax, ay), (bx, by) = nbrs[w - 2]
                if o(vx, vy, wx, wy, ax, ay) * o(vx, vy, wx, wy, bx, by) < 0:
                    continue
            gw = gv + math.hypot(wx - vx, wy - vy)
            counts["edges_found"] += 1
            if gw < g_best[w]:
                g_best[w] = gw
                heapq.heappush(heap, (gw + h[w], gw, w, v))

    path, length, stopped = astar(n, h[0], closed, expand, None, deadline, on_progress, every)
    if stopped:
        counts["stopped"] = stopped
    return path, length, counts
