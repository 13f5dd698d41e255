"""The benchmark sweep: scenarios x planners x time budgets x seeded runs, each run isolated
in its own process (a planner that segfaults or hangs costs one row, recorded as
``crashed`` or ``timeout``, never the sweep): locally a forked child of this process,
which built each scenario's C-space once (:mod:`planners.bench.pool`, at most ``--workers``
at a time), a fresh process where fork is missing, or on a Dask cluster (``--scheduler``,
in batches: :mod:`planners.bench.cluster`).
Each run is :func:`planners.bench.rows.run_one`, which calls :func:`planners.core.plan.plan`
as ``cspace plan`` does.

Rows are sorted by (scenario, planner, budget, seed) in the order given on the command
line, so the same sweep gives the same rows whatever the number of workers (timings aside;
anytime planners stopped by a clock are not deterministic anyway, planners that stop at
their first solution are).
"""
from __future__ import annotations

from ..pictures.bench_figure import curves
from ..progress import BenchBar
from .rows import complete_row, hard_limit, live_children, stop_event


def isolated_run(task: dict, limit: float | None = None) -> dict | None:
    """Run one task in a fresh process (see :func:`planners.bench.pool.isolated_run`)."""
    from .pool import isolated_run as run

    return run(task, limit)


# ---------------------------------------------------------------- the sweep

def sweep(tasks: list[dict], workers: int = 1, scheduler: str | None = None,
          progress: bool = False, held: dict | None = None, on_row=None,
          on_batch=None) -> tuple[list[dict], bool]:
    """Run every task; returns ``(rows sorted in task order, interrupted)``.

    With ``held`` (file -> (scenario, cspace), from :func:`reference`) and ``os.fork``,
    runs are forked children of this process (:mod:`planners.bench.pool`); otherwise
    (or on a Dask cluster) each run is a fresh process. Ctrl-C stops the sweep:
    running children are killed, finished rows are kept. ``on_row(row)``, if given, gets each
    finished row as it arrives (``cspace bench --db`` stores it then). On a cluster
    (``scheduler``: an address or a ``distributed.Client``, :mod:`planners.bench.cluster`) runs
    go in batches, and ``on_batch(rows)``, if given, gets each finished batch's rows instead.
    """
    from ..children import CAN_FORK
    from .pool import run_forked

    stop_event.clear()
    rows: list[dict] = []
    bar = BenchBar(len(tasks), progress)
    interrupted = False

    hook = on_row or (lambda row: None)

    def on_forked(task, row, wall):
        rows.append(complete_row(task, row, wall))
        bar.step(rows[-1])
        hook(rows[-1])

    try:
        if scheduler:
            _sweep_dask(tasks, scheduler, rows, bar, hook, on_batch)
        elif held is not None and CAN_FORK and all(t["file"] in held for t in tasks):
            from ..adapters.glue import ompl
            from ..core import plan  # noqa: F401  (imported once, before forking)

            ompl()
            run_forked(tasks, held, workers, lambda t: hard_limit(t["time_budget"]), on_forked)
        else:
            _sweep_local(tasks, workers, rows, bar, hook)
    except KeyboardInterrupt:
        interrupted = True
        stop_event.set()
        for proc in list(live_children):
            proc.kill()
    bar.close()
    rows.sort(key=lambda r: r["order"])
    for r in rows:
        del r["order"]
    return rows, interrupted


def _sweep_local(tasks, workers, rows, bar, hook) -> None:
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
                    hook(row)
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


def _sweep_dask(tasks, scheduler, rows, bar, hook, on_batch) -> None:
    from .cluster import sweep_on_cluster

    def got(batch):
        rows.extend(batch)
        for row in batch:
            bar.step(row)
        if on_batch is not None:
            on_batch(batch)
        else:
            for row in batch:
                hook(row)

    sweep_on_cluster(tasks, scheduler, got)


# ---------------------------------------------------------------- statistics

def summary(rows: list[dict], scenarios: list[dict] | None = None) -> str:
    """A table: median error, median min clearance and success rate at the largest budget,
    per scenario and planner; in SE(2) the median length against the exact planner's path
    ("vs exact": length / its length - 1, negative where a run beat it) and, from
    ``scenarios`` (:func:`reference`'s), the exact planner's own row."""
    from .clearance import clearance_cell

    cs, clear, vs = curves(rows), curves(rows, "min_clearance"), curves(rows, "error_upper")
    bounded = {r["scenario"] for r in rows if r.get("reference") == "lower_bound"}
    lower = {r["scenario"] for r in rows if r.get("min_clearance_bound") == "lower"}
    upper = {r["scenario"] for r in rows if r.get("upper") is not None}
    proven = False
    lines = [f"{'scenario':<20} {'planner':<16} {'budget':>7} {'median error':>13} {'min clearance':>14} "
             f"{'success':>8}" + (f" {'vs exact':>9}" if upper else "")]
    for (scen, p), c in cs.items():
        m = c["median"][-1]
        text = "-" if m is None else (f"<= {m:.4f}" if scen in bounded else f"{m:.4f}")
        v = vs[scen, p]["median"][-1] if scen in upper else None
        ok = "proven" if c["proven"][-1] == 1.0 else f"{c['success'][-1]:.0%}"  # no path exists: not a failure
        proven |= c["proven"][-1] == 1.0
        lines.append(f"{scen:<20} {p:<16} {c['time'][-1]:>7g} {text:>13} "
                     f"{clearance_cell(clear[scen, p]['median'][-1], scen in lower):>14} {ok:>8}"
                     + (f" {'-' if v is None else f'{v:+.4f}':>9}" if upper else ""))
    for s in scenarios or []:
        if "exact_s" in s:  # the exact planner's own row: its time, once (deterministic)
            lines.append(f"{s['scenario']:<20} {'exact':<16} {'-':>7} {'-':>13} {'-':>14} "
                         f"{'100%' if s['upper'] is not None else '0%':>8}"
                         + (f" {'+0.0000' if s['upper'] is not None else '-':>9}" if upper else "")
                         + f"  ({s['exact_s']:.3g} s: {s['exact_message']})")
    if proven:
        lines.append("proven: every run ended with a proof that no collision-free path exists (not a failure)")
    if bounded:
        lines.append(f"<= : {space_names(bounded, scenarios)} scenes have no exact optimum: length / (inscribed-disk "
                     "lower bound) - 1, an upper bound on the error")
    if lower:
        lines.append(f">= : the min clearance of {space_names(lower, scenarios)} paths is a certified lower bound")
    if upper:
        lines.append("vs exact: length / (the exact planner's certified path length) - 1; that path is an upper bound "
                     "on the optimum")
    return "\n".join(lines)


SPACE_NAMES = {"se2": "SE(2)", "dubins": "Dubins car", "reeds-shepp": "Reeds-Shepp car"}


def space_names(scens: set, scenarios: list[dict] | None) -> str:
    """The spaces of these scenarios in words (from :func:`reference`'s ``scenarios``).

    >>> space_names({"a"}, [{"scenario": "a", "space": "dubins"}])
    'Dubins car'
    >>> space_names({"a", "b"}, [{"scenario": "a", "space": "se2"}, {"scenario": "b", "space": "reeds-shepp"}])
    'SE(2) and Reeds-Shepp car'
    >>> space_names({"a"}, None)
    'rotating-robot or car'
    """
    spaces = {s.get("space") for s in scenarios or [] if s["scenario"] in scens}
    names = [SPACE_NAMES[k] for k in SPACE_NAMES if k in spaces]
    if not names or len(spaces) != len(names):
        return "rotating-robot or car"
    return " and ".join(names) if len(names) < 3 else ", ".join(names[:-1]) + " and " + names[-1]
