"""The exact planner on every bundled scenario against independent references (issue #6).

Solvable scenes: the length equals a brute-force visibility graph over all piece vertices
(tests/paths/test_shortest.py) to 1e-9 relative. Unsolvable ones: the start and the goal lie in
different polygons of GEOS's free space (bounds minus the union of the C-obstacles), an
independent proof. The three largest scenes (thousands of piece vertices) are left to
the brute force's O(V^2) limits: disks_cluttered, circles and env2 are planned exactly in
tests/io/test_scenarios.py and tests/translation/test_circles_queries.py.
"""
import glob
import os

import pytest
import shapely

from conftest import SCENARIOS
from cspace import CSpace, load_scenario
from cspace.paths.shortest import shortest_path
from test_shortest import brute_force

TOO_LARGE = {"disks_cluttered.toml", "circles.toml", "env2.toml"}
FILES = sorted(f for f in glob.glob(os.path.join(SCENARIOS, "*.toml")) + glob.glob(os.path.join(SCENARIOS, "ompl", "*.toml"))
               if os.path.basename(f) not in TOO_LARGE)


def free_components(cs):
    box = shapely.box(cs.bounds[0], cs.bounds[2], cs.bounds[1], cs.bounds[3])
    free = box.difference(shapely.union_all([shapely.Polygon(p) for p in cs.pieces]))
    return list(getattr(free, "geoms", [free]))


@pytest.mark.parametrize("path", FILES, ids=[os.path.relpath(f, SCENARIOS) for f in FILES])
@pytest.mark.slow
def test_exact_matches_independent_reference(path):
    sc = load_scenario(path)
    cs = CSpace.from_scenario(sc)
    sp = shortest_path(cs.pieces, cs.bounds, sc.start, sc.goal)
    if sc.expect == "unsolvable":
        assert sp.length == float("inf")
        parts = free_components(cs)
        home = [i for i, p in enumerate(parts) if p.covers(shapely.Point(sc.start))]
        away = [i for i, p in enumerate(parts) if p.covers(shapely.Point(sc.goal))]
        assert home and away and not set(home) & set(away)
    else:
        ref = brute_force(cs.pieces, cs.bounds, sc.start, sc.goal)
        assert sp.length == pytest.approx(ref, rel=1e-9)
