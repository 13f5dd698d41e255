"""The old exact search, kept as the fallback and as the tests' oracle: lazy A* over
bitangent candidate edges, each tested when popped with GEOS's ``covers``.

Every candidate edge is pushed unverified and tested only when popped from the
open list, so it needs no mesh of F: :mod:`cspace.spaces.shortest` uses it when zero-area
pieces are present (their blocking rule, :class:`cspace.spaces.pathcheck.Degenerate`, is
outside F's area) or when GEOS's triangulation of F fails the exact checks of
:mod:`cspace.spaces.freemesh`. It pushes O(V) candidates per settled node, so it slows
down past a few thousand reflex corners (OMPL's env2 takes minutes).
"""
from __future__ import annotations

import heapq
import math
import time
from typing import Callable

import numpy as np


def _lazy_astar(pts: np.ndarray, nbrs: list, region, deadline: float | None = None,
                on_progress: Callable[[int, int, float], None] | None = None, deg=None, every: int = 64) -> tuple:
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
        if on_progress is not None and settled % every == 0:
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
