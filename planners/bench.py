"""``cspace bench``: error against run time for OMPL planners, measured against the exact shortest path.

This module owns the benchmark sweep: scenarios x planners x time budgets x seeded runs,
each run isolated in its own process (a planner that segfaults or hangs costs one row,
recorded as ``crashed`` or ``timeout``, never the sweep): locally a forked child of this
process, which built each scenario's C-space once (:mod:`planners.bench_pool`, at most
``--workers`` at a time), a fresh process where fork is missing, or on a Dask cluster
(``--scheduler``). Each run calls :func:`planners.plan.plan`, as ``cspace plan`` does, with the
sweep's ``--objective``; its row keeps the ``min_clearance`` that plan() measures on the solved
path after the timed solve (:mod:`planners.bench_clearance` checks the objective and words the
summary's clearance).
Its outputs: ``results.csv``, ``results.json`` and one OMPL benchmark log per (scenario,
budget) under ``ompl/`` (``ompl_benchmark_statistics.py ompl/*.log`` turns them into the
Planner Arena database) are written by :mod:`planners.bench_outputs`; the
``error_vs_time.png`` figure (error, clearance and success against the budget) by
:mod:`planners.plot_bench`.

The reference is the exact shortest path (:mod:`cspace.spaces.shortest`), computed once per
scenario in the parent. It is an infimum (it touches C-obstacle boundaries), so every
verified planner path is at least as long: ``error = length / optimum - 1 >= 0``.

Rows are sorted by (scenario, planner, budget, seed) in the order given on the command
line, so the same sweep gives the same rows whatever the number of workers (timings aside;
anytime planners stopped by a clock are not deterministic anyway, planners that stop at
their first solution are).
"""
from __future__ import annotations

import math
import os
import sys
import threading
import time

from .bench_reference import make_tasks, reference  # noqa: F401  (part of the bench's API)
from .errors import InputError
from .objectives import OBJECTIVES
# The figure and the progress bar live in their own modules (matplotlib and tqdm are
# imported only when drawn); the bench keeps these names for its callers.
from .plot_bench import curves, plot_error_vs_time  # noqa: F401
from .progress import BenchBar as _Progress

DEFAULT_PLANNERS = ("RRTConnect", "RRTstar", "PRMstar", "BITstar")
DEFAULT_TIMES = (0.01, 0.03, 0.1, 0.3, 1.0)
# Hard limit of one run: budget x HARD_FACTOR + HARD_MARGIN seconds (process start,
# C-space build, simplification and verification all fit many times over).
HARD_FACTOR = 2.0
HARD_MARGIN = 30.0
MAX_BUDGET = 1e6  # seconds per run (11 days); OMPL's clock overflows near 8e9 s
# Fields of a row, in CSV order. Times in seconds; lengths in scenario units.
FIELDS = (
    "scenario", "file", "planner", "time_budget", "seed", "status", "solved",
    "length", "length_unsimplified", "optimum", "reference", "error", "error_unsimplified",
    "first_solution_s", "solve_s", "simplify_s", "state_checks", "motion_checks",
    "wall_s", "message", "min_clearance", "min_clearance_bound", "clearance_s",
)
# clearance_s: measuring min_clearance, after the run's timed solve (in wall_s, not in solve_s).
TIMING_FIELDS = ("first_solution_s", "solve_s", "simplify_s", "wall_s", "clearance_s")
STATUSES = ("ok", "crashed", "timeout")
_MARK = "CSPACE_BENCH_ROW "


# ---------------------------------------------------------------- command line

def register(sub) -> None:
    import argparse

    p = sub.add_parser("bench", help="error against run time for OMPL planners vs the exact shortest path",
                       description="Benchmark OMPL planners: path length error against the exact shortest "
                                   "path, per time budget. Exit 0 done, 2 bad input, 130 interrupted "
                                   "(finished rows are written).")
    p.add_argument("scenario", nargs="+", help="scenario TOML files")
    p.add_argument("--planners", help=f"comma-separated OMPL planners (default {','.join(DEFAULT_PLANNERS)}; "
                                      "with --objective clearance or balanced, those of them that take it)")
    p.add_argument("--times", default=",".join(f"{t:g}" for t in DEFAULT_TIMES),
                   help="comma-separated time budgets in seconds (default 0.01,0.03,0.1,0.3,1)")
    p.add_argument("--runs", type=int, default=10, help="seeded runs per planner and budget (seeds 0..N-1)")
    p.add_argument("--iterations", type=int, help="also stop each run after this many planner iterations")
    p.add_argument("--workers", type=int, default=1, help="runs in parallel (local processes)")
    p.add_argument("--out", default="bench_out", help="output folder (created if missing)")
    p.add_argument("--scheduler", help="address of a Dask distributed scheduler to run on")
    p.add_argument("--objective", choices=OBJECTIVES, default="length",
                   help="what the optimising planners (RRTstar, SORRTstar, BITstar) optimise: path length "
                        "(default), the minimum clearance, or length weighted by clearance")
    p.add_argument("--no-plot", action="store_true", help="skip error_vs_time.png")
    from .cli_plan import add_space_options

    add_space_options(p)
    p.add_argument("--quiet", "-q", action="store_true", help="no progress line")
    # Test hook: the child of this (planner, seed) calls os.abort(), as a segfaulting planner would.
    p.add_argument("--abort-on", help=argparse.SUPPRESS)
    p.set_defaults(run=run)


def parse_planners(text: str, source: str = "bench") -> list[str]:
    """Canonical OMPL planner names from a comma-separated list (``exact`` is the reference, not a contestant).

    >>> parse_planners("rrtconnect,BITstar")
    ['RRTConnect', 'BITstar']
    """
    from .ompl_glue import PLANNERS

    table = {p.lower(): p for p in PLANNERS}
    names = [s.strip() for s in str(text).split(",") if s.strip()]
    if not names:
        raise InputError(source, "--planners", "empty list")
    out = []
    for n in names:
        canon = table.get(n.lower())
        if canon is None:
            raise InputError(source, "--planners", f"unknown planner {n!r} (choose from: {', '.join(PLANNERS)})")
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


def run(args) -> int:
    from .ompl_glue import OMPL_HINT, ompl_available

    from .bench_clearance import check_planners, check_scenarios, default_planners

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
    abort_on = None
    if args.abort_on:
        name, _, seed = args.abort_on.partition(":")
        abort_on = (parse_planners(name)[0], int(seed or 0))
    out = args.out
    from .output import check_folder

    check_folder(out, "--out")
    held: dict = {}
    if args.slabs is not None and not 4 <= args.slabs <= 4096:
        raise InputError("bench", "--slabs", f"must be an integer from 4 to 4096, got {args.slabs}")
    scenarios = reference(args.scenario, quiet=args.quiet, held=held, space=args.space, slabs=args.slabs)
    check_scenarios(objective, held)
    os.makedirs(out, exist_ok=True)
    tasks = make_tasks(scenarios, planners, times, args.runs, args.iterations, abort_on, objective)
    t0 = time.perf_counter()
    rows, interrupted = sweep(tasks, workers=args.workers, scheduler=args.scheduler, progress=not args.quiet,
                              held=held)
    meta = {"scenarios": scenarios, "planners": planners, "times": times, "runs": args.runs,
            "iterations": args.iterations, "objective": objective, "workers": args.workers, "scheduler": args.scheduler,
            "wall_s": time.perf_counter() - t0, "complete": not interrupted,
            "hard_limit": f"budget * {HARD_FACTOR:g} + {HARD_MARGIN:g} s"}
    # Never mix two sweeps in one folder: an earlier sweep's outputs go only now, so a sweep
    # killed before it writes (kill -9, a power cut) leaves the earlier results whole.
    _clear_outputs(out)
    interrupted = _write_deferring_sigint(rows, out, meta, plot=not args.no_plot) or interrupted
    if not args.quiet:
        sys.stderr.write(summary(rows) + "\n")
        sys.stderr.write(f"{len(rows)} rows written to {out}/ in {meta['wall_s']:.1f} s"
                         + (" (interrupted)" if interrupted else "") + "\n")
    return 130 if interrupted else 0


from .bench_outputs import (  # noqa: E402,F401  (the outputs live there; re-exported)
    OUTPUTS, _clear_outputs, _write_deferring_sigint, ompl_logs, to_csv, write_outputs,
)

# ---------------------------------------------------------------- one run (in the child)

def run_one(task: dict, scenario=None, cspace=None) -> dict:
    """Plan one seeded run in this process and return its row (status ``ok``).

    The run goes through :func:`planners.plan.plan`, the routine of ``cspace plan``
    (anytime planners solved in slices to time the first solution): the path is
    simplified and verified exactly, and a run is solved only if it passes.
    ``scenario`` and ``cspace`` reuse a loaded scenario and its built C-space. The row's
    ``min_clearance`` is the one ``plan()`` measures on the solved path, after the solve
    (so outside ``solve_s``; its time is ``clearance_s``).
    """
    from cspace.io.scenario import load_scenario

    from .plan import plan

    if task.get("abort"):
        os.abort()
    sc = scenario if scenario is not None else load_scenario(task["file"], space=task.get("space"))
    planner, budget, iters = task["planner"], float(task["time_budget"]), task.get("iterations")
    res = plan(sc, planner=planner, time=budget, seed=int(task["seed"]), iterations=iters,
               cspace=cspace, slices=True, slabs=task.get("slabs") if cspace is None else None,
               objective=task.get("objective", "length"))
    ok = bool(res.solved)
    opt = task["optimum"]
    length = float(res.length) if ok else None
    raw_len = res.length_unsimplified if ok else None
    return {
        "scenario": task["scenario"], "file": task["file"], "planner": planner, "time_budget": budget,
        "seed": int(task["seed"]), "status": "ok", "solved": ok,
        "length": length, "length_unsimplified": raw_len, "optimum": opt,
        "reference": task.get("reference", "optimum"),
        "error": _error(length, opt), "error_unsimplified": _error(raw_len, opt),
        "first_solution_s": res.first_solution if ok else None, "solve_s": res.timings["solve"],
        "simplify_s": res.timings["simplify"], "state_checks": int(res.checks["states"]),
        "motion_checks": int(res.checks["motions"]), "wall_s": None,
        "message": res.message, "progress": res.progress,
        # Measured by plan() on the solved path after its solve (None: unsolved, or a car).
        "min_clearance": res.min_clearance, "min_clearance_bound": res.min_clearance_bound,
        "clearance_s": res.timings.get("clearance"),
    }


def _error(length, optimum):
    """Relative excess length over the optimum (None when either is missing).

    >>> _error(3.0, 2.0)
    0.5
    """
    if length is None or not optimum:
        return None
    return length / optimum - 1.0


# ---------------------------------------------------------------- one run (isolated)

_live: set = set()  # child processes running now, killed on Ctrl-C
_stop = threading.Event()


def hard_limit(budget: float) -> float:
    """Seconds after which a run is killed and recorded as ``timeout``.

    >>> hard_limit(1.0)
    32.0
    """
    return budget * HARD_FACTOR + HARD_MARGIN


def isolated_run(task: dict, limit: float | None = None) -> dict | None:
    """Run one task in a fresh process (see :func:`planners.bench_pool.isolated_run`)."""
    from .bench_pool import isolated_run as run

    return run(task, limit)


def _complete(task: dict, row: dict, wall: float) -> dict:
    """A full row: the task's identity, the child's results, the wall time."""
    base = {f: None for f in FIELDS}
    base.update({"scenario": task["scenario"], "file": task["file"], "planner": task["planner"],
                 "time_budget": task["time_budget"], "seed": task["seed"], "optimum": task["optimum"],
                 "reference": task.get("reference", "optimum"), "solved": False, "progress": []})
    base.update(row)
    base["wall_s"] = wall
    base["order"] = task["order"]
    return base


# ---------------------------------------------------------------- the sweep

def sweep(tasks: list[dict], workers: int = 1, scheduler: str | None = None,
          progress: bool = False, held: dict | None = None) -> tuple[list[dict], bool]:
    """Run every task; returns ``(rows sorted in task order, interrupted)``.

    With ``held`` (file -> (scenario, cspace), from :func:`reference`) and ``os.fork``,
    runs are forked children of this process (:mod:`planners.bench_pool`); otherwise
    (or on a Dask cluster) each run is a fresh process. Ctrl-C stops the sweep:
    running children are killed, finished rows are kept.
    """
    from .bench_pool import CAN_FORK, run_forked

    _stop.clear()
    rows: list[dict] = []
    bar = _Progress(len(tasks), progress)
    interrupted = False

    def on_row(task, row, wall):
        rows.append(_complete(task, row, wall))
        bar.step(rows[-1])

    try:
        if scheduler:
            _sweep_dask(tasks, scheduler, rows, bar)
        elif held is not None and CAN_FORK and all(t["file"] in held for t in tasks):
            from . import plan as _plan  # noqa: F401  (imported once, before forking)
            from .ompl_glue import ompl

            ompl()
            run_forked(tasks, held, workers, lambda t: hard_limit(t["time_budget"]), on_row)
        else:
            _sweep_local(tasks, workers, rows, bar)
    except KeyboardInterrupt:
        interrupted = True
        _stop.set()
        for proc in list(_live):
            proc.kill()
    bar.close()
    rows.sort(key=lambda r: r["order"])
    for r in rows:
        del r["order"]
    return rows, interrupted


def _sweep_local(tasks, workers, rows, bar) -> None:
    from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

    pool = ThreadPoolExecutor(max_workers=workers)
    try:
        pending = {pool.submit(isolated_run, t) for t in tasks}
        while pending:
            # A short timeout keeps the main thread responsive to Ctrl-C.
            done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
            for fut in done:
                row = fut.result()
                if row is not None:
                    rows.append(row)
                    bar.step(row)
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


def _sweep_dask(tasks, scheduler, rows, bar) -> None:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise InputError("bench", "--scheduler", "needs dask[distributed] (pip install 'cspace[cluster]')") from None
    try:
        client = Client(scheduler, timeout="10s")
    except OSError as exc:
        raise InputError("bench", "--scheduler", f"cannot connect to {scheduler}: {exc}") from None
    futures = client.map(isolated_run, tasks, pure=False)
    try:
        for fut in as_completed(futures):
            row = fut.result()
            if row is not None:
                rows.append(row)
                bar.step(row)
    except KeyboardInterrupt:
        client.cancel(futures)
        raise
    finally:
        client.close()


# ---------------------------------------------------------------- statistics

def summary(rows: list[dict]) -> str:
    """A table: median error, median min clearance and success rate at the largest budget,
    per scenario and planner."""
    from .bench_clearance import clearance_cell

    cs, clear = curves(rows), curves(rows, "min_clearance")
    bounded = {r["scenario"] for r in rows if r.get("reference") == "lower_bound"}
    lower = {r["scenario"] for r in rows if r.get("min_clearance_bound") == "lower"}
    lines = [f"{'scenario':<20} {'planner':<16} {'budget':>7} {'median error':>13} {'min clearance':>14} "
             f"{'success':>8}"]
    for (scen, p), c in cs.items():
        m = c["median"][-1]
        text = "-" if m is None else (f"<= {m:.4f}" if scen in bounded else f"{m:.4f}")
        lines.append(f"{scen:<20} {p:<16} {c['time'][-1]:>7g} {text:>13} "
                     f"{clearance_cell(clear[scen, p]['median'][-1], scen in lower):>14} {c['success'][-1]:>8.0%}")
    if bounded:
        lines.append("<= : SE(2) scenes have no exact optimum: length / (inscribed-disk lower bound) - 1, an upper "
                     "bound on the error")
    if lower:
        lines.append(">= : an SE(2) path's min clearance is a certified lower bound")
    return "\n".join(lines)
