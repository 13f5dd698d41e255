"""Planning car-like robots (Dubins, Reeds–Shepp) end to end: scenes, CLI, API, pictures.

Every path is judged by an independent shapely sweep along its curves
(scripts/sweep_oracle.py: shapely's own rotation about each turning centre), not by the
C-space that certified it.
"""
import glob
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import planners
from conftest import ROOT, SCENARIOS, load_script
from cspace.car.curves import curve_length, dubins_segments, reeds_shepp_segments
from cspace.io.load import ScenarioError, load_scenario

CARS = sorted(glob.glob(os.path.join(SCENARIOS, "car", "*.toml")))
oracle = load_script("sweep_oracle")


def cli(*args):
    return subprocess.run([sys.executable, "-m", "planners.cli", *args], capture_output=True, text=True,
                          cwd=ROOT, timeout=300)


def _segments_of(sc):
    f = dubins_segments if sc.space == "dubins" else reeds_shepp_segments
    return lambda a, b: f(a, b, sc.turning_radius)


def judge(sc, res):
    """The independent checks of a solved car plan."""
    p = res.path
    assert p.shape[1] == 3
    assert tuple(p[0]) == tuple(sc.start) and tuple(p[-1]) == tuple(sc.goal)
    judged = oracle.car_sweep_check(sc, p, _segments_of(sc), sc.turning_radius)
    assert not judged["collides"] and not judged["out_of_bounds"], judged
    # Each curve ends at its target pose (within its computation's rounding; the gap, if
    # any, is a straight SE(2) motion that the oracle sweeps too).
    assert judged["end_gap"] < 1e-5 * sc.turning_radius, judged
    # The length is the distance driven along the curves, as OMPL's metric of the space.
    driven = sum(curve_length(_segments_of(sc)(tuple(a), tuple(b))) for a, b in zip(p[:-1], p[1:]))
    assert res.length == pytest.approx(driven, rel=1e-12)
    assert res.length >= float(np.hypot(*np.diff(p[:, :2], axis=0).T).sum()) * (1 - 1e-12)
    # The JSON's curves describe the same motions.
    assert len(res.curves) == len(p) - 1
    total = sum(s["length"] for c in res.curves for s in c["segments"])
    assert total == pytest.approx(res.length, rel=1e-12)
    if sc.space == "dubins":
        assert all(s["direction"] == "forward" for c in res.curves for s in c["segments"])


@pytest.mark.slow
@pytest.mark.parametrize("path", CARS, ids=os.path.basename)
def test_bundled_car_scene_plans_with_its_defaults(path):
    sc = load_scenario(path)
    res = planners.plan(sc)
    if sc.expect == "unsolvable":  # a claim with a proof, made before sampling
        assert not res.solved and res.path.shape[0] == 0 and res.message.startswith("proven unsolvable"), res.message
        return
    assert res.solved, res.message
    judge(sc, res)


def test_parking_uses_reverse_gear():
    """Reeds–Shepp parks with at least one reverse segment. (Forward only, the planners find no
    way in; a failure is not a proof that none exists, so no test claims one: issue 39.13.)"""
    f = os.path.join(SCENARIOS, "car", "parking.toml")
    res = planners.plan(f, seed=1)
    assert res.solved, res.message
    assert any(s["direction"] == "reverse" for c in res.curves for s in c["segments"])


def test_the_car_oracle_sees_a_collision():
    """The judge is not blind: driving straight into the parked car collides."""
    sc = load_scenario(os.path.join(SCENARIOS, "car", "parking.toml"))
    bad = np.array([[1.0, 0.55, 0.0], [4.45, 0.55, 0.0]])
    assert oracle.car_sweep_check(sc, bad, _segments_of(sc), sc.turning_radius)["collides"]


def test_same_seed_same_path():
    f = os.path.join(SCENARIOS, "car", "maze.toml")
    a, b = planners.plan(f, seed=4), planners.plan(f, seed=4)
    assert a.solved and b.solved and np.array_equal(a.path, b.path)


@pytest.mark.slow
def test_cli_writes_curves_plot_and_animation(tmp_path):
    out = tmp_path / "r.json"
    r = cli("plan", os.path.join(SCENARIOS, "car", "u_turn.toml"), "--json", str(out),
            "--plot", str(tmp_path / "p.png"), "--animate", str(tmp_path / "a.gif"), "--seed", "2")
    assert r.returncode == 0, r.stderr
    d = json.loads(out.read_text())
    assert d["solved"] and d["curves"]
    kinds = {s["type"] for c in d["curves"] for s in c["segments"]}
    assert kinds <= {"left", "straight", "right"}
    assert (tmp_path / "p.png").stat().st_size > 0
    assert (tmp_path / "a.gif").read_bytes()[:6] in (b"GIF89a", b"GIF87a")


def test_cli_space_and_turning_radius_override(tmp_path):
    f = os.path.join(SCENARIOS, "se2", "car_maze.toml")
    r = cli("plan", f, "--space", "dubins", "--turning-radius", "1.0", "--time", "20")
    assert r.returncode in (0, 1) and "car-maze" in r.stdout, r.stderr
    r = cli("plan", f, "--space", "dubins")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "turning_radius" in r.stderr
    r = cli("plan", f, "--space", "reeds-shepp", "--turning-radius", "-1")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "positive" in r.stderr
    r = cli("plan", f, "--turning-radius", "1")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "dubins" in r.stderr


@pytest.mark.parametrize("text, fault", [
    ('space = "dubins"\n', "turning_radius: is required"),
    ('space = "reeds-shepp"\nturning_radius = 0\n', "turning_radius: must be positive"),
    ('space = "reeds-shepp"\nturning_radius = "big"\n', "turning_radius: must be a number"),
    ('space = "se2"\nturning_radius = 1.0\n', "turning_radius: applies to"),
    ('turning_radius = 1.0\n', "turning_radius: applies to"),
])
def test_bad_turning_radius_is_one_line(tmp_path, text, fault):
    f = tmp_path / "s.toml"
    f.write_text(text + "[bounds]\nxmin=0\nxmax=4\nymin=0\nymax=4\n[start]\nx=1\ny=1\n[goal]\nx=3\ny=3\n")
    with pytest.raises(ScenarioError) as e:
        load_scenario(str(f))
    assert fault in str(e.value)
    r = cli("plan", str(f))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and fault in r.stderr


def test_exact_planner_refuses_a_car_in_one_line():
    r = cli("plan", os.path.join(SCENARIOS, "car", "maze.toml"), "--planner", "exact")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and 'space = "dubins"' in r.stderr


def test_a_car_path_is_drawn_along_its_curves():
    """The dense poses of the plot follow the arcs: each lies on the curve of its motion."""
    from planners.adapters.car import dense_curve

    sc = load_scenario(os.path.join(SCENARIOS, "car", "maze.toml"))
    res = planners.plan(sc, seed=0)
    poses, rev = dense_curve(res.path, sc.space, sc.turning_radius, step=0.05)
    assert not rev.any()  # Dubins drives forward only
    steps = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    assert steps.max() <= 0.05 * (1 + 1e-9)
    assert steps.sum() == pytest.approx(res.length, rel=1e-3)  # chords of an arc: a hair shorter
    assert math.isclose(poses[-1, 0], sc.goal[0]) and math.isclose(poses[-1, 1], sc.goal[1])


def test_bench_car_runs_and_ours_accepts_no_colliding_motion():
    bench = load_script("bench_car")
    rows = bench.part_m(m=4)
    assert {r["scene"] for r in rows} == {load_scenario(f).name for f in CARS}
    for r in rows:
        assert r["accepted_colliding"]["ours"] == 0
        assert r["us_per_motion"]["ours"] > 0 and r["us_per_motion"]["discrete"] > 0


def test_a_failed_dubins_path_says_curves_are_one_way():
    """Planners that use motions both ways (PRM, ...) can return Dubins paths that fail the
    certified re-check; the message says why and which planners to use."""
    from planners.core.plan import make_adapter, build_cspace

    sc = load_scenario(os.path.join(SCENARIOS, "car", "maze.toml"))
    ad = make_adapter(sc, build_cspace(sc))
    through_wall = np.array([sc.start, (3.0, 8.5, 0.0), sc.goal])  # straight up through the wall at y = 5.5
    ok, msg = ad.verify(through_wall, sc.start, sc.goal)
    assert not ok and "one-way" in msg and "RRTConnect" in msg
    ok, msg = ad.verify(through_wall[::-1], sc.goal, sc.start)
    assert not ok


def test_a_car_path_reports_the_clearance_of_its_curves(tmp_path):
    """The SE(2) clearance bound follows OMPL's SE(2) interpolation, not a car's curves: a car's
    result carries the bound measured along its curves (cspace.car.clearance), not the
    SE(2) one between its waypoints (found in review: the adapter inherited it from the SE(2) one)."""
    from cspace.car.clearance import car_path_clearance
    from cspace.se2.clearance import se2_path_clearance

    res = planners.plan(os.path.join(SCENARIOS, "car", "maze.toml"), seed=0)
    assert res.solved and res.min_clearance_bound == "lower"
    cs = res.cspace
    r = res.scenario_data.turning_radius  # maze.toml: a Dubins car
    curves = car_path_clearance(res.path, lambda a, b: dubins_segments(a, b, r), r, cs.body_pieces,
                                cs.obstacle_pieces)
    assert res.min_clearance == curves.distance
    chords = se2_path_clearance(res.path, cs.body_pieces, cs.obstacle_pieces)
    assert res.min_clearance != chords.distance
    r = cli("plan", os.path.join(SCENARIOS, "car", "maze.toml"), "--objective", "clearance")
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "objective" in r.stderr
    r = cli("plan", os.path.join(SCENARIOS, "car", "maze.toml"))
    assert r.returncode == 0 and "min clearance " in r.stdout and "(a certified lower bound)" in r.stdout


def test_kept_curves_are_the_computed_curves():
    """CarSpace keeps the curves of the motions it was asked about: a kept curve is the one
    car_curves computes, for the same pose pair only (a zero coordinate, equal to -0.0, is
    never a key), and a copy the caller may change."""
    from planners.core.plan import build_cspace, make_adapter

    for path in CARS:
        sc = load_scenario(path)
        adapter = make_adapter(sc, build_cspace(sc))
        f = _segments_of(sc)
        rng = np.random.default_rng(5)
        xmin, xmax, ymin, ymax = sc.bounds
        poses = [(float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)), float(rng.uniform(-3, 3)))
                 for _ in range(40)]
        pairs = list(zip(poses[:-1], poses[1:]))
        pairs += [((1.0, 2.0, 0.0), (3.0, 2.0, -0.0)), ((1.0, 2.0, -0.0), (3.0, 2.0, 0.0)), (poses[0], poses[0])]
        for _ in range(2):  # the second time from the kept curves
            for a, b in pairs:
                got = adapter.segments(a, b)
                assert got == f(a, b)
                assert [math.copysign(1.0, v) for _, v in got] == [math.copysign(1.0, v) for _, v in f(a, b)]
                got.append(("S", 1.0))  # the caller's copy
        assert adapter.segments(np.array(poses[0]), np.array(poses[1])) == f(poses[0], poses[1])


def test_a_car_plan_counts_its_curves_as_motions():
    """A car's motion check is a curve check: the plan's "motions" are the curves it asked about
    (planning and the final verification), not the short SE(2) joins inside them."""
    sc = load_scenario(os.path.join(SCENARIOS, "car", "loading_dock.toml"))
    from planners.core.plan import build_cspace

    cs = build_cspace(sc)
    before = cs.report()["checks"].get("curves", 0)
    res = planners.plan(sc, planner="RRTConnect", seed=2, time=10.0, cspace=cs)
    assert res.solved
    asked = cs.report()["checks"]["curves"] - before
    assert res.checks["motions"] == asked >= len(res.path) - 1


def test_a_car_samples_at_most_twenty_turning_radii_per_step_on_a_large_map():
    """OMPL's default range (a fifth of the space's extent: 28 m on a 100 m map) draws curves that
    almost always meet a rack or a wall: a car's planners step at most 20 turning radii there, and
    keep OMPL's own range on every bundled scene (smaller than about 100 radii)."""
    from cspace.io.load import scenario_from_dict
    from planners.adapters.glue import RANGE_FLOOR, RANGE_SHARE, make_setup
    from planners.core.plan import build_cspace, make_adapter

    box = [[-0.45, -0.31], [0.45, -0.31], [0.45, 0.31], [-0.45, 0.31]]
    data = {"space": "reeds-shepp", "turning_radius": 0.5, "bounds": {"xmin": 0, "xmax": 100, "ymin": 0, "ymax": 100},
            "robot": {"polygon": box}, "start": {"x": 5, "y": 5, "theta": 0}, "goal": {"x": 95, "y": 95, "theta": 1},
            "obstacles": [{"polygon": [[40, 40], [60, 40], [60, 60], [40, 60]]}]}
    for space in ("reeds-shepp", "dubins"):
        sc = scenario_from_dict(data, "<large>", space=space, turning_radius=0.5)
        adapter = make_adapter(sc, build_cspace(sc))
        ss = make_setup(adapter, "RRTConnect", 0)[0]
        got = math.ldexp(ss.getPlanner().getRange(), -adapter.k)
        assert got == pytest.approx(20 * 0.5, rel=1e-12)
        assert got < math.ldexp(RANGE_SHARE * ss.getSpaceInformation().getMaximumExtent(), -adapter.k)
        res = planners.plan(sc, planner="RRTConnect", seed=0, iterations=2000, time=30.0, simplify=False)
        assert res.solved and np.hypot(*np.diff(res.path[:, :2], axis=0).T).max() <= 10.0 * (1 + 1e-9) + 1e-9
    data["turning_radius"] = 2e-7  # a tiny radius: the bound stops at a quarter of OMPL's range (its
    sc = scenario_from_dict(data, "<large>", space="reeds-shepp", turning_radius=2e-7)  # connect walks in range steps
    ss = make_setup(make_adapter(sc, build_cspace(sc)), "RRTConnect", 0)[0]
    own = RANGE_SHARE * ss.getSpaceInformation().getMaximumExtent()
    assert ss.getPlanner().getRange() == pytest.approx(RANGE_FLOOR * own, rel=1e-12)
    for path in CARS:  # a small scene: the range OMPL's setup picks (unset before it)
        sc = load_scenario(path)
        ss = make_setup(make_adapter(sc, build_cspace(sc)), "RRTConnect", 0)[0]
        assert ss.getPlanner().getRange() == 0.0
