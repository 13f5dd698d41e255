"""Bench-MR's path metrics (issue 50, point 3), computed as its code computes them.

Oracles: closed forms on paths whose metrics are known (a straight line: no curvature, no
turn; points on a circle of radius R: curvature 1/R everywhere, heading change = arc angle;
a reversal: a cusp), and OMPL's own interpolation (500 states, the path's length from OMPL).
"""
from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

from conftest import ROOT
from planners.bench.benchmr import interpolated, metrics
from planners.cli import main


def test_a_straight_path_has_no_curvature_turn_or_cusp():
    pts = np.column_stack((np.linspace(0, 10, 41), np.linspace(0, 5, 41)))
    m = metrics(pts, (10, 5))
    assert m["path_length"] == pytest.approx(math.hypot(10, 5))
    assert m["max_curvature"] == 0 and m["normalized_curvature"] == 0 and m["aol"] == 0 and m["cusps"] == 0
    assert m["exact_goal_path"] and not metrics(pts, (10, 5.5))["exact_goal_path"]


@pytest.mark.parametrize("radius", [2.0, 4.0, 25.0])
def test_points_on_a_circle_have_its_curvature(radius):
    t = np.linspace(0, math.pi, 400)
    pts = radius * np.column_stack((np.cos(t), np.sin(t)))
    m = metrics(pts, pts[-1])
    assert m["max_curvature"] == pytest.approx(1 / radius, rel=1e-6)
    chord = np.hypot(*np.diff(pts, axis=0).T).sum()
    assert m["path_length"] == pytest.approx(chord)
    # the heading turns by the arc's angle less one step (the first and last segments' headings)
    assert m["aol"] * m["path_length"] == pytest.approx(math.pi - math.pi / 399, rel=1e-9)
    assert m["cusps"] == 0


def test_a_reversal_is_a_cusp():
    pts = np.array([[0, 0], [1, 0], [2, 0], [1.5, 0.01], [1, 0.02]], float)
    assert metrics(pts, pts[-1])["cusps"] == 1


def test_ompl_interpolation_gives_500_states_along_the_curves():
    pytest.importorskip("ompl")
    path = np.array([[0, 0, 0], [5, 3, 1.0], [9, 0, -0.5]], float)
    pts = interpolated(path, "reeds-shepp", 2.0, (-20, 20, -20, 20))
    assert len(pts) == 500 and np.allclose(pts[0], path[0]) and np.allclose(pts[-1], path[-1])
    assert all(np.isclose(pts, p).all(axis=1).any() for p in path)  # the waypoints are kept


def test_plan_json_has_bench_mr_metrics_beside_ours(tmp_path):
    pytest.importorskip("ompl")
    out = tmp_path / "p.json"
    code = main(["plan", os.path.join(ROOT, "scenarios", "basic.toml"), "--json", str(out)])
    d = json.loads(out.read_text())
    m = d["bench_mr"]
    assert code == 0 and m["certified"] and m["path_collides"] is False and m["exact_goal_path"]
    assert m["path_length"] == pytest.approx(d["length"], rel=1e-9)  # a translating robot: straight segments
    assert m["min_clearance"] == d["min_clearance"]
