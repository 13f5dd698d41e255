"""The peer planning benchmark's pieces: the shapely and coal checkers answer like the
exact C-space on random states, the judges of colliding paths agree with each other
on paths built to collide or not, and a one-seed run through the planning routine
returns no colliding path of ours. Timings are not asserted (speed lives in
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
    from planners.exact import shortest_path

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
