"""``cspace bench``: outputs and their schema, rows independent of workers and of Dask,
crashed and hung runs recorded, Ctrl-C keeps finished rows, the OMPL log converts into
the Planner Arena database, and no planner beats the exact shortest path."""
from __future__ import annotations

import csv
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

import conftest
from planners import bench
from planners.cli import main

ROOT = Path(conftest.ROOT)
BASIC = str(ROOT / "scenarios" / "basic.toml")
# RRTConnect and RRT stop at their first solution (found in a few ms on basic.toml), so
# their rows are deterministic for a seed; RRTstar runs to its budget (rows vary).
PLANNERS = "RRTConnect,RRT,RRTstar"
TIMES = "0.2,0.5"
FIRST_SOLUTION = {"RRTConnect", "RRT"}


def _sweep(out: Path, workers: int, extra=()) -> int:
    return main(["bench", BASIC, "--planners", PLANNERS, "--times", TIMES, "--runs", "2",
                 "--workers", str(workers), "--out", str(out), "--abort-on", "RRT:1", "-q", *extra])


@pytest.fixture(scope="module")
def sweeps(tmp_path_factory):
    base = tmp_path_factory.mktemp("bench")
    codes = {w: _sweep(base / f"w{w}", w) for w in (1, 2)}
    return base, codes


def _rows(folder: Path) -> list[dict]:
    return json.loads((folder / "results.json").read_text())["rows"]


def _stable(row: dict) -> dict:
    """A row without what depends on the clock."""
    drop = set(bench.TIMING_FIELDS) | {"progress"}
    if row["planner"] not in FIRST_SOLUTION:  # stopped by the clock: only identity and status
        return {k: row[k] for k in ("scenario", "planner", "time_budget", "seed", "status", "optimum")}
    return {k: v for k, v in row.items() if k not in drop}


@pytest.mark.slow
def test_outputs_and_schema(sweeps):
    base, codes = sweeps
    assert codes == {1: 0, 2: 0}
    out = base / "w1"
    with open(out / "results.csv", newline="") as fh:
        reader = csv.DictReader(fh)
        assert tuple(reader.fieldnames) == bench.FIELDS
        crow = list(reader)
    data = json.loads((out / "results.json").read_text())
    assert data["fields"] == list(bench.FIELDS)
    assert data["meta"]["complete"] is True
    rows = data["rows"]
    assert len(rows) == len(crow) == 3 * 2 * 2
    for r, c in zip(rows, crow):
        assert set(bench.FIELDS) <= set(r)
        assert r["status"] in bench.STATUSES
        assert c["planner"] == r["planner"] and float(c["time_budget"]) == r["time_budget"]
        assert int(c["seed"]) == r["seed"] and c["status"] == r["status"]
        if r["solved"]:
            assert float(c["length"]) == r["length"]
            assert r["error"] == pytest.approx(r["length"] / r["optimum"] - 1, rel=1e-12, abs=1e-15)
            assert 0 < r["first_solution_s"] <= r["solve_s"] + 1e-9
            assert r["motion_checks"] > 0
    # Order: scenario, planner (as given), budget, seed.
    assert [(r["planner"], r["time_budget"], r["seed"]) for r in rows] == \
        [(p, t, s) for p in PLANNERS.split(",") for t in (0.2, 0.5) for s in (0, 1)]
    png = (out / "error_vs_time.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
    assert sorted(os.listdir(out / "ompl")) == ["basic_t0.2.log", "basic_t0.5.log"]
    assert not [f for f in os.listdir(out) if f.startswith(".tmp-")]  # atomic writes left nothing


def test_optimum_is_the_exact_length_and_never_beaten(sweeps):
    from planners import shortest_path

    base, _ = sweeps
    exact = shortest_path(BASIC).length
    rows = _rows(base / "w1") + _rows(base / "w2")
    assert all(r["optimum"] == exact for r in rows)
    solved = [r for r in rows if r["solved"]]
    assert len(solved) >= len(rows) // 2
    for r in solved:
        assert r["length"] >= exact * (1 - 1e-9), r
        assert r["length_unsimplified"] >= exact * (1 - 1e-9), r


def test_same_rows_for_one_and_two_workers(sweeps):
    base, _ = sweeps
    a, b = _rows(base / "w1"), _rows(base / "w2")
    assert [_stable(r) for r in a] == [_stable(r) for r in b]
    # The deterministic planners solved (their budget is 50x their need), so the comparison had teeth.
    assert all(r["solved"] for r in a if r["planner"] == "RRTConnect")


def test_crashed_run_is_recorded_and_the_sweep_goes_on(sweeps):
    base, _ = sweeps
    rows = _rows(base / "w1")
    crashed = [r for r in rows if r["status"] == "crashed"]
    assert [(r["planner"], r["seed"]) for r in crashed] == [("RRT", 1), ("RRT", 1)]
    assert all("signal" in r["message"] and not r["solved"] and r["length"] is None for r in crashed)
    later = [r for r in rows if r["planner"] == "RRTstar"]
    assert later and all(r["status"] == "ok" for r in later)


# The columns of the bench before min_clearance: kept, in this order, the new ones appended.
FIELDS_BEFORE_CLEARANCE = (
    "scenario", "file", "planner", "time_budget", "seed", "status", "solved",
    "length", "length_unsimplified", "optimum", "reference", "error", "error_unsimplified",
    "first_solution_s", "solve_s", "simplify_s", "state_checks", "motion_checks", "wall_s", "message",
)


def test_rows_carry_the_min_clearance_that_plan_reports(sweeps):
    from planners import plan

    base, _ = sweeps
    assert bench.FIELDS[:len(FIELDS_BEFORE_CLEARANCE)] == FIELDS_BEFORE_CLEARANCE
    rows = _rows(base / "w1")
    with open(base / "w1" / "results.csv", newline="") as fh:
        crow = list(csv.DictReader(fh))
    for r, c in zip(rows, crow):
        if not r["solved"]:  # the aborted runs: nothing measured, an empty cell
            assert r["min_clearance"] is None and c["min_clearance"] == "" and c["min_clearance_bound"] == ""
            continue
        assert r["min_clearance"] > 0 and r["min_clearance_bound"] == "exact"
        assert float(c["min_clearance"]) == r["min_clearance"]  # the same double
        assert r["clearance_s"] > 0
        if r["planner"] in FIRST_SOLUTION:  # deterministic for a seed: plan() is the oracle
            res = plan(BASIC, planner=r["planner"], time=r["time_budget"], seed=r["seed"])
            assert res.solved
            assert r["min_clearance"] == pytest.approx(res.min_clearance, rel=0, abs=1e-12)
    assert any(r["solved"] for r in rows if r["planner"] in FIRST_SOLUTION)


def test_hung_run_is_killed_as_timeout():
    task = bench.make_tasks([{"file": BASIC, "scenario": "basic", "optimum": 1.0}], ["RRTstar"], [5.0], 1)[0]
    t0 = time.perf_counter()
    row = bench.isolated_run(task, limit=0.3)
    assert row["status"] == "timeout" and not row["solved"]
    assert time.perf_counter() - t0 < 3.0


def test_ompl_log_converts_to_planner_arena_database(sweeps, tmp_path):
    import ompl

    base, _ = sweeps
    script = Path(ompl.__file__).parent / "ompl_benchmark_statistics.py"
    assert script.exists()
    db = tmp_path / "bench.db"
    logs = sorted(str(p) for p in (base / "w1" / "ompl").glob("*.log"))
    res = subprocess.run([sys.executable, str(script), "-d", str(db), *logs],
                         capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr[-500:]
    con = sqlite3.connect(db)
    counts = con.execute("""SELECT e.name, e.timelimit, p.name, COUNT(*) FROM runs r
                            JOIN plannerConfigs p ON r.plannerid = p.id JOIN experiments e ON r.experimentid = e.id
                            GROUP BY e.name, p.name ORDER BY e.timelimit, p.name""").fetchall()
    assert counts == [(f"basic_t{t:g}", t, f"geometric_{p}", 2) for t in (0.2, 0.5) for p in sorted(PLANNERS.split(","))]
    # Status enum: the aborted child is a Crash; solved runs are Exact solutions with their lengths.
    crash = con.execute("SELECT description FROM enums WHERE name='status' AND value=?", (7,)).fetchone()[0]
    assert crash == "Crash"
    st = con.execute("""SELECT r.status, r.seed FROM runs r JOIN plannerConfigs p ON r.plannerid = p.id
                        WHERE p.name='geometric_RRT' ORDER BY r.seed""").fetchall()
    assert st == [(6, 0), (6, 0), (7, 1), (7, 1)]
    rows = _rows(base / "w1")
    db_len = sorted(v for (v,) in con.execute("SELECT simplified_solution_length FROM runs") if v is not None)
    assert db_len == pytest.approx(sorted(r["length"] for r in rows if r["solved"]), rel=1e-15)
    assert con.execute("SELECT COUNT(*) FROM progress").fetchone()[0] > 0


@pytest.mark.parametrize("argv, field", [
    (["--planners", "RRTConnect,Nope"], "--planners"),
    (["--planners", "exact"], "--planners"),
    (["--times", "0.1,-1"], "--times"),
    (["--times", "0.1,,1"], "--times"),
    (["--times", "abc"], "--times"),
    (["--runs", "0"], "--runs"),
])
def test_bad_options_exit_2_naming_the_field(argv, field, capsys, tmp_path):
    code = main(["bench", BASIC, "--out", str(tmp_path / "o"), "-q", *argv])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and f": {field}: " in err
    assert not (tmp_path / "o").exists()


def test_missing_scenario_exit_2(capsys, tmp_path):
    missing = str(tmp_path / "nope.toml")
    code = main(["bench", BASIC, missing, "--out", str(tmp_path / "o"), "-q"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and missing in err


@pytest.mark.slow
def test_ctrl_c_keeps_finished_rows(tmp_path):
    out = tmp_path / "o"
    proc = subprocess.Popen([sys.executable, "-m", "planners.cli", "bench", BASIC, "--planners", "RRTConnect,RRTstar",
                             "--times", "0.3,1", "--runs", "10", "--out", str(out), "-q"],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.time() + 60
    # Wait until a few RRTConnect runs are surely done (each takes well under a second; the
    # 40 runs take over 20 s, so the sweep is still going, even on a loaded machine).
    time.sleep(8.0)
    assert proc.poll() is None, "the sweep ended before the interrupt"
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=max(1, deadline - time.time()))
    assert proc.returncode == 130
    data = json.loads((out / "results.json").read_text())
    assert data["meta"]["complete"] is False
    assert 0 < len(data["rows"]) < 40
    assert all(r["status"] == "ok" for r in data["rows"])  # the killed runs are not recorded
    with open(out / "results.csv") as fh:
        assert len(fh.read().splitlines()) == len(data["rows"]) + 1


@pytest.mark.slow
def test_dask_cluster_gives_the_same_rows(sweeps, tmp_path):
    distributed = pytest.importorskip("distributed")
    base, _ = sweeps
    out = tmp_path / "dask"
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        code = _sweep(out, 1, ["--scheduler", cluster.scheduler_address])
    assert code == 0
    a, b = _rows(base / "w1"), _rows(out)
    assert [_stable(r) for r in a] == [_stable(r) for r in b]
