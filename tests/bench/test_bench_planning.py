"""The peer planning benchmark's pieces: the shapely and coal checkers answer like the
exact C-space on random states, the judges of colliding paths agree with each other
on paths built to collide or not, a one-seed run through the planning routine
returns no colliding path of ours, a returned path that collides is not a solution
(not counted as solved, not in the medians, no ratio), and coal-fine's spacing is
half the thinnest C-obstacle piece (and stops tunnelling through a thin wall). Timings are not asserted (speed lives in
scripts/bench_planning.py)."""
import os

import numpy as np
import pytest

from conftest import SCENARIOS, load_script
from cspace import CSpace, load_scenario

pytest.importorskip("ompl")


@pytest.fixture(scope="module")
def bench():
    return load_script("bench_planning")


class State(tuple):
    """An indexable (x, y), as OMPL's states are to the checkers."""


@pytest.mark.parametrize("name", ["maze.toml", "parts.toml", "u_robot.toml", os.path.join("ompl", "env1.toml")])
def test_peer_checkers_agree_with_the_exact_cspace(bench, name):
    sc = load_scenario(os.path.join(SCENARIOS, name))
    cs = CSpace.from_scenario(sc)
    checkers = {"shapely": bench.shapely_checker(sc)}
    if bench.coal_available():
        checkers["coal"] = bench.coal_checker(sc)
    xmin, xmax, ymin, ymax = sc.bounds
    rng = np.random.default_rng(7)
    pts = np.column_stack([rng.uniform(xmin, xmax, 400), rng.uniform(ymin, ymax, 400)])
    # Away from C-obstacle boundaries (random states land on one with probability 0), the
    # peers' collision answers are the exact ones.
    truth = cs.is_free(pts)
    for who, check in checkers.items():
        got = np.array([check(State(p)) for p in pts.tolist()])
        assert (got == truth).all(), (who, pts[got != truth][:3])
    assert truth.any() and not truth.all()


def test_judges_of_colliding_paths_agree(bench):
    sc = load_scenario(os.path.join(SCENARIOS, "basic.toml"))
    cs = CSpace.from_scenario(sc)
    judge = bench.shapely_judge(sc)
    through = np.array([sc.start[:2], sc.goal[:2]], dtype=float)  # the diagonal crosses an obstacle
    assert bench.colliding_exact(cs, through) and judge(through)
    from planners import shortest_path

    free = shortest_path(os.path.join(SCENARIOS, "basic.toml"))
    # The exact optimum touches C-obstacles (closed: a collision); its corners pulled
    # back towards the free space, by a plan of ours instead:
    from planners import plan

    res = plan(os.path.join(SCENARIOS, "basic.toml"), seed=1)
    assert res.solved and free.solved
    assert not bench.colliding_exact(cs, res.path) and not judge(res.path)


def test_one_seed_run(bench, capsys):
    assert bench.main(["--scenes", "env1,narrow_closed", "--seeds", "1", "--planners", "RRTConnect,RRTstar",
                       "--time", "2"]) == 0
    out = capsys.readouterr().out
    assert "ompl/env1" in out and "narrow_closed" not in out  # proven unsolvable: skipped
    assert "colliding paths returned: ours 0," in out


# A wall 0.1 thick across the whole space: every path from start to goal goes through it.
# OMPL's default discrete check (states 1 % of the extent, ~0.22, apart) can step over it;
# states 0.05 apart (half its width) cannot.
WALL = """
name = "wall"
[bounds]
xmin = 0
xmax = 20
ymin = 0
ymax = 10
[[obstacles]]
polygon = [[10.3, 0], [10.4, 0], [10.4, 10], [10.3, 10]]
[start]
x = 2
y = 5
[goal]
x = 18
y = 5
"""
SEED = 0  # checked: the shapely and coal peers both tunnel through the wall with it


def _run(path, wall, length):
    return {"solved": path is not None, "wall": wall, "cpu": wall, "length": length, "path": path}


def test_summarize_counts_only_collision_free_paths_as_solved(bench):
    free, through = np.array([[0., 0], [1, 1]]), np.array([[0., 0], [5, 5]])
    runs = [_run(free, 0.2, 1.5), _run(through, 0.001, 7.0), _run(free, 0.4, 2.5), _run(None, None, None)]
    row = bench.summarize(runs, lambda p: p is through, lambda p: p is through)
    assert row["returned"] == "3/4" and row["valid"] == "2/4"
    assert row["colliding"] == 1 and row["shapely says"] == 1
    # Medians over the two valid runs only: the fast colliding run would pull them down.
    assert row["first wall ms"] == pytest.approx(300.0) and row["first cpu ms"] == pytest.approx(300.0)
    assert row["length"] == pytest.approx(2.0)
    none = bench.summarize([_run(through, 0.001, 7.0)] * 2, lambda p: True, lambda p: True)
    assert none["valid"] == "0/2" and none["first wall ms"] is None and none["length"] is None


def test_ratio_only_where_both_have_a_valid_run(bench):
    ours = {"valid": "3/3", "first wall ms": 30.0, "colliding": 0}
    assert bench.ratio_cell(ours, {"valid": "1/3", "first wall ms": 10.0, "colliding": 2}, "coal") == pytest.approx(3.0)
    cell = bench.ratio_cell(ours, {"valid": "0/3", "first wall ms": None, "colliding": 3}, "coal")
    assert cell == "coal: 0/3 valid (3 colliding)"
    peer = {"valid": "2/3", "first wall ms": 5.0, "colliding": 0}
    nothing = {"valid": "0/3", "first wall ms": None, "colliding": 0}
    assert bench.ratio_cell(nothing, peer, "coal") == "ours: 0/3 valid"
    assert bench.ratio_cell(nothing, nothing, "coal-fine") == "ours: 0/3 valid; coal-fine: 0/3 valid (0 colliding)"


def test_a_tunnelling_run_is_not_solved(bench, write_toml):
    sc = load_scenario(write_toml(WALL))
    cs = CSpace.from_scenario(sc)
    peer = bench.PeerSpace(cs, bench.shapely_checker(sc))
    run = bench.one_run(peer, "RRTConnect", SEED, (2.0, 5.0), (18.0, 5.0), 2.0)
    assert run["solved"] and bench.colliding_exact(cs, run["path"])  # it returned a path through the wall
    row = bench.summarize([run], lambda p: bench.colliding_exact(cs, p), bench.shapely_judge(sc))
    assert (row["returned"], row["valid"], row["colliding"], row["shapely says"]) == ("1/1", "0/1", 1, 1)
    assert row["first wall ms"] is None


def test_polygon_width_by_hand(bench):
    assert bench.polygon_width(np.array([[0., 0], [1, 0], [1, 10], [0, 10]])) == pytest.approx(1.0)
    # The right triangle 3-4-5: its narrowest slab rests on the hypotenuse, height 3 * 4 / 5.
    assert bench.polygon_width(np.array([[0., 0], [4, 0], [0, 3]])) == pytest.approx(2.4)


def test_fine_spacing_is_half_the_thinnest_c_obstacle(bench, write_toml):
    bar = WALL.replace("[[10.3, 0], [10.4, 0], [10.4, 10], [10.3, 10]]", "[[5, 0], [6, 0], [6, 10], [5, 10]]")
    assert bench.fine_spacing(load_scenario(write_toml(bar))) == pytest.approx(0.5)  # point robot: 1 / 2
    robot = bar.replace("[start]", "[robot]\npolygon = [[0, 0], [2, 0], [2, 3], [0, 3]]\n[start]")
    assert bench.fine_spacing(load_scenario(write_toml(robot, "r.toml"))) == pytest.approx(1.5)  # (1 + 2) / 2
    empty = WALL.split("[[obstacles]]")[0] + WALL.split("[10.3, 10]]")[1]
    assert bench.fine_spacing(load_scenario(write_toml(empty, "e.toml"))) is None


def test_coal_fine_does_not_tunnel_where_coal_does(bench, write_toml):
    pytest.importorskip("coal")
    sc = load_scenario(write_toml(WALL))
    cs = CSpace.from_scenario(sc)
    check = bench.coal_checker(sc)
    coarse = bench.one_run(bench.PeerSpace(cs, check), "RRTConnect", SEED, (2.0, 5.0), (18.0, 5.0), 2.0)
    assert coarse["solved"] and bench.colliding_exact(cs, coarse["path"])
    step = bench.fine_spacing(sc)
    assert step == pytest.approx(0.05)
    fine = bench.one_run(bench.PeerSpace(cs, check, step), "RRTConnect", SEED, (2.0, 5.0), (18.0, 5.0), 1.0)
    assert not fine["solved"]  # every motion across the wall puts a checked state inside it
