"""Exact shortest paths against an independent brute-force visibility graph."""
import heapq
import math

import numpy as np
import pytest
import shapely

from cspace.kernel.polygons.hull import convex_hull
from cspace.paths.shortest import shortest_path


def brute_force(pieces, bounds, s, g):
    """Dijkstra over ALL piece vertices + box corners + start/goal; an edge is valid iff
    it stays in the box and meets the union's interior nowhere (DE-9IM T********)."""
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    box = shapely.box(bounds[0], bounds[2], bounds[1], bounds[3])
    pts = [tuple(s), tuple(g)] + [tuple(v) for p in pieces for v in p.tolist()]
    pts += [(bounds[0], bounds[2]), (bounds[1], bounds[2]), (bounds[1], bounds[3]), (bounds[0], bounds[3])]
    pts = [p for i, p in enumerate(pts) if i < 2 or (box.covers(shapely.Point(p)) and
                                                    not union.relate_pattern(shapely.Point(p), "T********"))]
    n = len(pts)

    def ok(a, b):
        seg = shapely.LineString([a, b]) if a != b else shapely.Point(a)
        return box.covers(seg) and not union.relate_pattern(seg, "T********")

    dist = [math.inf] * n
    dist[0] = 0.0
    heap = [(0.0, 0)]
    done = [False] * n
    while heap:
        d, u = heapq.heappop(heap)
        if done[u]:
            continue
        done[u] = True
        if u == 1:
            return d
        for w in range(n):
            if not done[w]:
                nd = d + math.dist(pts[u], pts[w])
                if nd < dist[w] and ok(pts[u], pts[w]):
                    dist[w] = nd
                    heapq.heappush(heap, (nd, w))
    return math.inf


def random_scene(seed, k=6):
    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(k):
        c = rng.uniform(1, 9, 2)
        pts = c + rng.normal(0, 0.9, (int(rng.integers(3, 7)), 2))
        h = convex_hull(pts)
        if len(h) >= 3:
            pieces.append(h)
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    free = []
    while len(free) < 2:
        p = tuple(rng.uniform(0, 10, 2))
        if not union.intersects(shapely.Point(p)):
            free.append(p)
    return pieces, (0.0, 10.0, 0.0, 10.0), free[0], free[1]


@pytest.mark.parametrize("seed", range(30))
def test_matches_brute_force(seed):
    pieces, bounds, s, g = random_scene(seed)
    sp = shortest_path(pieces, bounds, s, g)
    ref = brute_force(pieces, bounds, s, g)
    if math.isinf(ref):
        assert not sp.solved and sp.proven_unsolvable
        return
    assert sp.solved
    assert sp.length == pytest.approx(ref, rel=1e-9)
    assert tuple(sp.path[0]) == s and tuple(sp.path[-1]) == g
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    for a, b in zip(sp.path[:-1], sp.path[1:]):
        assert not union.relate_pattern(shapely.LineString([a, b]), "T********")
    assert np.isclose(np.hypot(*np.diff(sp.path, axis=0).T).sum(), sp.length)


def test_wall_splits_the_box_is_proven_unsolvable():
    wall = np.array([[4.0, 0.0], [5.0, 0.0], [5.0, 10.0], [4.0, 10.0]])
    sp = shortest_path([wall], (0, 10, 0, 10), (1, 1), (9, 9))
    assert not sp.solved and sp.proven_unsolvable and math.isinf(sp.length)


def test_trivial_cases():
    sq = np.array([[4.0, 4.0], [5.0, 4.0], [5.0, 5.0], [4.0, 5.0]])
    same = shortest_path([sq], (0, 10, 0, 10), (1, 1), (1, 1))
    assert same.solved and same.length == 0.0 and len(same.path) == 1
    straight = shortest_path([sq], (0, 10, 0, 10), (1, 1), (9, 1))
    assert straight.solved and len(straight.path) == 2 and straight.length == 8.0


def test_start_inside_an_obstacle_is_not_free():
    sq = np.array([[4.0, 4.0], [5.0, 4.0], [5.0, 5.0], [4.0, 5.0]])
    sp = shortest_path([sq], (0, 10, 0, 10), (4.5, 4.5), (9, 9))
    assert not sp.solved and not sp.proven_unsolvable


def test_path_slides_along_shared_edges_of_overlapping_pieces():
    # Two pieces that share an edge form one rectangle: the path wraps the rectangle's
    # corners, never the shared edge between them.
    a = np.array([[3.0, 2.0], [5.0, 2.0], [5.0, 8.0], [3.0, 8.0]])
    b = np.array([[5.0, 2.0], [7.0, 2.0], [7.0, 8.0], [5.0, 8.0]])
    sp = shortest_path([a, b], (0, 10, 0, 10), (1, 5), (9, 5))
    assert sp.length == pytest.approx(2 * math.hypot(2, 3) + 4, rel=1e-12)


def test_peer_scenarios_against_brute_force():
    from cspace.translation.cspace import CSpace
    from cspace.io.load import load_scenario

    from conftest import SCENARIOS

    sc = load_scenario(f"{SCENARIOS}/ompl/env1.toml")
    cs = CSpace.from_scenario(sc)
    sp = shortest_path(cs.pieces, cs.bounds, sc.start, sc.goal)
    assert sp.length == pytest.approx(brute_force(cs.pieces, cs.bounds, sc.start, sc.goal), rel=1e-9)
