"""Walks over the slab graph of the exact SE(2) planner (:mod:`cspace.se2.exact`).

A node is a connected component of one slab's FREE or POSSIBLE region (plus the start
and the goal nodes, :data:`S_NODE` and :data:`G_NODE`), an edge a link
between overlapping components of neighbouring slabs. These are the searches over it: what
is reachable, a short walk through FREE entered at link points, the components of FREE,
and the POSSIBLE walk that crosses the fewest places where FREE breaks. All deterministic.
"""
from __future__ import annotations

import heapq
import math

S_NODE, G_NODE = (-1, 0), (-2, 0)  # the virtual start and goal nodes (sort before slab nodes)


def reach(adj: dict, sources: list) -> set:
    """Every node reachable from ``sources`` in the graph ``adj`` (node -> neighbours).

    >>> sorted(reach({1: [2], 2: [1], 3: []}, [1]))
    [1, 2]
    """
    seen, todo = set(sources), list(sources)
    while todo:
        n = todo.pop()
        for m in sorted(adj[n]):
            if m not in seen:
                seen.add(m)
                todo.append(m)
    return seen


def shortest_walk(adj: dict, s, g, s_xy: tuple, g_xy: tuple, turn_cost) -> list | None:
    """A short walk s -> g as [(node, link point to the next node), ..., (g, None)], else None.

    Dijkstra where a node is entered at its link point: the cost of an edge is the distance
    from the point where its node was entered (the start for s) to the edge's point, plus
    ``turn_cost(node, next)`` (the robot radius times the turn); g is entered at the goal.
    Deterministic: ties go to the smaller node."""
    dist = {s: 0.0}
    prev: dict = {s: None}
    at = {s: s_xy}
    heap = [(0.0, s)]
    while heap:
        d, n = heapq.heappop(heap)
        if d > dist[n]:
            continue
        if n == g:
            break
        x, y = at[n]
        for m, pt in adj[n]:
            q = g_xy if pt is None else pt
            nd = d + math.hypot(q[0] - x, q[1] - y) + turn_cost(n, m)
            if m not in dist or nd < dist[m]:
                dist[m], prev[m], at[m] = nd, (n, pt), q
                heapq.heappush(heap, (nd, m))
    if g not in prev:
        return None
    walk, n, pt = [], g, None
    while n is not None:
        walk.append((n, pt))
        n, pt = prev[n] if prev[n] is not None else (None, None)
    return walk[::-1]  # [(s, link to n_1), (n_1, link to n_2), ..., (g, None)]


def labels(fadj: dict) -> dict:
    """Connected-component label of every FREE node (the smallest node of its component)."""
    label: dict = {}
    plain = {u: [m for m, _ in v] for u, v in fadj.items()}
    for n in sorted(fadj):
        if n not in label:
            label.update(dict.fromkeys(reach(plain, [n]), n))
    return label


def cheapest_walk(padj: dict, bad_node: set, good_edge: set) -> list:
    """The POSSIBLE walk from start to goal that crosses the fewest places where FREE breaks
    (a node FREE does not fill as one piece, a link FREE does not reproduce), then the fewest
    nodes: Dijkstra with (breaks, hops) costs; deterministic ties."""
    dist = {S_NODE: (0, 0)}
    prev: dict = {S_NODE: None}
    heap = [((0, 0), S_NODE)]
    while heap:
        d, n = heapq.heappop(heap)
        if d != dist[n]:
            continue
        if n == G_NODE:
            break
        for m in sorted(padj[n]):
            cost = int(m in bad_node) + int((n, m) not in good_edge)
            nd = (d[0] + cost, d[1] + 1)
            if m not in dist or nd < dist[m]:
                dist[m], prev[m] = nd, n
                heapq.heappush(heap, (nd, m))
    if G_NODE not in prev:
        return []
    walk, n = [], G_NODE
    while n is not None:
        walk.append(n)
        n = prev[n]
    return walk[::-1]
