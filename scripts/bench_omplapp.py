"""OMPL.app's planar problems, side by side: cspace's default planner ``auto`` against OMPL's
RRTConnect with a coal state checker, every path judged by an independent swept check.

Problems (read from an OMPL.app checkout, ``--omplapp DIR``: the folder that holds
``resources/2D``, or that folder itself; nothing of it is copied here): its five geometric planar
problems, BugTrap_planar, Maze_planar, RandomPolygons_planar, Barriers and UniqueSolutionMaze
(each a ``.cfg`` and its COLLADA meshes, read by ``cspace.io.load.load_scenario``). Its car
problems, BugTrap_dcar.cfg and Maze_kcar.cfg, are kinodynamic (``control = dynamic_car``,
``kinematic_car``: speed and steering are controls, with no turning radius of a Dubins or
Reeds-Shepp car): cspace plans no control space, so they are listed as skipped.

Per problem the C-space is built once before its seeds, its slabs included (the column
"C-space"), as the peer's coal checker is. Per seed, in turn: ours, cspace's time to its first
certified path with ``auto`` (``se2_peers.ours_first``: the proof before sampling, the slab
graph's quick search, sampling; unsimplified; CPU seconds), and the peer, OMPL's RRTConnect on
the same state space with coal (``se2_peers.coal_checker``) and OMPL's discrete motion check at
its default step, stopped at its first solution (``se2_peers.peer_first``). A seed whose two runs
both take under 0.1 s is run ``--repeats`` times (interleaved) and the medians taken. After the
timed runs every path of both is judged by ``sweep_oracle.sweep_check`` (shapely, independent of
cspace): "colliding" when a pose along it meets an obstacle, "undecided" when it passes closer
than the judge resolves; only the rest is sound. A path of ours that is not sound is a fault:
printed as such, and the script exits 1.

The ratio ours / coal: the median of the per-seed ratios over the seeds both solve with coal's
path sound (beside it, over all the seeds both solve); the target (issue 47) is <= 0.5x.

Usage: python scripts/bench_omplapp.py [--omplapp DIR] [--seeds N] [--time S] [--repeats N]
       [--problems WORDS] [--json FILE]
Without a checkout (--omplapp DIR, or $OMPLAPP) it says so and exits 0.
"""
from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

import se2_peers  # noqa: E402  (ours and the peer, one seed at a time)
from sweep_oracle import sweep_check  # noqa: E402

PROBLEMS = ("BugTrap_planar.cfg", "Maze_planar.cfg", "RandomPolygons_planar.cfg", "Barriers.cfg",
            "UniqueSolutionMaze.cfg")
KINODYNAMIC = ("BugTrap_dcar.cfg", "Maze_kcar.cfg")  # control problems: not planned here
TARGET = 0.5  # ours / coal's sound runs, medians (issue 47)
REPEAT_BELOW = 0.1  # CPU s: a seed faster than this is run several times (timer noise, caches)


def resources(checkout: str) -> str | None:
    """The folder of the planar problems: ``checkout/resources/2D`` or ``checkout`` itself; None
    when neither holds them.

    >>> resources("/nowhere") is None
    True
    """
    for d in (os.path.join(checkout, "resources", "2D"), checkout):
        if checkout and any(os.path.isfile(os.path.join(d, f)) for f in PROBLEMS):
            return d
    return None


def verdict(j: dict) -> str:
    """The sweep's answer in one word: 'colliding', 'out of bounds', 'undecided' or 'sound'.

    >>> verdict({"collides": False, "out_of_bounds": False, "undecided": 2})
    'undecided'
    """
    return ("colliding" if j["collides"] else "out of bounds" if j["out_of_bounds"]
            else "undecided" if j["undecided"] else "sound")


def paired(ours: list, peer: list, keep: list) -> float | None:
    """The median of ours / peer over the seeds both solved (times, None: not solved) and ``keep``.

    >>> paired([1.0, 2.0, None, 1.0], [4.0, 1.0, 1.0, 2.0], [True, False, True, True])
    0.375
    """
    r = [a / b for a, b, k in zip(ours, peer, keep) if a is not None and b and k]
    return statistics.median(r) if r else None


def run_problem(path: str, seeds: int, limit: float, repeats: int) -> dict:
    """Ours and the peer on one problem, interleaved per seed, every path judged afterwards."""
    from cspace.io.load import load_scenario
    from planners.core.plan import build_cspace, make_adapter

    c0 = time.process_time()
    sc = load_scenario(path)
    cs = build_cspace(sc)
    for k in range(getattr(cs, "slabs", 0)):  # the C-space's slabs, once (as the peer's checker is built once)
        cs.slab(k)
    adapter = make_adapter(sc, cs)
    prep = time.process_time() - c0
    checker = se2_peers.coal_checker(cs.obstacle_pieces, cs.robot_pieces, sc.bounds)
    q = sc.all_queries()[0]
    start, goal = adapter.pose(q.start), adapter.pose(q.goal)

    def one_round(seed):
        return {"ours": se2_peers.ours_first(sc, cs, adapter, q, seed, limit, "auto"),
                "coal": se2_peers.peer_first(adapter, checker, start, goal, seed, limit, "RRTConnect")}

    runs = []
    for seed in range(seeds):
        rounds = [one_round(seed)]
        if max(c for _, c in rounds[0].values()) < REPEAT_BELOW:
            rounds += [one_round(seed) for _ in range(repeats - 1)]
        row = {"seed": seed, "rounds": len(rounds)}
        for m, (p, _) in rounds[0].items():  # the same seed: the same path in every round
            row[f"{m}_s"] = statistics.median(r[m][1] for r in rounds) if p is not None else None
            row[f"{m}_path"] = p
        runs.append(row)
    for row in runs:  # the judge runs after the timed runs: its sweeps would flush the caches between them
        for m in ("ours", "coal"):
            p = row.pop(f"{m}_path")
            row[m] = None if p is None else verdict(sweep_check(sc, p))
    return {"problem": sc.name, "file": os.path.basename(path), "vertices": sum(len(o.polygon) for o in sc.obstacles),
            "prep_s": prep, "runs": runs}


def summary(r: dict) -> dict:
    """A row of the table: solved, medians, the judge's counts, the ratios and the target."""
    runs = r["runs"]
    med = lambda v: statistics.median(v) if v else None  # noqa: E731
    ours = [x["ours_s"] for x in runs]
    coal = [x["coal_s"] for x in runs]
    sound = [x["coal"] == "sound" for x in runs]
    ratio = paired(ours, coal, sound)
    return {"problem": r["problem"], "vertices": r["vertices"], "seeds": len(runs), "prep_s": r["prep_s"],
            "ours_solved": sum(t is not None for t in ours), "ours_median_s": med([t for t in ours if t is not None]),
            "ours_not_sound": sum(x["ours"] not in (None, "sound") for x in runs),
            "coal_solved": sum(t is not None for t in coal), "coal_median_s": med([t for t in coal if t is not None]),
            "coal_colliding": sum(x["coal"] in ("colliding", "out of bounds") for x in runs),
            "coal_undecided": sum(x["coal"] == "undecided" for x in runs),
            "ratio_sound": ratio, "sound_seeds": sum(a is not None and b is not None and k
                                                     for a, b, k in zip(ours, coal, sound)),
            "ratio_all": paired(ours, coal, [True] * len(runs)),
            "target_met": ratio is not None and ratio <= TARGET}


def table(rows: list[dict]) -> str:
    """The printed table (CPU seconds; ratios over coal's sound seeds, and over all beside)."""
    s = lambda v: "-" if v is None else f"{v:.4f}"  # noqa: E731
    x = lambda v: "-" if v is None else f"{v:.2f}"  # noqa: E731
    head = (f"  {'problem':20} {'verts':>5} {'C-space':>8} {'ours':>6} {'ours s':>8} {'unsound':>7} {'coal':>6}"
            f" {'coal s':>8} {'rejected':>8} {'undec.':>6} {'ours/coal':>9} {'(all)':>6}  target <= {TARGET}x")
    lines = [head]
    for r in rows:
        n = r["seeds"]
        lines.append(f"  {r['problem']:20} {r['vertices']:>5} {r['prep_s']:8.3f} {r['ours_solved']:>3}/{n:<2}"
                     f" {s(r['ours_median_s']):>8} {r['ours_not_sound']:>7} {r['coal_solved']:>3}/{n:<2}"
                     f" {s(r['coal_median_s']):>8} {r['coal_colliding']:>8} {r['coal_undecided']:>6}"
                     f" {x(r['ratio_sound']):>9} {x(r['ratio_all']):>6}  "
                     + ("met" if r["target_met"] else "MISSED"))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--omplapp", default=os.environ.get("OMPLAPP", ""), metavar="DIR",
                    help="an OMPL.app checkout (github.com/ompl/omplapp) or its resources/2D; default: $OMPLAPP")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--time", type=float, default=10.0, help="seconds per run")
    ap.add_argument("--repeats", type=int, default=3, help=f"runs per method of a seed whose runs all take under "
                                                           f"{REPEAT_BELOW} s (the median is taken)")
    ap.add_argument("--problems", default="", help="only the problems whose file name contains one of these "
                                                   "comma-separated words (e.g. Maze,BugTrap)")
    ap.add_argument("--json", "--out-json", dest="json", metavar="FILE", help="write the rows and runs as JSON")
    args = ap.parse_args(argv)
    if args.seeds < 1 or not args.time > 0 or args.repeats < 1:
        ap.error(f"--seeds and --repeats: at least 1, --time: above 0 (got {args.seeds}, {args.repeats}, {args.time})")
    folder = resources(args.omplapp)
    if folder is None:
        print(f"no OMPL.app checkout at {args.omplapp!r} (give --omplapp DIR or set OMPLAPP): nothing run")
        return 0
    from benchutil import check_json, write_json

    check_json(args.json, [folder])  # (never over the checkout's files)
    words = [w for w in args.problems.split(",") if w]
    files = [f for f in PROBLEMS if os.path.isfile(os.path.join(folder, f)) and (not words or any(w in f for w in words))]
    if words and not files:
        ap.error(f"--problems: no problem of {', '.join(PROBLEMS)} matches {args.problems!r}")
    if importlib.util.find_spec("coal") is None:  # (every option checked first: a bad one is refused anyway)
        print("coal is not installed (pip install coal, or the bench extra): nothing run")
        return 0
    load = os.getloadavg()
    print(f"load average at start {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f} ({os.cpu_count()} CPUs)")
    skipped = [f for f in KINODYNAMIC if os.path.isfile(os.path.join(folder, f))]
    for f in skipped:
        print(f"{f}: skipped (a kinodynamic control problem: cspace plans no control space)")
    from benchutil import Progress

    progress = Progress(f"bench_omplapp: {len(files)} problems x {args.seeds} seeds, ours and coal, interleaved (the judge's sweeps aside)",
                        len(files), most_s=args.seeds * 2 * args.time, unit="problems")
    results = []
    for f in files:
        results.append(run_problem(os.path.join(folder, f), args.seeds, args.time, max(1, args.repeats)))
        progress.step(f)
    rows = [summary(r) for r in results]
    print("time to the first solution, CPU s (median over solved seeds): ours = auto, certified; coal = OMPL's "
          "RRTConnect with coal and its discrete motion check (1 % step);")
    print("rejected = coal's paths the sweep finds colliding; undec. = too close for the sweep to decide (not sound);")
    print("ours/coal = the median of per-seed ratios over the seeds whose coal path is sound, (all) over every seed")
    print(table(rows))
    faults = [(r["problem"], x["seed"], x["ours"]) for r in results for x in r["runs"] if x["ours"] not in (None, "sound")]
    for name, seed, v in faults:
        print(f"FAULT: ours on {name}, seed {seed}: the sweep says {v}")
    met = sum(r["target_met"] for r in rows)
    print(f"target ours/coal <= {TARGET}x over coal's sound seeds: met on {met} of {len(rows)} problems; "
          f"coal's paths rejected {sum(r['coal_colliding'] for r in rows)}, undecided "
          f"{sum(r['coal_undecided'] for r in rows)}; ours not sound {len(faults)}")
    if args.json:
        write_json(args.json, {"rows": rows, "skipped": skipped, "seeds": args.seeds, "time": args.time,
                               "load_start": list(load), "load_end": list(os.getloadavg()), "results": results})
    return 1 if faults else 0


if __name__ == "__main__":
    sys.exit(main())
