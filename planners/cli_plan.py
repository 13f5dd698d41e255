"""``cspace plan``: plan a path for a scenario file, print a summary, write JSON and a plot."""
from __future__ import annotations

import sys

from .output import PLOT_FORMATS, check_distinct, check_output, write_json


def register(sub) -> None:
    p = sub.add_parser("plan", help="plan a collision-free path for a scenario",
                       description="Plan a path for a translating robot; exit 0 solved, 1 not solved, 2 bad input.")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--planner", help="OMPL planner (case-insensitive) or 'exact'; default: the scenario's, else RRTConnect")
    p.add_argument("--time", type=number, help="time limit in seconds; default: the scenario's, else 1")
    p.add_argument("--seed", type=integer, help="random seed; default: the scenario's, else 0")
    p.add_argument("--iterations", type=integer, help="also stop after this many planner iterations (deterministic budget)")
    p.add_argument("--all-queries", action="store_true", help="plan every [[queries]] entry on one C-space")
    p.add_argument("--no-simplify", action="store_true", help="keep the planner's raw path")
    p.add_argument("--plot", help="save a picture of the path (.png, .svg or .pdf)")
    p.add_argument("--json", help="write the result as JSON")
    p.add_argument("--verbose", "-v", action="store_true", help="print the C-space report and OMPL's messages")
    p.set_defaults(run=run)


def number(s: str) -> float:
    return float(s)


def integer(s: str) -> int:
    return int(s)


def run(args) -> int:
    from cspace.scenario import MAX_SEED, check_input

    from .errors import InputError

    src = args.scenario
    if args.time is not None and not args.time > 0:
        raise InputError(src, "--time", f"must be a positive number of seconds, got {args.time}")
    if args.seed is not None and args.seed < 0:
        raise InputError(src, "--seed", f"must be a non-negative integer, got {args.seed}")
    if args.iterations is not None and args.iterations < 1:
        raise InputError(src, "--iterations", f"must be a positive integer, got {args.iterations}")
    if args.seed is not None and args.seed > MAX_SEED:
        raise InputError(src, "--seed", f"must be at most 2^63 - 1, got {args.seed}")
    check_input(src)
    fmt = check_output(args.plot, "--plot", PLOT_FORMATS, inputs=[src]) if args.plot is not None else None
    if args.json is not None:
        check_output(args.json, "--json", inputs=[src])
    check_distinct([(args.json, "--json"), (args.plot, "--plot")])
    from .plan import plan

    if args.verbose:
        from .ompl_glue import ompl

        ompl()[2].setLogLevel(ompl()[2].LOG_INFO)
    res = plan(src, planner=args.planner, time=args.time, seed=args.seed, iterations=args.iterations,
               simplify=not args.no_simplify, all_queries=args.all_queries)
    print(summary(res, verbose=args.verbose))
    if args.json is not None:
        write_json(args.json, res.as_dict(), "--json")
    if args.plot is not None:
        from .plot import plot_result

        plot_result(res, args.plot, fmt=fmt)
    results = res.queries or [res]
    return 0 if all(r.solved for r in results) else 1


def summary(res, verbose: bool = False) -> str:
    """A short human summary of a plan."""
    lines = []
    results = res.queries or [res]
    for i, r in enumerate(results):
        tag = f"{r.scenario}" + (f" query {i}" if res.queries else "")
        if r.solved:
            lines.append(f"{tag}: solved by {r.planner} (seed {r.seed}): length {r.length:.6g}, "
                         f"{len(r.path)} waypoints, solve {r.timings.get('solve', 0.0) * 1e3:.1f} ms")
        else:
            lines.append(f"{tag}: NOT solved by {r.planner} (seed {r.seed}) within the limit: {r.message}")
    if res.queries:
        n = sum(r.solved for r in res.queries)
        lengths = [r.length for r in res.queries if r.solved]
        mean = sum(lengths) / len(lengths) if lengths else float("nan")
        lines.append(f"{n}/{len(res.queries)} queries solved, mean length {mean:.6g}")
    t = res.timings
    lines.append("time: " + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in t.items()))
    lines.append("stages: " + " -> ".join(res.stages))
    if verbose and res.cspace_report:
        rep = res.cspace_report
        lines.append(f"C-space: {rep['pieces']} pieces ({rep['obstacle_pieces']} obstacle pieces x "
                     f"{max(rep['robot_pieces'], 1)} robot pieces), build {rep['build_seconds'] * 1e3:.1f} ms")
        for s in rep["stages"]:
            counts = {k: v for k, v in s.items() if k not in ("stage", "ran", "seconds", "note")}
            state = "ran" if s["ran"] else "skipped"
            note = f" ({s['note']})" if s.get("note") else ""
            lines.append(f"  {s['stage']:<20} {state:<8} {s['seconds'] * 1e3:8.2f} ms  {counts}{note}")
        lines.append(f"checks: {res.checks}")
    return "\n".join(lines)
