"""``cspace recheck RESULTS.json``: re-check every path of a results file in Bench-MR's format (a
Bench-MR run's, or ``cspace plan --bench-mr-json``'s) against its environment, exactly: the
robot swept along each motion of the steer function (:mod:`planners.bench.benchmr_results`).
Per planner: the paths, how many the file calls collision-free, how many collide, the first
colliding pose. Exit 0 when no path called collision-free collides, 1 otherwise, 2 bad input."""
from __future__ import annotations


HELP = "re-check the paths of a Bench-MR results file exactly (any planner's)"


def register(sub) -> None:
    p = sub.add_parser("recheck", help=HELP,
                       description="Re-check every path of a results file in Bench-MR's format against its "
                                   "environment with the exact swept footprint check. Exit 0 no path called "
                                   "collision-free collides, 1 some do, 2 bad input.")
    p.add_argument("results", help="a results JSON in Bench-MR's format")
    p.add_argument("--steering", choices=("reeds_shepp", "dubins", "linear"),
                   help="the steer function between waypoints (default: the file's settings.steering)")
    p.add_argument("--json", help="write the per-planner counts and every colliding path as JSON")
    p.set_defaults(run=run)


def run(args) -> int:
    import time

    from ..bench.benchmr_results import per_planner, read_results, recheck
    from ..output import check_output, say, write_json

    if args.json is not None:
        check_output(args.json, "--json", inputs=[args.results])
    doc = read_results(args.results)
    t0 = time.perf_counter()
    rows = recheck(doc, args.results, args.steering)
    seconds = time.perf_counter() - t0
    summary = per_planner(rows)
    lines = []
    for name, d in sorted(summary.items()):
        first = (f"; first colliding pose ({', '.join(f'{v:.6g}' for v in d['first']['pose'])}) in run "
                 f"{d['first']['run']}" if d["first"] else "")
        lines.append(f"{name}: {d['paths']} paths, {d['called_free']} called collision-free, {d['colliding']} collide "
                     f"({d['called_free_colliding']} of those called free){first}")
    gone = say("\n".join(lines + [f"rechecked {len(rows)} paths in {seconds:.2f} s"]))  # (then --json all the same)
    if args.json is not None:
        write_json(args.json, {"planners": summary, "paths": rows, "seconds": seconds}, "--json")
    if gone:
        raise BrokenPipeError
    return 1 if any(d["called_free_colliding"] for d in summary.values()) else 0
