"""A benchmark campaign in a database (``cspace bench --db FILE [--resume] [--log DIR]``).

Every finished run goes into the database as it arrives, in its own transaction (a batch: the
rows the sweep reports together), so a sweep killed at any moment, even by ``kill -9``, keeps
every run it had stored. ``--resume`` drops from the sweep the runs already stored (same
scenario file content, planner, budget, seed, space, objective, iteration cap, slab count);
without it, a database that already holds one of the sweep's runs is refused (exit 2), so a
run is never stored twice (the database's unique index on a run's key says so too). A
campaign claims its database for as long as it runs (:mod:`planners.bench.arena_file`): a
second sweep on it is refused, one after the other is fine.

The file is checked before the sweep (a special name, a foreign or damaged database, a
read-only file or folder: exit 2, nothing written). A database error during the sweep (a full
disk, the file removed under it) stops the storing, not the sweep: the runs stored so far stay,
every row still goes to ``--out``, and the command then ends with one exit-2 line
(:attr:`Campaign.failure`).

The database is :mod:`planners.bench.arena_db`'s (Planner Arena's schema); ``--log``
writes OMPL's text logs from it (:mod:`planners.bench.ompl_log`); without ``--db`` the
database lives in memory for the logs only.
"""
from __future__ import annotations


from ..errors import InputError
from . import arena_db as adb
from .arena_file import DB_ERRORS


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
        from .arena_file import open_campaign_db

        self.path, self.fd = path, None
        self.failure: InputError | None = None  # the first fault after the checks (exit 2 at the end)
        if path:
            self.conn, self.fd = open_campaign_db(path, adb.make_schema)
        else:
            self.conn = adb.memory_db()
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

    def known_planner(self, name: str) -> int | None:
        """The id of planner ``name`` if the database has it (nothing written)."""
        row = self.conn.execute("SELECT id FROM plannerConfigs WHERE name = ? AND settings = ''",
                                (f"geometric_{name}",)).fetchone()
        return None if row is None else row[0]

    def stored_tasks(self, tasks: list[dict]) -> list[dict]:
        """The tasks whose run the database already holds."""
        out = []
        for t in tasks:
            e = self.experiment(t, create=False)
            p = None if e is None else self.known_planner(t["planner"])
            if p is not None and adb.has_run(self.conn, e, p, int(t["seed"])):
                out.append(t)
        return out

    def stored_rows(self, tasks: list[dict]) -> list[dict]:
        """The rows of the tasks whose run the database holds, read back from it (what
        ``--resume`` skips still belongs to the campaign's outputs)."""
        from .rows import complete_row

        out = []
        try:
            for t in tasks:
                e = self.experiment(t, create=False)
                p = None if e is None else self.known_planner(t["planner"])
                got = None if p is None else adb.stored_run(self.conn, e, p, t["seed"])
                if got is not None:
                    out.append(complete_row(t, got, got["wall_s"]))
        except DB_ERRORS as exc:
            from .arena_file import describe

            raise InputError(self.path, "--db", describe(exc)) from None
        return out

    def select(self, tasks: list[dict], resume: bool) -> list[dict]:
        """The tasks left to run: all (refused if some are stored), or, resuming, those not stored."""
        try:
            done = self.stored_tasks(tasks)
        except DB_ERRORS as exc:
            from .arena_file import describe

            raise InputError(self.path, "--db", describe(exc)) from None
        if done and not resume:
            raise InputError("bench", "--db", f"{self.path} already holds {len(done)} of this sweep's "
                                              f"{len(tasks)} runs: add --resume to run only the others, or "
                                              "give another --db")
        keys = {self.task_key(t) for t in done}
        return [t for t in tasks if self.task_key(t) not in keys]

    def add(self, rows: list[dict]) -> None:
        """Store finished runs in one transaction (a run already stored is skipped, never doubled).
        A database error stops the storing (:attr:`failure`), not the sweep."""
        self.pending.extend(rows)
        if self.failure is not None:
            return
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
        except BaseException as exc:
            self.pending = todo + self.pending  # rolled back: stored at the next batch or at close
            self.experiments.clear()  # an experiment created in the rolled-back transaction is gone too
            self.planners.clear()
            if not isinstance(exc, DB_ERRORS):
                raise
            self.fail(exc)

    def fail(self, exc: Exception) -> None:
        from .arena_file import describe

        if self.failure is None:
            self.failure = InputError(self.path or "bench", "--db",
                                      f"{describe(exc)} after {self.stored} runs were stored: those are kept, "
                                      f"{len(self.pending)} finished runs are not (every row is in --out)")

    def check(self) -> None:
        """Exit 2 (one line) if storing failed during the sweep; call once the outputs are written."""
        if self.failure is not None:
            raise self.failure

    def on_row(self, row: dict) -> None:
        """The sweep's hook: one finished run, stored at once."""
        self.add([row])

    def finish(self, log_dir: str | None = None, inputs=()) -> list[str]:
        """Store what is left, write the logs, compute OMPL's views, give up the claim; returns the
        log files. A database error is kept in :attr:`failure` (see :meth:`check`)."""
        if self.pending:
            self.add([])
        logs = []
        try:
            if log_dir:
                from .ompl_log import write_logs

                try:
                    logs = write_logs(self.conn, log_dir, inputs)
                except InputError as exc:  # a log that cannot be written: said at the end, --out first
                    self.failure = self.failure or exc
            self.conn.close()
            if self.path and self.failure is None:
                try:  # OMPL's own views (best planner per experiment), as its converter makes them
                    from ompl.tools import computeViews
                except ImportError:  # pragma: no cover - the bench needs OMPL
                    computeViews = None
                if computeViews is not None:
                    computeViews(self.path, False)
        except DB_ERRORS as exc:
            self.fail(exc)
        finally:
            self.close()
        return logs

    def close(self) -> None:
        """Close the database and give up the claim on it (again: nothing happens)."""
        from .arena_file import release

        self.conn.close()
        release(self.fd)
        self.fd = None
