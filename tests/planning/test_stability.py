"""The stability catalogue: every case meets its layer's guarantee, and the checks can fail.

Besides running each case, a few answers are re-checked here independently (shapely,
worked examples, the exact references on known inputs), and the harness is shown to
report a wrong or crashing layer as a failure rather than passing it.
"""
from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest
import shapely

import cspace
from planners.stability import catalogue as st
from planners.stability import exact as ex
from planners.cli import main

CASES = {c.name: c for c in st.catalogue()}


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.slow
def test_case_meets_its_guarantee(name):
    row = st.run_case(CASES[name])
    assert row["passed"], f"{name}: {row['result']} error={row['error']} ({row['guarantee']})"
    assert row["error"] is not None and math.isfinite(row["error"]) and row["error"] >= 0
    assert "CRASH" not in row["result"]


def test_catalogue_covers_every_layer_and_kind():
    layers = {c.layer for c in CASES.values()}
    assert layers == set(st.GUARANTEES)
    names = " ".join(CASES)
    for kind in ("1e-09", "1e+09", "offset_1e8", "near_parallel", "collinear_repeated", "sliver",
                 "circle_100k", "touch_edge_edge", "touch_vertex_edge", "touch_vertex_vertex",
                 "cspace_exact", "cspace_wider", "cspace_narrower", "int_2^52"):
        assert kind in names, kind


# ---------------------------------------------------------------- the references themselves


def test_exact_references_on_worked_examples():
    F = Fraction
    sq = [(F(0), F(0)), (F(1), F(0)), (F(1), F(1)), (F(0), F(1))]
    assert st.exact_hull(sq + [(F(1, 2), F(0)), (F(1, 2), F(1, 2)), (F(0), F(0))]) == sq
    assert st.exact_distance(sq, [(x + 3, y) for x, y in sq]) == 2.0
    assert st.exact_distance(sq, [(x + 1, y + 1) for x, y in sq]) == 0.0
    assert st.exact_relation(sq, [(x + 1, y + 1) for x, y in sq]) == "touching"
    big = [(F(0), F(0)), (F(2), F(0)), (F(2), F(2)), (F(0), F(2))]
    inner = [(F(3, 2), F(1, 2)), (F(3), F(1, 2)), (F(3), F(3, 2)), (F(3, 2), F(3, 2))]
    assert st.exact_depth(big, inner) == 0.5
    rect = [(F(0), F(0)), (F(4), F(0)), (F(4), F(3)), (F(0), F(3))]
    assert st.exact_erosion(rect, sq) == [(0, 0), (3, 0), (3, 2), (0, 2)]
    for q in (F(2), F(1, 3), F(10 ** 40, 7), F(1, 10 ** 50)):
        assert abs(ex._sqrt(q) - math.sqrt(q)) <= 2 * math.ulp(math.sqrt(q))


def test_vertex_error_sees_a_one_ulp_shift():
    ref = ex.to_fractions([[0, 0], [1, 0], [0, 1]])
    out = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    assert st.vertex_error(out, ref) == 0.0
    out[1, 0] = math.nextafter(1.0, 2.0)
    assert st.vertex_error(out, ref) == math.ulp(1.0)


# ---------------------------------------------------------------- independent re-checks


def test_gjk_distances_agree_with_shapely():
    rng = np.random.default_rng(5)
    for s in st.SCALES:
        a = st.random_convex(rng, 20, s)
        b = a + [3 * s, s / 7]
        d = cspace.gjk_distance(a, b).distance
        # GEOS's own distance under/overflows at 2^+-700 (it returns inf): ask it at unit scale.
        ref = shapely.Polygon(a / s).distance(shapely.Polygon(b / s)) * s
        assert abs(d - ref) <= 1e-9 * s * 4


def test_touching_contacts_are_exactly_zero_at_offset():
    for _, a, b in st.contact_pairs(1.0, 1e8):
        assert {cspace.gjk_distance(a, b).status for _ in range(3)} == {"touching"}
        assert cspace.gjk_distance(a, b).distance == 0.0
        assert cspace.epa_penetration(a, b).depth == 0.0
        assert shapely.Polygon(a).touches(shapely.Polygon(b))


def test_sum_area_against_shapely_brute_force():
    rng = np.random.default_rng(9)
    p, q = st.random_convex(rng, 30, 1.0, 1e8), st.random_convex(rng, 30, 1.0, 1e8)
    out = cspace.minkowski_sum(p, q)
    brute = shapely.MultiPoint((p[:, None, :] + q[None, :, :]).reshape(-1, 2)).convex_hull
    # area of shapes near 1e8: compare in a frame at the origin
    local = shapely.affinity.translate(brute, -2e8, -2e8)
    assert abs(shapely.Polygon(out - 2e8).area - local.area) <= 1e-6 * local.area


def test_large_circle_hull_and_sum_keep_every_vertex():
    circle = st.circle_points(100_000)
    assert len(cspace.convex_hull(circle)) == 100_000
    out = cspace.minkowski_sum(circle, st.box_polygon(0, 0, 0.5, 0.5))
    assert len(out) == 100_004 and np.isfinite(out).all()


def test_integer_sum_is_exact_vertex_for_vertex():
    rng = np.random.default_rng(11)
    p = cspace.convex_hull(st.int_points(rng, 50, 2 ** 51))
    q = cspace.convex_hull(st.int_points(rng, 50, 2 ** 51))
    ref = st.exact_sum([(int(x), int(y)) for x, y in p.tolist()], [(int(x), int(y)) for x, y in q.tolist()])
    assert [(int(x), int(y)) for x, y in cspace.minkowski_sum(p, q).tolist()] == ref


def test_decomposition_covers_the_polygon_shapely():
    poly = st.comb_points(6, 1e9)
    pieces = cspace.convex_decompose(poly)
    union = shapely.union_all([shapely.Polygon(x) for x in pieces])
    assert union.symmetric_difference(shapely.Polygon(poly)).area <= 1e-9 * shapely.Polygon(poly).area


def test_zero_clearance_is_collision_consistently():
    """Closed obstacles: a passage exactly the robot's width is closed, by every query, every time."""
    for w, o in ((1.0, 0.0), (1.0, 1e8), (0.1, 0.3)):
        sc = cspace.scenario_from_dict(st.passage(w, 0.0, o))
        cs = cspace.CSpace.from_scenario(sc)
        assert {cs.is_free((o, o)) for _ in range(5)} == {False}
        assert {cs.segment_free((o - 3 * w, o), (o + 3 * w, o)) for _ in range(5)} == {False}
        assert st.exact_free(sc, (o, o)) is False
        wider = cspace.CSpace.from_scenario(cspace.scenario_from_dict(st.passage(w, 1e-6 * w, o)))
        assert wider.is_free((o, o)) and wider.segment_free((o - 3 * w, o), (o + 3 * w, o))


def test_non_representable_zero_clearance_is_decided_within_one_rounding():
    """0.3-wide robot and passage at 1e8 + 0.1: the true float geometry leaves a gap below one ulp;
    the C-space (its C-obstacle vertices rounded once) closes it, the same way every time."""
    sc = cspace.scenario_from_dict(st.passage(0.3, 0.0, 1e8 + 0.1))
    assert not st.sums_representable(sc)
    q = (1e8 + 0.1, 1e8 + 0.1)
    gap = st.exact_clearance(sc, q)
    assert st.exact_free(sc, q) and 0 < gap <= 2 * st.EPS * 1e8
    cs = cspace.CSpace.from_scenario(sc)
    assert {cs.is_free(q) for _ in range(5)} == {False}
    assert ex.own_free(cs, q) is False  # exact on its own pieces


# ---------------------------------------------------------------- the harness can fail


def test_a_wrong_layer_fails_its_case(monkeypatch):
    real = cspace.minkowski_sum

    def off_by_one(*a):
        out = real(*a).copy()
        out[0, 0] += 1.0  # one unit: wrong for integer input
        return out

    monkeypatch.setattr(cspace, "minkowski_sum", off_by_one)
    assert st.run_case(CASES["sum_int_2^52"])["passed"] is False


def test_a_crash_is_reported_not_raised():
    def boom():
        raise RuntimeError("boom")

    row = st.run_case(st.Case("boom", "hull", boom))
    assert row["passed"] is False and "CRASH" in row["result"] and row["error"] is None


def test_a_nan_error_fails():
    row = st.run_case(st.Case("nan", "hull", lambda: ("x", float("nan"), True, 0.0)))
    assert row["passed"] is False


# ---------------------------------------------------------------- the command


@pytest.mark.slow
def test_cli_writes_json_and_plot(tmp_path, capsys):
    j, p = tmp_path / "out.json", tmp_path / "out.png"
    assert main(["stability", "--json", str(j), "--plot", str(p)]) == 0
    data = json.loads(j.read_text())
    assert data["passed"] is True and set(data["guarantees"]) == set(st.GUARANTEES)
    assert len(data["cases"]) == len(CASES)
    for row in data["cases"]:
        assert set(row) == {"case", "layer", "result", "error", "time_ms", "passed", "guarantee"}
        assert row["passed"] is True and row["time_ms"] >= 0
    assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = capsys.readouterr().out
    assert f"{len(CASES)}/{len(CASES)} cases pass" in out and "FAIL" not in out
    widest = max(out.splitlines(), key=len)
    assert len(widest) <= 80, f"{len(widest)} columns: {widest!r}"  # fits a classic terminal
    for name in CASES:  # every case is in the table, with its result on the next line
        assert f"\n{name} " in out


def test_table_fits_80_columns_with_failures_and_long_results():
    rows = [{"case": "x" * 40, "layer": "hull", "result": "word " * 60, "error": None, "time_ms": 12345.6,
             "passed": False}]
    table = st.format_table(rows)
    assert max(len(line) for line in table.splitlines()) <= 80
    assert "FAIL" in table and " ".join(table.split()).count("word") == 60  # wrapped, nothing lost


def test_cli_bad_output_path_is_input_error(tmp_path, capsys):
    assert main(["stability", "--plot", str(tmp_path / "x.jpg")]) == 2
    assert "error:" in capsys.readouterr().err
