"""``cspace bench`` outputs: results.csv, results.json and OMPL's benchmark logs, written so
that a sweep is never mixed with an earlier one and Ctrl-C never leaves ``complete: true``.

The OMPL logs (one per scenario and budget, under ``ompl/``) are in the format
``ompl_benchmark_statistics.py`` (shipped in the ompl wheel) turns into the Planner
Arena database. The figure is drawn by :func:`planners.pictures.bench_figure.plot_error_vs_time` (through
:mod:`planners.bench`, which re-exports it).
"""
from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import socket
import time


def write_deferring_sigint(rows, out, meta, plot) -> int:
    """Write the outputs with Ctrl-C (and SIGTERM, which the command line takes as Ctrl-C) held
    until they are consistent; the signal's number if one came, else 0.

    results.json is written last; if a signal came meanwhile it is written again with
    ``"complete": false`` (a figure or a log may be missing), never ``true``.
    """
    import signal

    hit: list[int] = []
    prev = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            prev[sig] = signal.signal(sig, lambda signum, _: hit.append(signum))
        except ValueError:  # not the main thread: no handler to swap
            pass
    try:
        write_outputs(rows, out, meta, plot=plot, stop=lambda: bool(hit))
        if hit:
            write_outputs(rows, out, {**meta, "complete": False}, plot=False, only_json=True)
    finally:
        for sig, handler in prev.items():
            signal.signal(sig, handler)
    return int(hit[0]) if hit else 0


OUTPUTS = ("results.json", "results.csv", "error_vs_time.png")


def clear_outputs(out: str) -> None:
    """Remove an earlier sweep's outputs from ``out`` (our own file names only)."""
    for name in OUTPUTS:
        with contextlib.suppress(FileNotFoundError):
            os.remove(os.path.join(out, name))
    logs = os.path.join(out, "ompl")
    if os.path.isdir(logs):
        for name in os.listdir(logs):
            if name.endswith(".log"):
                with contextlib.suppress(FileNotFoundError):
                    os.remove(os.path.join(logs, name))


def write_outputs(rows: list[dict], out: str, meta: dict, plot: bool = True, stop=None,
                  only_json: bool = False) -> None:
    """Write results.csv, the OMPL logs, (optionally) the figure and results.json, each atomically.

    results.json comes last: its ``complete`` is the sweep's word on everything else.
    ``stop()`` true (Ctrl-C came) skips what is left before it.
    """
    from .rows import FIELDS
    from ..output import write_json, write_text

    stop = stop or (lambda: False)
    if not only_json:
        write_text(os.path.join(out, "results.csv"), to_csv(rows))
        logs = os.path.join(out, "ompl")
        os.makedirs(logs, exist_ok=True)
        for name, text in ompl_logs(rows, meta).items():
            if not stop():
                write_text(os.path.join(logs, name), text)
        if plot and rows and not stop():
            from ..pictures.bench_figure import plot_error_vs_time

            plot_error_vs_time(rows, os.path.join(out, "error_vs_time.png"))
    if stop():
        meta = {**meta, "complete": False}
    write_json(os.path.join(out, "results.json"), {"meta": _clean(meta), "fields": list(FIELDS),
                                                   "rows": [_clean(r) for r in rows]})


def _clean(x):
    """JSON-safe copy: non-finite floats become None."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    return x


def to_csv(rows: list[dict]) -> str:
    """The rows as CSV text with the :data:`FIELDS` header (missing values empty).

    >>> to_csv([]).split(",")[:3]
    ['scenario', 'file', 'planner']
    """
    from .rows import FIELDS

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(FIELDS)
    for r in rows:
        w.writerow(["" if r.get(f) is None else (repr(r[f]) if isinstance(r[f], float) else r[f]) for f in FIELDS])
    return buf.getvalue()


# OMPL's benchmark log (the format ompl_benchmark_statistics.py parses): one
# experiment per file, so one file per (scenario, time budget).
_ENUM = ("status|Unknown status|Invalid start|Invalid goal|Unrecognized goal type|Timeout|"
         "Approximate solution|Exact solution|Crash|Abort|Infeasible")
_RUN_PROPS = (
    ("time", "REAL", "solve_s"), ("solved", "BOOLEAN", "solved"), ("status", "ENUM", None),
    ("correct solution", "BOOLEAN", "solved"), ("solution length", "REAL", "length_unsimplified"),
    ("simplified solution length", "REAL", "length"), ("simplification time", "REAL", "simplify_s"),
    ("optimum", "REAL", "optimum"), ("error", "REAL", "error"), ("first solution time", "REAL", "first_solution_s"),
    ("state checks", "INTEGER", "state_checks"), ("motion checks", "INTEGER", "motion_checks"),
    ("seed", "INTEGER", "seed"), ("wall time", "REAL", "wall_s"), ("min clearance", "REAL", "min_clearance"),
)


def _status_code(row: dict) -> int:
    """Index into the status enum: exact solution, timeout, crash or abort (killed)."""
    if row["status"] == "crashed":
        return 7
    if row["status"] == "timeout":
        return 8
    return 6 if row["solved"] else 4


def _val(v) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "nan"
    if isinstance(v, bool):
        return str(int(v))
    return repr(v) if isinstance(v, float) else str(v)


def ompl_logs(rows: list[dict], meta: dict | None = None) -> dict[str, str]:
    """OMPL benchmark logs ``{file name: text}``, one per (scenario, time budget).

    Planners appear as ``geometric_NAME``; the runs table gets the columns of
    ``_RUN_PROPS``; anytime runs add a progress table (time, best raw cost).
    """
    from importlib.metadata import PackageNotFoundError, version

    from cspace.io.scenario.messages import printable

    try:
        ver = version("ompl")
    except PackageNotFoundError:  # pragma: no cover
        ver = "0.0.0"
    groups: dict = {}
    for r in rows:
        groups.setdefault((r["scenario"], r["time_budget"]), []).append(r)
    out = {}
    date = time.strftime("%Y-%m-%d %H:%M:%S")
    for (scen, budget), rs in groups.items():
        planners: dict = {}
        for r in rs:
            planners.setdefault(r["planner"], []).append(r)
        opt = rs[0]["optimum"]
        lines = [f"OMPL version {ver}", f"Experiment {_token(scen)}_t{budget:g}",
                 "2 experiment properties", f"optimum REAL = {_val(opt)}", f"budget REAL = {budget!r}",
                 f"Running on {socket.gethostname()}", f"Starting at {date}",
                 "<<<|", printable(f"cspace bench: scenario {scen} ({rs[0]['file']}), budget {budget:g} s, "
                                   "error against the exact shortest path"), "|>>>",
                 "<<<|", "|>>>", "0 is the random seed", f"{budget!r} seconds per run", "0 MB per run",
                 f"{max(len(v) for v in planners.values())} runs per planner",
                 f"{sum(r['wall_s'] or 0.0 for r in rs)!r} seconds spent to collect the data",
                 "1 enum types", _ENUM, f"{len(planners)} planners"]
        for p, prs in planners.items():
            lines += [f"geometric_{p}", "0 common properties", f"{len(_RUN_PROPS)} properties for each run"]
            lines += [f"{name} {kind}" for name, kind, _ in _RUN_PROPS]
            lines.append(f"{len(prs)} runs")
            for r in prs:
                vals = [str(_status_code(r)) if key is None and name == "status" else _val(r.get(key))
                        for name, _, key in _RUN_PROPS]
                lines.append("; ".join(vals) + "; ")
            if any(r.get("progress") for r in prs):
                lines += ["2 progress properties", "time REAL", "best cost REAL", f"{len(prs)} runs"]
                for r in prs:
                    lines.append("".join(f"{t!r},{c!r},;" for t, c in (r.get("progress") or [])))
            lines.append(".")
        fname = f"{_token(scen)}_t{budget:g}.log"
        n = 2
        while fname in out:  # two labels that differ only in characters a file name cannot keep
            fname = f"{_token(scen)}-{n}_t{budget:g}.log"
            n += 1
        out[fname] = "\n".join(lines) + "\n"
    return out


TOKEN_MAX = 80  # characters of a scenario's name kept in log and experiment names


def _token(name: str) -> str:
    """A name safe as one whitespace-free token and file name (long names: cut, plus a hash).

    >>> _token("maze 8x8/a")
    'maze_8x8_a'
    >>> len(_token("x" * 300)) <= TOKEN_MAX + 9
    True
    """
    import hashlib

    tok = "".join(c if c.isalnum() or c in "-_." else "_" for c in str(name)) or "scenario"
    if len(tok) > TOKEN_MAX:
        tok = tok[:TOKEN_MAX] + "-" + hashlib.sha256(str(name).encode()).hexdigest()[:8]
    return tok
