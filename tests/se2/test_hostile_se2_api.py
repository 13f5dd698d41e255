"""Hostile inputs to the SE(2) C-space's public queries and to the car curves (issue 36, items 5 and 6).

``is_free``, ``motion_free`` and ``curve_free`` answer a bool or raise ValueError/TypeError,
on the compiled and the pure path alike; the car curves take extreme radii and headings; a
scenario's turning radius and a rotating robot's size are bounded (one line, exit 2); and a
huge rotating robot never runs past ``--time``.
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from cspace.io.load import ScenarioError, load_scenario
from cspace.io.scenario.schema import MAX_ROTATING_VERTICES
from cspace.compiled import fastpath
from cspace.car.curves import curve_length, dubins_segments, reeds_shepp_segments
from cspace.car.motion import CarCSpace
from cspace.se2.cspace import SE2CSpace

SQ = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
BOX = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])


def _space():
    return CarCSpace((0, 10, 0, 10), [SQ], [BOX], slabs=16)


def _spaces():
    """The same C-space on the compiled path (when built) and on the pure path."""
    out = [("compiled" if fastpath.compiled() else "pure", _space())]
    with fastpath.disabled():
        cs = _space()
        for k in range(cs.slabs):  # an SE(2) C-space's slabs keep the path they are built on
            cs.slab(k)
        out.append(("pure", cs))
    return out


SPACES = _spaces()

junk_number = st.one_of(
    st.just(math.nan), st.just(math.inf), st.just(-math.inf), st.just(1e308), st.just(-1e300), st.just(5e-324),
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**400, 10**400), st.text(max_size=4),
    st.none(), st.just([1.0]), st.just({"x": 1}), st.just(b"1"), st.just(1 + 2j), st.booleans())
junk_pose = st.one_of(
    st.lists(junk_number, max_size=6), st.tuples(junk_number, junk_number, junk_number),
    st.tuples(st.floats(0, 10), st.floats(0, 10), junk_number),
    st.text(max_size=6), st.none(), st.integers(), st.floats(allow_nan=True),
    st.lists(st.lists(st.floats(0, 10), max_size=3), max_size=3),
    st.sampled_from([np.zeros((3, 1)), np.zeros((1, 3)), np.zeros(4), np.zeros(2), np.array(["1", "2", "3"]),
                     np.array([1, 2, 3], dtype=object), np.array([1.0, np.nan, 0]), np.zeros(0),
                     np.array([1 + 0j, 2, 3]), np.float64(3.0), {"x": 1, "y": 2, "theta": 0}]))
good_pose = st.tuples(st.floats(0.5, 9.5), st.floats(0.5, 9.5), st.floats(-4, 4))
junk_segments = st.one_of(
    st.lists(st.tuples(st.sampled_from(["L", "S", "R", "X", "", 1, None]), junk_number), max_size=4),
    st.lists(junk_number, max_size=3), st.text(max_size=4), st.none(), st.integers(),
    st.just([("L", 1e300)]), st.just([("S", 1e300)]), st.just([("R", -1e15)]), st.just([("L", math.nan)]))
junk_radius = st.one_of(junk_number, st.floats(1e-12, 1e12), st.just(0.0), st.just(-1.0))


def _only_bool_or_fault(f, *args):
    try:
        got = f(*args)
    except (ValueError, TypeError):
        return None
    assert isinstance(got, bool)
    return got


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(junk_pose, good_pose)
def test_junk_poses_are_a_bool_or_a_value_or_type_error(q, good):
    for _, cs in SPACES:
        _only_bool_or_fault(cs.is_free, q)
        _only_bool_or_fault(cs.motion_free, q, good)
        _only_bool_or_fault(cs.motion_free, good, q)
        _only_bool_or_fault(cs.curve_free, q, [("S", 1.0)], 1.0)
        _only_bool_or_fault(cs.curve_free, good, [("S", 1.0)], 1.0, q)


@settings(max_examples=100, deadline=None, suppress_health_check=list(HealthCheck))
@given(good_pose, junk_segments, junk_radius)
def test_junk_curves_are_a_bool_or_a_value_or_type_error(q, segments, radius):
    for _, cs in SPACES:
        t = time.perf_counter()
        _only_bool_or_fault(cs.curve_free, q, segments, radius)
        assert time.perf_counter() - t < 5.0  # never an unbounded sweep


@pytest.mark.parametrize("path,cs", SPACES, ids=[p for p, _ in SPACES])
@pytest.mark.parametrize("bad", [(1.0, math.nan, 0.0), (math.inf, 1.0, 0.0), (1.0, 1.0, -math.inf)])
def test_non_finite_poses_raise_value_error(path, cs, bad):
    with pytest.raises(ValueError, match="finite"):
        cs.is_free(bad)
    with pytest.raises(ValueError, match="q0: .*finite"):
        cs.motion_free(bad, (1, 1, 0))
    with pytest.raises(ValueError, match="q0: .*finite"):
        cs.curve_free(bad, [("S", 1.0)], 1.0)


@pytest.mark.parametrize("path,cs", SPACES, ids=[p for p, _ in SPACES])
def test_malformed_poses_name_the_argument(path, cs):
    with pytest.raises(ValueError, match="three numbers"):
        cs.is_free((1.0, 1.0, 0.0, 0.0))  # four numbers were once accepted
    with pytest.raises(TypeError, match="q: "):
        cs.is_free("1.0")
    with pytest.raises(TypeError, match="q1: "):
        cs.motion_free((1, 1, 0), (1, "2", 0))
    with pytest.raises(ValueError, match="shape"):
        cs.is_free(np.zeros((3, 1)))
    assert cs.is_free(np.array([1.0, 1.0, 0.0])) is True and cs.is_free((5, 5, 0)) is False


@pytest.mark.parametrize("path,cs", SPACES, ids=[p for p, _ in SPACES])
def test_unbounded_segments_are_refused_before_any_work(path, cs):
    t = time.perf_counter()
    with pytest.raises(ValueError, match="segments\\[0\\]"):
        cs.curve_free((2, 2, 0), [("L", 1e300)], 1.0)
    with pytest.raises(ValueError, match="full turns"):
        cs.curve_free((2, 2, 0), [("L", 65 * 2 * math.pi)], 1.0)
    with pytest.raises(ValueError, match="radius"):
        cs.curve_free((2, 2, 0), [("S", 1.0)], 1e-200)
    assert time.perf_counter() - t < 1.0
    assert cs.curve_free((2, 2, 0), [("L", 2 * math.pi)], 0.5) is True  # a full turn in free space


def test_a_robot_of_fewer_than_three_points_is_refused():
    with pytest.raises(ValueError, match="robot\\[0\\].*3"):
        SE2CSpace((0, 10, 0, 10), [SQ], [np.array([[0., 0], [1, 0]])])
    with pytest.raises(ValueError, match="robot\\[0\\]"):
        SE2CSpace((0, 10, 0, 10), [SQ], [np.array([0., 1, 2])])


def test_a_rotating_robot_beyond_the_vertex_limit_is_refused():
    a = np.linspace(0, 2 * math.pi, MAX_ROTATING_VERTICES + 1, endpoint=False)
    disk = np.column_stack([np.cos(a), np.sin(a)])
    t = time.perf_counter()
    with pytest.raises(ValueError, match=f"at most {MAX_ROTATING_VERTICES}"):
        SE2CSpace((0, 20, 0, 20), [SQ], [disk], robot_is_disk=True)
    assert time.perf_counter() - t < 1.0
    SE2CSpace((0, 20, 0, 20), [SQ], [disk[:-1]], robot_is_disk=True)  # at the limit: taken


# -- the car curves: extreme but valid radii and headings -------------------------------------

@settings(max_examples=200, deadline=None)
@example((0.0, 0.0, 0.0), (0.0, 7.493799904722312e-178, 1.0350308004348528e-270), 8.337909262997433e-101)
@given(st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3), st.floats(-1e18, 1e18)),
       st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3), st.floats(-1e18, 1e18)),
       st.one_of(st.floats(5e-324, 1e-100), st.floats(1e-9, 1e9), st.floats(1e100, 1.7e308)))
def test_car_curves_take_extreme_radii_and_headings(q0, q1, r):
    for f in (dubins_segments, reeds_shepp_segments):
        try:
            segs = f(q0, q1, r)
        except ValueError as exc:
            assert "radius" in str(exc)
            continue
        assert all(k in "LSR" and math.isfinite(v) for k, v in segs)
        d = math.hypot(q1[0] - q0[0], q1[1] - q0[1])
        assert curve_length(segs) >= d * (1 - 1e-9) - 1e-9 * r  # at least the straight line
        # two poses of other headings are never joined by nothing, unless OMPL's near-coincident
        # rule applies: under 1e-6 radii apart with headings within 1e-6 (one straight step along
        # the heading, nothing when that step is 0)
        near = d < 1e-6 * r and abs(math.remainder(q1[2] - q0[2], 2 * math.pi)) < 1e-6
        if q0[:2] != q1[:2] and math.sin(q0[2] - q1[2]) != 0.0 and not near:
            assert segs


def test_a_huge_goal_heading_is_wrapped():
    big = 1e17
    wrapped = math.remainder(big, 2 * math.pi)
    for f in (dubins_segments, reeds_shepp_segments):
        got = f((0.0, 0.0, 0.0), (4.0, 0.0, big), 1.0)
        want = f((0.0, 0.0, 0.0), (4.0, 0.0, wrapped), 1.0)
        assert [k for k, _ in got] == [k for k, _ in want] and len(got) == 3
        assert np.allclose([v for _, v in got], [v for _, v in want], rtol=1e-6, atol=1e-6)


# -- scenarios: turning radius range, robot size, time limit ----------------------------------

CAR = """space = "{space}"
turning_radius = {r}
[bounds]
xmin = 0.0
xmax = 10.0
ymin = 0.0
ymax = 10.0
[robot]
polygon = [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]
[start]
x = 1.0
y = 1.0
[goal]
x = 8.0
y = 1.0
"""


@pytest.mark.parametrize("r", ["1e-308", "5e-324", "1e-200", "1e-9", "1e11", "1e300"])
@pytest.mark.parametrize("space", ["dubins", "reeds-shepp"])
def test_turning_radius_outside_the_scene_range_is_refused(tmp_path, r, space):
    f = tmp_path / "car.toml"
    f.write_text(CAR.format(space=space, r=r))
    with pytest.raises(ScenarioError, match="turning_radius: .*(outside|beyond)"):
        load_scenario(str(f))
    f.write_text(CAR.format(space=space, r="1e-8"))  # 1e-9 of the extent 10: in range
    assert load_scenario(str(f)).turning_radius == 1e-8


def _cli(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "planners", *args], capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ))


def test_turning_radius_1e_200_is_one_line_exit_2(tmp_path):
    f = tmp_path / "car.toml"
    f.write_text(CAR.format(space="dubins", r="1e-200"))
    p = _cli("plan", str(f), "--time", "1")
    assert p.returncode == 2, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and "turning_radius" in p.stderr


DISK = """name = "big-disk"
space = "se2"
disk_tolerance = {tol}
[bounds]
xmin = 0.0
xmax = 20.0
ymin = 0.0
ymax = 20.0
[robot]
radius = 1.0
[[obstacles]]
polygon = [[9, 0], [10, 0], [10, 8.5], [9, 8.5]]
[[obstacles]]
polygon = [[9, 11.5], [10, 11.5], [10, 20], [9, 20]]
[[obstacles]]
polygon = [[3, 3], [5, 3], [4, 5]]
[start]
x = 2.0
y = 10.0
[goal]
x = 17.0
y = 10.0
"""


def test_a_7025_gon_robot_keeps_the_time_limit(tmp_path):
    """Issue 36 item 5: the 7 025-gon disk (disk_tolerance 1e-7) ran 38 s with --time 2."""
    f = tmp_path / "disk.toml"
    f.write_text(DISK.format(tol="1e-7"))
    t = time.perf_counter()
    p = _cli("plan", str(f), "--time", "2")
    assert time.perf_counter() - t < 10.0
    assert p.returncode in (1, 2), (p.returncode, p.stderr)
    assert len(p.stderr.strip().splitlines()) == 1 and "7025 vertices" in p.stderr and "disk_tolerance" in p.stderr


@pytest.mark.slow
def test_the_cspace_build_counts_against_the_time_limit(tmp_path):
    """A robot within the vertex limit whose slabs take longer than --time: not solved, saying so."""
    f = tmp_path / "disk.toml"
    f.write_text(DISK.format(tol="1e-4"))  # a 223-gon: its slabs take a good part of a second
    t = time.perf_counter()
    p = _cli("plan", str(f), "--time", "0.05")
    assert time.perf_counter() - t < 10.0
    assert p.returncode == 1, (p.returncode, p.stderr)
    assert "not solved within the time limit (C-space build took" in p.stdout


@pytest.mark.parametrize("r", ["1e-8", "1e10"])  # the ends of the range for the extent 10
@pytest.mark.parametrize("space", ["dubins", "reeds-shepp"])
def test_a_free_straight_motion_is_solved_at_the_ends_of_the_radius_range(tmp_path, r, space):
    import planners

    f = tmp_path / "car.toml"
    f.write_text(CAR.format(space=space, r=r))
    res = planners.plan(str(f), planner="RRTConnect", time=2.0)
    assert res.solved, res.message
    assert res.length == pytest.approx(7.0)
