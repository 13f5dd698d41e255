"""``cspace bench`` and clearance: every solved run's min_clearance (the one ``plan()``
measures, checked against shapely), a car's left empty, the ``--objective`` option."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
import shapely

from planners.cli import main

ROOT = Path(__file__).resolve().parents[1]
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
    from planners.plan import plan
    from test_clearance import swept_clearance

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


def test_a_car_run_has_no_min_clearance(sweep):
    rows, crow = sweep
    cars = [(r, c) for r, c in zip(rows, crow) if r["file"] == CAR]
    assert cars and any(r["solved"] for r, _ in cars)  # solved, and still not measured
    for r, c in cars:
        assert r["min_clearance"] is None and r["min_clearance_bound"] is None and r["clearance_s"] is None
        assert c["min_clearance"] == "" and c["clearance_s"] == ""
