"""Bench-MR's results format and `cspace recheck` (issue 50, points 3 and 4): our plans written in
it and read back, anyone's paths re-checked exactly, hostile files refused in one line.

Oracles: scenes built so the answer is known (a thin wall between two free waypoints: the
straight motion crosses it; a path around it: free), shapely placements of the robot at each
of the 500 interpolated states Bench-MR's "path collides" samples (all free, yet the motion
crosses the wall), and the round trip of our own certified paths (never colliding).
"""
from __future__ import annotations

import json
import os

import numpy as np
import pytest
import shapely
from shapely import affinity

from conftest import ROOT
from planners.cli import main

WALL = [[48.9, -5.0], [49.1, -5.0], [49.1, 5.0], [48.9, 5.0]]  # 0.2 wide, 10 tall, between two samples
BOX = [[-0.5, -0.25], [0.5, -0.25], [0.5, 0.25], [-0.5, 0.25]]


def results(path, steering="linear", radius=None, collides=False) -> dict:
    return {"settings": {"env": {"collision": {"collision_model": 1, "robot_shape": BOX}},
                         "steer": {"car_turning_radius": radius}, "steering": steering},
            "runs": [{"environment": {"type": "polygon", "obstacles": [WALL, [[0, 20], [100, 20], [100, 21], [0, 21]]]},
                      "plans": {"peer": {"path": path, "stats": {"path_found": True, "path_collides": collides}}}}]}


def write(tmp_path, doc, name="r.json") -> str:
    f = tmp_path / name
    f.write_text(json.dumps(doc) if not isinstance(doc, str) else doc)
    return str(f)


def test_a_motion_across_a_thin_wall_is_caught_though_500_samples_miss_it(tmp_path, capsys):
    pytest.importorskip("ompl")
    from planners.bench.benchmr import interpolated

    path = [[0.0, 0.0, 0.0], [1000.0, 0.0, 0.0]]
    # Bench-MR's check: the robot at each of the 500 interpolated states (2.0 apart) misses the wall
    states = interpolated(np.array(path), "se2", None, (-10, 1010, -10, 30))
    wall = shapely.Polygon(WALL)
    body = shapely.Polygon(BOX)
    assert len(states) == 500 and not any(
        affinity.translate(affinity.rotate(body, s[2], origin=(0, 0), use_radians=True), s[0], s[1]).intersects(wall)
        for s in states)
    f = write(tmp_path, results(path))
    code = main(["recheck", f, "--json", str(tmp_path / "o.json")])
    out = capsys.readouterr().out
    assert code == 1 and "peer: 1 paths, 1 called collision-free, 1 collide (1 of those called free)" in out
    assert json.loads((tmp_path / "o.json").read_text())["paths"][0]["first_colliding"] == [0.0, 0.0, 0.0]


def test_a_path_around_the_wall_is_free(tmp_path, capsys):
    f = write(tmp_path, results([[0.0, 0.0, 0.0], [40.0, 0.0, 0.0], [40.0, 10.0, 0.0], [60.0, 10.0, 0.0],
                                 [60.0, 0.0, 0.0]]))
    assert main(["recheck", f]) == 0 and "0 collide" in capsys.readouterr().out


def test_a_closed_pipe_still_gets_the_json(tmp_path):
    # `cspace recheck results.json --json o.json | head -1`, the reader gone before the first line:
    # the JSON is written all the same, then 141, quietly
    import subprocess
    import sys

    f = write(tmp_path, results([[0.0, 0.0, 0.0], [40.0, 0.0, 0.0], [40.0, 10.0, 0.0], [60.0, 10.0, 0.0]]))
    r, w = os.pipe()
    os.close(r)
    try:
        p = subprocess.run([sys.executable, "-m", "planners.cli", "recheck", f, "--json", str(tmp_path / "o.json")],
                           cwd=ROOT, stdout=w, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(w)
    assert p.returncode == 141 and p.stderr == "", p.stderr
    assert len(json.loads((tmp_path / "o.json").read_text())["paths"]) == 1


def test_reeds_shepp_curves_between_waypoints_are_checked(tmp_path, capsys):
    # the two poses face away from each other across the wall's end: the shortest curve swings through it
    doc = results([[49.0, 6.5, np.pi], [51.0, 6.5, 0.0]], "reeds_shepp", 2.0)
    doc["runs"][0]["environment"]["obstacles"][0] = [[49.9, -5.0], [50.1, -5.0], [50.1, 8.0], [49.9, 8.0]]
    assert main(["recheck", write(tmp_path, doc)]) == 1
    assert "1 collide" in capsys.readouterr().out


def test_our_plans_round_trip_through_the_format(tmp_path, capsys):
    pytest.importorskip("ompl")
    out = tmp_path / "bm.json"
    code = main(["plan", os.path.join(ROOT, "scenarios", "basic.toml"), "--bench-mr-json", str(out)])
    assert code == 0
    doc = json.loads(out.read_text())
    plan = next(iter(doc["runs"][0]["plans"].values()))
    assert plan["stats"]["path_found"] and len(plan["trajectory"]) == 500
    assert set(plan["stats"]) >= {"path_length", "max_curvature", "normalized_curvature", "aol", "cusps",
                                  "planning_time", "exact_goal_path", "path_collides"}
    capsys.readouterr()
    assert main(["recheck", str(out)]) == 0 and "1 called collision-free, 0 collide" in capsys.readouterr().out


HOSTILE = {
    "not json": ("{runs: oops", "not a JSON"),
    "no runs": ({"settings": {}}, "runs"),
    "nan obstacle": ({"settings": {"env": {"collision": {"robot_shape": BOX}}}, "runs": [
        {"environment": {"obstacles": [[[0, 0], [1, float("nan")], [1, 1]]]},
         "plans": {"p": {"path": [[0, 0, 0], [1, 1, 0]], "stats": {"path_found": True}}}}]}, "obstacles[0]"),
    "grid": ({"settings": {"env": {"collision": {"robot_shape": BOX}}}, "runs": [{"environment": {"type": "grid"},
                                                                             "plans": {}}]}, "only polygon"),
    "no radius": ({"settings": {"steering": "dubins", "env": {"collision": {"robot_shape": BOX}}}, "runs": []},
                  "car_turning_radius"),
    "bad path": ({"settings": {"env": {"collision": {"robot_shape": BOX}}}, "runs": [
        {"environment": {"obstacles": [WALL]}, "plans": {"p": {"path": [[0, 0]], "stats": {"path_found": True}}}}]},
        "path"),
}


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_results_get_one_line_and_exit_2(tmp_path, capsys, name):
    doc, words = HOSTILE[name]
    f = write(tmp_path, doc)
    code = main(["recheck", f])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and words in err[0], err


def test_runs_of_one_world_share_a_c_space_and_keep_their_verdicts(tmp_path, monkeypatch):
    """A results file repeats its world in every run: one C-space per distinct environment (1 000
    trajectories took 8.5 s, 125 builds; now 0.2 s), its bounds holding every run's paths, and
    each run's verdict the same as with a C-space of its own (a later run's path far outside the
    first run's box still meets the wall)."""
    import cspace.car.motion as motion
    from planners.bench.benchmr_results import recheck

    free = [[0.0, 0.0, 0.0], [40.0, 0.0, 0.0], [40.0, 10.0, 0.0], [60.0, 10.0, 0.0], [60.0, 0.0, 0.0]]
    far = [[0.0, -300.0, 0.0], [48.0, -300.0, 0.0], [48.0, 0.0, 0.0], [52.0, 0.0, 0.0]]  # ends across the wall
    doc = results(free)
    other = {"environment": {"type": "polygon", "obstacles": [WALL]}, "plans": {"peer": {"path": free, "stats": {
        "path_found": True, "path_collides": False}}}}
    doc["runs"] += [json.loads(json.dumps(doc["runs"][0])) for _ in range(3)] + [other]
    doc["runs"][2]["plans"]["peer"]["path"] = far
    built = []
    real = motion.CarCSpace.__init__
    monkeypatch.setattr(motion.CarCSpace, "__init__", lambda self, *a, **k: built.append(a[0]) or real(self, *a, **k))
    rows = recheck(doc, "r.json")
    assert [r["colliding"] for r in rows] == [0, 0, 1, 0, 0]
    assert len(built) == 2 and built[0][2] <= -300.0  # two worlds; the first one's bounds hold the far path
    alone = [recheck({**doc, "runs": [run]}, "r.json")[0]["colliding"] for run in doc["runs"]]
    assert alone == [0, 0, 1, 0, 0]
