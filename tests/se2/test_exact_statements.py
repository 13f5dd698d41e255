"""A "not decided" statement is true (issue 49, point 2): each scene here has a witness path whose
clearance to the obstacles as written is measured independently (shapely: translations sweep the
robot's hull between the ends, turns in place the disk of the robot's radius about the point);
the search either finds a path or states a D of at least that clearance (thin bounds, margins,
disks, the ±π seam)."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings, strategies as st

from cspace.io.load import scenario_from_dict
from cspace.se2.exact import from_scenario


def witness_clearance(sc, waypoints) -> float:
    """A lower bound on the clearance of the polyline of poses (each step a translation at a fixed
    angle or a turn in place) to the TRUE obstacles (disks as circles)."""
    robot = shapely.Polygon(sc.robot[0].polygon) if sc.robot[0].disk is None else \
        shapely.Point(0, 0).buffer(sc.robot[0].disk[2], quad_segs=256)
    r = max(math.hypot(x, y) for x, y in np.asarray(robot.exterior.coords)) * 1.0001
    obs = [shapely.Point(o.disk[:2]).buffer(o.disk[2], quad_segs=1024) if o.disk else o.to_shapely()
           for o in sc.obstacles]
    swept = []
    for (x0, y0, t0), (x1, y1, t1) in zip(waypoints, waypoints[1:]):
        if (x0, y0) == (x1, y1):
            swept.append(shapely.Point(x0, y0).buffer(r, quad_segs=256))
        else:
            assert t0 == t1
            a = shapely.affinity.rotate(robot, t0, origin=(0, 0), use_radians=True)
            swept.append(shapely.union(shapely.affinity.translate(a, x0, y0),
                                       shapely.affinity.translate(a, x1, y1)).convex_hull)
    sweep = shapely.union_all(swept)
    return min(shapely.distance(sweep, o) for o in obs)


def stated(res) -> float:
    return float(re.search(r"clearance above ([0-9.e+-]+)", res.stats["statement"]).group(1))


def assert_true_statement(sc, waypoints, **kw):
    c = witness_clearance(sc, waypoints)
    assert c > 0
    res = from_scenario(sc, **kw)
    assert res.status != "unsolvable"
    if res.status == "undecided":
        assert stated(res) >= c, (res.stats["statement"], c)
    return res


def rail(height, clearance=0.0, margin=None):
    """A bar on a rail (the reference point confined to a strip ``height`` high) between a floor
    and a ceiling, to turn from 0 to π/2 in a hall at the middle."""
    data = {"space": "se2", "bounds": {"xmin": 1.0, "xmax": 9.0, "ymin": 5.0, "ymax": 5.0 + height},
            "robot": {"polygon": [[-0.5, -0.1], [0.5, -0.1], [0.5, 0.1], [-0.5, 0.1]]},
            "start": {"x": 1.5, "y": 5.0, "theta": 0.0}, "goal": {"x": 5.0, "y": 5.0, "theta": math.pi / 2},
            "obstacles": [{"polygon": [[0, 0], [10, 0], [10, 4.5], [6, 4.5], [6, 4.0], [4, 4.0], [4, 4.5], [0, 4.5]]},
                          {"polygon": [[0, 5.5], [4, 5.5], [4, 6.0], [6, 6.0], [6, 5.5], [10, 5.5], [10, 10], [0, 10]]}]}
    if clearance:
        data["clearance"] = clearance
    return scenario_from_dict(data, "rail.toml")


@pytest.mark.parametrize("height", [1e-9, 1e-6, 0.0 + 1e-3])
def test_a_rail_of_any_thinness_is_decided_or_truly_stated(height):
    sc = rail(height)
    way = [(1.5, 5.0, 0.0), (5.0, 5.0, 0.0), (5.0, 5.0, math.pi / 2)]
    res = assert_true_statement(sc, way, time_limit=30.0)
    assert res.status == "solved"  # FREE links the slabs through points of the thin overlaps


def test_a_margin_is_in_the_statement():
    """With clearance 0.35 and a witness keeping 0.38 (the hall is wide), an undecided search may not
    state less than 0.38: the statement adds the margin's reach."""
    sc = rail(1e-3, clearance=0.35)
    way = [(1.5, 5.0, 0.0), (5.0, 5.0, 0.0)]
    # the witness only needs to get to the hall: state the claim on the whole scene's statement
    res = from_scenario(sc, time_limit=30.0, min_width=2 * math.pi / 16)
    if res.status == "undecided":
        assert stated(res) > 0.35
    assert witness_clearance(sc, way) > 0


DOOR = dict(R=st.floats(1.0, 20.0), spare=st.floats(0.01, 0.3), seam=st.booleans(), clearance=st.sampled_from([0.0, 0.05]))


@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(**DOOR)
@example(R=10.0, spare=0.003 / 0.3, seam=False, clearance=0.0)  # the pillars: D must count the disks
@example(R=5.0, spare=0.2, seam=True, clearance=0.05)
def test_an_undecided_door_between_disks_states_at_least_its_witness(R, spare, seam, clearance):
    """A box crossing between round pillars at angle 0 (or π: the ±π seam) with ``spare`` × its
    half-height to spare, at a coarse floor: solved, or a statement of at least the witness's
    clearance minus the clearance asked (the statement is about the robot as written)."""
    h, w = 0.3, 0.8
    c = R + h + spare * h
    th = math.pi if seam else 0.0
    data = {"space": "se2", "bounds": {"xmin": -R - 4, "xmax": R + 4, "ymin": -R / 2, "ymax": R / 2},
            "robot": {"polygon": [[-w, -h], [w, -h], [w, h], [-w, h]]},
            "start": {"x": -R - 3, "y": 0.0, "theta": th}, "goal": {"x": R + 3, "y": 0.0, "theta": -th},
            "obstacles": [{"center": [0.0, c], "radius": R}, {"center": [0.0, -c], "radius": R}]}
    if clearance:
        data["clearance"] = clearance
    sc = scenario_from_dict(data, "door.toml")
    way = [(-R - 3, 0.0, th), (R + 3, 0.0, th)]
    wc = witness_clearance(sc, way)
    res = from_scenario(sc, time_limit=30.0, min_width=2 * math.pi / 64)
    assert res.status != "unsolvable"
    if res.status == "undecided" and wc > clearance:
        assert stated(res) >= wc, (res.stats["statement"], wc)


def test_a_time_limit_inside_a_refinement_states_what_the_last_searched_partition_established(monkeypatch):
    """The time limit comes while FREE of a refined partition is built: its graph was never searched,
    so D is the last searched partition's (8 slabs, Δ = π/4), not the finer one's; before any FREE
    graph was searched there is no statement (the clock is the test's: the deadline is set past)."""
    from conftest import load_script
    from cspace.se2 import exact

    sc = load_script("se2_families").door(0, 0.003)
    split = exact._Search._split

    def split_all_then_late(self, _which):
        done = split(self, set(range(len(self.part))))  # every slab halved: Δ π/8
        self.deadline = -math.inf  # the time is up while the halves' FREE is built
        return done

    monkeypatch.setattr(exact._Search, "_split", split_all_then_late)
    res = from_scenario(sc, time_limit=1e9)
    assert res.status == "undecided" and res.stats["reason"] == "time limit"
    assert res.stats["widest_slab"] < 0.4  # the partition was refined ...
    # ... but D is r·π/4 at least (r >= L/2), where the refined partition's would be r·π/8 <= 0.71·(L/2)·π/4
    half = float(sc.robot[0].polygon[:, 0].max())
    assert res.stats["resolution"] >= half * math.pi / 4 and stated(res) >= half * math.pi / 4 * 0.999
    monkeypatch.setattr(exact._Search, "_split", split)
    res = from_scenario(sc, time_limit=-1.0)  # no time: no FREE graph searched
    assert res.status == "undecided" and res.resolution == math.inf
    assert "no statement" in res.stats["statement"]


def test_a_statement_with_disks_names_the_setting_that_narrows_them():
    from conftest import load_script

    sc = load_script("se2_families").pillars(0)  # the room (0.004) is below the disks' polygon error (0.017)
    res = from_scenario(sc, refine=False)
    assert res.status == "undecided" and "disks' polygon error" in res.stats["statement"]
    assert "a smaller disk_tolerance" in res.stats["statement"]
    res = from_scenario(rail(1e-3), refine=False)  # no disk: not said
    assert res.status != "undecided" or "disk_tolerance" not in res.stats["statement"]
