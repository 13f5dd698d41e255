"""The channel path (cspace.paths.channel: A* over F's triangles, then the funnel), as
``shortest_path(method="channel")``, against the exact shortest path.

Oracles: the exact shortest path (the channel path is never shorter, and where F is simply
connected the triangle sleeve between two points is unique, so the funnel's path must *be*
the shortest path); the pieces' exact segment test (every returned path); integer grid scenes
for the degenerate cases (collinear walls, cells touching at a corner).
"""
import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cspace.kernel.polygons.hull import convex_hull
from cspace.paths import shortest
from cspace.paths.channel import funnel
from cspace.paths.pathcheck import path_violations
from cspace.paths.shortest import free_space, shortest_path
from test_shortest_mesh import cell_sets, grid_scene


def check(pieces, bounds, s, g):
    """The channel answer agrees with the exact one on solvability, is never shorter, runs
    from s to g and passes the exact segment test. Returns (channel, exact)."""
    ch = shortest_path(pieces, bounds, s, g, method="channel")
    ex = shortest_path(pieces, bounds, s, g)
    assert ch.solved == ex.solved and ch.proven_unsolvable == ex.proven_unsolvable
    if ch.solved:
        assert ch.length >= ex.length * (1 - 1e-12) - 1e-12
        assert tuple(ch.path[0]) == tuple(map(float, s)) and tuple(ch.path[-1]) == tuple(map(float, g))
        assert path_violations(ch.path, pieces, bounds) == []
        assert ch.length == pytest.approx(float(np.hypot(*np.diff(ch.path, axis=0).T).sum()), rel=1e-12)
    return ch, ex


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cell_sets)
def test_grid_scenes_certified_and_never_shorter(args):
    n, cells, s2, g2 = args
    pieces, bounds = grid_scene(sorted(cells), n)
    check(pieces, bounds, (s2[0] / 2, s2[1] / 2), (g2[0] / 2, g2[1] / 2))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10**6), st.sampled_from([4, 8, 14]))
def test_random_float_scenes_certified_and_never_shorter(seed, k):
    rng = np.random.default_rng(seed)
    pieces = [h for h in (convex_hull(rng.uniform(1, 9, 2) + rng.normal(0, 0.8, (int(rng.integers(3, 8)), 2)))
                          for _ in range(k)) if len(h) >= 3]
    check(pieces, (0.0, 10.0, 0.0, 10.0), tuple(rng.uniform(0, 10, 2)), tuple(rng.uniform(0, 10, 2)))


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 9))
def test_simply_connected_free_space_gives_the_shortest_path(seed, walls):
    # Walls hanging from the top or standing on the bottom edge of the bounds (a comb): F has
    # no hole, so the channel between two triangles is unique and the funnel's path through it
    # is the exact shortest path.
    rng = np.random.default_rng(seed)
    xs = np.sort(rng.choice(np.arange(1, 40), size=walls, replace=False)) * 0.25
    pieces = []
    for k, x in enumerate(xs):
        w, h = rng.uniform(0.02, 0.2), rng.uniform(2.0, 8.0)
        y0, y1 = (0.0, h) if (k + seed) % 2 else (10.0 - h, 10.0)
        pieces.append(np.array([[x, y0], [x + w, y0], [x + w, y1], [x, y1]]))
    assert len(shapely.get_parts(free_space(pieces, (0, 11, 0, 10)))) >= 1
    s, g = (0.1, rng.uniform(0, 10)), (10.9, rng.uniform(0, 10))
    ch, ex = check(pieces, (0.0, 11.0, 0.0, 10.0), s, g)
    if ex.solved and len(shapely.get_parts(free_space(pieces, (0, 11, 0, 10)))[0].interiors) == 0:
        assert ch.length == pytest.approx(ex.length, rel=1e-9)


def test_the_funnel_bends_at_the_portal_ends_a_taut_string_touches():
    # a zigzag of gates: the string from (0, 0) to (6, 0) must pass above (2, 1) and below (4, -1)
    gates = [((2.0, 3.0), (2.0, 1.0)), ((4.0, -1.0), (4.0, -3.0))]
    assert funnel((0.0, 0.0), (6.0, 0.0), gates) == [(0.0, 0.0), (2.0, 1.0), (4.0, -1.0), (6.0, 0.0)]
    # wide gates: straight through; a gate whose end is the apex itself (a fan around a corner)
    assert funnel((0.0, 0.0), (6.0, 0.0), [((2.0, 1.0), (2.0, -1.0)), ((4.0, 2.0), (4.0, -2.0))]) == \
        [(0.0, 0.0), (6.0, 0.0)]
    assert funnel((0.0, 0.0), (2.0, 2.0), [((0.0, 0.0), (1.0, 0.0)), ((0.0, 0.0), (1.0, 1.0))]) == \
        [(0.0, 0.0), (2.0, 2.0)]


def test_wrong_free_polygons_from_a_caller_never_give_a_colliding_path():
    # ``free=`` is trusted for speed only: with F claimed to be the whole box (the wall
    # missing), the straight line through the wall fails the exact check against the pieces.
    wall = np.array([[4.0, 0.0], [5.0, 0.0], [5.0, 9.0], [4.0, 9.0]])
    shortest.clear_cache()
    for method in ("channel", "auto"):
        sp = shortest_path([wall], (0, 10, 0, 10), (1, 1), (9, 1), method=method, free=[shapely.box(0, 0, 10, 10)])
        assert not sp.solved or path_violations(sp.path, [wall], (0, 10, 0, 10)) == []
        shortest.clear_cache()
    good = shortest_path([wall], (0, 10, 0, 10), (1, 1), (9, 1), method="channel")
    assert good.solved and good.length > 16


def test_scenes_are_kept_while_queries_alternate_between_them(monkeypatch):
    # The exact SE(2) planner translates in one slab, then another, then the first again: each
    # slab's F is computed once, not once per visit (the cache kept one scene before).
    calls = []
    real = shortest.free_space
    monkeypatch.setattr(shortest, "free_space", lambda p, b: calls.append(1) or real(p, b))
    shortest.clear_cache()
    a = [np.array([[4.0, 0.0], [5.0, 0.0], [5.0, 9.0], [4.0, 9.0]])]
    b = [np.array([[4.0, 1.0], [5.0, 1.0], [5.0, 10.0], [4.0, 10.0]])]
    for _ in range(3):
        for pieces in (a, b):
            assert shortest_path(pieces, (0, 10, 0, 10), (1, 5), (9, 5), method="channel").solved
    assert len(calls) == 2
    shortest.clear_cache()


def test_warm_builds_the_meshes_before_the_first_query(monkeypatch):
    from cspace.paths import freemesh

    shortest.clear_cache()
    pieces = [np.array([[4.0, 0.0], [5.0, 0.0], [5.0, 9.0], [4.0, 9.0]])]
    assert shortest.warm(pieces, (0, 10, 0, 10)) == 1
    monkeypatch.setattr(freemesh.FreeMesh, "__init__", lambda *a: pytest.fail("a mesh was built again"))
    assert shortest_path(pieces, (0, 10, 0, 10), (1, 5), (9, 5), method="channel").stats["method"] == "channel"
    shortest.clear_cache()
