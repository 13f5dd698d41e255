"""Car-like robots (Dubins, Reeds–Shepp): certified curve checks against OMPL's sampled ones, and plans.

(M) Motions. For each bundled car scene, M seeded random motions between free poses
    (the second within 0.2 x the space's maximum extent). Ours:
    ``CarSpace.motion_free`` (the shortest curve's segments, certified: exact straight
    segments, arcs bounded by hulls about the turning centre). Baseline: OMPL's own
    checking on the same state space (``DubinsStateSpace`` / ``ReedsSheppStateSpace``)
    with a shapely checker (robot rotated and translated by ``shapely.affinity``,
    ``STRtree`` + prepared ``intersects``): its default discrete motion validator (states
    sampled along the curve at 1 % of the space's extent), and for Dubins also OMPL's
    ``DubinsMotionValidator`` (which samples the same way). Timed per motion, interleaved,
    CPU time, medians. Every motion either accepts is judged by an independent shapely
    sweep along the curve (``scripts/sweep_oracle.py``, ``car_sweep_check``): "collides"
    when a placement meets an obstacle or a straight segment's exact sweep does.
    Targets: ours accepts 0 colliding motions; ours costs <= 2x the baseline per motion.
    The same medians over the motions both accept are printed too ("free"): a colliding
    motion ends early on both sides, a free one pays for the whole certificate.
(T) Time to first solution: every bundled solvable car scene, the planner of its
    ``[planner]`` table, 10 seeds, 10 s each, through ``planners.plan`` (the routine of
    ``cspace plan``); solved count, median solve time and length, each path judged.

Usage: python scripts/bench_car.py [--quick] [--parts MT] [--json FILE]
(--json is checked before any work, never over a bundled scene, and written atomically.)
"""
from __future__ import annotations

import argparse
import glob
import math
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

from bench_se2 import _si, shapely_se2_checker, solve_runs  # noqa: E402
from sweep_oracle import car_sweep_check  # noqa: E402

from cspace.car.curves import dubins_segments, reeds_shepp_segments  # noqa: E402
from cspace.io.load import load_scenario  # noqa: E402

CAR_DIR = os.path.join(ROOT, "scenarios", "car")


def random_motions(sc, cs, m: int, seed: int):
    """m motions between free poses, the second within 0.2 x the space's maximum extent."""
    rng = np.random.default_rng(seed)
    xmin, xmax, ymin, ymax = sc.bounds
    reach = 0.2 * math.hypot(xmax - xmin, ymax - ymin)
    out = []
    while len(out) < m:
        a = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        if not cs.is_free(a):
            continue
        d = rng.normal(size=2)
        d *= rng.uniform(0, reach) / np.linalg.norm(d)
        b = (min(max(a[0] + d[0], xmin), xmax), min(max(a[1] + d[1], ymin), ymax), rng.uniform(-math.pi, math.pi))
        if cs.is_free(b):
            out.append((a, b))
    return out


def part_m(m: int) -> list[dict]:
    from planners.core.plan import make_adapter, build_cspace

    rows = []
    for f in sorted(glob.glob(os.path.join(CAR_DIR, "*.toml"))):
        sc = load_scenario(f)
        cs = build_cspace(sc, sc.slabs)
        adapter = make_adapter(sc, cs)
        motions = random_motions(sc, cs, m, seed=7)
        check = shapely_se2_checker(sc)
        peers = {"discrete": _si(adapter, check, "discrete")}
        if sc.space == "dubins":
            peers["dubins_mv"] = _si(adapter, check, "dubins")
        times = {"ours": [], **{k: [] for k in peers}}
        ok = {k: [] for k in times}
        states = {k: (v[1][1].allocState(), v[1][1].allocState()) for k, v in peers.items()}
        for i, (a, b) in enumerate(motions):
            order = ["ours", *peers]
            order = order[i % len(order):] + order[:i % len(order)]
            for who in order:
                if who == "ours":
                    t = time.process_time()
                    ok[who].append(adapter.motion_free(a, b))
                    times[who].append(time.process_time() - t)
                    continue
                si = peers[who][0]
                s1, s2 = states[who]
                adapter.set_state(s1, a)
                adapter.set_state(s2, b)
                t = time.process_time()
                ok[who].append(bool(si.checkMotion(s1, s2)))
                times[who].append(time.process_time() - t)
        seg = dubins_segments if sc.space == "dubins" else reeds_shepp_segments
        judge = {}

        def collides(k):
            if k not in judge:
                r = car_sweep_check(sc, np.array(motions[k]), lambda p, q: seg(p, q, sc.turning_radius),
                                    sc.turning_radius)
                judge[k] = bool(r["collides"])
            return judge[k]

        both = [i for i in range(len(motions)) if ok["ours"][i] and ok["discrete"][i]]
        rows.append({
            "scene": sc.name, "space": sc.space, "motions": m,
            "us_per_motion": {k: 1e6 * statistics.median(v) for k, v in times.items()},
            # the same medians over the motions both accept (free ones: no early exit on a collision)
            "us_per_free_motion": {k: 1e6 * statistics.median([v[i] for i in both]) if both else None
                                   for k, v in times.items()},
            "accepted": {k: sum(v) for k, v in ok.items()},
            "accepted_colliding": {k: sum(1 for i, acc in enumerate(v) if acc and collides(i)) for k, v in ok.items()},
            "floor_decisions": cs.checks.get("motion_floor", 0),
        })
    return rows


def part_t(seeds: int, budget: float) -> list[dict]:
    seg = {"dubins": dubins_segments, "reeds-shepp": reeds_shepp_segments}
    rows = []
    for f in sorted(glob.glob(os.path.join(CAR_DIR, "*.toml"))):
        sc = load_scenario(f)
        if sc.expect == "unsolvable":
            continue
        solved, times, lengths, bad = solve_runs(
            sc, seeds, budget,
            lambda path: car_sweep_check(sc, path, lambda p, q: seg[sc.space](p, q, sc.turning_radius),
                                         sc.turning_radius)["collides"])
        rows.append({"scene": sc.name, "space": sc.space, "planner": sc.planner.get("name", "RRTConnect"),
                     "solved": solved, "seeds": seeds,
                     "median_solve_s": statistics.median(times) if times else None,
                     "median_length": statistics.median(lengths) if lengths else None, "colliding_paths": bad})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer motions and seeds")
    ap.add_argument("--parts", default="MT")
    ap.add_argument("--json", help="write the figures to this file")
    a = ap.parse_args(argv)
    from benchutil import check_json, write_json

    check_json(a.json, [CAR_DIR])  # (never over a scene)
    out = {}
    if "M" in a.parts:
        out["motions"] = part_m(m=60 if a.quick else 400)
        print("(M) car motions: ours certified vs OMPL's sampled checks (shapely checker), us per motion (CPU, median)")
        print(f"  {'scene':14} {'space':12} {'ours':>8} {'discrete':>9} {'ratio':>6} {'dubinsMV':>9}"
              f" {'acc. ours/disc.':>15} {'coll. ours':>10} {'coll. disc.':>11} {'coll. dMV':>9} {'floor':>5}"
              f" {'free: ours':>10} {'disc.':>7} {'ratio':>6}")
        for r in out["motions"]:
            u, acc, bad = r["us_per_motion"], r["accepted"], r["accepted_colliding"]
            dmv = f"{u['dubins_mv']:9.1f}" if "dubins_mv" in u else f"{'-':>9}"
            cmv = f"{bad['dubins_mv']:9}" if "dubins_mv" in bad else f"{'-':>9}"
            print(f"  {r['scene']:14} {r['space']:12} {u['ours']:8.1f} {u['discrete']:9.1f} "
                  f"{u['ours'] / u['discrete']:6.2f} {dmv} {acc['ours']:>7}/{acc['discrete']:<7}"
                  f" {bad['ours']:10} {bad['discrete']:11} {cmv} {r['floor_decisions']:5}", end="")
            fr = r["us_per_free_motion"]
            if fr["ours"] is not None:
                print(f" {fr['ours']:10.1f} {fr['discrete']:7.1f} {fr['ours'] / fr['discrete']:6.2f}")
            else:
                print(f" {'-':>10} {'-':>7} {'-':>6}")
    if "T" in a.parts:
        out["plans"] = part_t(seeds=3 if a.quick else 10, budget=10.0)
        print("(T) the bundled car scenes, their [planner], 10 s budget")
        for r in out["plans"]:
            ms = f"{r['median_solve_s']:.3f} s" if r["median_solve_s"] is not None else "-"
            ml = f"{r['median_length']:.3f}" if r["median_length"] is not None else "-"
            print(f"  {r['scene']:14} {r['space']:12} solved {r['solved']}/{r['seeds']}  median first solution {ms}"
                  f"  median length {ml}  colliding paths {r['colliding_paths']}")
    if a.json:
        write_json(a.json, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
