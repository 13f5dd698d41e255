"""Scheduler overhead of ``cspace bench --scheduler``, measured (issue 37's target: a 10 000-run
campaign, 2 scenes x 5 planners x 5 budgets x 200 seeds of short budgets, on a 2-worker
LocalCluster: overhead <= 5 % of the wall time against the same runs in one local process with
the same parallelism; database <= 50 MB).

The same runs go through :func:`planners.bench.sweep.sweep` twice per repeat, interleaved (the
order alternates): on the local pool (``--workers 2``: forked children of this process, which
built the C-spaces) and on a LocalCluster of 2 worker processes of 1 thread (batches of runs,
each worker's C-space cache emptied before each repeat, so it pays its own builds). The clock
times the runs alone; the rows then go into a fresh benchmark database (its size is reported).
With ``--with-db`` the clock also takes the writes as ``cspace bench --db`` makes them, each row as
it arrives: the pool one transaction per run, the cluster one per batch. Reported: the median wall time of each, the overhead
(cluster / pool - 1) and the cluster's database size, with its size per 10 000 runs.

    python scripts/bench_cluster.py [--runs 1000] [--reps 3] [--quick]

``--runs`` is rounded to a multiple of 50 (2 scenes x 5 planners x 5 budgets); 10000 is the
issue's campaign (about 10 minutes per sweep on a 2-core machine).
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

SCENES = [os.path.join(ROOT, "scenarios", f) for f in ("basic.toml", "bug_trap.toml")]
PLANNERS = ["RRTConnect", "RRTstar", "PRMstar", "BITstar", "KPIECE1"]
TIMES = [0.005, 0.01, 0.02, 0.03, 0.05]


def warm() -> None:
    from planners.adapters.glue import ompl
    from planners.core import plan  # noqa: F401

    ompl()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=1000, help="runs per sweep (multiple of 50; default 1000)")
    ap.add_argument("--reps", type=int, default=3, help="repeats of each side, interleaved (default 3)")
    ap.add_argument("--with-db", action="store_true", help="time the sweeps with their database writes (default: "
                                                           "the runs alone; the rows are stored after the clock)")
    ap.add_argument("--quick", action="store_true", help="200 runs, 2 repeats (about a minute)")
    args = ap.parse_args(argv)
    if args.quick:
        args.runs, args.reps = 200, 2
    from distributed import Client, LocalCluster

    from planners.bench.campaign import Campaign
    from planners.bench.cluster import clear_held
    from planners.bench.reference import make_tasks, reference
    from planners.bench.sweep import sweep

    seeds = max(1, args.runs // (len(SCENES) * len(PLANNERS) * len(TIMES)))
    held: dict = {}
    scen = reference(SCENES, held=held)
    tasks = make_tasks(scen, PLANNERS, TIMES, seeds)
    n = len(tasks)
    print(f"{n} runs: {len(SCENES)} scenes x {len(PLANNERS)} planners x {len(TIMES)} budgets "
          f"({','.join(map(str, TIMES))} s) x {seeds} seeds; {args.reps} repeats, interleaved; "
          + ("timed with the database writes" if args.with_db else "database written after the clock"))
    walls: dict[str, list[float]] = {"pool": [], "cluster": []}
    sizes = []
    with tempfile.TemporaryDirectory() as tmp, \
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as lc, \
            Client(lc) as client:
        client.run(warm)  # each worker imports OMPL and the planning code once, as the pool's process did

        def run(side: str, k: int) -> None:
            db = os.path.join(tmp, f"{side}{k}.db")
            camp = Campaign(db, tasks)
            hooks = {}
            if args.with_db:  # as ``cspace bench --db`` does: the pool a transaction per run, the cluster per batch
                hooks = {"on_batch": camp.add} if side == "cluster" else {"on_row": camp.on_row}
            if side == "cluster":
                client.run(clear_held)
                t0 = time.perf_counter()
                rows, _ = sweep(tasks, scheduler=client, **hooks)
            else:
                t0 = time.perf_counter()
                rows, _ = sweep(tasks, workers=2, held=held, **hooks)
            wall = time.perf_counter() - t0
            if not args.with_db:  # stored after the clock: the same database
                camp.add(rows)
            camp.finish()
            assert len(rows) == n == camp.stored, (side, len(rows), camp.stored)
            walls[side].append(wall)
            if side == "cluster":
                sizes.append(os.path.getsize(db))
            print(f"  {side:<8} {wall:7.2f} s  ({sum(r['solved'] for r in rows)}/{n} solved)", flush=True)

        for k in range(args.reps):
            for side in (("pool", "cluster") if k % 2 == 0 else ("cluster", "pool")):
                run(side, k)
    pool, clus = statistics.median(walls["pool"]), statistics.median(walls["cluster"])
    size = statistics.median(sizes)
    print(f"median wall: pool {pool:.2f} s, cluster {clus:.2f} s; scheduler overhead {100 * (clus / pool - 1):+.1f} %"
          " (target <= 5 %)")
    print(f"database: {size / 1e6:.2f} MB for {n} runs, {size / 1e6 * 10000 / n:.1f} MB per 10 000 runs "
          "(target <= 50 MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
