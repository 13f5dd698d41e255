"""``cspace bench --db/--log/--runs`` under hostile and unlucky inputs (issue 48; ``--scheduler``:
test_hostile_scheduler.py).

Each test covers a class of fault, not one case: any foreign or damaged database file is refused
before a byte of it changes; a database that fails during the sweep keeps its stored runs and
the command says so in one exit-2 line; a campaign holds its database alone; log names from a
database never leave ``--log DIR``; a sweep's size is bounded; SIGTERM ends a sweep as Ctrl-C does.
"""
from __future__ import annotations

import hashlib
import os
import random
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

import conftest
from planners.bench import arena_db
from planners.bench.pool import CAN_FORK
from planners.cli import main

ROOT = Path(conftest.ROOT)
BASIC = str(ROOT / "scenarios" / "basic.toml")
pytest.importorskip("ompl")
ARGS = ["--planners", "RRTConnect", "--times", "0.01", "--runs", 2]


def bench(*args) -> int:
    return main(["bench", *map(str, args), "-q", "--no-plot"])


def digest(path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def one_line(capsys, *needles) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, err
    return err


def runs_in(db) -> int:
    conn = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    try:
        return conn.execute("SELECT COUNT(*) FROM runs").fetchone()[0]
    finally:
        conn.close()


@pytest.fixture(scope="module")
def good_db(tmp_path_factory):
    """A benchmark database of two runs (copied by the tests that change one)."""
    tmp = tmp_path_factory.mktemp("good")
    db = tmp / "good.db"
    assert bench(BASIC, *ARGS, "--out", tmp / "o", "--db", db) == 0
    return db


def copy(src, dst) -> Path:
    Path(dst).write_bytes(Path(src).read_bytes())
    return Path(dst)


# ---------------------------------------------------------------- foreign, special and damaged files

def app_db(path, build) -> Path:
    conn = sqlite3.connect(path)
    conn.executescript(build)
    conn.commit()
    conn.close()
    return Path(path)


FOREIGN = {
    "an application's tables": "CREATE TABLE users (id INTEGER PRIMARY KEY, name TEXT); "
                               "INSERT INTO users (name) VALUES ('ada');",
    "a runs table of another schema": "CREATE TABLE runs (x TEXT); INSERT INTO runs VALUES ('keep me');",
    "four of the five tables": "CREATE TABLE experiments (id INTEGER PRIMARY KEY, name TEXT); "
                               "CREATE TABLE plannerConfigs (id INTEGER PRIMARY KEY, name TEXT, settings TEXT); "
                               "CREATE TABLE enums (name TEXT, value INTEGER, description TEXT); "
                               "CREATE TABLE runs (id INTEGER PRIMARY KEY, experimentid INTEGER, plannerid INTEGER);",
    "the five tables, runs without plannerid":
        "CREATE TABLE experiments (id INTEGER PRIMARY KEY, name TEXT); "
        "CREATE TABLE plannerConfigs (id INTEGER PRIMARY KEY, name TEXT, settings TEXT); "
        "CREATE TABLE enums (name TEXT, value INTEGER, description TEXT); "
        "CREATE TABLE runs (id INTEGER PRIMARY KEY, experimentid INTEGER); "
        "CREATE TABLE progress (runid INTEGER, time REAL);",
}


@pytest.mark.parametrize("kind", list(FOREIGN))
def test_a_foreign_sqlite_database_is_refused_unchanged(tmp_path, capsys, kind):
    db = app_db(tmp_path / "app.db", FOREIGN[kind])
    before = digest(db)
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--db", db) == 2
    one_line(capsys, "--db", "not a benchmark database")
    assert digest(db) == before and sorted(os.listdir(tmp_path)) == ["app.db", "o"]


def test_a_failed_schema_upgrade_changes_nothing(tmp_path, capsys):
    # every table a benchmark database has, but two runs with one key: the unique run-key index,
    # the last step of the upgrade, cannot be made; the columns added before it are rolled back too
    db = app_db(tmp_path / "dup.db", "".join(
        s + ";" for s in arena_db.SCHEMA) + "ALTER TABLE runs ADD seed INTEGER; "
        "INSERT INTO runs (experimentid, plannerid, seed) VALUES (1, 1, 0); "
        "INSERT INTO runs (experimentid, plannerid, seed) VALUES (1, 1, 0);")
    before = digest(db)
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--db", db) == 2
    one_line(capsys, "--db")
    assert digest(db) == before


@pytest.mark.parametrize("name", [":memory:", "file:x.db?mode=memory", "/dev/null", "{tmp}", "{tmp}/fifo"])
def test_special_names_are_refused(tmp_path, capsys, name):
    os.mkfifo(tmp_path / "fifo")
    name = name.format(tmp=tmp_path)
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--db", name) == 2
    one_line(capsys, "--db")
    assert not os.path.exists("x.db") and not os.path.exists(":memory:")


def test_a_database_that_cannot_be_written_is_refused_before_the_sweep(tmp_path, capsys, good_db):
    # SQLite's journal beside the file cannot be made (a folder in its place: as a read-only
    # folder, also for root); with nothing to change in the schema, only the write probe finds it
    db = copy(good_db, tmp_path / "ro.db")
    os.mkdir(tmp_path / "ro.db-journal")
    before = digest(db)
    assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.03", "--runs", 1, "--out", tmp_path / "o",
                 "--db", db) == 2
    one_line(capsys, "--db", "cannot write")
    assert digest(db) == before and not (tmp_path / "o" / "results.json").exists()


def test_a_read_only_file_is_refused(tmp_path, capsys, good_db):
    # read-only by its mode, or (root writes those) immutable (chattr +i)
    db = copy(good_db, tmp_path / "ro.db")
    os.chmod(db, 0o444)
    immutable = os.geteuid() == 0
    if immutable and subprocess.run(["chattr", "+i", str(db)], capture_output=True).returncode != 0:
        pytest.skip("root, and no chattr +i here")
    try:
        before = digest(db)
        assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.03", "--runs", 1, "--out", tmp_path / "o",
                     "--db", db) == 2
        one_line(capsys, "--db", "cannot write")
        assert digest(db) == before
    finally:
        if immutable:
            subprocess.run(["chattr", "-i", str(db)], capture_output=True)


def test_every_damaged_page_is_refused_unchanged(tmp_path, capsys, good_db):
    # each page of a real benchmark database (but the header page) overwritten with noise:
    # refused in one line, never exit 3, the file left as it was
    data = good_db.read_bytes()
    page = int.from_bytes(data[16:18], "big")
    page = 65536 if page == 1 else page
    rng = random.Random(48)
    pages = len(data) // page
    assert pages >= 5
    for k in range(1, pages):
        bad = bytearray(data)
        bad[k * page:(k + 1) * page] = bytes(rng.randrange(256) for _ in range(page))
        db = tmp_path / f"bad{k}.db"
        db.write_bytes(bytes(bad))
        code = bench(BASIC, "--planners", "RRTConnect", "--times", "0.03", "--runs", 1, "--out", tmp_path / "o",
                     "--db", db)
        assert code == 2, k
        one_line(capsys, "--db")
        assert db.read_bytes() == bytes(bad), k


def test_a_database_error_during_the_sweep_keeps_the_stored_runs(tmp_path, capsys, monkeypatch):
    # after two stored runs the journal can no longer be made (a full disk, a lost mount): the
    # sweep goes on, --out gets every row, the two runs stay, and the command says so, exit 2
    from planners.bench.campaign import Campaign

    db = tmp_path / "late.db"
    real = Campaign.on_row

    def on_row(self, row):
        if self.stored == 2 and not os.path.exists(f"{db}-journal"):
            os.mkdir(f"{db}-journal")
        real(self, row)

    monkeypatch.setattr(Campaign, "on_row", on_row)
    assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.01", "--runs", 5, "--out", tmp_path / "o",
                 "--db", db, "--log", tmp_path / "logs") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len([line for line in err if line.startswith("error:")]) == 1 and "Traceback" not in "".join(err)
    assert "after 2 runs were stored" in err[-1] and "--db" in err[-1]
    os.rmdir(f"{db}-journal")
    assert runs_in(db) == 2
    import json

    assert len(json.loads((tmp_path / "o" / "results.json").read_text())["rows"]) == 5


# ---------------------------------------------------------------- one campaign per database

HOLD = """import sys, time
sys.path.insert(0, {root!r})
from planners.bench.arena_file import claim
claim({db!r})
print("held", flush=True)
time.sleep(120)
"""


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX locks")
@pytest.mark.parametrize("fresh", [True, False])
def test_a_database_in_use_by_another_bench_is_refused(tmp_path, capsys, good_db, fresh):
    db = tmp_path / "busy.db"
    if not fresh:
        copy(good_db, db)
    holder = subprocess.Popen([sys.executable, "-c", HOLD.format(root=str(ROOT), db=str(db))],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        before = digest(db)
        assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--db", db) == 2
        one_line(capsys, "in use by another bench")
        assert digest(db) == before
    finally:
        holder.kill()
        holder.wait()
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--db", db, *([] if fresh else ["--resume"])) == 0


@pytest.mark.skipif(not CAN_FORK, reason="needs os.fork")
def test_two_sweeps_at_once_store_each_run_once(tmp_path):
    db = tmp_path / "two.db"
    args = ["bench", BASIC, "--planners", "RRTConnect", "--times", "0.02", "--runs", "6", "-q", "--no-plot",
            "--db", str(db)]
    procs = [subprocess.Popen([sys.executable, "-m", "planners.cli", *args, "--out", str(tmp_path / f"o{i}")],
                              cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
             for i in range(2)]
    outs = [(p.wait(timeout=300), p.stderr.read()) for p in procs]
    codes = sorted(c for c, _ in outs)
    assert codes in ([0, 2], [0, 0]), outs  # [0, 0]: the second started after the first ended
    if codes == [0, 2]:
        assert "in use by another bench" in next(e for c, e in outs if c == 2)
    conn = sqlite3.connect(db)
    keys = arena_db.run_keys(conn)
    conn.close()
    assert len(keys) == len(set(keys)) == 6


# ---------------------------------------------------------------- identifiers and logs

def test_quoted_identifiers_and_hostile_experiment_names_stay_in_the_log_folder(tmp_path, capsys, good_db):
    db = copy(good_db, tmp_path / "h.db")
    conn = sqlite3.connect(db)
    conn.execute('ALTER TABLE runs ADD "weird col" REAL')
    conn.execute('ALTER TABLE runs ADD "a""b;c" TEXT')
    conn.execute("UPDATE runs SET \"a\"\"b;c\" = 'x;y\n|>>>'")
    (eid,) = conn.execute("SELECT id FROM experiments LIMIT 1").fetchone()
    names = [os.path.join(os.pardir, os.pardir, "escaped"), str(tmp_path / "abs"), "line\n|>>>\nbreak", "\x1b[31mred"]
    for i, name in enumerate(names):
        conn.execute("INSERT INTO experiments (name, totaltime, timelimit, memorylimit, runcount, version, "
                     "hostname, cpuinfo, date, seed, setup, iterations, objective, reference, scenario_sha256, "
                     "slabs, space, time_budget) SELECT ?, totaltime, timelimit, memorylimit, runcount, version, "
                     "hostname, cpuinfo, date, seed, ?, iterations, objective, reference, ?, slabs, space, "
                     "time_budget FROM experiments WHERE id = ?", (name, name, f"x{i}", eid))
    conn.commit()
    conn.close()
    (tmp_path / "escaped.log").write_text("keep\n")
    logs = tmp_path / "deep" / "er" / "logs"
    assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.03", "--runs", 1, "--out", tmp_path / "o",
                 "--db", db, "--log", logs) == 0, capsys.readouterr().err
    assert (tmp_path / "escaped.log").read_text() == "keep\n" and not (tmp_path / "abs.log").exists()
    written = sorted(os.listdir(logs))
    assert len(written) == 2 + len(names) and all(f.endswith(".log") and "/" not in f for f in written)
    for f in written:
        text = (logs / f).read_text()
        assert "\x1b" not in text and "\n|>>>\nbreak" not in text
    converted = tmp_path / "c.db"
    proc = subprocess.run([sys.executable, "-m", "ompl.ompl_benchmark_statistics", "-d", str(converted),
                           *[str(logs / f) for f in written]], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert runs_in(converted) == 2 + 1  # the two stored runs and the new one (the copies have none)


def test_log_folder_is_checked_against_out_and_the_inputs(tmp_path, capsys):
    out = tmp_path / "o"
    assert bench(BASIC, *ARGS, "--out", out, "--log", out / "ompl") == 2
    one_line(capsys, "--log", "ompl folder")
    scen = tmp_path / "basic_t0.01.log"
    scen.write_bytes(Path(BASIC).read_bytes())
    before = digest(scen)
    assert bench(scen, *ARGS, "--out", out, "--log", tmp_path) == 2
    one_line(capsys, "--log", "input")
    assert digest(scen) == before
    assert bench(BASIC, *ARGS, "--out", out, "--db", out / "results.json") == 2
    one_line(capsys, "--db", "outputs")


def test_control_characters_in_a_file_name_do_not_reach_the_log_or_terminal(tmp_path, capsys):
    scen = tmp_path / "evil\n|>>>\n\x1b[31m.toml"
    scen.write_bytes(Path(BASIC).read_bytes().replace(b'name = "basic"', b"", 1))
    logs = tmp_path / "logs"
    assert bench(scen, *ARGS, "--out", tmp_path / "o", "--log", logs) == 0
    err = capsys.readouterr().err
    assert "\x1b" not in err
    files = [str(p) for p in logs.glob("*.log")]
    assert len(files) == 1 and "\x1b" not in Path(files[0]).read_text()
    for own in (tmp_path / "o" / "ompl").glob("*.log"):  # --out's own logs too
        lines = own.read_text().splitlines()
        assert "\x1b" not in "".join(lines) and lines.count("|>>>") == lines.count("<<<|") == 2
    converted = tmp_path / "c.db"
    proc = subprocess.run([sys.executable, "-m", "ompl.ompl_benchmark_statistics", "-d", str(converted), *files],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert runs_in(converted) == 2


# ---------------------------------------------------------------- size and SIGTERM

@pytest.mark.parametrize("runs,times,planners", [(10**9, "0.01", "RRTConnect"), (20000, "0.01,0.02,0.03",
                                                                              "RRTConnect,RRTstar")])
def test_a_sweep_beyond_the_bound_is_refused_with_its_count(tmp_path, capsys, runs, times, planners):
    from planners.cli.bench import MAX_RUNS

    count = runs * len(times.split(",")) * len(planners.split(","))
    assert bench(BASIC, "--planners", planners, "--times", times, "--runs", runs, "--out", tmp_path / "o") == 2
    one_line(capsys, "--runs", str(count), str(MAX_RUNS))


@pytest.mark.skipif(not CAN_FORK, reason="needs os.fork")
def test_sigterm_ends_a_sweep_as_ctrl_c_with_its_rows_written(tmp_path):
    import json

    db = tmp_path / "t.db"
    proc = subprocess.Popen([sys.executable, "-m", "planners.cli", "bench", BASIC, "--planners", "RRTConnect",
                             "--times", "0.2", "--runs", "40", "--out", str(tmp_path / "o"), "--db", str(db), "-q",
                             "--no-plot"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            if runs_in(db) >= 2:
                break
        except sqlite3.Error:
            pass
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=120) == 143
    rows = json.loads((tmp_path / "o" / "results.json").read_text())
    assert rows["meta"]["complete"] is False and len(rows["rows"]) >= 2
    assert runs_in(db) == len(rows["rows"])


def test_an_internal_error_in_bench_does_not_point_to_an_option_it_lacks(tmp_path, capsys, monkeypatch):
    import planners.cli.bench as cli_bench

    def boom(*a, **k):
        raise RuntimeError("planted fault")

    monkeypatch.setattr(cli_bench, "sweep", boom)
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o") == 3
    err = one_line(capsys, "internal error: RuntimeError: planted fault")
    assert "--verbose" not in err


def test_a_refused_sweep_leaves_an_up_to_date_database_byte_for_byte(tmp_path, capsys, good_db):
    # the checks and the write probe of a database that needs no upgrade are rolled back: a sweep
    # refused after them (its runs already stored, no --resume) leaves the file as it was
    db = copy(good_db, tmp_path / "same.db")
    before = digest(db)
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--db", db) == 2
    one_line(capsys, "already holds 2 of this sweep's 2 runs")
    assert digest(db) == before


def test_a_database_in_a_read_only_folder_is_refused_before_the_sweep(tmp_path, capsys, good_db):
    folder = tmp_path / "ro"
    folder.mkdir()
    db = copy(good_db, folder / "c.db")
    os.chmod(folder, 0o555)
    immutable = os.geteuid() == 0
    if immutable and subprocess.run(["chattr", "+i", str(folder)], capture_output=True).returncode != 0:
        pytest.skip("root, and no chattr +i here")
    try:
        before = digest(db)
        assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.03", "--runs", 1, "--out", tmp_path / "o",
                     "--db", db) == 2
        one_line(capsys, "--db", "cannot write")
        assert digest(db) == before and os.listdir(folder) == ["c.db"]
    finally:
        if immutable:
            subprocess.run(["chattr", "-i", str(folder)], capture_output=True)
        os.chmod(folder, 0o755)


@pytest.mark.parametrize("byte", [0x80, 0xFF, 0x00])
def test_single_damaged_bytes_in_the_schema_page_never_give_exit_3(tmp_path, capsys, good_db, byte):
    # a byte that is not UTF-8 in the schema's SQL made SQLite's error message undecodable
    # (UnicodeDecodeError: exit 3, found by the campaigns fuzz); any byte of page 1 past the
    # header: exit 0 (harmless) or 2, refused unchanged
    data = good_db.read_bytes()
    for k, pos in enumerate(range(300, 4096, 227)):
        bad = bytearray(data)
        bad[pos] = byte
        db = tmp_path / f"b{k}.db"
        db.write_bytes(bytes(bad))
        code = bench(BASIC, "--planners", "RRTConnect", "--times", "0.03", "--runs", 1, "--out", tmp_path / "o",
                     "--db", db)
        err = capsys.readouterr().err
        assert code in (0, 2) and "internal error" not in err, (pos, err)
        lines = [line for line in err.strip().splitlines() if line.startswith("error:")]
        if code == 2:
            assert len(lines) == 1, (pos, err)
        if code == 2 and "runs were stored" not in lines[0]:  # refused: unchanged (else a later error)
            assert db.read_bytes() == bytes(bad), (pos, err)
