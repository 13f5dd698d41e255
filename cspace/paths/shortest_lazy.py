"""The old exact search, kept as the fallback and as the tests' oracle: lazy A* over
bitangent candidate edges, each tested when popped with GEOS's ``covers``.

Every candidate edge is pushed unverified and tested only when popped from the
open list, so it needs no mesh of F: :mod:`cspace.paths.shortest` uses it when zero-area
pieces are present (their blocking rule, :class:`cspace.paths.pathcheck.Degenerate`, is
outside F's area) or when GEOS's triangulation of F fails the exact checks of
:mod:`cspace.paths.freemesh`. It pushes O(V) candidates per settled node, so it slows
down past a few thousand reflex corners (OMPL's env2 takes minutes).
"""
from __future__ import annotations

import heapq
from typing import Callable

import numpy as np

from .astar import astar


def lazy_astar(pts: np.ndarray, nbrs: list, region, deadline: float | None = None,
                on_progress: Callable[[int, int, float], None] | None = None, deg=None, every: int = 64) -> tuple:
    """A* from node 0 to node 1 over bitangent candidate edges, each checked when popped."""
    import shapely

    n = len(pts)
    goal = pts[1]
    h = np.hypot(pts[:, 0] - goal[0], pts[:, 1] - goal[1])
    closed = np.zeros(n, dtype=bool)
    tested = pushed = 0
    # Neighbour vectors of each reflex vertex, for the tangency filter.
    na = np.array([x[0] for x in nbrs]).reshape(-1, 2)
    nb = np.array([x[1] for x in nbrs]).reshape(-1, 2)

    def accept(par: int, v: int) -> bool:
        nonlocal tested
        tested += 1
        seg = shapely.LineString([pts[par], pts[v]])
        return region.covers(seg) and not (deg is not None and deg.blocks(pts[par], pts[v]))

    def expand(v: int, gv: float, par: int, heap: list) -> None:
        nonlocal pushed
        cand = np.flatnonzero(~closed)
        if len(cand) == 0:
            return
        d = np.hypot(pts[cand, 0] - pts[v, 0], pts[cand, 1] - pts[v, 1])
        keep = _tangent_mask(pts, v, cand, na, nb)
        # Every candidate is pushed unverified: a tentative cost must not shadow a
        # costlier but visible edge to the same node, so no pruning before the test.
        gw = gv + d[keep]
        for fw, gw_, w in zip((gw + h[cand[keep]]).tolist(), gw.tolist(), cand[keep].tolist()):
            heapq.heappush(heap, (fw, gw_, w, v))
        pushed += int(keep.sum())

    path, length, stopped = astar(n, float(h[0]), closed, expand, accept, deadline, on_progress, every)
    counts = {"edges_tested": tested, "edges_pushed": pushed}
    if stopped:
        counts["stopped"] = stopped
    return path, length, counts


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
