"""A scene with no path, in every space, gives bench rows that say so (issue 51, point 1).

Every route of ``planners.core.plan.plan`` (the sampling routine, the exact planners, the
proof before sampling of a rotating robot or a car) returns a result with the keys the
bench's rows read; a proven-unsolvable run is stored as Planner Arena's status 9, the
summary table says "proven" instead of 0 %, and the figure says no path exists.
"""
from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

import conftest
from planners.bench import arena_db
from planners.bench.sweep import summary
from planners.cli import main
from planners.core.result import PlanResult

pytest.importorskip("ompl")
# One impossible scene per space, with its budget: a translation (proven by the exact reference,
# the run samples its whole budget), a rotating robot and a car (proven before sampling within a
# share of the budget, then the run ends: a generous budget costs nothing and holds under load).
SCENES = {
    "translation": (os.path.join(conftest.SCENARIOS, "narrow_closed.toml"), "0.1"),
    "se2": (os.path.join(conftest.SCENARIOS, "se2", "wide_square.toml"), "5"),
    "car": (os.path.join(conftest.SCENARIOS, "car", "tight_corner.toml"), "5"),
}


@pytest.mark.parametrize("space", sorted(SCENES))
def test_a_proven_unsolvable_scene_is_not_a_crash_in_any_space(space, tmp_path, capsys):
    out = tmp_path / "o"
    scene, budget = SCENES[space]
    code = main(["bench", scene, "--planners", "RRTConnect", "--times", budget, "--runs", "2",
                 "--out", str(out), "--db", str(tmp_path / "r.db"), "--no-plot"])
    cap = capsys.readouterr()
    text = cap.out + cap.err  # the summary table goes to stderr
    assert code == 0
    rows = json.loads((out / "results.json").read_text())["rows"]
    assert len(rows) == 2 and all(r["status"] == "ok" and not r["solved"] for r in rows), rows
    assert [arena_db.status_code(r) for r in rows] == [arena_db.UNSOLVABLE] * 2
    line = next(ln for ln in text.splitlines() if ln.split()[:2][1:] == ["RRTConnect"])
    assert line.split()[-1] == "proven", text


def test_a_result_says_whether_it_was_proven_unsolvable():
    proof = PlanResult("s", False, False, np.zeros((0, 3)), math.inf, "", 0, timings={"proof": 0.01},
                       message="proven unsolvable before sampling: ...")
    assert proof.proven_unsolvable and proof.as_dict()["proven_unsolvable"]
    assert not PlanResult("s", False, False, np.zeros((0, 2)), math.inf, "RRT", 0).proven_unsolvable


def test_the_table_tells_impossible_from_hard():
    base = {"scenario": "s", "time_budget": 1.0, "status": "ok", "solved": False, "error": None,
            "reference": "optimum", "optimum": 2.0}
    proven = [{**base, "planner": "A", "message": "proven unsolvable before sampling: ..."}] * 2
    failed = [{**base, "planner": "B", "message": "no solution"}] * 2
    lines = summary(proven + failed).splitlines()
    cell = {ln.split()[1]: ln.split()[-1] for ln in lines[1:3]}
    assert cell == {"A": "proven", "B": "0%"}
    assert any(ln.startswith("proven:") for ln in lines)
