"""The A* loop both exact shortest-path searches share: settle, report, stop, walk back.

:func:`cspace.paths.visibility.mesh_astar` (edges found visible on settling, pushed
with their cost) and :func:`cspace.paths.shortest_lazy._lazy_astar` (candidate edges
pushed untested, each tested when popped) differ only in where an edge comes from and
when it is checked; :func:`astar` is the rest: the open list, the settled set, the
deadline, the progress reports with the lower bound, and the path from the parents.
"""
from __future__ import annotations

import heapq
import math
import time
from typing import Callable


def astar(n: int, h0: float, closed, expand: Callable, accept: Callable | None = None,
          deadline: float | None = None, on_progress: Callable[[int, int, float], None] | None = None,
          every: int = 64) -> tuple:
    """A* from node 0 to node 1 of ``n`` nodes; ``h0`` is node 0's heuristic.

    The open list holds ``(f, g, node, parent)``. A popped entry whose node is not yet
    settled settles it, unless ``accept(parent, node)`` (called for every entry but the
    start's) refuses its edge; then ``expand(v, g, parent, heap)`` pushes v's
    successors onto ``heap`` (with ``heapq.heappush``). ``closed`` is the caller's
    settled flags (a list or a boolean array, all false), which ``expand`` may read.
    ``on_progress(settled, n, bound)`` is called every ``every`` settlements and at
    the end, ``bound`` being the last settled f (a lower bound on the length).

    Returns ``(path as node indices or None, length, why the search stopped early or None)``.

    >>> # a line 0 - 2 - 1 of unit edges, heuristic 0: the path goes through node 2
    >>> edges = {0: [2], 2: [0, 1], 1: [2]}
    >>> closed = [False] * 3
    >>> def expand(v, g, parent, heap):
    ...     for w in edges[v]:
    ...         if not closed[w]:
    ...             heapq.heappush(heap, (g + 1.0, g + 1.0, w, v))
    >>> astar(3, 0.0, closed, expand)
    ([0, 2, 1], 2.0, None)
    """
    parent = [-1] * n
    heap = [(h0, 0.0, 0, -1)]
    settled = 0
    bound = h0
    stopped = None
    length = math.inf
    while heap:
        if deadline is not None and time.perf_counter() > deadline:
            stopped = "time limit"
            break
        f, gv, v, par = heapq.heappop(heap)
        if closed[v]:
            continue
        if par >= 0 and accept is not None and not accept(par, v):
            continue
        closed[v] = True
        parent[v] = par
        settled += 1
        bound = f
        if on_progress is not None and settled % every == 0:
            on_progress(settled, n, bound)
        if v == 1:
            length = gv
            break
        expand(v, gv, par, heap)
    if on_progress is not None:
        on_progress(settled, n, bound)
    if not closed[1]:
        return None, math.inf, stopped
    path = [1]
    while path[-1] != 0:
        path.append(parent[path[-1]])
    return path[::-1], length, stopped
