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

The database may come from elsewhere (``--db`` of an earlier sweep, or OMPL's converter): its
names never decide where a log goes (the file name is the experiment's name as a token,
:func:`planners.bench.arena_db.token`, inside DIR, never an input), its identifiers are
quoted, and its text is written with control characters escaped, so a name cannot start a
line of the format (``|>>>``) or act on a terminal.
"""
from __future__ import annotations

import math
import os

from cspace.io.scenario.messages import printable

from .arena_db import ENUM_NAME, EXP_PROPS, token
from .arena_file import columns, quote


def _val(v) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "nan"
    return repr(v) if isinstance(v, float) else _text(v).replace(";", ",")  # ";" ends a value


def _text(v) -> str:
    """A value as log text: one line, no control character."""
    return printable(v)


def _columns(conn, table: str, skip: int) -> list[tuple[str, str]]:
    """(column, declared type) of a table, after its first ``skip`` columns."""
    return columns(conn, table)[skip:]


def _props(cols: list[tuple[str, str]]) -> list[str]:
    """The property lines (``name TYPE``) of columns: OMPL's converter makes each a bare SQL
    column name again (spaces as underscores), so a name keeps letters, digits and spaces only
    (others become ``_``; a leading digit gets ``p``; a repeated one ``_2``...), and a type is
    one word (none: TEXT).

    >>> _props([("weird col", "REAL"), ('a"b', ""), ("a_b", "TEXT"), ("1st", "INTEGER")])
    ['weird col REAL', 'a b TEXT', 'a b 2 TEXT', 'p1st INTEGER']
    """
    out, seen = [], set()
    for col, kind in cols:
        name = "".join(c if c.isascii() and c.isalnum() else "_" for c in str(col)) or "p"
        name = ("p" + name) if name[0].isdigit() else name
        base, n = name, 2
        while name.lower() in seen:
            name = f"{base}_{n}"
            n += 1
        seen.add(name.lower())
        word = "".join(c for c in str(kind) if c.isascii() and c.isalnum()) or "TEXT"
        out.append(f"{name.replace('_', ' ')} {word}")
    return out


def experiment_log(conn, exp_id: int) -> tuple[str, str]:
    """(experiment name, log text) of one experiment of the database."""
    cur = conn.execute("SELECT * FROM experiments WHERE id = ?", (exp_id,))
    names = [d[0] for d in cur.description]
    e = dict(zip(names, cur.fetchone()))
    lib, _, ver = str(e["version"]).partition(" ")
    props = [(k, kind) for k, kind in EXP_PROPS]
    lines = [f"{_text(lib)} version {_text(ver)}", f"Experiment {_text(e['name'])}",
             f"{len(props)} experiment properties"]
    lines += [f"{k} {kind} = {_text(e[k])}" for k, kind in props]
    lines += [f"Running on {_text(e['hostname'])}", f"Starting at {_text(e['date'])}",
              "<<<|", _text(str(e["setup"]).rstrip("\n")), "|>>>"]
    if e["cpuinfo"] is not None:
        lines += ["<<<|"] + ([_text(str(e["cpuinfo"]).rstrip("\n"))] if e["cpuinfo"] else []) + ["|>>>"]
    lines += [f"{_text(e['seed'])} is the random seed", f"{e['timelimit']!r} seconds per run",
              f"{e['memorylimit']!r} MB per run", f"{_text(e['runcount'])} runs per planner",
              f"{e['totaltime']!r} seconds spent to collect the data"]
    enum = [d for (d,) in conn.execute("SELECT description FROM enums WHERE name = ? ORDER BY value",
                                       (ENUM_NAME,))]
    lines += ["1 enum types", "|".join([ENUM_NAME] + [_text(d).replace("|", "/") for d in enum])]
    run_cols = _columns(conn, "runs", 3)
    prog_cols = _columns(conn, "progress", 1)
    planners = conn.execute("SELECT DISTINCT p.id, p.name FROM runs r JOIN plannerConfigs p ON r.plannerid = p.id "
                            "WHERE r.experimentid = ? ORDER BY p.id", (exp_id,)).fetchall()
    lines.append(f"{len(planners)} planners")
    for pid, pname in planners:
        lines += [_text(pname), "0 common properties", f"{len(run_cols)} properties for each run"]
        lines += _props(run_cols)
        runs = conn.execute(f"SELECT id, {', '.join(quote(c) for c, _ in run_cols)} FROM runs WHERE experimentid = ? "
                            "AND plannerid = ? ORDER BY id", (exp_id, pid)).fetchall()
        lines.append(f"{len(runs)} runs")
        lines += ["".join(f"{_val(v)}; " for v in r[1:]) for r in runs]
        series = [conn.execute(f"SELECT {', '.join(quote(c) for c, _ in prog_cols)} FROM progress WHERE runid = ? "
                               "ORDER BY time", (r[0],)).fetchall() for r in runs]
        if any(series):
            lines += [f"{len(prog_cols)} progress properties"] + _props(prog_cols)
            lines.append(f"{len(runs)} runs")
            lines += ["".join("".join(f"{_val(v)}," for v in point) + ";" for point in s) for s in series]
        lines.append(".")
    return e["name"], "\n".join(lines) + "\n"


def write_logs(conn, folder: str, inputs=(), experiments: list[int] | None = None) -> list[str]:
    """Write one log per experiment (all of the database's by default) into ``folder``, each named
    by its experiment as a token (two that give one token: ``-2``, ``-3``...), never over one of
    ``inputs``; returns the files written."""
    from ..output import check_not_input, write_text

    os.makedirs(folder, exist_ok=True)
    ids = experiments if experiments is not None else [i for (i,) in conn.execute(
        "SELECT id FROM experiments ORDER BY id")]
    out, taken = [], set()
    for i in ids:
        name, text = experiment_log(conn, i)
        base = stem = token(name)
        n = 2
        while stem in taken:
            stem = f"{base}-{n}"
            n += 1
        taken.add(stem)
        path = os.path.join(folder, f"{stem}.log")
        try:
            st = os.stat(path)
        except OSError:
            st = None
        check_not_input(path, "--log", inputs, st)
        write_text(path, text, "--log")
        out.append(path)
    return out
