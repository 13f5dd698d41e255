"""The mesh search (exact triangular expansion, cspace.paths.visibility) against the lazy search
(cspace.paths.shortest_lazy, today's answers), brute-force visibility and brute-force shortest paths.

Integer grid scenes (unit cells, like OMPL's env2) are the hard cases: collinear
walls, cells touching at a corner (points where rings of F touch), sight lines
grazing corners and running along walls.
"""
import glob
import math
import os

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import SCENARIOS
from cspace import CSpace, load_scenario
from cspace.paths.freemesh import FreeMesh, MeshError
from cspace.kernel.polygons.hull import convex_hull
from cspace.paths.shortest import free_space, shortest_path
from cspace.paths.visibility import visible_from
from test_shortest import brute_force

SKIP = {"env2.toml"}  # the lazy search takes minutes there (tests/io/test_scenarios.py plans it)
FILES = sorted(f for f in glob.glob(os.path.join(SCENARIOS, "*.toml")) + glob.glob(os.path.join(SCENARIOS, "ompl", "*.toml"))
               if os.path.basename(f) not in SKIP)


def same(a, b):
    """Both unsolved the same way, or both solved with lengths equal to 1e-9."""
    if not (a.solved and b.solved):
        return a.solved == b.solved and a.proven_unsolvable == b.proven_unsolvable
    return a.length == pytest.approx(b.length, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("path", FILES, ids=[os.path.relpath(f, SCENARIOS) for f in FILES])
def test_bundled_scenes_match_the_lazy_search(path):
    sc = load_scenario(path)
    cs = CSpace.from_scenario(sc)
    for q in sc.queries[:3]:  # (circles has 100: the lazy search takes minutes over all)
        new = shortest_path(cs.pieces, cs.bounds, q.start, q.goal)
        old = shortest_path(cs.pieces, cs.bounds, q.start, q.goal, method="lazy")
        assert same(new, old), (q, new.length, old.length)
        if new.solved:
            assert new.stats["method"] == "mesh"


def grid_scene(cells, n):
    """Unit squares at the given integer cells of [0, n]^2, in a box one unit wider (the brute
    force would let a path slide between the bounds and a cell touching them)."""
    return ([np.array([[i, j], [i + 1, j], [i + 1, j + 1], [i, j + 1]], dtype=np.float64) for i, j in cells],
            (-1.0, n + 1.0, -1.0, n + 1.0))


cell_sets = st.integers(4, 7).flatmap(lambda n: st.tuples(
    st.just(n), st.sets(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)), max_size=n * n // 2),
    st.tuples(st.integers(0, 2 * n), st.integers(0, 2 * n)), st.tuples(st.integers(0, 2 * n), st.integers(0, 2 * n))))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cell_sets)
def test_grid_scenes_match_the_lazy_search(args):
    # Start and goal on the half-integer lattice: inside cells, on walls, at corners.
    n, cells, s2, g2 = args
    pieces, bounds = grid_scene(sorted(cells), n)
    s, g = (s2[0] / 2, s2[1] / 2), (g2[0] / 2, g2[1] / 2)
    new = shortest_path(pieces, bounds, s, g)
    old = shortest_path(pieces, bounds, s, g, method="lazy")
    assert same(new, old), (new.length, old.length)
    # (No brute force here: it would pass through a point where two cells touch into
    # another component of F, which both searches, by the closed-obstacle rule, do not.)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10**6), st.sampled_from([4, 8, 14]))
def test_random_float_scenes_match_lazy_search_and_brute_force(seed, k):
    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(k):
        c = rng.uniform(1, 9, 2)
        h = convex_hull(c + rng.normal(0, 0.8, (int(rng.integers(3, 8)), 2)))
        if len(h) >= 3:
            pieces.append(h)
    s, g = tuple(rng.uniform(0, 10, 2)), tuple(rng.uniform(0, 10, 2))
    new = shortest_path(pieces, (0.0, 10.0, 0.0, 10.0), s, g)
    old = shortest_path(pieces, (0.0, 10.0, 0.0, 10.0), s, g, method="lazy")
    assert same(new, old), (new.length, old.length)
    if new.solved and k <= 8:
        assert new.length == pytest.approx(brute_force(pieces, (0.0, 10.0, 0.0, 10.0), s, g), rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(cell_sets)
def test_visible_vertices_equal_geos_covers(args):
    # Every vertex of F, from a lattice point: seen by the expansion only if F covers the
    # segment, and seen when it does and no other vertex is on it (a sight line may stop
    # at a corner it grazes; integer input: GEOS's distance 0 is exact here).
    n, cells, s2, _ = args
    pieces, bounds = grid_scene(sorted(cells), n)
    p = (s2[0] / 2, s2[1] / 2)
    F = free_space(pieces, bounds)
    region = next((r for r in shapely.get_parts(F) if r.covers(shapely.Point(p))), None)
    if region is None:
        return
    mesh = FreeMesh(region)
    seen, _, _ = visible_from(mesh, *p, [3 * t for t in mesh.locate(*p)], None, [True] * len(mesh.x))
    shapely.prepare(region)
    pts = [(mesh.x[i], mesh.y[i]) for i in range(len(mesh.x))]

    def behind_a_vertex(q):  # a sight line through a corner of F stops there (the path may bend there)
        seg = shapely.LineString([p, q])
        return any(r not in (p, q) and seg.distance(shapely.Point(r)) == 0 for r in pts)

    covered = {i for i, q in enumerate(pts) if q != p and region.covers(shapely.LineString([p, q]))}
    got = set(seen) - {i for i in seen if pts[i] == p}
    assert {i for i in covered if not behind_a_vertex(pts[i])} <= got <= covered


def test_a_triangulation_failing_the_checks_falls_back(monkeypatch):
    import cspace.paths.freemesh

    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    good = shortest_path([sq], (0, 10, 0, 10), (1, 5), (9, 5))
    real = shapely.constrained_delaunay_triangles
    monkeypatch.setattr(shapely, "constrained_delaunay_triangles",
                        lambda poly: shapely.GeometryCollection(list(shapely.get_parts(real(poly)))[1:]))
    with pytest.raises(MeshError):
        cspace.paths.freemesh.FreeMesh(free_space([sq], (0, 10, 0, 10)))
    sp = shortest_path([sq], (0, 10, 0, 12), (1, 5), (9, 5))  # other bounds: not the scene cached above
    assert sp.stats["method"] == "lazy" and "mesh_error" in sp.stats
    assert sp.length == good.length == pytest.approx(2 + 2 * math.hypot(3, 1))


def test_zero_area_pieces_use_the_lazy_search():
    dot = np.array([[5.0, 5.0], [5.0, 5.0], [5.0, 5.0]])
    sp = shortest_path([dot], (0, 10, 0, 10), (0, 5), (9, 5))
    assert sp.stats["method"] == "lazy" and sp.solved
    with pytest.raises(ValueError, match="no mesh search"):
        shortest_path([dot], (0, 10, 0, 10), (0, 5), (9, 5), method="mesh")
    with pytest.raises(ValueError, match="method"):
        shortest_path([dot], (0, 10, 0, 10), (0, 5), (9, 5), method="fast")


def test_geos_triangulation_errors_are_retried_then_fall_back(monkeypatch):
    # GEOS's ear clipper fails on some valid polygons depending on where the rings start:
    # the mesh retries other starts; when every try fails, the lazy search answers.
    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    real = shapely.constrained_delaunay_triangles
    calls = []

    def flaky(poly):
        calls.append(1)
        if len(calls) == 1:
            raise shapely.errors.GEOSException("IllegalStateException: Unable to find a convex corner")
        return real(poly)

    monkeypatch.setattr(shapely, "constrained_delaunay_triangles", flaky)
    sp = shortest_path([sq], (0, 10, 0, 13), (1, 5), (9, 5))
    assert sp.stats["method"] == "mesh" and len(calls) == 2
    assert sp.length == pytest.approx(2 + 2 * math.hypot(3, 1))

    def broken(poly):
        raise shapely.errors.GEOSException("IllegalStateException: Unable to find a convex corner")

    monkeypatch.setattr(shapely, "constrained_delaunay_triangles", broken)
    sp = shortest_path([sq], (0, 10, 0, 14), (1, 5), (9, 5))
    assert sp.stats["method"] == "lazy" and "GEOS could not triangulate" in sp.stats["mesh_error"]
    assert sp.length == pytest.approx(2 + 2 * math.hypot(3, 1))
