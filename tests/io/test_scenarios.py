"""Every bundled scenario plans with its own [planner] defaults, and its path is checked
independently: in bounds, from start to goal, the robot swept along each segment
overlapping no obstacle's interior (shapely). Unsolvable-on-purpose scenes say so."""
import glob
import os

import numpy as np
import pytest
import shapely

import planners
from cspace.io.load import load_scenario
from conftest import SCENARIOS

FILES = sorted(glob.glob(os.path.join(SCENARIOS, "*.toml")) + glob.glob(os.path.join(SCENARIOS, "ompl", "*.toml")))
# env2 (1161 obstacles in 60 layered walls) needs tens of seconds of PRM: kept out of the default run.
SLOW = {"env2.toml"}


def swept_overlap(sc, path) -> bool:
    """Does the robot swept along a segment meet an obstacle's interior? Each robot part is
    split into triangles (GEOS's triangulation, independent of ours); a triangle sweeps the
    convex hull of its two end placements."""
    obstacles = shapely.union_all([o.to_shapely() for o in sc.obstacles])
    tris = []
    for part in sc.robot:
        for t in shapely.get_parts(shapely.constrained_delaunay_triangles(part.to_shapely())):
            tris.append(np.asarray(t.exterior.coords)[:3])
    for a, b in zip(path[:-1], path[1:]):
        if not tris:
            swept = [shapely.LineString([a, b]) if tuple(a) != tuple(b) else shapely.Point(a)]
        else:
            swept = [shapely.MultiPoint(np.vstack([t + a, t + b])).convex_hull for t in tris]
        if any(obstacles.relate_pattern(s, "T********") for s in swept):
            return True
    return False


def test_at_least_twelve_own_scenarios():
    assert len(glob.glob(os.path.join(SCENARIOS, "*.toml"))) >= 12


@pytest.mark.parametrize("path", [f for f in FILES if os.path.basename(f) not in SLOW], ids=os.path.basename)
def test_bundled_scenario_plans(path):
    sc = load_scenario(path)
    res = planners.plan(sc)
    if sc.expect == "unsolvable":
        assert not res.solved
        proof = planners.shortest_path(sc)
        assert proof.message.startswith("proven unsolvable")
        return
    assert res.solved, res.message
    p = res.path
    assert tuple(p[0]) == tuple(map(float, sc.start)) and tuple(p[-1]) == tuple(map(float, sc.goal))
    xmin, xmax, ymin, ymax = sc.bounds
    assert (p[:, 0] >= xmin).all() and (p[:, 0] <= xmax).all() and (p[:, 1] >= ymin).all() and (p[:, 1] <= ymax).all()
    assert not swept_overlap(sc, p)
