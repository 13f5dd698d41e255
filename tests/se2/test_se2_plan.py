"""Planning rotating robots end to end: scenes, the CLI, the API, pictures, determinism.

Every path is judged by an independent shapely sweep (scripts/sweep_oracle.py: the
robot's hull between poses 2e-3 rad apart, padded by the arc's sagitta), not by the
C-space that certified it.
"""
import glob
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import planners
from conftest import ROOT, SCENARIOS, load_script
from cspace.io.load import load_scenario

SE2 = sorted(glob.glob(os.path.join(SCENARIOS, "se2", "*.toml")))
oracle = load_script("sweep_oracle")


def cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "planners.cli", *args], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=300)


@pytest.mark.slow
@pytest.mark.parametrize("path", SE2, ids=os.path.basename)
def test_bundled_se2_scene_plans_with_its_defaults(path):
    sc = load_scenario(path)
    res = planners.plan(sc)
    if sc.expect == "unsolvable":
        assert not res.solved and res.message.startswith("proven unsolvable")
        return
    assert res.solved, res.message
    p = res.path
    assert p.shape[1] == 3
    assert tuple(p[0]) == sc.start and tuple(p[-1]) == sc.goal
    xmin, xmax, ymin, ymax = sc.bounds
    assert ((p[:, 0] >= xmin) & (p[:, 0] <= xmax) & (p[:, 1] >= ymin) & (p[:, 1] <= ymax)).all()
    judged = oracle.sweep_check(sc, p)
    assert not judged["collides"] and not judged["out_of_bounds"], judged
    # The length is the reference point's, at least the inscribed-disk lower bound.
    from planners.core.bounds import disk_bound

    db = disk_bound(sc, sc.all_queries()[0])
    assert db.lower_bound <= res.length * (1 + 1e-12)


def test_the_oracle_sees_a_collision():
    """The judge is not blind: a bar swept straight through a wall collides."""
    sc = load_scenario(os.path.join(SCENARIOS, "se2", "bar_door.toml"))
    bad = np.array([[4.0, 10.0, math.pi / 2], [16.0, 10.0, math.pi / 2]])
    assert oracle.sweep_check(sc, bad)["certain"]
    turning = np.array([[9.5, 10.0, 0.0], [9.5, 10.0, math.pi / 2]])  # turning inside the door
    assert oracle.sweep_check(sc, turning)["collides"]


def test_same_seed_same_path():
    f = os.path.join(SCENARIOS, "se2", "bar_door.toml")
    a = planners.plan(f, seed=3)
    b = planners.plan(f, seed=3)
    assert a.solved and b.solved and np.array_equal(a.path, b.path)


def test_translation_scene_planned_in_se2():
    """`--space se2` on a translation file: its theta becomes the pose angle of start and goal."""
    res = planners.plan(os.path.join(SCENARIOS, "theta.toml"), space="se2", time=20)
    assert res.solved and res.path.shape[1] == 3
    assert res.path[0, 2] == res.path[-1, 2] == pytest.approx(math.pi / 2, abs=0)


def test_exact_in_se2_proves_unsolvable_or_says_why_not(tmp_path):
    r = cli("plan", os.path.join(SCENARIOS, "se2", "wide_square.toml"), "--json", str(tmp_path / "r.json"))
    assert r.returncode == 1, r.stderr
    assert "proven unsolvable" in r.stdout
    r = cli("plan", os.path.join(SCENARIOS, "se2", "bar_door.toml"), "--planner", "exact")
    assert r.returncode == 0 and "solved by exact" in r.stdout, r.stdout + r.stderr  # the slab graph


@pytest.mark.slow
def test_plot_and_animation(tmp_path):
    from PIL import Image

    png, gif = tmp_path / "p.png", tmp_path / "a.gif"
    r = cli("plan", os.path.join(SCENARIOS, "se2", "bar_door.toml"), "--plot", str(png), "--animate", str(gif))
    assert r.returncode == 0, r.stderr
    assert png.stat().st_size > 10_000
    with Image.open(gif) as im:
        assert im.format == "GIF" and im.n_frames >= 20
        first = im.convert("RGB").tobytes()
        im.seek(im.n_frames - 1)
        last = im.convert("RGB").tobytes()
    assert first != last  # the robot moves
    assert r.stderr.count("\n") == 1 and r.stderr.startswith(f"animation: {gif} written ({im.n_frames} frames"), r.stderr


def test_an_animation_frame_is_the_scene_with_the_robot_at_its_pose(tmp_path):
    # the blitted frames (the scene drawn once, the robot over it) are what a full redraw of the same
    # frame gives: the background holds no robot, and each frame holds the robot where the path puts it
    import numpy as np
    from PIL import Image

    from planners.pictures.animate import animate_path

    res = planners.plan(os.path.join(SCENARIOS, "se2", "bar_door.toml"), seed=1)
    gif = tmp_path / "a.gif"
    assert animate_path(res, str(gif), frames=12, progress=False) == 12
    with Image.open(gif) as im:
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB"), dtype=int))
    green = [((f[..., 1] > f[..., 0] + 40) & (f[..., 1] > f[..., 2] + 20)).sum() for f in frames]
    assert min(green) > 50  # the robot (green) in every frame ...
    moved = [np.abs(frames[k] - frames[k + 1]).sum() for k in range(len(frames) - 1)]
    assert min(moved) > 0  # ... and it moves
    # no frame keeps the robot of another: frame k's green pixels lie around pose k only
    xs = [np.nonzero((f[..., 1] > f[..., 0] + 40) & (f[..., 1] > f[..., 2] + 20))[1] for f in frames]
    assert xs[0].max() < xs[-1].min()  # bar_door's path runs left to right: first and last robots apart


def test_show_draws_one_slab(tmp_path):
    out = tmp_path / "s.png"
    r = cli("show", os.path.join(SCENARIOS, "se2", "tee_slot.toml"), "--theta", "1.5708", "--plot", str(out))
    assert r.returncode == 0, r.stderr
    assert "slab 48 of 64" in r.stdout and out.stat().st_size > 10_000


@pytest.mark.parametrize("args, field", [
    (["--slabs", "2"], "--slabs"),
    (["--space", "se3"], "--space"),
    (["--animate", "x.mp4"], "--animate"),
])
def test_bad_se2_options(args, field, tmp_path):
    r = cli("plan", os.path.join(SCENARIOS, "se2", "bar_door.toml"), *args, cwd=str(tmp_path))
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr


def test_bench_on_an_se2_scene(tmp_path):
    """The bench plans SE(2) scenes through the same routine; the reference is the
    inscribed-disk lower bound, so every error it reports is >= 0 (an upper bound)."""
    import csv

    out = tmp_path / "b"
    r = cli("bench", os.path.join(SCENARIOS, "se2", "bar_door.toml"), "--planners", "RRTConnect", "--times", "3",
            "--runs", "2", "--out", str(out), "-q")
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(open(out / "results.csv")))
    assert len(rows) == 2 and all(row["reference"] == "lower_bound" for row in rows)
    solved = [row for row in rows if row["solved"] == "True"]
    assert solved, rows
    for row in solved:
        assert float(row["length"]) >= float(row["optimum"]) and float(row["error"]) >= 0.0
        assert int(row["state_checks"]) > 0 and int(row["motion_checks"]) > 0
