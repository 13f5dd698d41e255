"""Issue 39, items 8 ("silent mismatches") and 10 ("progress bars that do not move")."""
from __future__ import annotations

import io
import os
import re
import subprocess
import sys
import time

import pytest

from conftest import ROOT

import test_cli  # noqa: E402  (its scenario text)

BASIC = os.path.join(ROOT, "scenarios", "basic.toml")

TWO_QUERIES = test_cli.BASIC.replace('name = "cli"', 'name = "two"') + """[[queries]]
start = [1, 9]
goal = [9, 9]
"""


def cspace(*args, env=None, timeout=120):
    exe = os.path.join(os.path.dirname(sys.executable), "cspace")
    return subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=timeout,
                          env=None if env is None else {**os.environ, **env})


# ---------------------------------------------------------------- item 8

def test_show_theta_on_a_translation_scene_is_refused():
    r = cspace("show", BASIC, "--theta", 1)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.count("\n") == 1 and "--theta" in r.stderr and "--space se2" in r.stderr
    r = cspace("show", BASIC, "--theta", 1, "--space", "se2")  # where it applies, it is followed
    assert r.returncode == 0, r.stderr
    assert "slab" in r.stdout


def test_plan_csv_with_all_queries_writes_every_query(write_toml, tmp_path):
    src, out = write_toml(TWO_QUERIES), tmp_path / "p.csv"
    r = cspace("plan", src, "--planner", "exact", "--all-queries", "--csv", out)
    assert r.returncode == 0, r.stderr
    lines = out.read_text().splitlines()
    assert lines[0] == "query,x,y"
    rows = [line.split(",") for line in lines[1:]]
    by_query: dict = {}
    for q, x, y in rows:
        by_query.setdefault(int(q), []).append((float(x), float(y)))
    assert sorted(by_query) == [0, 1]
    assert by_query[0][0] == (1.0, 1.0) and by_query[0][-1] == (9.0, 1.0)
    assert by_query[1][0] == (1.0, 9.0) and by_query[1][-1] == (9.0, 9.0)


def test_plan_csv_of_one_query_keeps_its_format(write_toml, tmp_path):
    src, out = write_toml(TWO_QUERIES), tmp_path / "p.csv"
    r = cspace("plan", src, "--planner", "exact", "--csv", out)
    assert r.returncode == 0, r.stderr
    lines = out.read_text().splitlines()
    assert lines[0] == "x,y" and lines[1] == "1.0,1.0" and lines[-1] == "9.0,1.0"


def test_plan_help_names_only_the_planners_that_take_an_objective():
    from planners.adapters.glue import PLANNERS
    from planners.adapters.objectives import OBJECTIVE_PLANNERS, check_objective

    r = cspace("plan", "--help")
    assert r.returncode == 0
    text = " ".join(r.stdout.split())
    part = text.split("--objective {length,clearance,balanced} ", 1)[1].split(" --", 1)[0]
    named = [p for p in PLANNERS if re.search(rf"\b{p}\b", part)]
    assert set(OBJECTIVE_PLANNERS) <= set(named)
    for p in named:  # each planner the help names is accepted with a non-length objective
        assert check_objective("clearance", p) == "clearance"
    with pytest.raises(ValueError):
        check_objective("clearance", "PRMstar")
    assert "PRMstar" not in part


def _rows(scen: str, reference: str) -> list[dict]:
    return [{"scenario": scen, "planner": "RRTConnect", "time_budget": 0.1, "seed": s, "status": "ok",
             "solved": True, "error": 0.1 * (s + 1), "reference": reference} for s in range(3)]


def test_bench_figure_labels_a_lower_bound_error_as_such():
    pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt

    from planners.pictures.bench_figure import figure_error_vs_time

    fig = figure_error_vs_time(_rows("car", "lower_bound"))
    try:
        label = fig.axes[0].get_ylabel()
        assert "lower bound" in label and "optimum" not in label
    finally:
        plt.close(fig)
    fig = figure_error_vs_time(_rows("plain", "optimum") + _rows("car", "lower_bound"))
    try:
        labels = [ax.get_ylabel() for ax in fig.axes[:2]]
        assert "optimum" in labels[0] and "lower bound" in labels[1]
    finally:
        plt.close(fig)


def test_bench_summary_names_the_space_of_a_car_scene():
    from planners.bench.sweep import summary

    rows = [{**r, "min_clearance": 0.1, "min_clearance_bound": "lower"} for r in _rows("u-turn", "lower_bound")]
    text = summary(rows, [{"scenario": "u-turn", "space": "reeds-shepp", "reference": "lower_bound"}])
    notes = [line for line in text.splitlines() if line.startswith(("<=", ">="))]
    assert len(notes) == 2 and not any("SE(2)" in line for line in notes), notes
    assert "Reeds-Shepp car scenes have no exact optimum" in notes[0] and "Reeds-Shepp car paths" in notes[1]


def test_bench_reference_note_says_lower_bound_once(capsys):
    from planners.bench.reference import reference

    out = reference([os.path.join(ROOT, "scenarios", "car", "u_turn.toml")], quiet=False)
    assert out[0]["reference"] == "lower_bound"
    err = capsys.readouterr().err
    assert err.count("lower bound") == 1, err


def test_version_says_whether_the_fast_path_is_on():
    import importlib.util

    built = importlib.util.find_spec("cspace.compiled._fast") is not None  # whatever CSPACE_PURE says here
    plain = cspace("--version", env={"CSPACE_PURE": "0"})
    pure = cspace("--version", env={"CSPACE_PURE": "1"})
    assert plain.returncode == pure.returncode == 0
    assert "pure Python path" in pure.stdout and "CSPACE_PURE" in pure.stdout
    assert "compiled fast path: on" not in pure.stdout
    if built:
        assert "compiled fast path: on" in plain.stdout
    else:
        assert "pure Python path" in plain.stdout and "not compiled" in plain.stdout


# ---------------------------------------------------------------- item 10

class FakeTTY(io.StringIO):
    def isatty(self):
        return True


@pytest.fixture
def tty(monkeypatch):
    """A fake terminal; each test puts it in place as sys.stderr (pytest's capture resets
    sys.stderr between a fixture's setup and the test)."""
    pytest.importorskip("tqdm")
    import planners.progress as pg

    monkeypatch.delenv("TQDM_DISABLE", raising=False)
    monkeypatch.setattr(pg, "TICK", 0.05)
    return FakeTTY()


def _last_line(text: str) -> str:
    return re.split(r"[\r\n]", text)[-2 if text.endswith(("\r", "\n")) else -1]


def test_a_stage_bar_names_its_stage_and_is_cleared_before_the_next_line(tty, monkeypatch):
    monkeypatch.setattr(sys, "stderr", tty)
    from planners.progress import progress

    with progress(None, "generate disks", unit="node", delay=0.2, tick=0.05) as bar:
        bar.describe("disks: building the C-space")
        time.sleep(0.6)  # a long stage without steps, past the delay
        during = tty.getvalue()
    assert "disks: building the C-space" in during
    assert "0node" not in during  # no count that would not move
    tty.write("wrote out.toml\n")
    before = tty.getvalue().split("wrote out.toml")[0]
    assert before.endswith(("\r", "\n"))  # the final line starts a line of its own ...
    assert _last_line(before).strip() == ""  # ... on a cleared one


def test_a_bar_with_steps_counts_them(tty, monkeypatch):
    monkeypatch.setattr(sys, "stderr", tty)
    from planners.progress import progress

    with progress(None, "exact search", unit="node", delay=0.0, tick=0.05) as bar:
        bar.set(128)
        time.sleep(0.2)
        during = tty.getvalue()
    assert "128node" in during


def test_exact_search_names_its_preparation_then_the_search(tty, monkeypatch):
    import cspace.paths.shortest as shortest
    import numpy as np
    import planners.progress as pg
    from cspace.io.load import load_scenario

    from planners.core.exact import exact_plan
    from planners.core.plan import build_cspace

    monkeypatch.setattr(pg, "DELAY", 0.1)
    monkeypatch.setattr(sys, "stderr", tty)
    real = shortest.shortest_path
    seen = []

    def slow(pieces, bounds, start, goal, time_limit=None, on_progress=None):
        time.sleep(0.4)  # the free space and its mesh: no settled node yet
        seen.append(tty.getvalue())
        assert on_progress is not None
        on_progress(64, 100, 1.0)
        time.sleep(0.3)
        seen.append(tty.getvalue())
        return real(pieces, bounds, start, goal)

    monkeypatch.setattr(shortest, "shortest_path", slow)
    sc = load_scenario(BASIC)
    res = exact_plan(sc, build_cspace(sc, None), sc.all_queries()[0], progress=None)
    assert res.solved and np.isfinite(res.length)
    assert "building the free space" in seen[0] and "0node" not in seen[0]
    assert "A*" in seen[1].split("building the free space")[-1]
    assert tty.getvalue().endswith(("\r", "\n")) and _last_line(tty.getvalue()).strip() == ""
