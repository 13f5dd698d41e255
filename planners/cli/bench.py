"""``cspace bench``: the command line of the error-against-run-time sweep (:mod:`planners.bench`)."""
from __future__ import annotations

import math
import os
import sys
import time

from ..adapters.objectives import OBJECTIVES
from ..bench.clearance import check_planners, check_scenarios, default_planners
from ..bench.outputs import OUTPUTS, clear_outputs, write_deferring_sigint
from ..bench.reference import make_tasks, reference
from ..bench.rows import HARD_FACTOR, HARD_MARGIN
from ..bench.sweep import summary, sweep
from ..errors import InputError
from . import interrupt


DEFAULT_PLANNERS = ("RRTConnect", "RRTstar", "PRMstar", "BITstar")


DEFAULT_TIMES = (0.01, 0.03, 0.1, 0.3, 1.0)


MAX_BUDGET = 1e6  # seconds per run (11 days); OMPL's clock overflows near 8e9 s


MAX_RUNS = 100_000  # runs in one sweep (scenes x planners x budgets x --runs): a sweep's tasks and
# rows are held in memory, and 10^5 runs of 0.01 s already take hours; a campaign goes in parts (--db)


def register(sub) -> None:
    import argparse

    p = sub.add_parser("bench", help="error against run time for OMPL planners vs the exact shortest path",
                       description="Benchmark OMPL planners: path length error against the exact shortest "
                                   "path, per time budget. Exit 0 done, 2 bad input, 130 interrupted "
                                   "(finished rows are written), 143 "
                                   "terminated (SIGTERM, as Ctrl-C).")
    p.add_argument("scenario", nargs="+", help="scenario TOML files")
    p.add_argument("--planners", help=f"comma-separated OMPL planners or auto (default {','.join(DEFAULT_PLANNERS)}; "
                                      "with --objective clearance or balanced, those of them that take it)")
    p.add_argument("--times", default=",".join(f"{t:g}" for t in DEFAULT_TIMES),
                   help="comma-separated time budgets in seconds (default 0.01,0.03,0.1,0.3,1)")
    p.add_argument("--runs", type=int, default=10, help="seeded runs per planner and budget (seeds 0..N-1)")
    p.add_argument("--iterations", type=int, help="also stop each run after this many planner iterations")
    p.add_argument("--workers", type=int, default=1, help="runs in parallel (local processes)")
    p.add_argument("--out", default="bench_out", help="output folder (created if missing)")
    p.add_argument("--scheduler", help="address of a Dask distributed scheduler to run on (tcp://HOST:8786): "
                                       "runs go in batches, each worker builds a scenario's C-space once")
    p.add_argument("--objective", choices=OBJECTIVES, default="length",
                   help="what the optimising planners (RRTstar, SORRTstar, BITstar) optimise: path length "
                        "(default), the minimum clearance, or length weighted by clearance")
    p.add_argument("--no-plot", action="store_true", help="skip error_vs_time.png")
    p.add_argument("--db", help="benchmark database (SQLite, Planner Arena's schema): each finished run is "
                                "stored as it arrives; created if missing")
    p.add_argument("--resume", action="store_true", help="with --db: skip the runs the database already holds")
    p.add_argument("--log", metavar="DIR", help="write OMPL benchmark logs (one per experiment) into DIR")
    from ..cli.plan import add_space_options

    add_space_options(p)
    p.add_argument("--quiet", "-q", action="store_true",
                   help="no progress bar and no reference lines (the summary table still prints)")
    # Test hook: the child of this (planner, seed) calls os.abort(), as a segfaulting planner would.
    p.add_argument("--abort-on", help=argparse.SUPPRESS)
    p.set_defaults(run=run)


def parse_planners(text: str, source: str = "bench") -> list[str]:
    """Canonical planner names from a comma-separated list: OMPL's, and ``auto`` (``exact`` is the
    reference, not a contestant).

    >>> parse_planners("rrtconnect,BITstar,AUTO")
    ['RRTConnect', 'BITstar', 'auto']
    """
    from ..adapters.glue import PLANNERS

    table = {p.lower(): p for p in PLANNERS}
    table["auto"] = "auto"
    names = [s.strip() for s in str(text).split(",") if s.strip()]
    if not names:
        raise InputError(source, "--planners", "empty list")
    out = []
    for n in names:
        canon = table.get(n.lower())
        if canon is None:
            raise InputError(source, "--planners", f"unknown planner {n!r} (choose from: auto, {', '.join(PLANNERS)})")
        if canon in out:
            raise InputError(source, "--planners", f"planner {canon} given twice")
        out.append(canon)
    return out


def parse_times(text: str, source: str = "bench") -> list[float]:
    """Time budgets from a comma-separated list: positive, finite, distinct; returned sorted.

    >>> parse_times("1,0.01,0.1")
    [0.01, 0.1, 1.0]
    """
    parts = [s.strip() for s in str(text).split(",")]
    if not parts or any(not s for s in parts):
        raise InputError(source, "--times", f"expected comma-separated seconds, got {text!r}")
    out = []
    for s in parts:
        try:
            t = float(s)
        except ValueError:
            raise InputError(source, "--times", f"not a number: {s!r}") from None
        if not (math.isfinite(t) and t > 0):
            raise InputError(source, "--times", f"must be positive seconds, got {s!r}")
        if t > MAX_BUDGET:
            raise InputError(source, "--times", f"at most {MAX_BUDGET:g} s per run, got {s!r}")
        if t in out:
            raise InputError(source, "--times", f"budget {s} given twice")
        out.append(t)
    return sorted(out)


def check_inputs_kept(files: list[str], out: str) -> None:
    """Refuse a sweep that would write or clear one of its inputs (a scenario, a map's image,
    a cfg's mesh): results.json, results.csv, error_vs_time.png and ompl/*.log in ``out``."""
    from ..output import check_not_input
    from .imports import input_files

    inputs = [f for src in files for f in input_files(src)]
    targets = [os.path.join(out, name) for name in OUTPUTS]
    logs = os.path.join(out, "ompl")
    if os.path.isdir(logs):
        targets += [os.path.join(logs, name) for name in sorted(os.listdir(logs)) if name.endswith(".log")]
    for target in targets:
        try:
            st = os.stat(target)
        except (OSError, ValueError):
            st = None
        check_not_input(target, "--out", inputs, st)


def check_campaign(db: str | None, log: str | None, resume: bool, out: str, files=()) -> None:
    """--db, --log and --resume: exit 2 on a combination or a path that cannot work: the database
    or a log over one of ``out``'s outputs or an input, the logs in ``out``'s own ``ompl`` folder."""
    from ..output import check_folder
    from .imports import input_files

    if resume and not db:
        raise InputError("bench", "--resume", "needs --db (the database of the sweep to resume)")
    inputs = [f for src in files for f in input_files(src)]
    if db is not None:
        if not db.strip() or os.path.isdir(db):
            raise InputError("bench", "--db", f"not a file name: {db!r}")
        parent = os.path.dirname(os.path.abspath(db))
        if not os.path.isdir(parent):
            raise InputError("bench", "--db", f"folder {parent} does not exist")
        for target in [os.path.join(out, name) for name in OUTPUTS] + [os.path.join(out, "ompl")]:
            if _same_place(db, target) or _same_place(os.path.dirname(os.path.abspath(db)), target):
                raise InputError(db, "--db", f"is in --out's outputs ({target}); give a path outside them")
        if log is not None and db.endswith(".log") and _same_place(os.path.dirname(os.path.abspath(db)), log):
            raise InputError(db, "--db", f"is named like a log in --log {log}, which would write over it")
    if log is not None:
        check_folder(log, "--log")
        if _same_place(log, os.path.join(out, "ompl")):
            raise InputError(log, "--log", "is --out's own ompl folder, which each sweep rewrites; give another")
        for f in inputs:
            if f.endswith(".log") and _same_place(os.path.dirname(os.path.abspath(f)), log):
                raise InputError(log, "--log", f"holds the input {f}, which a log of that name would replace")


def _same_place(a: str, b: str) -> bool:
    """Whether two paths name one file or folder (existing: by inode; else by resolved path)."""
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return os.path.realpath(a) == os.path.realpath(b)


def check_size(count: int, source: str = "bench") -> None:
    """Refuse a sweep of more than :data:`MAX_RUNS` runs (before anything is allocated for it)."""
    if count > MAX_RUNS:
        raise InputError(source, "--runs", f"the sweep would make {count} runs (scenes x planners x budgets x "
                                           f"--runs), more than the bound {MAX_RUNS}: split it (--db keeps a "
                                           "campaign's parts together)")


def run(args) -> int:
    from ..adapters.glue import OMPL_HINT
    from ..adapters.glue import ompl_available  # (Ctrl-C held while OMPL loads)

    objective = getattr(args, "objective", "length")
    planners = parse_planners(args.planners or ",".join(default_planners(objective, DEFAULT_PLANNERS)))
    check_planners(objective, planners)
    times = parse_times(args.times)
    if not ompl_available():
        raise InputError("bench", "--planners", f"the bench runs OMPL's planners, and OMPL is not installed "
                                                f"({OMPL_HINT})")
    if args.runs < 1:
        raise InputError("bench", "--runs", f"must be at least 1, got {args.runs}")
    if args.workers < 1:
        raise InputError("bench", "--workers", f"must be at least 1, got {args.workers}")
    if args.iterations is not None and args.iterations < 1:
        raise InputError("bench", "--iterations", f"must be at least 1, got {args.iterations}")
    if args.scheduler is not None:  # its form now (an empty one is refused, not run locally); its answer later
        from ..bench.cluster import scheduler_address

        scheduler_address(args.scheduler)
    abort_on = None
    if args.abort_on:
        name, _, seed = args.abort_on.partition(":")
        abort_on = (parse_planners(name)[0], int(seed or 0))
    out = args.out
    from ..output import check_folder

    check_size(len(args.scenario) * len(planners) * len(times) * args.runs)
    check_folder(out, "--out")
    check_inputs_kept(args.scenario, out)
    held: dict = {}
    if args.slabs is not None and not 4 <= args.slabs <= 4096:
        raise InputError("bench", "--slabs", f"must be an integer from 4 to 4096, got {args.slabs}")
    db, log = getattr(args, "db", None), getattr(args, "log", None)
    check_campaign(db, log, getattr(args, "resume", False), out, args.scenario)
    iterations, resume = args.iterations, getattr(args, "resume", False)
    campaign, left = None, None

    def open_campaign(ids):  # every file read, no reference computed yet: a conflict costs nothing
        nonlocal campaign, left
        from ..bench.campaign import Campaign

        first = make_tasks(ids, planners, times, args.runs, iterations, abort_on, objective)
        campaign = Campaign(db, first)  # (closed below if what follows fails)
        left = {campaign.task_key(t) for t in campaign.select(first, resume)}

    try:
        scenarios = reference(args.scenario, quiet=args.quiet, held=held, space=args.space, slabs=args.slabs,
                              before=open_campaign if (db or log) else None)
        check_scenarios(objective, held)
        os.makedirs(out, exist_ok=True)
        tasks = make_tasks(scenarios, planners, times, args.runs, iterations, abort_on, objective)
        stored = []
        if campaign is not None:
            campaign.tasks = {campaign.task_key(t): t for t in tasks}
            n, every = len(tasks), tasks
            tasks = [t for t in tasks if campaign.task_key(t) in left]
            if len(tasks) < n:  # resumed: the stored runs are read back, so --out describes the campaign
                stored = campaign.stored_rows(every)
                if not args.quiet:
                    sys.stderr.write(f"--resume: {n - len(tasks)} of {n} runs already in {db}\n")
    except BaseException:
        if campaign is not None:
            campaign.close()
        raise
    t0 = time.perf_counter()
    try:
        rows, interrupted = sweep(tasks, workers=args.workers, scheduler=args.scheduler, progress=not args.quiet,
                                  held=held, on_row=campaign.on_row if campaign else None,
                                  on_batch=campaign.add if campaign else None)
    finally:
        if campaign is not None:
            from .imports import input_files

            campaign.finish(log, [f for src in args.scenario for f in input_files(src)])
    if stored:  # in the sweep's row order, as if every run had been made now
        place = {campaign.task_key(t): i for i, t in enumerate(every)}
        for r in stored:
            r.pop("order", None)
        rows = sorted(stored + rows, key=lambda r: place[campaign.task_key(r)])
    meta = {"scenarios": scenarios, "planners": planners, "times": times, "runs": args.runs,
            "iterations": args.iterations, "objective": objective, "workers": args.workers, "scheduler": args.scheduler,
            "wall_s": time.perf_counter() - t0, "complete": not interrupted,
            "hard_limit": f"budget * {HARD_FACTOR:g} + {HARD_MARGIN:g} s"}
    # Never mix two sweeps in one folder: an earlier sweep's outputs go only now, so a sweep
    # killed before it writes (kill -9, a power cut) leaves the earlier results whole.
    clear_outputs(out)
    late = write_deferring_sigint(rows, out, meta, plot=not args.no_plot)  # a signal while writing: its number
    interrupted = bool(late) or interrupted
    sys.stderr.write(summary(rows, scenarios) + "\n")  # the result: printed with -q too
    if not args.quiet:
        sys.stderr.write(f"{len(rows)} rows written to {out}/ in {meta['wall_s']:.1f} s"
                         + (" (interrupted)" if interrupted else "") + "\n")
    if campaign is not None:
        campaign.check()  # a database error during the sweep: one line, exit 2, now that --out is written
    return (128 + late if late else interrupt.exit_code()) if interrupted else 0
