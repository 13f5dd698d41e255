"""Resume after ``kill -9``, measured: a small ``cspace bench --db`` campaign is killed at a random
moment, then resumed with ``--resume``; repeated N times (issue 37's target: 0 finished runs
lost, 0 repeated, over 10 kills).

The kill moment: once a random number of runs (0 to all but one) are stored, plus a random
0-60 ms (inside the next run, or its commit). Per trial: the runs stored just before the kill (re-read just after it: every committed run),
then after the resume: *lost* = stored runs (id and key) missing or rewritten; *repeated* = run
keys stored more than once; the final set must be the whole grid.

    python scripts/bench_resume.py [--trials 10] [--seeds 10] [--seed 0]
"""
from __future__ import annotations

import argparse
import os
import random
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from planners.bench.arena_db import run_keys  # noqa: E402

BASIC = os.path.join(ROOT, "scenarios", "basic.toml")
PLANNERS = ("RRTConnect", "RRTstar")


def stored(db: str) -> list[tuple]:
    """(run id, run key) of every run committed now ([] before the database exists)."""
    if not os.path.exists(db):
        return []
    try:
        conn = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=30)
        try:
            ids = [r[0] for r in conn.execute("SELECT id FROM runs ORDER BY id")]
            return [(i, *k) for i, k in zip(ids, run_keys(conn))]
        finally:
            conn.close()
    except sqlite3.Error:
        return []


def trial(folder: str, seeds: int, kill_at: int, extra: float) -> dict:
    """Kill once ``kill_at`` runs are stored, ``extra`` seconds later (inside a run or a commit)."""
    db = os.path.join(folder, "campaign.db")
    args = [sys.executable, "-m", "planners.cli", "bench", BASIC, "--planners", ",".join(PLANNERS), "--times",
            "0.05", "--runs", str(seeds), "--out", os.path.join(folder, "out"), "--db", db, "-q", "--no-plot"]
    proc = subprocess.Popen(args, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t_start = time.perf_counter()
    while proc.poll() is None and len(stored(db)) < kill_at and time.perf_counter() - t_start < 300:
        time.sleep(0.002)
    time.sleep(extra)
    kill_after = time.perf_counter() - t_start
    finished_first = proc.poll() is not None
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = stored(db)
    t0 = time.perf_counter()
    subprocess.run(args + ["--resume"], cwd=ROOT, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = stored(db)
    keys = [k[1:] for k in after]
    grid = len(PLANNERS) * seeds
    return {"kill_after": kill_after, "stored_at_kill": len(before), "finished_first": finished_first,
            "lost": len(set(before) - set(after)), "repeated": len(keys) - len(set(keys)),
            "final": len(set(keys)), "grid": grid, "resumed_runs": len(after) - len(before),
            "resume_s": time.perf_counter() - t0}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=10)
    ap.add_argument("--seeds", type=int, default=10, help="seeds per planner (runs: 2 planners x seeds)")
    ap.add_argument("--seed", type=int, default=0, help="random seed of the kill moments")
    a = ap.parse_args(argv)
    rng = random.Random(a.seed)
    lost = repeated = incomplete = 0
    for i in range(a.trials):
        with tempfile.TemporaryDirectory() as tmp:
            r = trial(tmp, a.seeds, rng.randrange(0, len(PLANNERS) * a.seeds), rng.uniform(0.0, 0.06))
        lost, repeated = lost + r["lost"], repeated + r["repeated"]
        incomplete += r["final"] != r["grid"]
        print(f"trial {i + 1}: killed after {r['kill_after']:.2f} s with {r['stored_at_kill']}/{r['grid']} runs "
              f"stored{' (had finished)' if r['finished_first'] else ''}; resume ran {r['resumed_runs']} "
              f"-> {r['final']}/{r['grid']}; lost {r['lost']}, repeated {r['repeated']}", flush=True)
    print(f"{a.trials} kills: lost {lost}, repeated {repeated}, incomplete {incomplete}")
    return 0 if lost == repeated == incomplete == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
