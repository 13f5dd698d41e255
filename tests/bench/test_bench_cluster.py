"""``cspace bench --scheduler``: batches of runs on a Dask cluster (a two-worker LocalCluster),
each worker's C-space cache, rows streamed into the database, a worker killed mid-way."""
from __future__ import annotations

import os
import signal
import sqlite3
from pathlib import Path

import pytest

pytest.importorskip("ompl")
pytest.importorskip("distributed", reason="dask[distributed] is not installed (pip install -e '.[cluster]')")

import conftest  # noqa: E402
from planners.bench import cluster  # noqa: E402
from planners.bench.campaign import Campaign  # noqa: E402
from planners.bench.pool import CAN_FORK  # noqa: E402
from planners.bench.reference import make_tasks, reference  # noqa: E402
from planners.bench.sweep import sweep  # noqa: E402
from planners.cli import main  # noqa: E402

ROOT = Path(conftest.ROOT)
BASIC = str(ROOT / "scenarios" / "basic.toml")
BUG = str(ROOT / "scenarios" / "bug_trap.toml")


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as lc, \
            Client(lc) as c:
        yield c


def db_runs(path) -> list[tuple]:
    conn = sqlite3.connect(path)
    try:
        return conn.execute("SELECT e.name, p.name, r.seed FROM runs r JOIN experiments e ON r.experimentid = e.id "
                            "JOIN plannerConfigs p ON r.plannerid = p.id").fetchall()
    finally:
        conn.close()


def test_batches_are_one_scenario_and_long_enough():
    tasks = make_tasks([{"file": f, "scenario": f, "optimum": 1.0} for f in ("a", "b")],
                       ["RRTConnect", "RRTstar"], [0.01, 0.05], 7)
    got = cluster.batches(tasks)
    assert sorted(id(t) for b in got for t in b) == sorted(id(t) for t in tasks)  # each task once
    for b in got:
        assert len({t["file"] for t in b}) == 1
    for f in ("a", "b"):
        mine = [b for b in got if b[0]["file"] == f]
        assert all(sum(t["time_budget"] for t in b) >= cluster.BATCH_SECONDS - 1e-12 for b in mine[:-1])
        # no batch longer than it needs: without its last run it was still short
        assert all(sum(t["time_budget"] for t in b[:-1]) < cluster.BATCH_SECONDS for b in mine)
    assert len(got) < len(tasks) / 3


@pytest.mark.skipif(not CAN_FORK, reason="workers fork a child per run")
def test_a_killed_worker_loses_and_doubles_nothing(client, tmp_path):
    held: dict = {}
    scen = reference([BASIC], held=held)
    tasks = make_tasks(scen, ["RRTstar", "PRMstar"], [0.05], 12)  # anytime: each run takes its budget
    db = str(tmp_path / "c.db")
    camp = Campaign(db, tasks)
    pids = client.run(os.getpid)
    killed: dict = {}

    def on_batch(rows):
        camp.add(rows)
        if not killed:  # the first batch is in: kill a worker while it is running another
            addr, pid = next(iter(pids.items()))
            killed["processing"] = client.processing().get(addr, ())
            os.kill(pid, signal.SIGKILL)
            killed["pid"] = pid

    rows, interrupted = sweep(tasks, scheduler=client, on_batch=on_batch)
    camp.finish()
    assert not interrupted and killed["processing"], "the kill hit an idle worker: nothing was lost to retry"
    with pytest.raises(ProcessLookupError):
        os.kill(killed["pid"], 0)
    want = sorted(("basic_t0.05", f"geometric_{p}", s) for p in ("RRTstar", "PRMstar") for s in range(12))
    assert sorted(db_runs(db)) == want  # the whole grid, each run once
    assert sorted((r["planner"], r["seed"]) for r in rows) == sorted((p, s) for p in ("RRTstar", "PRMstar")
                                                                      for s in range(12))
    assert all(r["status"] == "ok" for r in rows), [(r["status"], r["message"]) for r in rows if r["status"] != "ok"]
    # each live worker built the scene's C-space once and kept it (the survivor ran several batches)
    stats = client.run(cluster.held_stats).values()
    assert all(held == built <= 1 for held, built in stats) and any(built == 1 for _, built in stats)


def test_a_retried_batch_stores_nothing_twice(tmp_path):
    held: dict = {}
    scen = reference([BASIC], held=held)
    tasks = make_tasks(scen, ["RRTConnect"], [0.01], 3)
    rows, _ = sweep(tasks, held=held)
    db = str(tmp_path / "r.db")
    camp = Campaign(db, tasks)
    camp.add(rows[:2])
    camp.add(rows)  # the same batch again, as a retried one would bring: no error, no double
    camp.finish()
    assert camp.stored == 3 and len(db_runs(db)) == 3


def test_cli_scheduler_streams_into_the_database(client, tmp_path):
    addr = client.scheduler.address
    db = str(tmp_path / "cli.db")
    args = ["bench", BASIC, BUG, "--planners", "RRTConnect", "--times", "0.02,0.05", "--runs", "3",
            "--out", str(tmp_path / "out"), "--db", db, "--scheduler", addr, "-q", "--no-plot"]
    assert main(args) == 0
    assert len(db_runs(db)) == 2 * 2 * 3 == len(set(db_runs(db)))
    assert main(args[:-2] + ["--runs", "5", "--resume", "-q", "--no-plot"]) == 0
    runs = db_runs(db)
    assert len(runs) == 2 * 2 * 5 == len(set(runs))
    # each worker built each scene's C-space at most once
    assert all(held == built <= 2 for held, built in client.run(cluster.held_stats).values())


@pytest.mark.slow
def test_cli_scheduler_unreachable_is_bad_input(tmp_path, capsys):
    args = ["bench", BASIC, "--planners", "RRTConnect", "--times", "0.01", "--runs", "1", "--out",
            str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:9", "-q", "--no-plot"]
    assert main(args) == 2
    assert "--scheduler: cannot connect to 127.0.0.1:9" in capsys.readouterr().err  # the address probed
