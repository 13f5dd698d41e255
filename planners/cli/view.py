"""``cspace view``: plan a scenario and write one offline HTML page of the plan: the scene and
its C-space (for a rotating robot or a car, a slider over the angle), the robot moving along the
path (play / pause, a slider), the closest approach, a proof's note, and the plan's report."""
from __future__ import annotations

import sys

HELP = "plan a scenario and write one offline, interactive HTML page of the plan"


def register(sub) -> None:
    p = sub.add_parser("view", help=HELP,
                       description="Plan a path as `cspace plan` does and write a self-contained HTML page "
                                   "(plotly; opens offline, nothing fetched) showing the scene, the C-space, "
                                   "the robot moving along the path and the report; needs plotly "
                                   "(pip install -e \".[view]\"). Exit 0 solved, 1 not solved (the page is "
                                   "written either way), 2 bad input.")
    p.add_argument("scenario", help="scenario TOML file, map YAML (.yaml) or OMPL.app problem (.cfg)")
    p.add_argument("--out", required=True, metavar="FILE.html", help="the page to write")
    from .imports import add_import_options
    from .plan import add_car_and_margin_options, add_space_options, integer, number

    p.add_argument("--planner", help="OMPL planner (case-insensitive), 'exact' or 'auto'; default: the "
                                     "scenario's, else auto for a rotating robot or a car, RRTConnect for a "
                                     "translating one")
    p.add_argument("--time", type=number, help="time limit in seconds; default: the scenario's, else 1")
    p.add_argument("--seed", type=integer, help="random seed; default: the scenario's, else 0")
    add_space_options(p)
    add_car_and_margin_options(p)
    p.add_argument("--angles", type=integer, default=32,
                   help="rotating robots and cars: steps of the angle slider over the slab C-spaces (default 32)")
    p.add_argument("--poses", type=integer, default=120,
                   help="frames of the robot moving along the path (default 120)")
    p.add_argument("--no-compress", action="store_true",
                   help="inline plotly.js as plain text (about 4.8 MB) instead of gzip-packed (about 1.9 MB, "
                        "unpacked by the browser's DecompressionStream; browsers of 2023 on)")
    p.add_argument("--verbose", "-v", action="store_true",
                   help="print the plan in detail, as `cspace plan -v` does, and the time the page took")
    add_import_options(p)
    p.set_defaults(run=run)


def run(args) -> int:
    from cspace.io.scenario.files import check_input

    from ..adapters.glue import MAX_TIME, OMPL_HINT, SEED_LIMIT, ompl_available, planner_name
    from ..errors import InputError
    from ..output import check_output, say

    src = args.scenario
    if args.time is not None and not 0 < args.time <= MAX_TIME:
        raise InputError(src, "--time", f"must be a positive number of seconds up to {MAX_TIME:g}, got {args.time}")
    if args.seed is not None and not 0 <= args.seed < SEED_LIMIT:
        raise InputError(src, "--seed", f"must be a non-negative integer below 2^32 - 1, got {args.seed}")
    if args.slabs is not None and not 4 <= args.slabs <= 4096:
        raise InputError(src, "--slabs", f"must be an integer from 4 to 4096, got {args.slabs}")
    if not 1 <= args.angles <= 720:
        raise InputError(src, "--angles", f"must be an integer from 1 to 720, got {args.angles}")
    if not 2 <= args.poses <= 2000:
        raise InputError(src, "--poses", f"must be an integer from 2 to 2000, got {args.poses}")
    from .imports import import_options, input_files
    from .plan import check_clearance

    check_clearance(args, src)
    check_input(src)
    options = import_options(args, src)
    check_output(args.out, "--out", {".html": "html", ".htm": "html"}, inputs=input_files(src, args.robot, None))
    from ..pictures.view import check_plotly

    check_plotly(args.out, "--out")
    if args.planner is not None:
        args.planner = planner_name(args.planner, src, "--planner")
        if args.planner != "exact" and not ompl_available():
            raise InputError(src, "--planner", f"{args.planner} needs OMPL, which is not installed ({OMPL_HINT})")
    elif not ompl_available():
        sys.stderr.write(f"note: OMPL is not installed: planning with the exact planner instead ({OMPL_HINT})\n")
        args.planner = "exact"
    import time

    from ..core.plan import plan
    from ..pictures.view import write_view
    from .plan import summary

    scenario, t_import = src, time.perf_counter()
    if options is not None:  # a map or an OMPL.app problem: imported here, as `cspace plan` does
        from .imports import imported_scenario

        scenario = imported_scenario(args, src, options, [(args.out, "--out")])
    import_s = time.perf_counter() - t_import
    loaded = options is not None  # a Scenario, its space and radius applied
    res = plan(scenario, planner=args.planner, time=args.time, seed=args.seed, slabs=args.slabs,
               space=None if loaded else args.space, turning_radius=None if loaded else args.turning_radius,
               clearance=args.clearance)
    if loaded:  # the import's time is this run's load
        from .imports import count_as_load

        count_as_load(res, import_s)
    gone = say(summary(res, verbose=args.verbose))  # (a reader gone: the page is still written)
    t0 = time.perf_counter()
    write_view(res, args.out, poses=args.poses, angles=args.angles, compress=not args.no_compress, option="--out")
    if args.verbose:
        gone = say(f"page: {args.out} written in {time.perf_counter() - t0:.2f} s", gone)
    if gone:
        raise BrokenPipeError
    return 0 if res.solved else 1
