"""The benchmark database of ``cspace bench --db``: the SQLite schema that OMPL's
``ompl_benchmark_statistics`` builds from benchmark logs and that Planner Arena reads.

Tables (the names and columns of OMPL 2's converter, ``ompl/_benchmark_statistics.py``):

- ``experiments``: one per (scenario, time budget, space, objective, iteration cap, slabs),
  named ``SCENARIO_tBUDGET``; OMPL's columns (name, totaltime, timelimit, memorylimit,
  runcount, version, hostname, cpuinfo, date, seed, setup) then this project's
  experiment properties (:data:`EXP_PROPS`), which also make a run's identity;
- ``plannerConfigs``: ``geometric_NAME``, no settings;
- ``enums``: ``status``, OMPL's planner statuses with index 8 "Abort" (the run was killed at
  its hard limit) and 9 "Proven unsolvable" (OMPL's INFEASIBLE, which OMPL itself prints as
  "Unknown status");
- ``runs``: one per finished run, the columns of :data:`RUN_PROPS` (OMPL's names, spaces as
  underscores), ``seed`` among them;
- ``progress``: the anytime curve, (runid, time, best_cost), one point per recorded
  improvement check (``planners.core.routine``'s slices; a planner that is not sliced has
  one point, at the end of its solve).

A run's identity (what ``--resume`` skips) is (scenario file content hash, planner, time
budget, seed, space, objective, iteration cap, slabs): the experiment's properties, the
planner's name and the run's seed. :mod:`planners.bench.campaign` drives the writes;
:mod:`planners.bench.ompl_log` writes the same data as OMPL's text logs.
"""
from __future__ import annotations

import hashlib
import math
import platform
import socket
import sqlite3
import time

from ..pictures.bench_figure import proven_unsolvable
from .arena_file import columns, quote

ENUM_NAME = "status"
STATUSES = ("Unknown status", "Invalid start", "Invalid goal", "Unrecognized goal type", "Timeout",
            "Approximate solution", "Exact solution", "Crash", "Abort", "Proven unsolvable")
TIMEOUT, EXACT, CRASH, ABORT, UNSOLVABLE = 4, 6, 7, 8, 9

# Experiment properties (name, SQL type): sorted, as OMPL's converter adds them.
EXP_PROPS = (("iterations", "INTEGER"), ("objective", "TEXT"), ("reference", "TEXT"),
             ("scenario_sha256", "TEXT"), ("slabs", "INTEGER"), ("space", "TEXT"), ("time_budget", "REAL"))

OMPL_EXP_COLUMNS = ("name", "totaltime", "timelimit", "memorylimit", "runcount", "version", "hostname",
                    "cpuinfo", "date", "seed", "setup")


def _flag(v):
    return None if v is None else int(bool(v))


def _num(v):
    return None if v is None or (isinstance(v, float) and not math.isfinite(v)) else v


def status_code(row: dict) -> int:
    """Index of a row's status in :data:`STATUSES`.

    >>> status_code({"status": "ok", "solved": True})
    6
    >>> status_code({"status": "ok", "solved": False, "message": "proven unsolvable: ..."})
    9
    >>> status_code({"status": "ok", "solved": False, "reference": "optimum", "optimum": None})
    9
    >>> status_code({"status": "timeout", "solved": False})
    8
    """
    if row.get("status") == "crashed":
        return CRASH
    if row.get("status") == "timeout":
        return ABORT
    if row.get("solved"):
        return EXACT
    if proven_unsolvable(row):
        return UNSOLVABLE  # the run's own proof, or the exact reference's (no path exists)
    return TIMEOUT


def collision_free(row: dict):
    """1 if the run's path passed the exact check, 0 if it failed it, None if there is no path."""
    if row.get("solved"):
        return 1
    return 0 if "failed the exact check" in (row.get("message") or "") else None


# Run properties: (OMPL log name, SQL type, value of a row). Column = name with "_" for " ".
RUN_PROPS = (
    ("time", "REAL", lambda r: _num(r.get("solve_s"))),
    ("solved", "BOOLEAN", lambda r: _flag(r.get("solved"))),
    ("status", "ENUM", status_code),
    ("approximate solution", "BOOLEAN", lambda r: 0 if r.get("solved") else None),
    ("correct solution", "BOOLEAN", lambda r: _flag(r.get("solved"))),
    ("solution length", "REAL", lambda r: _num(r.get("length_unsimplified"))),
    ("simplified solution length", "REAL", lambda r: _num(r.get("length"))),
    ("simplification time", "REAL", lambda r: _num(r.get("simplify_s"))),
    ("solution clearance", "REAL", lambda r: _num(r.get("min_clearance"))),
    ("certified", "BOOLEAN", lambda r: int(bool(r.get("solved")))),
    ("exact collision free", "BOOLEAN", collision_free),
    ("min clearance", "REAL", lambda r: _num(r.get("min_clearance"))),
    ("min clearance is lower bound", "BOOLEAN",
     lambda r: None if r.get("min_clearance") is None else int(r.get("min_clearance_bound") == "lower")),
    ("reference length", "REAL", lambda r: _num(r.get("optimum"))),
    ("length error", "REAL", lambda r: _num(r.get("error"))),
    ("length error is upper bound", "BOOLEAN", lambda r: int(r.get("reference") == "lower_bound")),
    ("exact planner length", "REAL", lambda r: _num(r.get("upper"))),
    ("length error vs exact planner", "REAL", lambda r: _num(r.get("error_upper"))),
    ("first solution time", "REAL", lambda r: _num(r.get("first_solution_s"))),
    ("state checks", "INTEGER", lambda r: r.get("state_checks")),
    ("motion checks", "INTEGER", lambda r: r.get("motion_checks")),
    ("graph states", "INTEGER", lambda r: r.get("graph_states")),
    ("seed", "INTEGER", lambda r: int(r["seed"])),
    ("wall time", "REAL", lambda r: _num(r.get("wall_s"))),
)
PROGRESS_PROPS = (("time", "REAL"), ("best cost", "REAL"))


def column(name: str) -> str:
    """OMPL's column name for a property (``"best cost"`` -> ``best_cost``)."""
    return "_".join(name.split())


SCHEMA = ("""CREATE TABLE IF NOT EXISTS experiments
    (id INTEGER PRIMARY KEY AUTOINCREMENT, name VARCHAR(512),
    totaltime REAL, timelimit REAL, memorylimit REAL, runcount INTEGER,
    version VARCHAR(128), hostname VARCHAR(1024), cpuinfo TEXT,
    date DATETIME, seed VARCHAR(24), setup TEXT)""",
          """CREATE TABLE IF NOT EXISTS plannerConfigs
    (id INTEGER PRIMARY KEY AUTOINCREMENT,
    name VARCHAR(512) NOT NULL, settings TEXT)""",
          """CREATE TABLE IF NOT EXISTS enums
    (name VARCHAR(512), value INTEGER, description TEXT,
    PRIMARY KEY (name, value))""",
          """CREATE TABLE IF NOT EXISTS runs
    (id INTEGER PRIMARY KEY AUTOINCREMENT, experimentid INTEGER, plannerid INTEGER,
    FOREIGN KEY (experimentid) REFERENCES experiments(id) ON DELETE CASCADE,
    FOREIGN KEY (plannerid) REFERENCES plannerConfigs(id) ON DELETE CASCADE)""",
          """CREATE TABLE IF NOT EXISTS progress
    (runid INTEGER, time REAL, PRIMARY KEY (runid, time),
    FOREIGN KEY (runid) REFERENCES runs(id) ON DELETE CASCADE)""")


def _add_columns(conn, table: str, props) -> None:
    have = {name for name, _ in columns(conn, table)}
    for name, kind in props:
        if column(name) not in have:
            conn.execute(f"ALTER TABLE {quote(table)} ADD {quote(column(name))} {kind}")


def make_schema(conn) -> None:
    """Create or upgrade a benchmark database's tables, columns, run-key index and status enum,
    in the caller's transaction (one statement at a time: ``executescript`` would commit first).

    A run's key is unique (an index on runs (experimentid, plannerid, seed)): a run is never
    stored twice.
    """
    for statement in SCHEMA:
        conn.execute(statement)
    _add_columns(conn, "experiments", EXP_PROPS)
    _add_columns(conn, "runs", [(n, k) for n, k, _ in RUN_PROPS])
    _add_columns(conn, "progress", PROGRESS_PROPS[1:])
    conn.execute("CREATE UNIQUE INDEX IF NOT EXISTS cspace_run_key ON runs (experimentid, plannerid, seed)")
    if conn.execute("SELECT 1 FROM enums WHERE name = ?", (ENUM_NAME,)).fetchone() is None:
        conn.executemany("INSERT INTO enums VALUES (?, ?, ?)", [(ENUM_NAME, i, s) for i, s in enumerate(STATUSES)])


def memory_db() -> sqlite3.Connection:
    """A benchmark database in memory (``--log`` without ``--db``: the logs' source only)."""
    conn = sqlite3.connect(":memory:")
    conn.execute("PRAGMA foreign_keys = ON")
    with conn:
        make_schema(conn)
    return conn


def file_hash(path: str) -> str:
    """SHA-256 of a file's bytes (a scenario's identity in the database)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def token(name: str) -> str:
    """A name safe as one whitespace-free token (an experiment's name, a log's file name).

    >>> token("maze 8x8/a")
    'maze_8x8_a'
    """
    tok = "".join(c if c.isalnum() or c in "-_." else "_" for c in str(name)) or "scenario"
    return tok if len(tok) <= 80 else tok[:80] + "-" + hashlib.sha256(str(name).encode()).hexdigest()[:8]


def experiment_props(task: dict, sha: str) -> dict:
    """The experiment properties of a task (:data:`EXP_PROPS`): its identity but for planner and seed."""
    return {"iterations": int(task.get("iterations") or 0), "objective": task.get("objective") or "length",
            "reference": task.get("reference") or "optimum", "scenario_sha256": sha,
            "slabs": int(task.get("slabs") or 0), "space": task.get("space") or "translation",
            "time_budget": float(task["time_budget"])}


def find_experiment(conn, props: dict) -> int | None:
    """The id of the experiment with these properties (the reference aside), or None."""
    keys = [k for k, _ in EXP_PROPS if k != "reference"]
    row = conn.execute("SELECT id FROM experiments WHERE " + " AND ".join(f"{k} = ?" for k in keys)
                       + " ORDER BY id LIMIT 1", [props[k] for k in keys]).fetchone()
    return None if row is None else row[0]


def add_experiment(conn, task: dict, props: dict, version: str) -> int:
    """Insert an experiment for ``task`` (a sweep's first run of it); returns its id."""
    base = token(task["scenario"]) + f"_t{float(task['time_budget']):g}"
    extra = [] if props["objective"] == "length" else [props["objective"]]
    extra += [f"i{props['iterations']}"] if props["iterations"] else []
    name = "_".join([base] + extra)
    taken = {r[0] for r in conn.execute("SELECT name FROM experiments")}
    if name in taken:  # the same scene and budget, another scene file content, space or slab count
        name += "-" + hashlib.sha256(repr(sorted(props.items())).encode()).hexdigest()[:8]
    setup = (f"cspace bench: scenario {task['scenario']} ({task['file']}), budget {float(task['time_budget']):g} s, "
             f"space {props['space']}, objective {props['objective']}; length error against the "
             + ("exact shortest path" if props["reference"] == "optimum" else "inscribed-disk lower bound")
             + "\n")
    cpu = f"{platform.machine()} {platform.processor()} {platform.platform()}".strip() + "\n"
    values = {"name": name, "totaltime": 0.0, "timelimit": float(task["time_budget"]), "memorylimit": 0.0,
              "runcount": 0, "version": version, "hostname": socket.gethostname(), "cpuinfo": cpu,
              "date": time.strftime("%Y-%m-%d %H:%M:%S"), "seed": "0", "setup": setup, **props}
    cols = list(values)
    cur = conn.execute(f"INSERT INTO experiments ({','.join(map(quote, cols))}) VALUES ({','.join('?' * len(cols))})",
                       [values[c] for c in cols])
    return cur.lastrowid


def planner_id(conn, name: str) -> int:
    """The id of the planner configuration ``geometric_NAME`` (no settings), created if needed."""
    full = f"geometric_{name}"
    row = conn.execute("SELECT id FROM plannerConfigs WHERE name = ? AND settings = ?", (full, "")).fetchone()
    if row is not None:
        return row[0]
    return conn.execute("INSERT INTO plannerConfigs (name, settings) VALUES (?, ?)", (full, "")).lastrowid


def has_run(conn, exp_id: int, plan_id: int, seed: int) -> bool:
    return conn.execute("SELECT 1 FROM runs WHERE experimentid = ? AND plannerid = ? AND seed = ?",
                        (exp_id, plan_id, seed)).fetchone() is not None


def insert_run(conn, exp_id: int, plan_id: int, row: dict) -> int:
    """Insert one finished run and its progress points (inside the caller's transaction)."""
    cols = ["experimentid", "plannerid"] + [column(n) for n, _, _ in RUN_PROPS]
    vals = [exp_id, plan_id] + [f(row) for _, _, f in RUN_PROPS]
    run_id = conn.execute(f"INSERT INTO runs ({','.join(map(quote, cols))}) VALUES ({','.join('?' * len(cols))})",
                          vals).lastrowid
    seen = set()
    for t, cost in row.get("progress") or []:
        t = _num(float(t))
        if t is None or t in seen:  # OMPL's converter keeps the first point of a time too
            continue
        seen.add(t)
        conn.execute("INSERT INTO progress (runid, time, best_cost) VALUES (?, ?, ?)", (run_id, t, _num(cost)))
    conn.execute("UPDATE experiments SET totaltime = totaltime + ?, runcount = (SELECT MAX(n) FROM "
                 "(SELECT COUNT(*) AS n FROM runs WHERE experimentid = ? GROUP BY plannerid)) WHERE id = ?",
                 (float(row.get("wall_s") or 0.0), exp_id, exp_id))
    return run_id


def stored_run(conn, exp_id: int, plan_id: int, seed: int) -> dict | None:
    """A stored run read back as the bench's row fields, as far as the database keeps them (the
    run properties of :data:`RUN_PROPS`; its progress points); None if it is not stored. The
    database keeps a run's status, not its message: a stored run says what its status says."""
    names = [n for n, _, _ in RUN_PROPS]
    got = conn.execute(f"SELECT id, {', '.join(quote(column(n)) for n in names)} FROM runs WHERE experimentid = ? "
                       "AND plannerid = ? AND seed = ?", (exp_id, plan_id, int(seed))).fetchone()
    if got is None:
        return None
    v = dict(zip(names, got[1:]))
    status, lower = v["status"], v["min clearance is lower bound"]
    message = {UNSOLVABLE: "proven unsolvable (a stored run)", CRASH: "crashed (a stored run)",
               ABORT: "killed at its hard limit (a stored run)"}.get(status, "")
    return {"status": {CRASH: "crashed", ABORT: "timeout"}.get(status, "ok"), "solved": bool(v["solved"]),
            "solve_s": v["time"], "length": v["simplified solution length"],
            "length_unsimplified": v["solution length"], "simplify_s": v["simplification time"],
            "min_clearance": v["min clearance"],
            "min_clearance_bound": None if lower is None else ("lower" if lower else "exact"),
            "error": v["length error"], "error_upper": v["length error vs exact planner"],
            "first_solution_s": v["first solution time"], "state_checks": v["state checks"],
            "motion_checks": v["motion checks"], "graph_states": v["graph states"], "wall_s": v["wall time"],
            "message": message,
            "progress": [list(p) for p in conn.execute("SELECT time, best_cost FROM progress WHERE runid = ? "
                                                       "ORDER BY time", (got[0],))]}


def run_keys(conn) -> list[tuple]:
    """Every stored run's identity: (experiment properties..., planner, seed), for tests and resume."""
    props = ", ".join(f"e.{k}" for k, _ in EXP_PROPS if k != "reference")
    return [tuple(r) for r in conn.execute(
        f"SELECT {props}, p.name, r.seed FROM runs r JOIN experiments e ON r.experimentid = e.id "
        "JOIN plannerConfigs p ON r.plannerid = p.id ORDER BY r.id")]
