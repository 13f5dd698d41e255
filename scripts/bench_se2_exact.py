"""The exact SE(2) planner (the slab graph) against RRTConnect, side by side, CPU time.

Per bundled SE(2) scene (scenarios/se2/*.toml), rounds interleave, in one process:

- ``exact``: ``planners.plan(sc, planner="exact")``, the C-space built inside the call (as
  ``cspace plan`` does). Reported: its answer, the CPU time to the certified path (the slab
  graph's search, ``timings["solve"]``), and the CPU time of the whole call (C-space, search,
  the certified re-check, OMPL's shortening, the clearance measure);
- ``RRTConnect``: ``planners.plan(sc, planner="RRTConnect", time=T, seed=r)``, the default
  planner, with the proof before sampling that every rotating plan now runs. Reported: the
  seeds solved within T, those proven unsolvable before sampling ("proven"), the median CPU
  time of its calls, and the median time to its first solution (OMPL's solve) over the solved
  seeds;

and the ratio exact / RRTConnect of the medians. Every path either returns is judged by the
independent shapely sweep (scripts/sweep_oracle.py): colliding paths are counted.

"Time to a path" (``PlanResult.first_path_cpu``) is the CPU time from the start of
``plan()`` until the first path exists, as a user of ``cspace plan`` waits for it: for exact,
the C-space, the slab graph's search and the certified re-check (before shortening); for
RRTConnect, the C-space, the proof before sampling, and OMPL's solve up to its first solution
(before simplification). A seed RRTConnect does not solve counts as never (its median is then
past the limit when most seeds fail). The narrower figures are printed beside it: exact's
search alone against OMPL's solve alone (which leaves out the proof and the C-space that
RRTConnect's sampling reads).

Targets (issue 34): plank_corner_tight (a plank round a corner with 1 % of room) solved by exact
in <= 1 s CPU, with RRTConnect's rate at 30 s beside it; wide_square (a robot too wide for every
gap) proven unsolvable in <= 0.1 s with the default planner; bug_trap_l (an L-shaped robot in a
bug trap) in <= 0.2 s; every scene answered by exact in <= 2 s, and exact's time to a certified
path <= RRTConnect's median time to a first solution on at least half of the scenes RRTConnect
solves; here, on at least half of the solvable bundled scenes (printed too: on at least half of
those RRTConnect solves at every seed).

Families (issue 49, ``--families N``: N scenes each, no bundled scenes): doors in a wall just
wider than a box robot (0.3 % and 0.1 % of its width to spare, random sizes, door heights, start
and goal poses), and a box between two round pillars with 1 % to spare (disks: never "proven
unsolvable"). Per family: scenes decided by exact, solved, median CPU of exact's plan() against
RRTConnect's at the same limit (one seed a scene, interleaved), colliding paths (the sweep
oracle), and proofs refused by ``check-proof``. Targets: doors at 0.3 % all solved, median
<= 1 s CPU; 0.1 %: all decided, median <= 3 s; 0 false "proven unsolvable", 0 refused proofs.
The designed solvable families (scripts/se2_families.py, each scene with a hand-built witness
path: a reference point far outside the body, two offset doors 0.5 % wider, a one-motion path
across the ±π seam, a two-part robot through a door 0.3 % wider, a tunnel 0.1 % wider at the
start's own angle, doors 0.1 % wider): every scene solved. ``--family a,b`` runs some of them,
``--peer-time 0`` leaves RRTConnect out (on a shared machine).

Usage: python scripts/bench_se2_exact.py [--seeds N] [--time T] [--scenes a,b] [--json FILE]
       [--families N [--family NAME,...] [--peer-time T]]
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

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import planners  # noqa: E402
import sweep_oracle  # noqa: E402
from se2_families import DESIGNED, door, pillars  # noqa: E402
from cspace.io.load import load_scenario  # noqa: E402

TARGETS = {"plank_corner_tight": 1.0, "wide_square": 0.1, "bug_trap_l": 0.2}


def cpu(fn):
    """``(fn(), CPU seconds)``."""
    t = time.process_time()
    out = fn()
    return out, time.process_time() - t


def collides(sc, res) -> bool:
    if not res.solved:
        return False
    j = sweep_oracle.sweep_check(sc, res.path)
    return bool(j["collides"] or j["out_of_bounds"])


def run_scene(path: str, seeds: int, limit: float, progress=None) -> dict:
    sc = load_scenario(path)
    name = os.path.splitext(os.path.basename(path))[0]
    ex_search, ex_total, rrt_total, rrt_first, answers = [], [], [], [], set()
    ex_path, rrt_path = [], []  # CPU from plan()'s start to the first path (inf: none)
    rrt_solved, proven, bad = 0, 0, {"exact": 0, "rrt": 0}
    for seed in range(seeds):  # interleaved: one exact run, one RRTConnect seed
        ex, t_ex = cpu(lambda: planners.plan(sc, planner="exact", time=30.0))
        ex_total.append(t_ex)
        ex_search.append(ex.timings.get("solve_cpu", t_ex))
        ex_path.append(ex.first_path_cpu if ex.solved else float("inf"))
        answers.add("solved" if ex.solved else ("proven unsolvable" if ex.proof is not None else "not decided"))
        bad["exact"] += collides(sc, ex)
        rr, t_rr = cpu(lambda: planners.plan(sc, planner="RRTConnect", time=limit, seed=seed))
        rrt_total.append(t_rr)
        rrt_path.append(rr.first_path_cpu if rr.solved else float("inf"))
        if rr.solved:
            rrt_solved += 1
            rrt_first.append(rr.timings.get("solve", t_rr))
        elif rr.proof is not None:
            proven += 1
        bad["rrt"] += collides(sc, rr)
        if progress is not None:
            progress.step(f"{name}, seed {seed}")
    med = statistics.median
    row = {"scene": name, "expect": sc.expect or "solvable", "exact_answer": " / ".join(sorted(answers)),
           "exact_search_cpu_s": med(ex_search), "exact_total_cpu_s": med(ex_total), "exact_max_total_cpu_s": max(ex_total),
           "rrt_solved": rrt_solved, "rrt_proven": proven, "seeds": seeds, "rrt_total_cpu_s": med(rrt_total),
           "rrt_first_solution_s": med(rrt_first) if rrt_first else None, "colliding": bad}
    row["ratio_total"] = row["exact_total_cpu_s"] / row["rrt_total_cpu_s"]
    row["exact_path_cpu_s"], row["rrt_path_cpu_s"] = med(ex_path), med(rrt_path)
    row["solvable"] = "solved" in answers
    row["exact_first_from_call"] = row["solvable"] and row["exact_path_cpu_s"] <= row["rrt_path_cpu_s"]
    row["exact_first"] = row["rrt_first_solution_s"] is not None and row["exact_search_cpu_s"] <= row["rrt_first_solution_s"]
    return row


def run_family(name: str, make, n: int, limit: float, peer: float | None = None, progress=None) -> dict:
    """One family of ``n`` scenes: exact at ``limit`` s, RRTConnect at ``peer`` s (``limit`` if
    None; 0: RRTConnect is not run, its columns print "-")."""
    from planners.core.proof_check import check_proof

    peer = limit if peer is None else peer

    ex_t, rr_t, decided, solved, rr_solved, bad, refused, proven = [], [], 0, 0, 0, 0, 0, 0
    undecided = []
    for seed in range(n):  # interleaved: exact, then RRTConnect, on the same scene
        sc = make(seed)
        ex, t_ex = cpu(lambda: planners.plan(sc, planner="exact", time=limit))
        if peer > 0:
            rr, t_rr = cpu(lambda: planners.plan(sc, planner="RRTConnect", time=peer, seed=seed))
        else:
            rr, t_rr = None, float("inf")
        ex_t.append(t_ex if ex.solved or ex.proof is not None else float("inf"))
        rr_t.append(t_rr if rr is not None and rr.solved else float("inf"))
        decided += ex.solved or ex.proof is not None
        solved += ex.solved
        rr_solved += rr is not None and rr.solved
        proven += ex.proof is not None
        bad += collides(sc, ex) + (rr is not None and collides(sc, rr))
        refused += ex.proof is not None and not check_proof(sc, ex.proof).valid
        if not (ex.solved or ex.proof is not None):
            undecided.append((seed, ex.message[:160]))
        if progress is not None:
            progress.step(f"{name}, scene {seed}")
    med = statistics.median
    row = {"family": name, "scenes": n, "decided": decided, "solved": solved, "proven": proven,
           "exact_median_cpu_s": med(ex_t), "exact_max_cpu_s": max(ex_t), "rrt_solved": rr_solved if peer > 0 else None,
           "rrt_median_cpu_s": med(rr_t) if peer > 0 else None, "colliding": bad, "proofs_refused": refused,
           "undecided": undecided}
    ratio = (row["exact_median_cpu_s"] / row["rrt_median_cpu_s"] if peer > 0 and math.isfinite(row["rrt_median_cpu_s"])
             else math.nan)  # (RRTConnect's median past its limit: no ratio)
    rrt = (f"RRTConnect {rr_solved:>3}/{n} median {row['rrt_median_cpu_s']:7.3f} s   "
           f"ratio {'-' if math.isnan(ratio) else format(ratio, '.3g')}" if peer > 0 else "RRTConnect not run (--peer-time 0)")
    print(f"{name:<18} decided {decided:>3}/{n:<3} solved {solved:>3} proven {proven:>3}  exact median "
          f"{row['exact_median_cpu_s']:7.3f} s (max {row['exact_max_cpu_s']:.3f})   {rrt}   colliding {bad}   "
          f"proofs refused {refused}", flush=True)
    for seed, msg in undecided:
        print(f"    not decided: seed {seed}: {msg}", flush=True)
    return row


def families(n: int, limit: float, peer: float | None = None, only: str | None = None) -> list:
    from benchutil import Progress

    fams = [(k, mk) for k, mk in FAMILIES.items() if only is None or k in only.split(",")]
    progress = Progress(f"bench_se2_exact --families {n}: {len(fams)} families x {n} scenes (exact {limit:g} s, "
                        f"RRTConnect {limit if peer is None else peer:g} s)", len(fams) * n,
                        most_s=limit + (limit if peer is None else peer), unit="scenes")
    rows = [run_family(k, mk, n, limit, peer, progress) for k, mk in fams]
    by = {r["family"]: r for r in rows}
    print("targets:")
    for name, what, most in (("doors 0.3 %", "solved", 1.0), ("doors 0.1 %", "decided", 3.0)):
        if name in by:
            r = by[name]
            print(f"  {name}: {what} {r[what]}/{n}, median {r['exact_median_cpu_s']:.3f} s CPU (all, <= {most:g} s): "
                  f"{'met' if r[what] == n and r['exact_median_cpu_s'] <= most else 'MISSED'}")
    if "disk pillars 1 %" in by:
        print(f"  disks: proven unsolvable {by['disk pillars 1 %']['proven']} (0)")
    for r in rows:
        if r["family"] in DESIGNED:
            print(f"  {r['family']}: solved {r['solved']}/{n} (all), median {r['exact_median_cpu_s']:.3f} s CPU, "
                  f"slowest {r['exact_max_cpu_s']:.3f} s: {'met' if r['solved'] == n else 'MISSED'}")
    print(f"  every family: proofs refused {sum(r['proofs_refused'] for r in rows)} (0), "
          f"colliding {sum(r['colliding'] for r in rows)} (0)")
    return rows


FAMILIES = {"doors 0.3 %": lambda s: door(s, 0.003), "doors 0.1 %": lambda s: door(1000 + s, 0.001),
            "disk pillars 1 %": pillars, **{k: mk for k, (mk, _) in DESIGNED.items()}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10, help="RRTConnect seeds (and exact repetitions) per scene")
    ap.add_argument("--time", type=float, default=30.0, help="RRTConnect's time limit per seed (s)")
    ap.add_argument("--scenes", help="comma-separated scene names (default: every scenarios/se2/*.toml)")
    ap.add_argument("--json", help="write the rows as JSON")
    ap.add_argument("--families", type=int, help="run the issue-49 families of N scenes each instead of the bundled scenes")
    ap.add_argument("--family", help="with --families: comma-separated family names (default: all)")
    ap.add_argument("--peer-time", type=float, help="with --families: RRTConnect's limit (default: --time; 0: not run)")
    args = ap.parse_args(argv)
    from benchutil import check_json, write_json

    check_json(args.json, [os.path.join(ROOT, "scenarios", "se2")])  # (never over a scene)
    if args.families:
        rows = families(args.families, args.time, args.peer_time, args.family)
        if args.json:
            write_json(args.json, rows)
        return 0
    paths = sorted(glob.glob(os.path.join(ROOT, "scenarios", "se2", "*.toml")))
    if args.scenes:
        want = set(args.scenes.split(","))
        paths = [p for p in paths if os.path.splitext(os.path.basename(p))[0] in want]
    rows = []
    from benchutil import Progress

    progress = Progress(f"bench_se2_exact: {len(paths)} scenes x {args.seeds} seeds (exact 30 s, RRTConnect {args.time:g} s)",
                        len(paths) * args.seeds, most_s=30.0 + args.time, unit="rounds")
    print(f"{'scene':<16} {'exact answer':<18} {'search s':>9} {'path s':>7} {'total s':>8} {'RRTConnect':>10} "
          f"{'proven':>6} {'RRT s':>7} {'RRT 1st s':>9} {'RRT path s':>10} {'exact/RRT':>9} {'colliding':>10}")
    for p in paths:
        r = run_scene(p, args.seeds, args.time, progress)
        rows.append(r)
        first = "-" if r["rrt_first_solution_s"] is None else f"{r['rrt_first_solution_s']:.3f}"
        print(f"{r['scene']:<16} {r['exact_answer'][:18]:<18} {r['exact_search_cpu_s']:9.3f} "
              f"{r['exact_path_cpu_s']:7.3f} {r['exact_total_cpu_s']:8.3f} "
              f"{r['rrt_solved']:>4}/{r['seeds']:<5} {r['rrt_proven']:>6} {r['rrt_total_cpu_s']:7.3f} {first:>9} "
              f"{r['rrt_path_cpu_s']:10.3f} {r['ratio_total']:9.3f} "
              f"{r['colliding']['exact']:>4} /{r['colliding']['rrt']:>3}", flush=True)
    print("\ntargets:")
    for name, t in TARGETS.items():
        r = next((r for r in rows if r["scene"] == name), None)
        if r is None:
            continue
        got = r["rrt_total_cpu_s"] if name != "plank_corner_tight" else r["exact_search_cpu_s"]
        what = "RRTConnect's plan() (the proof before sampling)" if name != "plank_corner_tight" else "exact's certified path"
        print(f"  {name}: {what} {got:.3f} s CPU (target <= {t:g} s): {'met' if got <= t else 'MISSED'}")
    worst = max(r["exact_max_total_cpu_s"] for r in rows)
    print(f"  every scene answered by exact: slowest {worst:.3f} s CPU (target <= 2 s): {'met' if worst <= 2 else 'MISSED'}")
    solvable = [r for r in rows if r["solvable"]]
    won = sum(r["exact_first_from_call"] for r in solvable)
    print(f"  time to a path from plan()'s start (CPU), exact <= RRTConnect's median: {won}/{len(solvable)} "
          f"solvable scenes (target: at least half): {'met' if 2 * won >= len(solvable) else 'MISSED'}")
    every = [r for r in solvable if r["rrt_solved"] == r["seeds"]]
    won_every = sum(r["exact_first_from_call"] for r in every)
    print(f"    on the scenes RRTConnect solves at every seed: {won_every}/{len(every)}")
    solved = [r for r in rows if r["rrt_first_solution_s"] is not None]
    faster = sum(r["exact_first"] for r in solved)
    print(f"    narrower, exact's search alone <= OMPL's solve alone (no C-space, no proof): {faster}/{len(solved)} "
          f"scenes RRTConnect solves")
    print(f"  colliding paths: exact {sum(r['colliding']['exact'] for r in rows)}, "
          f"RRTConnect {sum(r['colliding']['rrt'] for r in rows)}")
    if args.json:
        write_json(args.json, rows)
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    os._exit(code)  # skip the bindings' "nanobind: leaked" report
