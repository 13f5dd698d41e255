"""``auto`` (the default for rotating robots and cars) against the planners it is made of.

(S) Every bundled SE(2) scene (scenarios/se2/): auto, RRTConnect and exact through
    ``planners.plan`` as ``cspace plan`` runs them (the scenario loaded and its C-space built in
    every call), ``--seeds`` seeds each, interleaved (one run of every planner per seed), CPU time
    from the call's start to its answer: the first certified path (``first_path_cpu``: before the
    shortening), or the whole call for a proof. Per scene: answered runs, median CPU, and auto's
    median over the faster of the other two (target <= 1.5x; never "no answer" where either
    answers). Every path is judged by the independent sweep (scripts/sweep_oracle.py).
(C) Every bundled Reeds–Shepp car scene (scenarios/car/): auto, and RRTConnect alone beside it at
    the same limit; solved runs, median CPU to the first path, colliding paths (the sweep along
    the curves). Target for the four scenes that need manoeuvres (parallel_tight,
    dead_end_alley, garage_reverse, u_turn_cusps): 10 of 10 seeds, median <= 0.5 s.

Side by side with OMPL + coal: ``python scripts/bench_se2.py --parts P --planners auto``.

Usage: python scripts/bench_auto.py [--parts SC] [--seeds N | --quick] [--limit S] [--json FILE]
(--json is checked before any work, never over a bundled scene, and written atomically.)

>>> ratio(0.3, 0.15, 0.5)
2.0
>>> ratio(None, 0.2, 0.5) is None, ratio(0.3, None, None) is None
(True, True)
"""
from __future__ import annotations

import argparse
import glob
import math
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

MANOEUVRES = ("parallel-tight", "dead-end-alley", "garage-reverse", "u-turn-cusps")


def ratio(auto, a, b):
    """auto's median over the faster of two others (None where auto or both others have none)."""
    best = min((x for x in (a, b) if x is not None), default=None)
    return None if auto is None or best is None else auto / best


def run(path: str, planner: str, seed: int, limit: float, judge) -> dict:
    """One plan: answered (a path the judge passes, or a proof), its CPU seconds, colliding."""
    import planners

    c0 = time.process_time()
    res = planners.plan(path, planner=planner, seed=seed, time=limit)
    total = time.process_time() - c0
    if res.solved:
        bad = judge(res.scenario_data, res.path)
        return {"answered": not bad, "cpu": res.first_path_cpu if res.first_path_cpu is not None else total,
                "colliding": bad, "stage": res.answered_by}
    return {"answered": res.proven_unsolvable, "cpu": total, "colliding": False, "stage": res.answered_by}


def se2_judge(sc, path) -> bool:
    from sweep_oracle import sweep_check

    j = sweep_check(sc, path)
    return bool(j["collides"] or j["out_of_bounds"])


def car_judge(sc, path) -> bool:
    from sweep_oracle import car_sweep_check

    from cspace.car.curves import dubins_segments, reeds_shepp_segments

    seg = dubins_segments if sc.space == "dubins" else reeds_shepp_segments
    j = car_sweep_check(sc, path, lambda p, q: seg(p, q, sc.turning_radius), sc.turning_radius)
    return bool(j["collides"] or j["out_of_bounds"])


def scene_rows(files: list, planners_: tuple, seeds: int, limit: float, judge) -> list[dict]:
    from benchutil import Progress

    from cspace.io.load import load_scenario

    rows = []
    progress = Progress(f"bench_auto: {len(files)} scenes x {seeds} seeds x {len(planners_)} planners",
                        len(files) * seeds * len(planners_), most_s=limit)
    for f in files:
        name = load_scenario(f).name
        runs = {p: [] for p in planners_}
        for seed in range(seeds):  # interleaved
            for p in planners_:
                runs[p].append(run(f, p, seed, limit, judge))
                progress.step(f"{name}, seed {seed}, {p}")
        row = {"scene": name, "seeds": seeds, "stages": sorted({str(r["stage"]) for r in runs["auto"]})}
        for p, rs in runs.items():
            times = [r["cpu"] for r in rs if r["answered"]]
            row[p] = {"answered": len(times), "median_cpu_s": statistics.median(times) if times else None,
                      "colliding": sum(r["colliding"] for r in rs)}
        rows.append(row)
    return rows


def fmt(x, w=8) -> str:
    return f"{x:{w}.3f}" if x is not None else f"{'-':>{w}}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--parts", default="SC", help="S the SE(2) scenes, C the Reeds-Shepp car scenes")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--quick", action="store_true", help="3 seeds (the benchmarks page's run)")
    ap.add_argument("--limit", type=float, default=10.0, help="seconds per plan")
    ap.add_argument("--json", help="write the figures to this file")
    a = ap.parse_args(argv)
    from benchutil import check_json, write_json

    check_json(a.json, [os.path.join(ROOT, "scenarios", d) for d in ("se2", "car")])  # (never over a scene)
    if a.quick:
        a.seeds = 3
    out = {}
    if "S" in a.parts:
        files = sorted(glob.glob(os.path.join(ROOT, "scenarios", "se2", "*.toml")))
        out["se2"] = rows = scene_rows(files, ("auto", "RRTConnect", "exact"), a.seeds, a.limit, se2_judge)
        print(f"(S) SE(2) scenes, {a.seeds} seeds, {a.limit:g} s: answered, median CPU s to the answer; "
              "auto / the faster (target <= 1.5)")
        print(f"  {'scene':20} {'auto':>12} {'RRTConnect':>15} {'exact':>13} {'ratio':>6}  stages  colliding")
        worst, misses = 0.0, 0
        for r in rows:
            q = ratio(r["auto"]["median_cpu_s"], r["RRTConnect"]["median_cpu_s"], r["exact"]["median_cpu_s"])
            worst = max(worst, q or 0.0)
            misses += r["auto"]["answered"] < max(r["RRTConnect"]["answered"], r["exact"]["answered"])
            print(f"  {r['scene']:20} {r['auto']['answered']:>3} {fmt(r['auto']['median_cpu_s'])} "
                  f"{r['RRTConnect']['answered']:>6} {fmt(r['RRTConnect']['median_cpu_s'])} "
                  f"{r['exact']['answered']:>4} {fmt(r['exact']['median_cpu_s'])} {fmt(q, 6)}  "
                  f"{','.join(r['stages'])}  {sum(r[p]['colliding'] for p in ('auto', 'RRTConnect', 'exact'))}")
        print(f"  worst ratio {worst:.2f} (target <= 1.5: {'met' if worst <= 1.5 else 'NOT met'}); scenes where auto "
              f"answered fewer seeds than another: {misses}")
    if "C" in a.parts:
        files = [f for f in sorted(glob.glob(os.path.join(ROOT, "scenarios", "car", "*.toml")))
                 if 'space = "reeds-shepp"' in open(f).read()]
        out["car"] = rows = scene_rows(files, ("auto", "RRTConnect"), a.seeds, a.limit, car_judge)
        print(f"(C) Reeds-Shepp car scenes, {a.seeds} seeds, {a.limit:g} s: answered, median CPU s; "
              "target for the manoeuvres: all seeds, <= 0.5 s")
        print(f"  {'scene':20} {'auto':>12} {'RRTConnect':>15}  stages  colliding")
        met = True
        for r in rows:
            if r["scene"] in MANOEUVRES:
                m = r["auto"]["median_cpu_s"]
                met &= r["auto"]["answered"] == a.seeds and m is not None and m <= 0.5
            print(f"  {r['scene']:20} {r['auto']['answered']:>3} {fmt(r['auto']['median_cpu_s'])} "
                  f"{r['RRTConnect']['answered']:>6} {fmt(r['RRTConnect']['median_cpu_s'])}  {','.join(r['stages'])}  "
                  f"{r['auto']['colliding'] + r['RRTConnect']['colliding']}")
        print(f"  the four manoeuvres: target {'met' if met else 'NOT met'}")
    if a.json:
        write_json(a.json, out, default=lambda x: None if isinstance(x, float) and math.isnan(x) else x)
    return 0


if __name__ == "__main__":
    sys.exit(main())
