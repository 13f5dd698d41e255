"""``cspace bench --db/--log/--resume``: Planner Arena's database, OMPL's logs, resumable campaigns.

The round trip uses OMPL's own converter (``ompl_benchmark_statistics``, shipped in the
ompl wheel) on the ``--log`` output and compares its database with the one ``--db`` wrote;
Planner Arena's own loader (``plannerarena.database.load_database``) reads both.
"""
from __future__ import annotations

import os
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
CLOSED = str(ROOT / "scenarios" / "narrow_closed.toml")
pytest.importorskip("ompl")


def bench(*args) -> int:
    return main(["bench", *map(str, args), "-q", "--no-plot"])


def dump(path) -> dict:
    """A database's content keyed by names (experiment, planner, seed), never by row ids."""
    conn = sqlite3.connect(path)
    try:
        def cols(table):
            return [(c[1], c[2]) for c in conn.execute(f"PRAGMA table_info({table})")]

        exps = {}
        for row in conn.execute("SELECT * FROM experiments"):
            d = dict(zip([c for c, _ in cols("experiments")], row))
            exps[d.pop("name")] = (d.pop("id"), d)
        names = {i: n for n, (i, _) in exps.items()}
        planners = dict(conn.execute("SELECT id, name FROM plannerConfigs"))
        run_cols = [c for c, _ in cols("runs")]
        runs, by_id = {}, {}
        for row in conn.execute("SELECT * FROM runs"):
            d = dict(zip(run_cols, row))
            key = (names[d.pop("experimentid")], planners[d.pop("plannerid")], d["seed"])
            assert key not in runs, f"run {key} stored twice"
            by_id[d.pop("id")] = key
            runs[key] = d
        progress: dict = {}
        for runid, t, cost in conn.execute("SELECT runid, time, best_cost FROM progress ORDER BY runid, time"):
            progress.setdefault(by_id[runid], []).append((t, cost))
        return {"columns": {t: cols(t) for t in ("experiments", "plannerConfigs", "enums", "runs", "progress")},
                "experiments": {n: d for n, (_, d) in exps.items()},
                "planners": sorted(conn.execute("SELECT name, settings FROM plannerConfigs")),
                "enums": sorted(conn.execute("SELECT * FROM enums")), "runs": runs, "progress": progress}
    finally:
        conn.close()


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """One small sweep written with --db and --log, and OMPL's converter run on the logs."""
    tmp = tmp_path_factory.mktemp("arena")
    db, logs = tmp / "a.db", tmp / "logs"
    assert bench(BASIC, "--planners", "RRTConnect,RRTstar", "--times", "0.01,0.03", "--runs", 2,
                 "--out", tmp / "out", "--db", db, "--log", logs) == 0
    files = sorted(str(p) for p in logs.glob("*.log"))
    converted = tmp / "b.db"
    proc = subprocess.run([sys.executable, "-m", "ompl.ompl_benchmark_statistics", "-d", str(converted), *files],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return db, converted, files


def test_logs_converted_by_ompl_give_the_database_bench_wrote(campaign):
    db, converted, files = campaign
    assert [os.path.basename(f) for f in files] == ["basic_t0.01.log", "basic_t0.03.log"]
    a, b = dump(db), dump(converted)
    assert len(a["runs"]) == 2 * 2 * 2
    assert {k[1] for k in a["runs"]} == {"geometric_RRTConnect", "geometric_RRTstar"}
    assert max(len(p) for k, p in a["progress"].items() if k[1] == "geometric_RRTstar") > 1  # an anytime curve
    assert all(p == sorted(p) for p in a["progress"].values())
    for part in ("columns", "experiments", "planners", "enums", "runs", "progress"):
        assert a[part] == b[part], part


def test_runs_carry_ompl_and_cspace_properties(campaign):
    runs = dump(campaign[0])["runs"]
    solved = [r for r in runs.values() if r["solved"]]
    assert len(solved) >= 4  # 0.01 s is short on a loaded machine: an unsolved run is a Timeout
    for r in runs.values():
        assert r["time"] > 0 and r["wall_time"] >= r["time"] and r["reference_length"] > 0
        if not r["solved"]:
            assert (r["status"], r["certified"], r["solution_length"]) == (arena_db.TIMEOUT, 0, None)
            continue
        assert r["status"] == arena_db.EXACT and r["certified"] == 1
        assert r["exact_collision_free"] == 1 and r["approximate_solution"] == 0
        assert r["simplified_solution_length"] <= r["solution_length"]
        assert r["length_error"] == pytest.approx(r["simplified_solution_length"] / r["reference_length"] - 1)
        assert r["min_clearance"] >= 0 and r["solution_clearance"] == r["min_clearance"]
    exps = dump(campaign[0])["experiments"]
    assert exps["basic_t0.03"]["timelimit"] == 0.03 and exps["basic_t0.03"]["runcount"] == 2
    assert exps["basic_t0.03"]["version"].startswith("OMPL ")


def test_planner_arena_loads_both_databases(campaign):
    pa = pytest.importorskip("plannerarena.database", reason="plannerarena not installed (pip install 'cspace[bench]')")
    db, converted, _ = campaign
    a, b = pa.load_database(db), pa.load_database(converted)
    assert a["problem_names"] == b["problem_names"] == ["basic_t0.01", "basic_t0.03"]
    for name in ("certified", "exact collision free", "length error", "min clearance", "status"):
        assert name in a["attributes"]
    assert a["attributes"] == b["attributes"]
    keys = ["experiment", "planner", "seed"]
    ra = a["runs"].drop("id", "experimentid", "plannerid").sort(keys)
    rb = b["runs"].drop("id", "experimentid", "plannerid").sort(keys)
    assert ra.height == 8 and ra.equals(rb)
    assert a["progress"].height == b["progress"].height > 0
    assert a["enums"].filter(a["enums"]["value"] == 9)["description"].to_list() == ["Proven unsolvable"]


def test_a_proven_unsolvable_scene_says_so(tmp_path):
    db = tmp_path / "c.db"
    assert bench(CLOSED, "--planners", "RRTConnect", "--times", "0.01", "--runs", 1, "--out", tmp_path / "o",
                 "--db", db) == 0
    (r,) = dump(db)["runs"].values()
    assert r["status"] == arena_db.UNSOLVABLE and r["solved"] == 0 and r["certified"] == 0
    assert r["reference_length"] is None and r["solution_length"] is None


def test_resume_runs_only_what_is_missing_and_a_second_sweep_adds_to_the_database(tmp_path, capsys):
    db = tmp_path / "r.db"
    args = ["--planners", "RRTConnect", "--times", "0.01", "--out", tmp_path / "o", "--db", db]
    assert bench(BASIC, *args, "--runs", 2) == 0
    first = dump(db)["runs"]
    assert bench(BASIC, *args, "--runs", 3) == 2  # would store seeds 0 and 1 twice
    assert "already holds 2 of this sweep's 3 runs" in capsys.readouterr().err
    assert bench(BASIC, *args, "--runs", 3, "--resume") == 0
    after = dump(db)["runs"]
    assert sorted(after) == [("basic_t0.01", "geometric_RRTConnect", s) for s in range(3)]
    assert all(after[k] == v for k, v in first.items())  # stored runs untouched
    assert bench(BASIC, *args[:-2], "--times", "0.02", "--runs", 1, "--db", db) == 0  # another sweep, same db
    assert len(dump(db)["runs"]) == 4 and len(dump(db)["experiments"]) == 2


@pytest.mark.parametrize("scene", [BASIC, str(ROOT / "scenarios" / "se2" / "door_tight.toml")],
                         ids=["translation", "se2"])
def test_a_campaign_conflict_is_found_before_any_reference_is_computed(tmp_path, capsys, monkeypatch, scene):
    # The reference (the exact planner's path, every slab, the proof's regions) is the costly part
    # of a sweep's start: a database that already holds the runs is refused before it, and
    # --resume still finds them (a run's identity, slab count included, is known before it).
    import planners.bench.reference as ref

    db = tmp_path / "c.db"
    args = ["--planners", "RRTConnect", "--times", "0.01", "--runs", 1, "--out", tmp_path / "o", "--db", db]
    assert bench(scene, *args) == 0
    capsys.readouterr()
    warmed = []
    real = ref.warmed
    monkeypatch.setattr(ref, "warmed", lambda *a, **k: warmed.append(a) or real(*a, **k))
    assert bench(scene, *args) == 2
    assert "already holds 1 of this sweep's 1 runs" in capsys.readouterr().err
    assert warmed == []
    assert bench(scene, *args, "--resume") == 0  # nothing left to run, nothing stored twice
    assert len(dump(db)["runs"]) == 1 and len(warmed) == 1


@pytest.mark.parametrize("extra, needle", [(["--resume"], "--resume: needs --db"),
                                           (["--db", "{tmp}"], "--db: not a file name"),
                                           (["--db", "{tmp}/text.db"], "not a benchmark database")])
def test_bad_campaign_options_exit_2_with_one_line(tmp_path, capsys, extra, needle):
    (tmp_path / "text.db").write_text("not sqlite\n" * 200)
    extra = [e.format(tmp=tmp_path) for e in extra]
    assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.01", "--runs", 1, "--out", tmp_path / "o",
                 *extra) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and len(err.splitlines()) == 1


def stored(db) -> list[tuple]:
    """(run id, key) of every run in the database now ([] while it is being created)."""
    try:
        conn = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=10)
        try:
            return [(i, *k) for i, k in zip([r[0] for r in conn.execute("SELECT id FROM runs ORDER BY id")],
                                            arena_db.run_keys(conn))]
        finally:
            conn.close()
    except sqlite3.Error:
        return []


def kill_and_resume(tmp: Path, wait_runs: int, seeds: int = 12) -> tuple[int, int, int]:
    """Start a campaign, kill -9 it once ``wait_runs`` runs are stored, resume it; returns
    (runs stored before the kill, finished runs lost, runs stored twice)."""
    db = tmp / "k.db"
    args = ["bench", BASIC, "--planners", "RRTConnect,RRTstar", "--times", "0.05", "--runs", str(seeds),
            "--out", str(tmp / "o"), "--db", str(db), "-q", "--no-plot"]
    proc = subprocess.Popen([sys.executable, "-m", "planners.cli", *args], cwd=ROOT,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    before = []
    while time.monotonic() < deadline and proc.poll() is None:
        before = stored(db)
        if len(before) >= wait_runs:
            break
        time.sleep(0.005)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = stored(db) if len(stored(db)) >= len(before) else before
    assert main(args[:-2] + ["--resume", "-q", "--no-plot"]) == 0
    after = stored(db)
    lost = len(set(before) - set(after))  # a stored run (its id and key) gone or rewritten
    keys = [k[1:] for k in after]
    repeated = len(keys) - len(set(keys))
    grid = {k[:-2] + (f"geometric_{p}", s) for k in keys for p in ("RRTConnect", "RRTstar") for s in range(seeds)}
    assert set(keys) == grid and len(grid) == 2 * seeds
    return len(before), lost, repeated


@pytest.mark.skipif(not CAN_FORK, reason="needs os.fork")
def test_a_campaign_killed_by_sigkill_resumes_without_loss_or_repeat(tmp_path):
    n_before, lost, repeated = kill_and_resume(tmp_path, wait_runs=5)
    assert 5 <= n_before < 24  # killed mid-way
    assert (lost, repeated) == (0, 0)


@pytest.mark.skipif(not CAN_FORK, reason="needs os.fork")
def test_the_resume_script_counts_lost_and_repeated_runs(capsys):
    from conftest import load_script

    assert load_script("bench_resume").main(["--trials", "1", "--seeds", "3", "--seed", "1"]) == 0
    out = capsys.readouterr().out
    assert "1 kills: lost 0, repeated 0, incomplete 0" in out and "-> 6/6" in out


def test_resume_writes_the_whole_campaign_to_out(tmp_path):
    # --out describes the campaign, not only the runs made now (issue 51, point 3): after a partial
    # resume, and after a resume with nothing left to run, it holds every run, the stored ones
    # read back from the database as the first sweep wrote them
    import csv
    import json

    db = tmp_path / "w.db"
    args = ["--planners", "RRTConnect", "--times", "0.01", "--db", db]
    assert bench(BASIC, *args, "--runs", 2, "--out", tmp_path / "a") == 0
    assert bench(BASIC, *args, "--runs", 3, "--out", tmp_path / "b", "--resume") == 0
    assert bench(BASIC, *args, "--runs", 3, "--out", tmp_path / "c", "--resume") == 0  # nothing left to run

    def rows(folder):
        with open(tmp_path / folder / "results.csv", newline="") as fh:
            return list(csv.DictReader(fh))

    first, resumed, again = rows("a"), rows("b"), rows("c")
    assert [r["seed"] for r in resumed] == [r["seed"] for r in again] == ["0", "1", "2"]
    kept = ("planner", "time_budget", "seed", "status", "solved", "length", "length_unsimplified", "optimum",
            "error", "first_solution_s", "solve_s", "simplify_s", "state_checks", "motion_checks", "min_clearance")
    for a, b in zip(first, resumed):
        assert {k: a[k] for k in kept} == {k: b[k] for k in kept}
    assert {k: again[2][k] for k in kept} == {k: resumed[2][k] for k in kept}  # seed 2, run by the second sweep
    assert len(json.loads((tmp_path / "c" / "results.json").read_text())["rows"]) == 3


def test_quiet_keeps_the_summary_table(tmp_path, capsys):
    # -q drops the progress bar and the reference lines, not the result (issue 51, point 7)
    assert bench(BASIC, "--planners", "RRTConnect", "--times", "0.01", "--runs", 1, "--out", tmp_path / "q") == 0
    err = capsys.readouterr().err
    assert err.splitlines()[0].split()[:3] == ["scenario", "planner", "budget"], err
    assert any(line.split()[:2] == ["basic", "RRTConnect"] for line in err.splitlines()), err
