"""The C-space route against the direct route: per-query cost of "is q free?" and of clearance.

The C-space route (``CSpace.is_free``) answers from the materialised C-obstacle pieces
behind a grid; the direct route (``DirectChecker.is_free``) places the robot's pieces
at q and runs GJK against the obstacle pieces a box test keeps. Same scenes, same
uniform random states, same run. Build times are measured too, so the break-even
number of queries (build cost / per-query saving) says when materialising pays.
Medians over repetitions of a batch of states.
Usage: python scripts/bench_direct.py [--states N] [--reps R] [scenario.toml ...]
"""
import argparse
import os
import statistics
import time

import numpy as np

from cspace.translation.cspace import CSpace
from cspace.translation.direct import DirectChecker

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT = ["combs.toml", "office.toml", "disks_cluttered.toml"]


def per_query(fn, states, reps):
    """Median over ``reps`` batches of the mean time per call of fn(q)."""
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        for q in states:
            fn(q)
        t.append((time.perf_counter() - t0) / len(states))
    return statistics.median(t)


def build_time(make, reps=3):
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        obj = make()
        t.append(time.perf_counter() - t0)
    return statistics.median(t), obj


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenarios", nargs="*", default=DEFAULT)
    ap.add_argument("--states", type=int, default=1000)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    rows = []
    for name in args.scenarios:
        path = name if os.path.exists(name) else os.path.join(ROOT, "scenarios", name)
        b_cs, cs = build_time(lambda: CSpace.from_scenario(path))
        b_dc, dc = build_time(lambda: DirectChecker.from_scenario(path))
        xmin, xmax, ymin, ymax = cs.bounds
        rng = np.random.default_rng(0)
        states = [tuple(q) for q in np.column_stack([rng.uniform(xmin, xmax, args.states),
                                                     rng.uniform(ymin, ymax, args.states)]).tolist()]
        free = sum(map(cs.is_free, states)) / len(states)
        assert [cs.is_free(q) for q in states] == [dc.is_free(q) for q in states], name
        t_cs = per_query(cs.is_free, states, args.reps)
        t_dc = per_query(dc.is_free, states, args.reps)
        few = states[: max(1, len(states) // 5)]
        c_cs = per_query(cs.clearance, few, max(1, args.reps // 2))
        c_dc = per_query(dc.clearance, few, max(1, args.reps // 2))
        even = (b_cs - b_dc) / (t_dc - t_cs) if t_dc > t_cs else float("nan")
        rows.append((os.path.basename(path), len(dc.robot_pieces), len(dc.obstacle_pieces), len(cs.pieces), free,
                     t_cs, t_dc, c_cs, c_dc, b_cs, b_dc, even))
    print(f"is_free and clearance per query (median of {args.reps} batches of {args.states} uniform states)")
    head = (f"{'scenario':22s} {'R':>2s} {'O':>4s} {'C-pcs':>5s} {'free':>5s} {'cs us':>7s} {'direct us':>9s} "
            f"{'ratio':>6s} {'clr cs us':>9s} {'clr dir us':>10s} {'ratio':>6s} {'build cs ms':>11s} "
            f"{'build dir ms':>12s} {'break-even q':>12s}")
    print(head)
    print("-" * len(head))
    for (n, r, o, c, free, t_cs, t_dc, c_cs, c_dc, b_cs, b_dc, even) in rows:
        print(f"{n:22s} {r:2d} {o:4d} {c:5d} {free:5.2f} {t_cs * 1e6:7.2f} {t_dc * 1e6:9.2f} {t_dc / t_cs:6.1f} "
              f"{c_cs * 1e6:9.1f} {c_dc * 1e6:10.1f} {c_dc / c_cs:6.1f} {b_cs * 1e3:11.2f} {b_dc * 1e3:12.2f} "
              f"{even:12.0f}")
    print("R, O: robot and obstacle convex pieces; C-pcs: C-obstacle pieces kept; ratio: direct / C-space;")
    print("break-even q: queries after which the C-space's extra build time is paid back by faster is_free.")


if __name__ == "__main__":
    main()
