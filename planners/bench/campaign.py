"""A benchmark campaign in a database (``cspace bench --db FILE [--resume] [--log DIR]``).

Every finished run goes into the database as it arrives, in its own transaction (a batch: the
rows the sweep reports together), so a sweep killed at any moment, even by ``kill -9``, keeps
every run it had stored. ``--resume`` drops from the sweep the runs already stored (same
scenario file content, planner, budget, seed, space, objective, iteration cap, slab count);
without it, a database that already holds one of the sweep's runs is refused (exit 2), so a
run is never stored twice (the database's unique index on a run's key says so too). Two
sweeps may write one after the other; an SQLite lock keeps two at once from interleaving a
transaction.

The database is :mod:`planners.bench.arena_db`'s (Planner Arena's schema); ``--log``
writes OMPL's text logs from it (:mod:`planners.bench.ompl_log`); without ``--db`` the
database lives in memory for the logs only.
"""
from __future__ import annotations

import sqlite3

from ..errors import InputError
from . import arena_db as adb


def ompl_version() -> str:
    """``OMPL X.Y.Z`` (the version Planner Arena filters by)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return f"OMPL {version('ompl')}"
    except PackageNotFoundError:  # pragma: no cover - the bench needs OMPL
        return "OMPL 0.0.0"


class Campaign:
    """Stores a sweep's runs in a benchmark database as they finish.

    ``path`` None: an in-memory database (for ``--log`` alone).
    """

    def __init__(self, path: str | None, tasks: list[dict]):
        self.path = path
        try:
            self.conn = adb.open_db(path or ":memory:")
        except sqlite3.Error as exc:
            raise InputError("bench", "--db", f"{path}: not a benchmark database ({exc})") from None
        self.version = ompl_version()
        self.hashes: dict[str, str] = {}
        self.experiments: dict[tuple, int] = {}
        self.planners: dict[str, int] = {}
        self.tasks = {self.task_key(t): t for t in tasks}
        self.stored = 0
        self.pending: list[dict] = []

    def task_key(self, t: dict) -> tuple:
        return (t["file"], t["planner"], float(t["time_budget"]), int(t["seed"]))

    def props(self, task: dict) -> dict:
        f = task["file"]
        if f not in self.hashes:
            try:
                self.hashes[f] = adb.file_hash(f)
            except OSError as exc:
                raise InputError(f, "scenario", f"cannot read: {exc}") from None
        return adb.experiment_props(task, self.hashes[f])

    def experiment(self, task: dict, create: bool) -> int | None:
        props = self.props(task)
        k = tuple(sorted(props.items()))
        if k not in self.experiments:
            found = adb.find_experiment(self.conn, props)
            if found is None and not create:
                return None
            self.experiments[k] = found if found is not None else adb.add_experiment(
                self.conn, task, props, self.version)
        return self.experiments[k]

    def planner(self, name: str) -> int:
        if name not in self.planners:
            self.planners[name] = adb.planner_id(self.conn, name)
        return self.planners[name]

    def stored_tasks(self, tasks: list[dict]) -> list[dict]:
        """The tasks whose run the database already holds."""
        out = []
        for t in tasks:
            e = self.experiment(t, create=False)
            row = None if e is None else self.conn.execute("SELECT id FROM plannerConfigs WHERE name = ? "
                                                           "AND settings = ''", (f"geometric_{t['planner']}",)
                                                           ).fetchone()
            if row is not None and adb.has_run(self.conn, e, row[0], int(t["seed"])):
                out.append(t)
        return out

    def stored_rows(self, tasks: list[dict]) -> list[dict]:
        """The rows of the tasks whose run the database holds, read back from it (what
        ``--resume`` skips still belongs to the campaign's outputs)."""
        from .rows import complete_row

        out = []
        for t in tasks:
            e = self.experiment(t, create=False)
            got = None if e is None else adb.stored_run(self.conn, e, self.planner(t["planner"]), t["seed"])
            if got is not None:
                out.append(complete_row(t, got, got["wall_s"]))
        return out

    def select(self, tasks: list[dict], resume: bool) -> list[dict]:
        """The tasks left to run: all (refused if some are stored), or, resuming, those not stored."""
        done = self.stored_tasks(tasks)
        if done and not resume:
            raise InputError("bench", "--db", f"{self.path} already holds {len(done)} of this sweep's "
                                              f"{len(tasks)} runs: add --resume to run only the others, or "
                                              "give another --db")
        keys = {self.task_key(t) for t in done}
        return [t for t in tasks if self.task_key(t) not in keys]

    def add(self, rows: list[dict]) -> None:
        """Store finished runs in one transaction (a run already stored is skipped, never doubled)."""
        self.pending.extend(rows)
        todo, self.pending = self.pending, []
        try:
            with self.conn:
                for row in todo:
                    task = self.tasks[self.task_key(row)]
                    full = {**task, **row}
                    e, p = self.experiment(full, create=True), self.planner(row["planner"])
                    if not adb.has_run(self.conn, e, p, int(row["seed"])):
                        adb.insert_run(self.conn, e, p, full)
                        self.stored += 1
        except BaseException:
            self.pending = todo + self.pending  # rolled back: stored at the next batch or at close
            self.experiments.clear()  # an experiment created in the rolled-back transaction is gone too
            self.planners.clear()
            raise

    def on_row(self, row: dict) -> None:
        """The sweep's hook: one finished run, stored at once."""
        self.add([row])

    def finish(self, log_dir: str | None = None) -> list[str]:
        """Store what is left, compute OMPL's views, write the logs; returns the log files."""
        if self.pending:
            self.add([])
        logs = []
        if log_dir:
            from .ompl_log import write_logs

            logs = write_logs(self.conn, log_dir)
        self.conn.close()
        if self.path:
            try:  # OMPL's own views (best planner per experiment), as its converter makes them
                from ompl.tools import computeViews

                computeViews(self.path, False)
            except ImportError:  # pragma: no cover - the bench needs OMPL
                pass
        return logs
