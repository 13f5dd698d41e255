"""Planner budgets and hangs (issue 24.2, 24.4, 24.5): iteration budgets mean iterations,
nothing deadlocks or busy-loops, absurd time limits are refused, start == goal plans,
Ctrl-C stops OMPL cleanly; and the planning messages (issue 18.5)."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import conftest
from cspace import CSpace, ScenarioError, load_scenario
from planners import plan
from planners.cli.plan import summary

ROOT = Path(conftest.ROOT)
SC = ROOT / "scenarios"
BASIC = str(SC / "basic.toml")


def cli(*args, timeout=20, **kw):
    return subprocess.run([sys.executable, "-m", "planners.cli", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=timeout, **kw)


@pytest.mark.parametrize("planner", ["PRM", "PRMstar"])
def test_prm_with_an_iteration_budget_finishes(planner):
    # Used to deadlock (the counting condition ran on PRM's solution thread).
    t = time.perf_counter()
    r = cli("plan", SC / "maze.toml", "--planner", planner, "--iterations", "3000", "--time", "2", timeout=15)
    assert r.returncode in (0, 1), r.stderr
    assert time.perf_counter() - t < 12


@pytest.mark.parametrize("planner, iterations", [("FMT", 300), ("BFMT", 300), ("BITstar", 3000),
                                                 ("LBKPIECE1", 3000), ("PRM", 300), ("PRMstar", 300)])
def test_iteration_budgets_let_every_planner_solve(planner, iterations):
    # FMT and BFMT used to stop during sampling ("Timeout"): now the budget is their sample count.
    sc = load_scenario(BASIC)
    cs = CSpace.from_scenario(sc)
    res = plan(sc, planner=planner, time=8.0, seed=0, iterations=iterations, cspace=cs)
    assert res.solved, res.message
    if planner not in ("PRM", "PRMstar"):  # PRM checks for a solution on its own thread
        again = plan(sc, planner=planner, time=8.0, seed=0, iterations=iterations, cspace=cs)
        assert np.array_equal(again.path, res.path)


def test_bitstar_counts_its_own_iterations(monkeypatch):
    import planners.core.routine as routine

    seen = []
    solve = routine._solve

    def spy(ss, *a, **k):
        out = solve(ss, *a, **k)
        seen.append(ss.getPlanner().numIterations())
        return out

    monkeypatch.setattr(routine, "_solve", spy)
    plan(BASIC, planner="BITstar", time=8.0, seed=0, iterations=700)
    assert seen == [700]


def test_aorrtc_on_an_empty_scene_neither_hangs_nor_fails():
    # Used to busy-loop past 120 s ("Failed to find any neighbours").
    r = cli("plan", SC / "ompl" / "empty.toml", "--planner", "AORRTC", "--time", "1", timeout=15)
    assert r.returncode == 0 and "solved by AORRTC" in r.stdout, r.stdout + r.stderr


def test_aorrtc_reaches_a_free_goal_in_an_empty_box(write_toml):
    # Used to return a path not reaching the (valid) goal.
    f = write_toml("[bounds]\nxmin=0\nxmax=10\nymin=0\nymax=10\n[start]\nx=1\ny=1\n[goal]\nx=9\ny=9\n")
    res = plan(f, planner="AORRTC", time=1.0)
    assert res.solved and res.path.tolist() == [[1.0, 1.0], [9.0, 9.0]]


def test_aorrtc_runs_where_it_must_plan():
    res = plan(BASIC, planner="AORRTC", time=0.5, seed=1)
    assert res.solved and len(res.path) > 2


@pytest.mark.skipif(not hasattr(os, "fork"), reason="the guard needs fork")
def test_a_planner_past_its_time_limit_is_killed_with_a_clear_message(monkeypatch):
    import planners.core.routine as routine

    monkeypatch.setattr(routine, "_plan_query", lambda *a: time.sleep(60))
    monkeypatch.setattr(routine, "GUARD_MARGIN", 0.5)
    t = time.perf_counter()
    res = plan(BASIC, planner="AORRTC", time=0.2)
    assert time.perf_counter() - t < 5
    assert not res.solved and "did not stop at its time limit" in res.message


@pytest.mark.parametrize("value", ["8e9", "1e300"])
def test_a_time_limit_beyond_the_clock_is_refused(value):
    r = cli("plan", BASIC, "--time", value)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and ": --time: at most" in r.stderr


def test_api_time_and_seed_beyond_ompls_range_blame_the_argument():
    with pytest.raises(ScenarioError, match=r"^plan\(\): time: at most"):
        plan(BASIC, time=8e9)
    with pytest.raises(ScenarioError, match=r"^plan\(\): seed: "):
        plan(BASIC, seed=2**64)
    r = cli("plan", BASIC, "--seed", str(2**64))
    assert r.returncode == 2 and ": --seed: " in r.stderr


@pytest.mark.parametrize("planner", ["InformedRRTstar", "SORRTstar", "AORRTC", "PRM"])
def test_start_equal_to_goal_is_a_one_point_path(write_toml, planner):
    f = write_toml(Path(BASIC).read_text().replace("x = 9.0\ny = 9.0", "x = 1.0\ny = 1.0"))
    assert load_scenario(f).start == load_scenario(f).goal
    r = cli("plan", f, "--planner", planner, "--time", "0.5")
    assert r.returncode == 0, r.stdout + r.stderr
    res = plan(f, planner=planner, time=0.5)
    assert res.solved and res.path.tolist() == [[1.0, 1.0]] and res.length == 0.0


@pytest.mark.parametrize("planner", ["PRM", "PRMstar"])
@pytest.mark.slow
def test_ctrl_c_stops_ompl_cleanly(planner):
    # Used to abort: "terminate called without an active exception" (SIGABRT).
    proc = subprocess.Popen([sys.executable, "-m", "planners.cli", "plan", str(SC / "narrow_passage.toml"),
                             "--planner", planner, "--time", "30"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(2.0)
    assert proc.poll() is None
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=10)
    assert proc.returncode == 130, err
    assert "terminate called" not in err and err.strip() == "interrupted"


# ---------------------------------------------------------------- messages (issue 18.5)

def test_exact_unsolvable_reads_proven_without_a_seed():
    r = cli("plan", SC / "narrow_closed.toml", "--planner", "exact")
    assert r.returncode == 1
    first = r.stdout.splitlines()[0]
    assert first.endswith("proven unsolvable (start and goal are in different free components)")
    assert "seed" not in r.stdout and "within the limit" not in r.stdout
    solved = cli("plan", BASIC, "--planner", "exact")
    assert solved.returncode == 0 and "seed" not in solved.stdout


def test_a_failed_sampling_planner_explains_and_suggests_exact():
    # a solvable scene on a budget of one iteration: not found, at any machine speed
    res = plan(SC / "narrow_passage.toml", planner="RRTConnect", time=5, iterations=1)
    assert not res.solved
    assert "no path found within the budget" in res.message and "--planner exact" in res.message


def test_a_translating_robot_without_a_path_is_proven_before_sampling():
    # no sampling budget is spent when the free space's components separate start and goal
    # (issue 51, point 6): the answer comes from the same proof as the exact planner's
    res = plan(SC / "narrow_closed.toml", planner="RRTConnect", time=60)
    assert not res.solved and res.proven_unsolvable and "different free components" in res.message
    assert res.stages[-1] == "free components" and "solve" not in res.timings and res.timings["proof"] > 0
    assert res.timings["total"] < 30  # far from the budget: nothing was sampled
    ok = plan(SC / "basic.toml", planner="RRTConnect", time=5, seed=1)
    assert ok.solved and "proof" in ok.timings  # the check runs, and lets a solvable query through
    from planners.core.routine import failure_message

    msg = failure_message("Approximate solution")
    assert "only comes near the goal" in msg


def test_all_queries_timings_per_query_and_total_on_separate_lines(write_toml):
    f = write_toml(Path(BASIC).read_text() + "\n[[queries]]\nstart = [1, 9]\ngoal = [9, 1]\n"
                   "[[queries]]\nstart = [5, 1]\ngoal = [5, 9]\n")
    res = plan(f, planner="RRTConnect", time=0.5, all_queries=True)
    assert len(res.queries) == 3
    lines = summary(res).splitlines()
    per = [ln for ln in lines if ln.startswith("query ") and " time: " in ln]
    assert len(per) == len(res.queries) and all("solve" in ln and "total" not in ln for ln in per)
    total = [ln for ln in lines if ln.startswith("total time: ")]
    assert len(total) == 1 and "total" in total[0] and "solve" not in total[0]


def test_a_misspelt_planner_blames_the_argument():
    with pytest.raises(ScenarioError, match=r"^plan\(\): planner: unknown planner 'RRTConect'"):
        plan(BASIC, planner="RRTConect")
    r = cli("plan", BASIC, "--planner", "RRTConect")
    assert r.returncode == 2 and ": --planner: unknown planner" in r.stderr


def test_all_queries_each_query_has_its_own_stream(write_toml):
    # Query 0 is closed (RRTConnect runs to its time limit, drawing as many samples as
    # the clock allows); query 1 is open. Query 1's raw path must not depend on that.
    from cspace.paths.shortest import shortest_path

    sc = load_scenario(SC / "narrow_closed.toml")
    cs = CSpace.from_scenario(sc)
    xs = np.linspace(sc.bounds[0], sc.bounds[1], 11)[1:-1]
    ys = np.linspace(sc.bounds[2], sc.bounds[3], 11)[1:-1]
    goal = max(((float(x), float(y)) for x in xs for y in ys if cs.is_free((x, y))
                and shortest_path(cs.pieces, cs.bounds, sc.start, (x, y)).solved),
               key=lambda p: np.hypot(p[0] - sc.start[0], p[1] - sc.start[1]))
    text = Path(SC / "narrow_closed.toml").read_text()
    f = write_toml(text + f"\n[[queries]]\nstart = [{sc.start[0]!r}, {sc.start[1]!r}]\n"
                          f"goal = [{goal[0]!r}, {goal[1]!r}]\n")
    runs = [plan(f, planner="RRTConnect", time=t, seed=3, all_queries=True, simplify=False) for t in (0.1, 0.3)]
    assert all(not r.queries[0].solved for r in runs)
    q = [r.queries[-1] for r in runs]
    assert q[0].solved and len(q[0].path) > 2  # the raw path went through random samples
    assert np.array_equal(q[0].path, q[1].path)
