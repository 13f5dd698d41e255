"""``cspace plan``: plan a path for a scenario file, print a summary, write JSON and a plot."""
from __future__ import annotations

import sys
import time

from ..adapters.glue import OMPL_HINT, ompl_available
from ..output import PLOT_FORMATS, check_distinct, check_output, say, write_json
from ..pictures.titles import planner_words


def register(sub) -> None:
    p = sub.add_parser("plan", help="plan a collision-free path for a scenario",
                       description="Plan a path for a translating robot, a rotating one (--space se2) or a car "
                                   "(--space dubins / reeds-shepp); "
                                   "exit 0 solved, 1 not solved, 2 bad input.")
    p.add_argument("scenario", help="scenario TOML file, or a ROS map (.yaml), OMPL.app problem (.cfg), SVG "
                                    "drawing (.svg) or MovingAI map (.map) to import on the fly (see the options "
                                    "for imported files)")
    p.add_argument("--planner", help="OMPL planner (case-insensitive), 'exact' or 'auto' (the proof, the slab "
                                     "graph, sampling and refinement in one budget); default: the scenario's, else auto "
                                     "for a rotating robot or a car, RRTConnect for a translating one")
    p.add_argument("--time", type=number, help="time limit in seconds; default: the scenario's, else 1")
    p.add_argument("--seed", type=integer, help="random seed; default: the scenario's, else 0")
    p.add_argument("--iterations", type=integer, help="also stop after this many planner iterations (deterministic budget)")
    p.add_argument("--all-queries", action="store_true", help="plan every [[queries]] entry on one C-space")
    p.add_argument("--queries", metavar="FILE", help="plan these [[queries]] (a TOML file of start/goal tables) "
                                                     "instead of the scenario's, all on one C-space")
    p.add_argument("--no-simplify", action="store_true", help="keep the planner's raw path")
    add_space_options(p)
    add_car_and_margin_options(p)
    p.add_argument("--plot", help="save a picture of the path (.png, .svg or .pdf)")
    p.add_argument("--animate", help="save an animation of the robot moving along the path (.gif)")
    p.add_argument("--html", help="write one offline, interactive page of the plan (.html; needs plotly), "
                                  "as `cspace view` does")
    p.add_argument("--json", help="write the result as JSON")
    p.add_argument("--csv", help="write the path's waypoints as CSV (x,y or x,y,theta, with a header)")
    p.add_argument("--bench-mr-json", metavar="FILE", help="write the plan (each query a run) in Bench-MR's results "
                                                           "format, with its metrics (needs OMPL)")
    p.add_argument("--proof", help="a rotating robot or a car proven to have no path: write the proof (JSON), "
                                   "which `cspace check-proof SCENARIO PROOF` re-checks independently")
    from ..adapters.objectives import OBJECTIVE_PLANNERS, OBJECTIVES

    takers = f"{', '.join(OBJECTIVE_PLANNERS[:-1])} or {OBJECTIVE_PLANNERS[-1]}"
    p.add_argument("--objective", choices=OBJECTIVES, default="length",
                   help="what the planner minimises: path length (default), the inverse of the minimum "
                        "clearance, or length weighted by clearance; clearance and balanced only with "
                        f"the planners {takers}, in space translation or se2")
    p.add_argument("--verbose", "-v", action="store_true", help="print the C-space report and OMPL's messages")
    from .imports import add_import_options
    from .scen import add_scen_options

    add_import_options(p)
    add_scen_options(p)
    p.set_defaults(run=run)


def add_space_options(p) -> None:
    """``--space`` and ``--slabs`` (plan, show and bench share them)."""
    p.add_argument("--space", choices=("translation", "se2", "dubins", "reeds-shepp"),
                   help="state space: translation (the robot keeps its angle), se2 (it also rotates), "
                        "dubins or reeds-shepp (a car: forward only, or forward and reverse, along arcs "
                        "of a minimum turning radius); default: the scenario's, else translation")
    p.add_argument("--slabs", type=integer, help="SE(2): angle slabs of the sliced C-space (default: derived "
                                                 "from the robot and the scene)")


def add_car_and_margin_options(p) -> None:
    """``--turning-radius`` and ``--clearance`` (plan and view share them)."""
    p.add_argument("--turning-radius", type=number, help="a car's minimum turning radius (space dubins or "
                                                         "reeds-shepp); default: the scenario's")
    p.add_argument("--clearance", type=number, help="safety margin D: keep the robot at least D from every "
                                                     "obstacle (default: the scenario's clearance, else 0)")


def check_clearance(args, src: str) -> None:
    """``--clearance``: a finite margin of the supported magnitudes (one line, exit 2, otherwise)."""
    if args.clearance is not None:
        from cspace.io.scenario.fields import clearance_fault

        from ..errors import InputError

        if fault := clearance_fault(args.clearance):
            raise InputError(src, "--clearance", fault)


def number(s: str) -> float:
    return float(s)


def integer(s: str) -> int:
    return int(s)


def run(args) -> int:
    from cspace.io.scenario.files import check_input

    from ..errors import InputError

    src = args.scenario
    if args.time is not None and not args.time > 0:
        raise InputError(src, "--time", f"must be a positive number of seconds, got {args.time}")
    if args.seed is not None and args.seed < 0:
        raise InputError(src, "--seed", f"must be a non-negative integer, got {args.seed}")
    if args.iterations is not None and args.iterations < 1:
        raise InputError(src, "--iterations", f"must be a positive integer, got {args.iterations}")
    check_clearance(args, src)
    if args.slabs is not None and not 4 <= args.slabs <= 4096:
        raise InputError(src, "--slabs", f"must be an integer from 4 to 4096, got {args.slabs}")
    from ..adapters.glue import MAX_TIME, SEED_LIMIT, planner_name

    if args.time is not None and args.time > MAX_TIME:
        raise InputError(src, "--time", f"at most {MAX_TIME:g} s (OMPL's clock overflows near 8e9 s), got {args.time:g}")
    if args.seed is not None and args.seed >= SEED_LIMIT:
        raise InputError(src, "--seed", f"must be below 2^32 - 1 (OMPL's seeds are 32-bit), got {args.seed}")
    if args.planner is not None:
        args.planner = planner_name(args.planner, src, "--planner")
        if args.planner != "exact" and not ompl_available():
            raise InputError(src, "--planner", f"{args.planner} needs OMPL, which is not installed "
                             f"({OMPL_HINT}); --planner exact works without it")
    elif not ompl_available():
        sys.stderr.write("note: OMPL is not installed: planning with the exact planner instead "
                         f"({OMPL_HINT})\n")
        args.planner = "exact"
    if args.objective != "length":
        from ..adapters.objectives import check_objective

        try:
            check_objective(args.objective, args.planner or "RRTConnect")
        except ValueError as exc:
            if args.planner is not None:
                raise InputError(src, "--objective", str(exc)) from None
    check_input(src)
    from .imports import import_options

    options = import_options(args, src)
    queries = None
    if args.queries is not None:
        from cspace.io.load import read_toml

        check_input(args.queries)
        queries = read_toml(args.queries)
        args.all_queries = True
        first = (queries.get("queries") or [{}])[0] if isinstance(queries.get("queries"), list) else {}
        from_queries = set()
        if options is not None and isinstance(first, dict):  # a map has no start: the first query's
            for key in ("start", "goal"):
                if getattr(options, key) is None and _pose(first.get(key)) is not None:
                    setattr(options, key, _pose(first.get(key)))
                    from_queries.add(key)
    from .scen import scen_rows

    rows = scen_rows(args, src)  # --scen: a MovingAI scenario file's rows as the queries
    if rows is not None:
        args.all_queries = True
    from .imports import input_files

    inputs = input_files(src, args.robot, args.queries, args.scen)  # every file read, the import's included
    fmt = check_output(args.plot, "--plot", PLOT_FORMATS, inputs=inputs) if args.plot is not None else None
    if args.animate is not None:
        check_output(args.animate, "--animate", {".gif": "gif"}, inputs=inputs)
    if args.html is not None:
        check_output(args.html, "--html", {".html": "html", ".htm": "html"}, inputs=inputs)
        from ..pictures.view import check_plotly

        check_plotly(args.html, "--html")
    if args.json is not None:
        check_output(args.json, "--json", inputs=inputs)
    if args.csv is not None:
        check_output(args.csv, "--csv", inputs=inputs)
    if args.proof is not None:
        check_output(args.proof, "--proof", inputs=inputs)
    if args.bench_mr_json is not None:
        check_output(args.bench_mr_json, "--bench-mr-json", inputs=inputs)
        if not ompl_available():
            raise InputError(src, "--bench-mr-json", f"Bench-MR's metrics interpolate with OMPL ({OMPL_HINT})")
    check_distinct([(args.json, "--json"), (args.plot, "--plot"), (args.animate, "--animate"), (args.html, "--html"),
                    (args.csv, "--csv"), (args.proof, "--proof"), (args.bench_mr_json, "--bench-mr-json")])
    from ..core.plan import plan

    if args.verbose and args.planner != "exact":
        from ..adapters.glue import ompl

        ompl()[2].setLogLevel(ompl()[2].LOG_INFO)
    from cspace.io.load import ScenarioError

    scenario = src
    t_import = time.perf_counter()  # a load done here (an import, a queries file) is this run's load
    outputs = [(args.json, "--json"), (args.plot, "--plot"), (args.animate, "--animate"), (args.html, "--html"),
               (args.csv, "--csv"), (args.proof, "--proof"), (args.bench_mr_json, "--bench-mr-json")]
    if rows is not None:  # a MovingAI map and its .scen rows
        from .scen import scen_scenario

        scenario, kept = scen_scenario(args, src, options, rows, outputs)
    elif options is not None:  # a map or an OMPL.app problem: imported here, planned as a scenario
        from .imports import imported_scenario

        try:
            scenario = imported_scenario(args, src, options, outputs)
        except ScenarioError as exc:
            if queries is not None and exc.field in from_queries:  # the pose came from the queries file
                raise InputError(args.queries, f"queries[0].{exc.field}", exc.message) from None
            raise
    if queries is not None:
        from cspace.io.load import load_scenario
        from cspace.io.scenario.validate import with_queries

        if options is None:
            scenario = load_scenario(src, space=args.space, turning_radius=args.turning_radius)
        scenario = with_queries(scenario, queries, args.queries)
    import_s = time.perf_counter() - t_import
    try:
        loaded = options is not None or queries is not None  # a Scenario, its space and radius applied (--scen too)
        res = plan(scenario, planner=args.planner, time=args.time, seed=args.seed, iterations=args.iterations,
                   simplify=not args.no_simplify, all_queries=args.all_queries,
                   space=None if loaded else args.space, slabs=args.slabs,
                   turning_radius=None if loaded else args.turning_radius,
                   clearance=args.clearance, objective=args.objective)
    except ScenarioError as exc:
        if exc.file == "plan()" and exc.field == "objective":  # the file's planner takes no objective
            raise InputError(src, "--objective", exc.message) from None
        raise
    if options is not None or queries is not None:  # loaded here, not by plan()
        from .imports import count_as_load

        count_as_load(res, import_s)
    gone = say(summary(res, verbose=args.verbose))
    doc = res.as_dict()
    if args.json is not None and ompl_available():  # Bench-MR's metrics of every solved path, beside ours
        from ..bench.benchmr import result_metrics

        doc["bench_mr"] = result_metrics(res)
        for q, r in zip(doc.get("queries", []), res.queries or []):
            q["bench_mr"] = result_metrics(r, res.scenario_data)
    if rows is not None:
        from .scen import annotate

        gone = say("\n".join(annotate(doc, rows, kept, res.queries or [res])), gone)
    if args.json is not None:
        write_json(args.json, doc, "--json")
    if args.bench_mr_json is not None:
        from ..bench.benchmr_results import results_document

        write_json(args.bench_mr_json, results_document(res), "--bench-mr-json")
    if args.csv is not None:
        write_paths_csv(args.csv, res)
    if args.plot is not None:
        from ..pictures.plot import plot_result

        plot_result(res, args.plot, fmt=fmt)
    if args.animate and res.solved:
        from ..pictures.animate import animate_path

        t0 = time.perf_counter()
        frames = animate_path(res, args.animate)
        sys.stderr.write(f"animation: {args.animate} written ({frames} frames, {time.perf_counter() - t0:.1f} s)\n")
    elif args.animate:
        sys.stderr.write(f"note: --animate {args.animate}: nothing to animate (not solved)\n")
    if args.html is not None:
        from ..pictures.view import write_view

        write_view(res, args.html)
    results = res.queries or [res]
    if args.proof is not None:
        write_proof(args.proof, results)
    if gone:  # every file asked for is written: now end as the closed pipe asks (141)
        raise BrokenPipeError
    return 0 if all(r.solved for r in results) and (rows is None or len(kept) == len(rows)) else 1


def write_paths_csv(path: str, res) -> None:
    """``--csv``: the path's waypoints; with several queries (``--all-queries``, ``--queries``)
    every solved query's, with a ``query`` column (a note names the unsolved ones)."""
    from ..output import queries_csv, write_csv, write_text

    dim = res.path.shape[1] if res.path.ndim == 2 else 2
    if not res.queries:
        if res.solved:
            write_csv(path, res.path, dim)
        else:
            sys.stderr.write(f"note: --csv {path}: no path to write (not solved)\n")
        return
    solved = [(i, r.path) for i, r in enumerate(res.queries) if r.solved]
    missing = [str(i) for i, r in enumerate(res.queries) if not r.solved]
    if solved:
        dim = solved[0][1].shape[1] if solved[0][1].ndim == 2 else 2
        write_text(path, queries_csv(solved, dim), "--csv")
    if missing:
        sys.stderr.write(f"note: --csv {path}: no path for query {', '.join(missing)} (not solved)\n")


def _pose(value):
    """A queries file's pose as the import's start or goal (None if it is not 2 or 3 numbers:
    the queries' own check then names the fault)."""
    if isinstance(value, list) and 2 <= len(value) <= 3 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                                 for v in value):
        return tuple(float(v) for v in value)
    return None


def write_proof(path: str, results: list) -> None:
    """The first proven query's proof, written atomically (a note when there is none)."""
    proven = [(i, r) for i, r in enumerate(results) if r.proof is not None]
    if not proven:
        sys.stderr.write(f"note: --proof {path}: no proof to write (no query was proven unsolvable"
                         f"{'' if results[0].path.shape[-1] == 3 else ': proofs are for rotating robots and cars'})\n")
        return
    i, r = proven[0]
    write_json(path, r.proof, "--proof")
    if len(results) > 1:
        sys.stderr.write(f"note: --proof {path}: the proof of query {i} (check it with --query {i})\n")


def summary(res, verbose: bool = False) -> str:
    """A short human summary of a plan.

    With several queries: one line per query (with its own stage times), then the
    count, then the whole run's total on a line of its own.
    """
    lines = []
    results = res.queries or [res]
    for i, r in enumerate(results):
        tag = f"{r.scenario}" + (f" query {i}" if res.queries else "")
        by = planner_words(r)
        if r.solved:
            lines.append(f"{tag}: solved by {by}: length {r.length:.6g}, "
                         f"{len(r.path)} waypoints, solve {r.timings.get('solve', 0.0) * 1e3:.1f} ms")
        elif r.proven_unsolvable:  # its message says by which proof
            lines.append(f"{tag}: {r.message}")
        elif r.planner == "exact":
            lines.append(f"{tag}: NOT solved by exact: {r.message}")
        else:
            lines.append(f"{tag}: NOT solved by {by} within the limit: {r.message}")
        if r.solved and r.path.shape[1] == 3 and (r.planner == "exact" or r.answered_by in ("slab graph", "refinement")):
            lines.append(r.message)
        if r.solved:
            lines.append(clearance_line(r))
    if res.queries:
        for i, r in enumerate(res.queries):
            lines.append(f"query {i} time: " + _times(r.timings, skip=("load", "cspace", "total")))
        n = sum(r.solved for r in res.queries)
        lengths = [r.length for r in res.queries if r.solved]
        mean = f", mean length {sum(lengths) / len(lengths):.6g}" if lengths else ""
        lines.append(f"{n}/{len(res.queries)} queries solved{mean}")
        t = res.timings
        lines.append("total time: " + _times({k: t[k] for k in ("load", "cspace", "total") if k in t}))
    else:
        lines.append("time: " + _times(res.timings))
    lines.append("stages: " + " -> ".join(res.stages))
    if verbose and res.cspace_report and "slabs" in res.cspace_report:  # a rotating robot's sliced C-space
        lines += se2_report_lines(res.cspace_report)
        lines.append(f"checks: {res.checks}")
    elif verbose and res.cspace_report:
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


def se2_report_lines(rep: dict) -> list[str]:
    """The sliced C-space of a rotating robot in words: K and why, the pieces, the slabs built.

    >>> se2_report_lines({"slabs": 8, "slabs_reason": "given", "obstacle_pieces": 2, "robot_pieces": 1,
    ...                   "setup_seconds": 0.001, "build_seconds": 0.002, "slabs_built": []})[0]
    'C-space: 8 slabs (given), 2 obstacle pieces x 1 robot pieces, setup 1.0 ms; 0 slabs built in 2.0 ms'
    """
    lines = [f"C-space: {rep['slabs']} slabs ({rep['slabs_reason']}), {rep['obstacle_pieces']} obstacle pieces x "
             f"{rep['robot_pieces']} robot pieces, setup {rep['setup_seconds'] * 1e3:.1f} ms; "
             f"{len(rep['slabs_built'])} slabs built in {rep['build_seconds'] * 1e3:.1f} ms"]
    for d in rep["slabs_built"]:
        lines.append(f"  slab {d['slab']:<5} {d['seconds'] * 1e3:8.2f} ms  {d['pieces']} pieces, "
                     f"{d.get('inner_pieces', 0)} certified-blocked pieces")
    return lines


def clearance_line(r) -> str:
    """The clearance of a solved path, in words: how close the robot comes, where, and
    whether the path touches (exact without a clearance: the limit of free paths).

    >>> class R: min_clearance, min_clearance_at, min_clearance_bound, touches, clearance = 0.5, (1.0, 2.0), "exact", False, 0.0
    >>> clearance_line(R())
    'min clearance 0.5 at (1, 2) (exact)'
    """
    c = r.min_clearance
    if c is None:
        return "min clearance: not measured"
    if c == float("inf"):
        return "min clearance: inf (no obstacle)"
    at = ", ".join(f"{v:.6g}" for v in (r.min_clearance_at or ()))
    kind = "a certified lower bound" if r.min_clearance_bound == "lower" else "exact"
    text = f"min clearance {c:.6g} at ({at}) ({kind})"
    if r.clearance > 0:
        text += f", margin asked {r.clearance:g}"
    if r.touches:
        text += ("; the path TOUCHES obstacles (the limit of free paths, not drivable as it is): "
                 "set a clearance (--clearance D) to keep away from them")
    return text


def _times(t: dict, skip=()) -> str:
    """``name 1.2 ms, ...`` for a timings dict.

    >>> _times({"solve": 0.0012, "total": 0.5}, skip=("total",))
    'solve 1.2 ms'
    """
    return ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in t.items() if k not in skip)
