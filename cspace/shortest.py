"""Exact shortest paths for a translating robot: a lazy A* over the reduced visibility graph.

The free C-space is F = B − int(∪ C_i): the bounds B minus the interior of the union
of the C-obstacle pieces. The shortest start–goal path in the closure of F is a
polygonal chain that bends only at reflex vertices of F (convex corners of the
obstacle union), and each of its inner edges is *bitangent*: the line through it
touches the obstacle at both ends without entering it (Lozano-Pérez & Wesley 1979;
Latombe, ch. 4). So the graph has the reflex vertices plus start and goal as nodes
and the bitangent segments as edges.

Search is lazy A* (Euclidean heuristic, consistent): an edge is only tested for
visibility when it is popped from the open list, so most of the O(V²) candidate edges
are never tested. A visibility test is one prepared ``covers`` of F by the segment
(GEOS, robust predicates), O(log n + k).

Cost: building F is a polygon union, O(N log N) for N piece vertices plus the
output; the search pushes O(V · V_closed) candidates and tests one segment per pop,
each test O(log n + k). Scenes with hundreds of reflex vertices, or thousands in open
space (OMPL's circles), take milliseconds; a maze of thousands of reflex vertices
where the straight-line heuristic misleads (OMPL's env2: 4647) takes minutes, so a
``time_limit`` bounds the search and says so when it stops.

Tolerance: F's vertices come from GEOS's union, whose new vertices (edge crossings
of overlapping pieces) are rounded to doubles; the length is exact for that F,
within ~1e-15 relative of the true one. Start and goal are connected iff they lie
in the same polygon of F, so an unsolvable query is *proven* unsolvable.
"""
from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np


@dataclass
class ShortestPath:
    """The result of :func:`shortest_path`. ``path`` runs from start to goal."""

    solved: bool
    path: np.ndarray
    length: float
    proven_unsolvable: bool = False
    stats: dict = field(default_factory=dict)


def free_space(pieces: list, bounds) -> "object":
    """The free C-space F = bounds minus the union of the pieces, a shapely geometry.

    >>> F = free_space([np.array([[1., 1], [2, 1], [2, 2], [1, 2]])], (0, 3, 0, 3))
    >>> F.area
    8.0
    """
    import shapely

    from .pathcheck import split_pieces

    xmin, xmax, ymin, ymax = map(float, bounds)
    box = shapely.box(xmin, ymin, xmax, ymax)
    # Zero-area pieces (points, segments) have no area to subtract: they are handled
    # by the search (cspace.pathcheck.Degenerate), not here.
    polys = [shapely.Polygon(p) for p in split_pieces(pieces)[0]]
    if not polys:
        return box
    return shapely.orient_polygons(box.difference(shapely.union_all(polys))) \
        if hasattr(shapely, "orient_polygons") else _orient(box.difference(shapely.union_all(polys)))


def _orient(geom):
    import shapely
    from shapely.geometry.polygon import orient

    parts = [orient(p, 1.0) for p in shapely.get_parts(geom) if p.geom_type == "Polygon"]
    return shapely.MultiPolygon(parts) if len(parts) != 1 else parts[0]


def shortest_path(pieces: list, bounds, start, goal, time_limit: float | None = None,
                  on_progress: Callable[[int, int, float], None] | None = None) -> ShortestPath:
    """The shortest path from start to goal through the free C-space.

    ``time_limit`` (seconds) bounds the search: past it the result is unsolved with
    ``stats["reason"] == "time limit"`` (never a silent wrong answer, never a hang).
    ``on_progress(settled, nodes, bound)``, when given, is called every
    :data:`PROGRESS_EVERY` settled nodes and once at the end: nodes settled so far,
    nodes of the graph, and a lower bound on the shortest length (the f value of the
    last settled node, which never decreases with a consistent heuristic).

    >>> sq = np.array([[1., 0], [2, 0], [2, 2], [1, 2]])
    >>> sp = shortest_path([sq], (0, 3, 0, 3), (0, 1), (3, 1))
    >>> sp.solved, round(sp.length, 12), sp.path.tolist()
    (True, 3.828427124746, [[0.0, 1.0], [1.0, 2.0], [2.0, 2.0], [3.0, 1.0]])
    >>> calls = []
    >>> _ = shortest_path([sq], (0, 3, 0, 3), (0, 1), (3, 1), on_progress=lambda *a: calls.append(a))
    >>> calls[-1][:2], round(calls[-1][2], 12)  # all 4 nodes settled; the bound reached the length
    ((4, 4), 3.828427124746)
    """
    import shapely

    from .pathcheck import Degenerate, path_violations, split_pieces
    from .polygon import as_array

    t0 = time.perf_counter()
    pieces = [as_array(p, copy=False, nonempty=True) for p in pieces]  # the one input gate: finite (N, 2) reals
    s, g = _point(start, "start"), _point(goal, "goal")
    bounds = tuple(_point(bounds[:2], "bounds")) + tuple(_point(bounds[2:], "bounds"))
    F = free_space(pieces, bounds)
    parts = [p for p in shapely.get_parts(F) if p.geom_type == "Polygon" and not p.is_empty]
    ps, pg = shapely.Point(s), shapely.Point(g)
    comp_s = next((k for k, p in enumerate(parts) if p.covers(ps)), None)
    comp_g = next((k for k, p in enumerate(parts) if p.covers(pg)), None)
    stats = {"counts": {"free_components": len(parts)}}
    degenerate = split_pieces(pieces)[1]
    deg = Degenerate(degenerate, parts[comp_s] if comp_s is not None else None) if degenerate else None
    if comp_s is None or comp_g is None or (deg is not None and (deg.contains(s) or deg.contains(g))):
        stats["reason"] = "start or goal is not in the free C-space"
        stats["time"] = time.perf_counter() - t0
        return ShortestPath(False, np.zeros((0, 2)), math.inf, False, stats)
    if comp_s != comp_g:
        stats["reason"] = "start and goal lie in different free components"
        stats["time"] = time.perf_counter() - t0
        return ShortestPath(False, np.zeros((0, 2)), math.inf, True, stats)
    region = parts[comp_s]
    shapely.prepare(region)
    if s == g:
        return ShortestPath(True, np.array([s]), 0.0, False, {**stats, "time": time.perf_counter() - t0})
    nodes, tangent_dirs = _reflex_vertices(region)
    if deg is not None:  # the free tips of zero-area pieces: the path may bend around them
        stats["counts"]["degenerate_pieces"] = len(degenerate)
        for tip in deg.wraps:
            nodes.append(tip)
            tangent_dirs.append((np.array(tip), np.array(tip)))  # any direction is tangent
    pts = np.array([s, g] + nodes, dtype=np.float64).reshape(-1, 2)
    deadline = None if time_limit is None else t0 + float(time_limit)
    path, length, counts = _lazy_astar(pts, tangent_dirs, region, deadline, on_progress, deg)
    stats["counts"].update(counts, nodes=len(pts))
    stats["time"] = time.perf_counter() - t0
    if path is None:  # a connected region has a path, unless zero-area pieces cut it
        stats["reason"] = stats["counts"].pop("stopped", "search exhausted")
        return ShortestPath(False, np.zeros((0, 2)), math.inf, False, stats)
    # The answer must agree with the pieces' own exact predicates, segment by segment.
    bad = path_violations(pts[path], pieces, bounds)
    if bad:
        stats["reason"] = f"the path failed the exact check against the pieces (edge {bad[0][0]}, piece {bad[0][1]})"
        return ShortestPath(False, np.zeros((0, 2)), math.inf, False, stats)
    return ShortestPath(True, pts[path], length, False, stats)


def _point(p, what: str) -> tuple[float, float]:
    """(x, y) as two finite floats, else ValueError (NaN and inf never reach the search)."""
    from .polygon import as_point

    try:
        return as_point(p)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"shortest_path: {what}: {exc}") from None


def _reflex_vertices(region) -> tuple[list, list]:
    """Reflex vertices of F (free side on the left of every ring) and their two edges.

    For each vertex v with ring neighbours a (before) and b (after), a right turn
    a -> v -> b means F's interior angle at v exceeds pi: an obstacle corner the
    shortest path can wrap around. The neighbours are kept for the tangency test.
    """
    from .predicates import orient2d_cols

    nodes: list = []
    nbrs: list = []
    rings = [region.exterior] + list(region.interiors)
    for ring in rings:
        c = np.asarray(ring.coords)[:-1, :2]
        if len(c) < 3:
            continue
        a, b = np.roll(c, 1, axis=0), np.roll(c, -1, axis=0)
        turn = orient2d_cols(a[:, 0], a[:, 1], c[:, 0], c[:, 1], b[:, 0], b[:, 1])
        # Exterior rings of F are CCW and holes CW (orient_polygons), so F is on the left.
        for k in np.flatnonzero(turn < 0):
            nodes.append((float(c[k, 0]), float(c[k, 1])))
            nbrs.append((a[k], b[k]))
    return nodes, nbrs


PROGRESS_EVERY = 64  # settled nodes between two progress reports


def _lazy_astar(pts: np.ndarray, nbrs: list, region, deadline: float | None = None,
                on_progress: Callable[[int, int, float], None] | None = None, deg=None) -> tuple:
    """A* from node 0 to node 1 over bitangent candidate edges, each checked when popped."""
    import shapely

    n = len(pts)
    goal = pts[1]
    h = np.hypot(pts[:, 0] - goal[0], pts[:, 1] - goal[1])
    closed = np.zeros(n, dtype=bool)
    g_best = np.full(n, np.inf)
    parent = np.full(n, -1)
    g_best[0] = 0.0
    heap = [(h[0], 0.0, 0, -1)]
    tested = pushed = 0
    # Neighbour vectors of each reflex vertex, for the tangency filter.
    na = np.array([x[0] for x in nbrs]).reshape(-1, 2)
    nb = np.array([x[1] for x in nbrs]).reshape(-1, 2)
    stopped = None
    settled = 0
    bound = float(h[0])
    while heap:
        if deadline is not None and time.perf_counter() > deadline:
            stopped = "time limit"
            break
        f, gv, v, par = heapq.heappop(heap)
        if closed[v]:
            continue
        if par >= 0:
            tested += 1
            seg = shapely.LineString([pts[par], pts[v]])
            if not region.covers(seg) or (deg is not None and deg.blocks(pts[par], pts[v])):
                continue
        closed[v] = True
        g_best[v] = gv
        parent[v] = par
        settled += 1
        bound = f
        if on_progress is not None and settled % PROGRESS_EVERY == 0:
            on_progress(settled, n, bound)
        if v == 1:
            break
        cand = np.flatnonzero(~closed)
        if len(cand) == 0:
            continue
        d = np.hypot(pts[cand, 0] - pts[v, 0], pts[cand, 1] - pts[v, 1])
        keep = _tangent_mask(pts, v, cand, na, nb)
        # Every candidate is pushed unverified: a tentative cost must not shadow a
        # costlier but visible edge to the same node, so no pruning before the test.
        gw = gv + d[keep]
        for fw, gw_, w in zip((gw + h[cand[keep]]).tolist(), gw.tolist(), cand[keep].tolist()):
            heapq.heappush(heap, (fw, gw_, w, v))
        pushed += int(keep.sum())
    if on_progress is not None:
        on_progress(settled, n, bound)
    counts = {"edges_tested": tested, "edges_pushed": pushed}
    if stopped:
        counts["stopped"] = stopped
    if not closed[1]:
        return None, math.inf, counts
    path = [1]
    while path[-1] != 0:
        path.append(int(parent[path[-1]]))
    return path[::-1], float(g_best[1]), counts


def _tangent_mask(pts: np.ndarray, v: int, cand: np.ndarray, na: np.ndarray, nb: np.ndarray) -> np.ndarray:
    """Candidate edges v-w that can lie on a shortest path: tangent at both reflex ends.

    At a reflex vertex r with ring neighbours a and b, the line through r and the
    other end must not separate a from b (the path would cut into the obstacle's
    corner instead of wrapping it). The test is in floats with a tolerance that only
    ever keeps more edges than needed (never drops a tangent one).
    """
    keep = np.ones(len(cand), dtype=bool)
    p = pts[v]
    q = pts[cand]
    # Tangency at the far end w (reflex nodes are 2..n-1).
    far = cand >= 2
    if far.any():
        w = cand[far] - 2
        keep[far] &= _not_separated(q[far], p, na[w], nb[w])
    if v >= 2:
        keep &= _not_separated(np.broadcast_to(p, q.shape), q, na[v - 2][None, :], nb[v - 2][None, :])
    return keep


def _not_separated(r: np.ndarray, other: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Whether a and b lie (weakly) on one side of the line through r and ``other``."""
    dx, dy = other[..., 0] - r[..., 0], other[..., 1] - r[..., 1]
    sa = dx * (a[..., 1] - r[..., 1]) - dy * (a[..., 0] - r[..., 0])
    sb = dx * (b[..., 1] - r[..., 1]) - dy * (b[..., 0] - r[..., 0])
    scale = (np.abs(dx) + np.abs(dy)) * (np.abs(a - r).sum(-1) + np.abs(b - r).sum(-1)) + 1e-300
    tol = 1e-9 * scale
    return ~(((sa > tol) & (sb < -tol)) | ((sa < -tol) & (sb > tol)))
