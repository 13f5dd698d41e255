"""Clearance (issue 21): what a safety margin costs, and what measuring min_clearance costs.

1. Build: the C-space of each bundled translation scene built without and with a margin
   (clearance D = ``--fraction`` x the bounds' extent, the scene's disk_tolerance; a scene
   with its own ``clearance`` keeps it), builds
   interleaved, medians over ``--reps``; the ratio is the margin's cost (target <= 1.5x).
   With ``--tolerance T`` the margin's polygon is built with disk_tolerance T instead.
2. Plan: each scene planned with its own planner (and with ``exact``) with the margin;
   min_clearance's share of the plan's total time (its ``clearance`` timing over
   ``total``), medians over ``--reps`` (target <= 10 %).
3. Anytime: RRTstar with ``--objective clearance`` on one scene, budgets doubling, the
   reported min clearance of each (``--anytime SCENE``): it rises with the budget.

Usage: python scripts/bench_clearance.py [--reps R] [--fraction F] [--tolerance T] [--anytime basic.toml]
                                         [scenario.toml ...]
"""
import argparse
import dataclasses
import glob
import os
import statistics
import time

from cspace import CSpace, load_scenario

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def scenes(names):
    paths = [os.path.join(ROOT, "scenarios", n) if not os.path.exists(n) else n for n in names] if names else \
        sorted(glob.glob(os.path.join(ROOT, "scenarios", "*.toml")))
    out = []
    for p in paths:
        sc = load_scenario(p)
        if sc.space == "translation":
            out.append(sc)
    return out


def margin_of(sc, fraction: float, tolerance: float | None):
    xmin, xmax, ymin, ymax = sc.bounds
    d = fraction * max(xmax - xmin, ymax - ymin)
    return dataclasses.replace(sc, clearance=d, disk_tolerance=tolerance or sc.disk_tolerance)


def build_ratio(sc, inflated, reps: int):
    """Median build seconds without and with the margin, interleaved, after one untimed build
    of each (the first scene of a run otherwise pays the margin code's first use)."""
    plain, margin = [], []
    CSpace.from_scenario(sc), CSpace.from_scenario(inflated)
    for _ in range(reps):
        for s, out in ((sc, plain), (inflated, margin)):
            t = time.perf_counter()
            CSpace.from_scenario(s)
            out.append(time.perf_counter() - t)
    return statistics.median(plain), statistics.median(margin)


def plan_share(sc, planner, reps: int):
    """Median share of min_clearance in the plan's total time, and the median total."""
    from planners import plan

    shares, totals = [], []
    for seed in range(reps):
        try:
            r = plan(sc, planner=planner, seed=seed)
        except ValueError:  # start or goal closer than the margin: not plannable with it
            return None
        if r.solved:
            shares.append(r.timings.get("clearance", 0.0) / r.timings["total"])
            totals.append(r.timings["total"])
    if not shares:
        return None
    return statistics.median(shares), statistics.median(totals)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenarios", nargs="*")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--fraction", type=float, default=0.01, help="clearance D as a fraction of the extent")
    ap.add_argument("--tolerance", type=float, help="disk_tolerance of the margin (default: the scene's)")
    ap.add_argument("--anytime", default="basic.toml", help="scene of the anytime line ('' to skip)")
    args = ap.parse_args()
    rows = []
    print(f"{'scene':<22} {'D':>7} {'plain ms':>9} {'margin ms':>9} {'ratio':>6}  "
          f"{'share (own planner)':>20} {'share (exact)':>14}")
    for sc in scenes(args.scenarios):
        # A scene with its own clearance (clearance.toml) is measured with it, against none.
        inflated = sc if sc.clearance > 0 and not args.tolerance else margin_of(sc, args.fraction, args.tolerance)
        sc = dataclasses.replace(sc, clearance=0.0, margin=None)
        a, b = build_ratio(sc, inflated, args.reps)
        own = plan_share(inflated, None, args.reps)
        ex = plan_share(inflated, "exact", max(1, args.reps // 2))
        rows.append((b / a, own, ex))
        fmt = lambda s: "-" if s is None else f"{100 * s[0]:5.1f} % of {s[1] * 1e3:6.1f} ms"
        print(f"{sc.name:<22} {inflated.clearance:7.3g} {a * 1e3:9.1f} {b * 1e3:9.1f} {b / a:6.2f}  "
              f"{fmt(own):>20} {fmt(ex):>14}")
    ratios = [r[0] for r in rows]
    shares = [s[0] for r in rows for s in r[1:] if s is not None]
    print(f"median build ratio {statistics.median(ratios):.2f}x (max {max(ratios):.2f}x); "
          f"min_clearance share: median {100 * statistics.median(shares):.1f} %, max {100 * max(shares):.1f} %")
    if args.anytime:
        from planners import plan

        sc = scenes([args.anytime])[0]
        line = []
        for budget in (0.1, 0.2, 0.4, 0.8, 1.6):
            r = plan(sc, planner="RRTstar", time=budget, seed=1, objective="clearance")
            line.append(f"{budget:g} s: {r.min_clearance:.4g}" if r.solved else f"{budget:g} s: -")
        print(f"anytime, RRTstar --objective clearance on {sc.name}, min clearance by budget: " + ", ".join(line))


if __name__ == "__main__":
    main()
