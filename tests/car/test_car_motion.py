"""Certified car motions (cspace.car.motion): never a false "free" along a curve.

The judge is independent of cspace: scripts/sweep_oracle.py places the robot with
shapely along each segment (translation for straight segments, shapely's rotation
about the turning centre for arcs) and checks the hulls of consecutive placements.
"""
import math
from types import SimpleNamespace

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from conftest import load_script
from cspace.car.curves import advance, knots
from cspace.car.motion import CarCSpace

oracle = load_script("sweep_oracle")

CAR = [[-0.3, -0.25], [0.9, -0.25], [0.9, 0.25], [-0.3, 0.25]]


class _Shape:
    def __init__(self, poly):
        self.polygon = np.asarray(poly, dtype=np.float64)

    def to_shapely(self):
        return shapely.Polygon(self.polygon)


def _scene(obstacles, robot=CAR, bounds=(0, 12, 0, 12)):
    """The C-space, and the plain scene the oracle reads (bounds, robot, obstacles)."""
    obstacles = [shapely.geometry.polygon.orient(shapely.Polygon(o)).exterior.coords[:-1] for o in obstacles]
    sc = SimpleNamespace(bounds=bounds, robot=[_Shape(robot)], obstacles=[_Shape(o) for o in obstacles])
    cs = CarCSpace(bounds, [o.polygon for o in sc.obstacles], [sc.robot[0].polygon], slabs=16)
    return sc, cs


def _placements_hit(sc, q0, segs, radius, dangle=1e-3):
    """Does a sampled placement of the robot along the curve meet an obstacle (shapely)?"""
    obstacles = shapely.union_all([o.to_shapely() for o in sc.obstacles])
    piece = shapely.Polygon(sc.robot[0].polygon)
    pose = q0
    for kind, length in segs:
        places, pose, _ = oracle.car_segment_placements(piece, pose, kind, length, radius, dangle, 1e-3)
        if any(obstacles.intersects(p) for p in places):
            return True
    return False


# Random obstacles: small triangles and thin walls scattered over the scene.
_tri = st.tuples(st.floats(1, 11), st.floats(1, 11), st.floats(0.05, 1.5), st.floats(0, 6.28))


def _triangle(cx, cy, r, a):
    return [[cx + r * math.cos(a + k * 2.0944), cy + r * math.sin(a + k * 2.0944)] for k in range(3)]


_seg = st.tuples(st.sampled_from("LSR"), st.floats(-4, 4).filter(lambda v: abs(v) > 1e-3))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(_tri, min_size=1, max_size=5), st.tuples(st.floats(3, 9), st.floats(3, 9), st.floats(-3.1, 3.1)),
       st.lists(_seg, min_size=1, max_size=3), st.floats(0.5, 3))
# A chain turning 12 rad (ends at an unwrapped angle): the oracle once joined its end to that
# angle by spinning two turns in place and called a free curve colliding.
@example([(4.0, 2.0, 1.5, 0.0)], (5.5, 3.0, -1.0), [("L", -2.0), ("L", -4.0)], 0.5)
@pytest.mark.slow
def test_curve_free_never_accepts_a_colliding_curve(tris, q0, segs, radius):
    sc, cs = _scene([_triangle(*t) for t in tris])
    ok = cs.curve_free(q0, segs, radius)
    if ok:
        assert not _placements_hit(sc, q0, segs, radius)
        judged = oracle.car_sweep_check(sc, np.array([q0, knots(q0, segs, radius)[-1]]),
                                        lambda a, b: segs, radius)
        assert not judged["collides"], judged


def test_curve_free_accepts_free_curves_and_counts():
    sc, cs = _scene([[[5, 5], [7, 5], [7, 7], [5, 7]]])
    assert cs.curve_free((2, 2, 0), [("L", math.pi / 2), ("S", 5), ("R", 2.0)], 1.0)
    assert cs.curve_free((2, 2, 0), [("S", -1.0), ("R", -2.0)], 1.0)  # reverse gears
    c = cs.report()["checks"]
    assert c["curves"] == 2 and c["arcs"] == 3 and c["motion_floor"] == 0


@pytest.mark.parametrize("where", [0.2, 0.45, 0.7])
def test_a_thin_wall_across_an_arc_is_never_driven_through(where):
    """A wall 1e-6 thick across the arc's path, at several places along a quarter turn."""
    radius = 3.0
    q0 = (2.0, 2.0, 0.0)
    # The reference point turns about (2, 5); put a thin radial wall across the arc.
    a = -math.pi / 2 + where * math.pi / 2
    cx, cy = 2.0, 5.0
    inner, outer = radius - 0.4, radius + 0.4
    d = np.array([math.cos(a), math.sin(a)])
    n = np.array([-d[1], d[0]]) * 0.5e-6
    wall = [[cx + inner * d[0] - n[0], cy + inner * d[1] - n[1]],
            [cx + outer * d[0] - n[0], cy + outer * d[1] - n[1]],
            [cx + outer * d[0] + n[0], cy + outer * d[1] + n[1]],
            [cx + inner * d[0] + n[0], cy + inner * d[1] + n[1]]]
    sc, cs = _scene([wall])
    segs = [("L", radius * math.pi / 2)]
    assert _placements_hit(sc, q0, segs, radius)  # the oracle sees it
    assert not cs.curve_free(q0, segs, radius)
    # The same arc with the wall moved off its path is free.
    sc2, cs2 = _scene([[[p[0] + 6, p[1]] for p in wall]])
    assert cs2.curve_free(q0, segs, radius)


def test_a_car_grazing_a_wall_on_an_arc_is_refined_not_rejected():
    """A wall just outside the swept region of an arc: the first hulls meet it (their
    excess over the arc), halving certifies the arc."""
    radius = 2.0
    q0 = (4.0, 2.0, 0.0)  # turns left about (4, 4): the car's outer corner reaches radius ~ sqrt(2.25^2 + 0.9^2)
    far = math.hypot(radius + 0.25, 0.9)
    sc, cs = _scene([[[4 + far + 0.002, 3.0], [4 + far + 0.2, 3.0], [4 + far + 0.2, 5.0], [4 + far + 0.002, 5.0]]])
    segs = [("L", radius * math.pi / 2)]
    assert cs.curve_free(q0, segs, radius)
    assert cs.report()["checks"]["arc_sweeps"] > 4  # refined
    assert not _placements_hit(sc, q0, segs, radius)


def test_an_arc_leaving_the_bounds_is_not_free():
    sc, cs = _scene([], bounds=(0, 6, 0, 6))
    # Left turn about (3, 5) with radius 2: the reference point reaches y = 7 > 6.
    assert not cs.curve_free((3.0, 3.0, 0.0), [("L", 2 * math.pi)], 2.0)
    assert cs.curve_free((3.0, 3.0, 0.0), [("L", 0.5)], 2.0)


def test_curve_end_is_joined_to_the_goal_pose():
    sc, cs = _scene([])
    end = knots((2.0, 2.0, 0.0), [("L", 1.0), ("S", 1.0)], 1.0)[-1]
    assert cs.curve_free((2.0, 2.0, 0.0), [("L", 1.0), ("S", 1.0)], 1.0, q1=end)
    assert advance((0.0, 0.0, 0.0), "R", math.pi, 1.0)[1] == pytest.approx(-2.0)
