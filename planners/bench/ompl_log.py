"""OMPL's benchmark log format (``cspace bench --log DIR``), written from a benchmark database
(:mod:`planners.bench.arena_db`): one file per experiment, ``NAME.log``, which OMPL's
``ompl_benchmark_statistics`` turns back into the same database (the tests check the round
trip with OMPL's own converter).

The layout is the one OMPL's ``Benchmark::saveResultsToStream`` writes: the version line,
``Experiment NAME``, the experiment properties (``name TYPE = value``), host and date, the
setup and CPU blocks (``<<<|`` ... ``|>>>``), seed, time and memory limits, runs per planner,
total time, the status enum, then per planner its run properties, one line of values per
run (``v1; v2; ...; ``, ``nan`` for a missing value), the progress properties and one line
of ``time,cost,;`` samples per run, and ``.``.
"""
from __future__ import annotations

import math
import os

from .arena_db import ENUM_NAME, EXP_PROPS


def _val(v) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "nan"
    return repr(v) if isinstance(v, float) else str(v)


def _columns(conn, table: str, skip: int) -> list[tuple[str, str]]:
    """(column, declared type) of a table, after its first ``skip`` columns."""
    return [(c[1], c[2]) for c in conn.execute(f"PRAGMA table_info({table})")][skip:]


def experiment_log(conn, exp_id: int) -> tuple[str, str]:
    """(experiment name, log text) of one experiment of the database."""
    cur = conn.execute("SELECT * FROM experiments WHERE id = ?", (exp_id,))
    names = [d[0] for d in cur.description]
    e = dict(zip(names, cur.fetchone()))
    lib, _, ver = str(e["version"]).partition(" ")
    props = [(k, kind) for k, kind in EXP_PROPS]
    lines = [f"{lib} version {ver}", f"Experiment {e['name']}", f"{len(props)} experiment properties"]
    lines += [f"{k} {kind} = {e[k]}" for k, kind in props]
    lines += [f"Running on {e['hostname']}", f"Starting at {e['date']}",
              "<<<|", str(e["setup"]).rstrip("\n"), "|>>>"]
    if e["cpuinfo"] is not None:
        lines += ["<<<|"] + ([str(e["cpuinfo"]).rstrip("\n")] if e["cpuinfo"] else []) + ["|>>>"]
    lines += [f"{e['seed']} is the random seed", f"{e['timelimit']!r} seconds per run",
              f"{e['memorylimit']!r} MB per run", f"{e['runcount']} runs per planner",
              f"{e['totaltime']!r} seconds spent to collect the data"]
    enum = [d for (d,) in conn.execute("SELECT description FROM enums WHERE name = ? ORDER BY value",
                                       (ENUM_NAME,))]
    lines += ["1 enum types", "|".join([ENUM_NAME] + enum)]
    run_cols = _columns(conn, "runs", 3)
    prog_cols = _columns(conn, "progress", 1)
    planners = conn.execute("SELECT DISTINCT p.id, p.name FROM runs r JOIN plannerConfigs p ON r.plannerid = p.id "
                            "WHERE r.experimentid = ? ORDER BY p.id", (exp_id,)).fetchall()
    lines.append(f"{len(planners)} planners")
    for pid, pname in planners:
        lines += [pname, "0 common properties", f"{len(run_cols)} properties for each run"]
        lines += [f"{c.replace('_', ' ')} {kind}" for c, kind in run_cols]
        runs = conn.execute(f"SELECT id, {', '.join(c for c, _ in run_cols)} FROM runs WHERE experimentid = ? "
                            "AND plannerid = ? ORDER BY id", (exp_id, pid)).fetchall()
        lines.append(f"{len(runs)} runs")
        lines += ["".join(f"{_val(v)}; " for v in r[1:]) for r in runs]
        series = [conn.execute(f"SELECT {', '.join(c for c, _ in prog_cols)} FROM progress WHERE runid = ? "
                               "ORDER BY time", (r[0],)).fetchall() for r in runs]
        if any(series):
            lines += [f"{len(prog_cols)} progress properties"] + [f"{c.replace('_', ' ')} {kind}"
                                                                  for c, kind in prog_cols]
            lines.append(f"{len(runs)} runs")
            lines += ["".join("".join(f"{_val(v)}," for v in point) + ";" for point in s) for s in series]
        lines.append(".")
    return e["name"], "\n".join(lines) + "\n"


def write_logs(conn, folder: str, experiments: list[int] | None = None) -> list[str]:
    """Write one log per experiment (all of the database's by default) into ``folder``;
    returns the files written."""
    from ..output import write_text

    os.makedirs(folder, exist_ok=True)
    ids = experiments if experiments is not None else [i for (i,) in conn.execute(
        "SELECT id FROM experiments ORDER BY id")]
    out = []
    for i in ids:
        name, text = experiment_log(conn, i)
        path = os.path.join(folder, f"{name}.log")
        write_text(path, text, "--log")
        out.append(path)
    return out
