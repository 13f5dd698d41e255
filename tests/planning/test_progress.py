"""Progress bars: drawn on a terminal, silent otherwise, and the exact search's reports are honest.

A terminal is faked with a StringIO whose ``isatty`` says yes; tqdm then draws into it.
"""
from __future__ import annotations

import io
import os
import sys

import numpy as np
import pytest

from conftest import ROOT
from cspace.translation.cspace import CSpace
from cspace.io.load import load_scenario
from cspace.paths.shortest import shortest_path
from planners import progress as pg
from planners.cli import main



class FakeTTY(io.StringIO):
    def isatty(self) -> bool:
        return True


def terminal(monkeypatch) -> FakeTTY:
    """Make stderr a terminal; bars show at once (no delay) and redraw at every step.

    Called in the test's body: pytest's output capture puts its own sys.stderr back
    between a fixture's setup and the test.
    """
    fake = FakeTTY()
    monkeypatch.setattr(sys, "stderr", fake)
    monkeypatch.setattr(pg, "DELAY", 0.0)
    monkeypatch.setattr(pg, "MININTERVAL", 0.0)
    monkeypatch.delenv("TQDM_DISABLE", raising=False)
    return fake


def test_bar_drawn_on_a_terminal(monkeypatch):
    tty = terminal(monkeypatch)
    with pg.progress(3, "cases", leave=True) as bar:
        assert bar.shown
        for _ in range(3):
            bar.update()
    assert not bar.shown  # closed
    out = tty.getvalue()
    assert "cases" in out and "3/3" in out


def test_silent_when_not_a_terminal(monkeypatch):
    fake = io.StringIO()
    monkeypatch.setattr(sys, "stderr", fake)
    with pg.progress(3, "cases") as bar:
        assert not bar.shown
        bar.update(3)
    assert list(pg.track(range(4), "x")) == [0, 1, 2, 3]
    assert fake.getvalue() == ""


def test_tqdm_disable_silences_a_terminal(monkeypatch):
    tty = terminal(monkeypatch)
    monkeypatch.setenv("TQDM_DISABLE", "1")
    with pg.progress(2, "cases") as bar:
        bar.update(2)
    assert tty.getvalue() == ""


def test_missing_tqdm_is_silent(monkeypatch):
    tty = terminal(monkeypatch)
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm raises ImportError
    with pg.progress(2, "cases", enabled=True) as bar:
        assert not bar.shown
        bar.update(2)
    assert bar.n == 2 and tty.getvalue() == ""


def test_ticker_redraws_a_stage_without_steps(monkeypatch):
    tty = terminal(monkeypatch)
    import time

    with pg.progress(None, "building", tick=0.02) as bar:
        before = tty.getvalue().count("\r")
        time.sleep(0.2)
        after = tty.getvalue().count("\r")
    assert after > before  # the clock ran while no step was made


def test_cli_commands_are_silent_off_a_terminal(tmp_path, capsys):
    out = tmp_path / "m.toml"
    assert main(["generate", "maze", "--size", "4", "--out", str(out)]) == 0
    assert main(["plan", os.path.join(ROOT, "scenarios", "basic.toml"), "--planner", "exact"]) == 0
    assert capsys.readouterr().err == ""


def test_generate_shows_its_stages_on_a_terminal(monkeypatch, tmp_path):
    tty = terminal(monkeypatch)
    assert main(["generate", "maze", "--size", "4", "--out", str(tmp_path / "m.toml")]) == 0
    out = tty.getvalue()
    assert "maze-4x4: building the C-space" in out and "maze-4x4: free-space components" in out, out[-500:]


def test_exact_plan_shows_its_search_on_a_terminal(monkeypatch):
    tty = terminal(monkeypatch)
    from planners import plan

    res = plan(os.path.join(ROOT, "scenarios", "ompl", "circles.toml"), planner="exact")
    assert res.solved
    out = tty.getvalue()
    assert "exact search" in out and "length >= " in out


def test_stability_shows_progress_on_a_terminal(monkeypatch):
    tty = terminal(monkeypatch)
    from planners.stability import catalogue as st

    rows = st.run_all(st.catalogue()[:3], progress=None)
    assert len(rows) == 3
    assert "stability" in tty.getvalue() and "/3 [" in tty.getvalue()


# ---------------------------------------------------------------- the exact search's reports


def _circles():
    sc = load_scenario(os.path.join(ROOT, "scenarios", "ompl", "circles.toml"))
    return sc, CSpace.from_scenario(sc)


def test_search_reports_a_rising_lower_bound_that_ends_at_the_length(monkeypatch):
    import cspace.paths.shortest

    monkeypatch.setattr(cspace.paths.shortest, "PROGRESS_EVERY", 1)  # a report per settled node
    sc, cs = _circles()
    calls = []
    sp = shortest_path(cs.pieces, cs.bounds, sc.start, sc.goal, on_progress=lambda *a: calls.append(a))
    plain = shortest_path(cs.pieces, cs.bounds, sc.start, sc.goal)
    assert sp.solved and np.array_equal(sp.path, plain.path) and sp.length == plain.length
    assert len(calls) >= 10  # one per settled node, then the final one
    settled = [c[0] for c in calls]
    bounds = [c[2] for c in calls]
    assert settled[:-1] == list(range(1, len(calls))) and settled[-1] == settled[-2]
    assert all(c[1] == sp.stats["counts"]["nodes"] for c in calls)
    assert all(a <= b for a, b in zip(bounds, bounds[1:]))  # never decreases
    assert all(b <= sp.length * (1 + 1e-12) for b in bounds)  # a true lower bound
    assert bounds[-1] == pytest.approx(sp.length, rel=1e-12)
    assert bounds[0] >= np.hypot(*(np.subtract(sc.goal[:2], sc.start[:2]))) * (1 - 1e-12)


# ---------------------------------------------------------------- the bench's drop-in bar


ROW = {"scenario": "s", "planner": "P", "time_budget": 0.1, "seed": 0, "status": "ok"}


def _steps(bar):
    bar.step(ROW)
    bar.step({**ROW, "seed": 1, "status": "crashed"})
    bar.close()
    return bar


def test_bench_bar_on_a_terminal(monkeypatch):
    tty = terminal(monkeypatch)
    bar = _steps(pg._Bar(2, True))
    assert (bar.n, bar.bad) == (2, 1)
    out = tty.getvalue()
    assert "bench" in out and "2/2" in out and "seed 1: crashed" in out


def test_bench_bar_off_a_terminal_reports_only_failed_runs(monkeypatch):
    fake = io.StringIO()
    monkeypatch.setattr(sys, "stderr", fake)
    _steps(pg._Bar(2, True))
    assert fake.getvalue() == "bench: s P 0.1s seed 1: crashed\n"


def test_bench_bar_quiet_is_silent(monkeypatch):
    tty = terminal(monkeypatch)
    _steps(pg._Bar(2, False))
    assert tty.getvalue() == ""
