"""``cspace bench`` processes: forked runs hold the built C-space, die with the bench,
are killed at their hard limit; Ctrl-C while writing never reports a complete sweep;
scenarios sharing a name are kept apart."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import conftest
from planners import bench
from planners.bench import outputs
from planners.bench import rows as bench_rows
from planners.pictures import bench_figure
from planners.bench.pool import CAN_FORK
from planners.cli import main

ROOT = Path(conftest.ROOT)
BASIC = str(ROOT / "scenarios" / "basic.toml")
needs_fork = pytest.mark.skipif(not CAN_FORK, reason="needs os.fork")


def _children(pid: int) -> set[int]:
    """Live (not zombie) processes whose parent is ``pid`` (Linux /proc)."""
    out = set()
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                stat = Path(f"/proc/{d}/stat").read_text()
            except OSError:
                continue
            fields = stat.rsplit(")", 1)[1].split()
            if int(fields[1]) == pid and fields[0] != "Z":
                out.add(int(d))
    return out


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@needs_fork
@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_children_die_with_the_bench(tmp_path, sig):
    proc = subprocess.Popen([sys.executable, "-m", "planners.cli", "bench", BASIC, "--planners", "RRTstar",
                             "--times", "20", "--runs", "2", "--workers", "2", "--out", str(tmp_path / "o"), "-q"],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 15
    kids: set[int] = set()
    while len(kids) < 2 and time.time() < deadline:
        time.sleep(0.1)
        kids = _children(proc.pid)
    assert len(kids) == 2, "the runs did not start"
    proc.send_signal(sig)
    proc.wait(timeout=10)
    deadline = time.time() + 5
    while any(_alive(k) for k in kids) and time.time() < deadline:
        time.sleep(0.05)
    assert not any(_alive(k) for k in kids), "a run outlived the bench"


@needs_fork
@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads /proc")
def test_a_sweep_killed_before_it_writes_leaves_the_earlier_results(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.json").write_text("earlier")
    proc = subprocess.Popen([sys.executable, "-m", "planners.cli", "bench", BASIC, "--planners", "RRTstar",
                             "--times", "20", "--runs", "1", "--workers", "1", "--out", str(out), "-q"],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 15
    while not _children(proc.pid) and time.time() < deadline:
        time.sleep(0.1)
    assert _children(proc.pid), "the run did not start"
    proc.kill()
    proc.wait(timeout=10)
    assert (out / "results.json").read_text() == "earlier"


@needs_fork
def test_forked_run_past_its_hard_limit_is_a_timeout_and_a_crash_is_recorded():
    from cspace import CSpace, load_scenario
    from planners.bench.pool import run_forked

    sc = load_scenario(BASIC)
    held = {BASIC: (sc, CSpace.from_scenario(sc))}
    tasks = bench.make_tasks([{"file": BASIC, "scenario": "basic", "optimum": 1.0}], ["RRTstar", "RRT"], [5.0], 1,
                             abort_on=("RRT", 0))
    got = []
    t0 = time.perf_counter()
    run_forked(tasks, held, 2, lambda t: 0.5, lambda task, row, wall: got.append((task["planner"], row)))
    assert time.perf_counter() - t0 < 4.0
    rows = dict(got)
    assert rows["RRTstar"]["status"] == "timeout"
    assert rows["RRT"]["status"] == "crashed" and f"signal {int(signal.SIGABRT)}" in rows["RRT"]["message"]


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_or_sigterm_while_writing_outputs_is_not_complete(tmp_path, monkeypatch, sig):
    rows = [bench_rows.complete_row(t, {"status": "ok", "solved": False}, 0.1)
            for t in bench.make_tasks([{"file": BASIC, "scenario": "basic", "optimum": 1.0}], ["RRT"], [0.1], 2)]
    for r in rows:
        del r["order"]
    monkeypatch.setattr(bench_figure, "plot_error_vs_time", lambda *a: os.kill(os.getpid(), sig))
    # The handler the process had (Python's default, or SIG_IGN in a background job of a
    # non-interactive shell, which an earlier version of this test wrongly assumed away).
    before = signal.getsignal(sig)
    hit = outputs.write_deferring_sigint(rows, str(tmp_path), {"complete": True}, plot=True)
    assert hit == sig  # its number: the command's exit code is 128 + it
    assert json.loads((tmp_path / "results.json").read_text())["meta"]["complete"] is False
    assert signal.getsignal(sig) is before  # the handler is restored


def test_a_new_sweep_never_keeps_an_earlier_sweeps_outputs(tmp_path):
    out = tmp_path / "o"
    (out / "ompl").mkdir(parents=True)
    for name in ("error_vs_time.png", "results.json", "ompl/old_t9.log"):
        (out / name).write_text("old")
    (out / "mine.txt").write_text("keep")
    assert main(["bench", BASIC, "--planners", "RRTConnect", "--times", "0.05", "--runs", "1", "--out", str(out),
                 "-q", "--no-plot"]) == 0
    assert not (out / "error_vs_time.png").exists() and not (out / "ompl" / "old_t9.log").exists()
    assert (out / "mine.txt").read_text() == "keep"
    assert json.loads((out / "results.json").read_text())["meta"]["complete"] is True


def test_scenarios_sharing_a_name_are_kept_apart(tmp_path):
    text = Path(BASIC).read_text()
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    (a / "s.toml").write_text(text)
    (b / "s.toml").write_text(text.replace("[[6, 4], [7, 4], [7, 10], [6, 10]]", "[[6, 2], [7, 2], [7, 10], [6, 10]]"))
    out = tmp_path / "o"
    assert main(["bench", str(a / "s.toml"), str(b / "s.toml"), "--planners", "RRTConnect", "--times", "0.2",
                 "--runs", "1", "--out", str(out), "-q", "--no-plot"]) == 0
    data = json.loads((out / "results.json").read_text())
    names = [s["scenario"] for s in data["meta"]["scenarios"]]
    assert len(set(names)) == 2 and all(n.startswith("basic") for n in names)
    assert data["meta"]["scenarios"][0]["optimum"] != data["meta"]["scenarios"][1]["optimum"]
    assert {r["scenario"] for r in data["rows"]} == set(names)
    for r in data["rows"]:  # each row carries its own scene's optimum
        assert r["optimum"] == next(s["optimum"] for s in data["meta"]["scenarios"] if s["file"] == r["file"])
    assert len(os.listdir(out / "ompl")) == 2
    assert len(bench_figure.curves(data["rows"])) == 2


def test_the_same_file_twice_is_refused(tmp_path, capsys):
    assert main(["bench", BASIC, BASIC, "--out", str(tmp_path / "o"), "-q"]) == 2
    assert "given twice" in capsys.readouterr().err


def test_budget_beyond_the_clock_is_refused(tmp_path, capsys):
    assert main(["bench", BASIC, "--times", "8e9", "--out", str(tmp_path / "o"), "-q"]) == 2
    err = capsys.readouterr().err
    assert ": --times: " in err and len(err.strip().splitlines()) == 1


def test_a_300_character_scenario_name_is_fine(tmp_path):
    f = tmp_path / "long.toml"
    f.write_text(Path(BASIC).read_text().replace('name = "basic"', f'name = "{"n" * 300}"'))
    out = tmp_path / "o"
    assert main(["bench", str(f), "--planners", "RRTConnect", "--times", "0.1", "--runs", "1", "--out", str(out),
                 "-q", "--no-plot"]) == 0
    (log,) = os.listdir(out / "ompl")
    assert len(log) < 120
