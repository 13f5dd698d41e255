"""``cspace bench`` and clearance: every solved run's min_clearance (the one ``plan()``
measures, checked against shapely), a car's a lower bound along its curves, the ``--objective`` option."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
import shapely

import conftest
from planners.cli import main

ROOT = Path(conftest.ROOT)
CLEARANCE = str(ROOT / "scenarios" / "clearance.toml")  # clearance = 0.3: every path keeps it
CAR = str(ROOT / "scenarios" / "car" / "loading_dock.toml")
MARGIN = 0.3


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """RRTConnect (its rows are deterministic for a seed) on the margin scene and on a car."""
    out = tmp_path_factory.mktemp("bench_clearance")
    code = main(["bench", CLEARANCE, CAR, "--planners", "RRTConnect", "--times", "0.5", "--runs", "2",
                 "--out", str(out), "--no-plot", "-q"])
    assert code == 0
    rows = json.loads((out / "results.json").read_text())["rows"]
    with open(out / "results.csv", newline="") as fh:
        return rows, list(csv.DictReader(fh))


def _pieces(polygons) -> list:
    """Convex pieces (shapely's own triangulation) of the scenario's polygons."""
    out = []
    for p in polygons:
        tris = shapely.constrained_delaunay_triangles(shapely.Polygon(p.polygon, getattr(p, "holes", None)))
        out += [np.asarray(t.exterior.coords)[:-1] for t in tris.geoms]
    return out


def test_margin_kept_and_equal_to_plan_and_to_shapely(sweep):
    from planners import plan
    from oracles import swept_clearance

    rows, _ = sweep
    mine = [r for r in rows if r["file"] == CLEARANCE]
    assert len(mine) == 2 and all(r["solved"] for r in mine)
    for r in mine:
        assert r["min_clearance"] >= MARGIN - 1e-12 and r["min_clearance_bound"] == "exact"
        res = plan(CLEARANCE, planner="RRTConnect", time=0.5, seed=r["seed"])
        assert r["min_clearance"] == pytest.approx(res.min_clearance, rel=0, abs=1e-12)
        sc = res.scenario_data
        truth = swept_clearance(res.path, _pieces(sc.robot), _pieces(sc.obstacles))
        assert r["min_clearance"] == pytest.approx(truth, rel=1e-9, abs=1e-12)


def test_a_car_run_has_a_lower_bound_of_its_min_clearance(sweep):
    rows, crow = sweep
    cars = [(r, c) for r, c in zip(rows, crow) if r["file"] == CAR]
    assert cars and any(r["solved"] for r, _ in cars)
    for r, c in cars:
        if not r["solved"]:
            continue
        # measured along the curves (tests/pictures/test_issue39_pictures.py checks it against shapely)
        assert r["min_clearance"] > 0 and r["min_clearance_bound"] == "lower" and r["clearance_s"] >= 0
        assert float(c["min_clearance"]) == pytest.approx(r["min_clearance"]) and c["clearance_s"] != ""


BASIC = str(ROOT / "scenarios" / "basic.toml")


def _objective_sweep(out: Path, objective: str) -> list[dict]:
    # An iteration budget (the time is only a backstop): RRTstar's runs are deterministic for a seed.
    code = main(["bench", BASIC, "--objective", objective, "--planners", "RRTstar", "--times", "30",
                 "--iterations", "300", "--runs", "3", "--out", str(out), "--no-plot", "-q"])
    assert code == 0
    data = json.loads((out / "results.json").read_text())
    assert data["meta"]["objective"] == objective
    return data["rows"]


def test_clearance_objective_gives_clearer_paths_than_length(tmp_path):
    """RRTstar, same seeds and iterations: the length objective's simplified paths graze the
    obstacles (clearance under 0.05 here), the clearance objective's keep about 0.45 and more."""
    med = {}
    for objective in ("length", "clearance"):
        rows = _objective_sweep(tmp_path / objective, objective)
        assert all(r["solved"] for r in rows)
        med[objective] = float(np.median([r["min_clearance"] for r in rows]))
    assert med["clearance"] > 2 * med["length"], med


def test_the_objective_object_reaches_the_planner(monkeypatch):
    """One run in this process: the routine builds the clearance objective and OMPL's setup holds it."""
    from planners import bench
    from planners.adapters import objectives

    made = []
    real = objectives.make_objective

    def spy(name, si, adapter):
        made.append(real(name, si, adapter))
        return made[-1]

    monkeypatch.setattr(objectives, "make_objective", spy)
    sc = {"file": BASIC, "scenario": "basic", "optimum": 1.0}
    task = bench.make_tasks([sc], ["RRTstar"], [30.0], 1, iterations=300, objective="clearance")[0]
    row = bench.run_one(task)
    assert [type(o).__name__ for o in made] == ["SoftMinClearance"]
    assert row["solved"] and row["min_clearance"] > 0


@pytest.mark.parametrize("argv, says", [
    (["--objective", "shortest"], "invalid choice: 'shortest'"),
    (["--objective", "clearance", "--planners", "RRTstar,RRTConnect"], "--objective: clearance needs an optimising"),
])
def test_bad_objective_exits_2_with_one_line(argv, says, capsys, tmp_path):
    try:
        code = main(["bench", BASIC, "--out", str(tmp_path / "o"), "-q", *argv])
    except SystemExit as exc:  # argparse's own refusal
        code = exc.code
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and says in err, err
    assert not (tmp_path / "o").exists()


def test_clearance_objective_on_a_car_exits_2(capsys, tmp_path):
    code = main(["bench", CAR, "--objective", "balanced", "--out", str(tmp_path / "o"), "-q"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and f"{CAR}: --objective: balanced is not available" in err
    assert not (tmp_path / "o" / "results.json").exists()  # refused before any run


def test_default_planners_are_those_that_take_the_objective(tmp_path):
    code = main(["bench", BASIC, "--objective", "balanced", "--times", "30", "--iterations", "20", "--runs", "1",
                 "--out", str(tmp_path / "o"), "--no-plot", "-q"])
    assert code == 0
    rows = json.loads((tmp_path / "o" / "results.json").read_text())["rows"]
    assert [r["planner"] for r in rows] == ["RRTstar", "BITstar"]


def test_summary_has_the_median_min_clearance(sweep):
    from planners import bench

    rows, _ = sweep
    text = bench.summary(rows)
    head, *lines = text.splitlines()
    assert "min clearance" in head
    mine = float(np.median([r["min_clearance"] for r in rows if r["file"] == CLEARANCE]))
    assert f" {mine:.4f} " in lines[0] and lines[0].startswith("clearance")
    car = float(np.median([r["min_clearance"] for r in rows if r["file"] == CAR and r["solved"]]))
    assert lines[1].startswith("loading-dock") and f" {car:.4f} " in lines[1]  # a car: a lower bound
