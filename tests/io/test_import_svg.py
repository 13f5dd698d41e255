"""SVG drawings as scenarios (issue 50, point 1): path data, transforms, fill rules, curves,
the robot from an SVG path, and hostile files (one line, exit 2).

Oracles: the coordinates each test writes (an obstacle must be exactly the polygon drawn,
mapped to y up), shapely for areas, the SVG specification's definitions of the commands
(a path written in absolute and in relative form is the same obstacle), and dense samples
of a curve (a flattened obstacle must contain them). The files are written here, in the
format Bench-MR's drawings use (Inkscape: a layer group with a translate, relative paths).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings, strategies as st

from cspace.io.importers.imported import ImportOptions, import_file
from cspace.io.importers.svg import filled_area, svg_robot
from cspace.io.importers.svg_path import parse_path, parse_transform
from planners.cli import main

SVG = '<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape">{}</svg>'


def write(tmp_path, body: str, name: str = "w.svg") -> str:
    f = tmp_path / name
    f.write_text(SVG.format(body))
    return str(f)


def obstacles(path: str, **kw) -> list:
    opts = ImportOptions(start=kw.pop("start", (0.5, -0.5)), goal=kw.pop("goal", (0.6, -0.5)), **kw)
    return [shapely.Polygon(o["polygon"], o.get("holes", [])) for o in import_file(path, opts).data["obstacles"]]


def same(a, b, tol=1e-9) -> bool:
    return shapely.symmetric_difference(a, b).area <= tol


def test_relative_and_absolute_commands_draw_the_same_obstacle(tmp_path):
    absolute = write(tmp_path, '<path id="a" d="M 2,3 L 6,3 H 7 V 5 L 2,5 Z"/>', "a.svg")
    relative = write(tmp_path, '<path id="r" d="m 2,3 4,0 h 1 v 2 l -5,0 z"/>', "r.svg")
    want = shapely.Polygon([(2, -3), (6, -3), (7, -3), (7, -5), (2, -5)])  # y flipped: y up
    assert same(obstacles(absolute)[0], want) and same(obstacles(relative)[0], want)


def test_group_translate_and_matrix_compose_as_svg_does(tmp_path):
    # Inkscape's layer: translate on the group, a matrix on the path (a quarter turn and a shift)
    f = write(tmp_path, '<g transform="translate(10,20)"><g transform="matrix(0,1,-1,0,1,0)">'
                        '<path d="m 0,0 h 2 v 1 h -2 z"/></g></g>')
    pts = np.array([[0, 0], [2, 0], [2, 1], [0, 1]], float)
    user = np.column_stack((-pts[:, 1] + 1, pts[:, 0])) + (10, 20)  # matrix(0,1,-1,0,1,0) then translate
    assert same(obstacles(f)[0], shapely.Polygon(user * (1, -1)))


def test_a_close_returns_to_the_subpath_start_and_subpaths_are_separate(tmp_path):
    # after z the current point is the subpath's start: "m 3,0" moves from (0,0), not from (0,1)
    f = write(tmp_path, '<path d="m 0,0 h 1 v 1 h -1 z m 3,0 h 1 v 1 h -1 z"/>')
    obs = sorted(obstacles(f), key=lambda p: p.bounds[0])
    assert len(obs) == 2 and same(obs[1], shapely.box(3, -1, 4, 0))


@pytest.mark.parametrize("rule, inner, area", [("nonzero", "reversed", 12.0), ("nonzero", "same", 16.0),
                                               ("evenodd", "same", 12.0)])
def test_fill_rules_make_holes_as_a_renderer_does(tmp_path, rule, inner, area):
    hole = "M 1,1 V 3 H 3 V 1 Z" if inner == "reversed" else "M 1,1 H 3 V 3 H 1 Z"
    f = write(tmp_path, f'<path style="fill-rule:{rule}" d="M 0,0 H 4 V 4 H 0 Z {hole}"/>')
    assert sum(p.area for p in obstacles(f, start=(-1, 1), goal=(-1, 2))) == pytest.approx(area)


def test_a_self_crossing_ring_is_split_at_its_crossing():
    bowtie = np.array([[0, 0], [2, 2], [2, 0], [0, 2]], float)
    got = filled_area([bowtie])
    assert got.is_valid and got.area == pytest.approx(2.0)


def test_curves_are_refused_in_one_line_naming_the_path(tmp_path, capsys):
    f = write(tmp_path, '<path id="kerb" d="M 0,0 C 1,1 2,1 3,0 Z"/>')
    code = main(["import", f, "--out", str(tmp_path / "o.toml"), "--start", "5,5", "--goal", "6,5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "path 'kerb'" in err[0] and "--flatten-curves" in err[0]


def test_an_unnamed_path_is_named_by_its_rank_among_paths_and_its_line(tmp_path, capsys):
    # groups and other elements before it must not shift its number: the user counts paths
    f = write(tmp_path, '<g>\n<rect/>\n<path d="M 0,0 H 1 V 1 Z"/>\n<g><path d="M 0,0 Q 2,3 4,0 Z"/></g></g>')
    code = main(["import", f, "--out", str(tmp_path / "o.toml"), "--start", "5,5", "--goal", "6,5"])
    err = capsys.readouterr().err.strip().splitlines()
    line = 1 + open(f).read().split("Q 2,3")[0].count("\n")
    assert code == 2 and len(err) == 1 and f"path #2 (line {line})" in err[0], err


@pytest.mark.parametrize("d", ["M 0,0 C 1,2 3,2 4,0 Z", "M 0,0 Q 2,3 4,0 Z", "M 0,0 A 2,1 0 0 1 4,0 Z",
                               "M 0,0 c 1,2 3,2 4,0 s 2,-2 3,0 z", "M 0,0 q 2,3 4,0 t 4,0 z"])
def test_flattened_curves_contain_the_curve(tmp_path, d):
    tol = 0.05
    f = write(tmp_path, f'<path d="{d}"/>')
    ob = shapely.union_all(obstacles(f, flatten_curves=tol, start=(-2, 2), goal=(-2, 3)))
    fine, _, _ = parse_path(d, flatten=1e-5)  # the oracle: the curve to 1e-5
    curve = shapely.Polygon(fine[0] * (1, -1))
    assert ob.contains(curve.buffer(-1e-4)) and shapely.hausdorff_distance(ob, curve) <= 3 * tol


def test_convex_hulls_replace_each_path_as_bench_mr_does(tmp_path):
    f = write(tmp_path, '<path d="M 0,0 H 3 V 3 H 2 V 1 H 1 V 3 H 0 Z"/>')  # a U
    true = obstacles(f, start=(4, -1), goal=(4, -2))
    hull = obstacles(f, start=(4, -1), goal=(4, -2), convex_hulls=True)
    pocket = shapely.Point(1.5, -2.5)  # inside the U's pocket: free, unless the hull fills it
    assert true[0].area == pytest.approx(7.0) and not true[0].intersects(pocket)
    assert hull[0].area == pytest.approx(9.0) and hull[0].contains(pocket)


def test_the_robot_is_the_first_path_centred_on_its_points_mean(tmp_path):
    # Bench-MR's car ends with "v 0": a repeated point, counted in the mean as Bench-MR counts it
    f = write(tmp_path, '<g transform="translate(-1,-1)"><path d="m 1,1 h 4 v 2 h -4 v 0"/></g>'
                        '<path d="m 0,0 h 1 v 1 z"/>', "car.svg")
    robot, centre, _ = svg_robot(f)
    pts = np.array([[0, 0], [4, 0], [4, -2], [0, -2], [0, -2]], float)
    assert centre.tolist() == pts.mean(axis=0).tolist()
    assert same(shapely.Polygon(robot["polygon"]), shapely.Polygon(np.array([[0, 0], [4, 0], [4, -2], [0, -2]])
                                                                   - pts.mean(axis=0)))


def test_plan_an_svg_world_with_an_svg_car_certified(tmp_path, capsys):
    pytest.importorskip("ompl")
    car = write(tmp_path, '<g transform="translate(5,5)"><path d="m 0,0 h 4 v 2 h -4 z"/></g>', "car.svg")
    world = write(tmp_path, '<g transform="translate(0,-20)"><path d="M 0,20 H 40 V 22 H 0 Z"/>'
                            '<path d="M 0,38 H 40 V 40 H 0 Z"/><path d="m 18,28 h 4 v 4 h -4 z"/></g>')
    out = tmp_path / "p.json"
    code = main(["plan", world, "--robot", car, "--start", "4,-5,0", "--goal", "34,-15,0", "--space",
                 "reeds-shepp", "--turning-radius", "2", "--time", "5", "--json", str(out),
                 "--plot", str(tmp_path / "p.png")])
    text = capsys.readouterr().out
    assert code == 0 and "solved" in text and (tmp_path / "p.png").stat().st_size > 0
    import json

    assert json.loads(out.read_text())["solved"] is True


HOSTILE = {
    "doctype": ('<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;">]>'
                '<svg xmlns="http://www.w3.org/2000/svg"><path d="&b;"/></svg>', "DOCTYPE"),
    "external": ('<!DOCTYPE svg SYSTEM "file:///etc/passwd"><svg/>', "DOCTYPE"),
    "undefined entity": ('<svg xmlns="http://www.w3.org/2000/svg"><path d="&x;"/></svg>', "not well-formed"),
    "unknown command": (SVG.format('<path id="p1" d="M 0,0 X 1,1 Z"/>'), "unknown command"),
    "nan": (SVG.format('<path id="p1" d="M 0,0 L nan,1 L 1,1 Z"/>'), "unknown command or number 'nan"),
    "overflow": (SVG.format('<path id="p1" d="M 0,0 L 1e400,1 L 1,1 Z"/>'), "overflows"),
    "huge": (SVG.format('<path id="p1" d="M 0,0 L 1e200,1 L 1,1 Z"/>'), "magnitude"),
    "huge transform": (SVG.format('<g transform="scale(1e300)"><path d="M 0,0 h 1e300 v 1 z"/></g>'), "magnitude"),
    "bad transform": (SVG.format('<g transform="shear(2)"><path d="M 0,0 h 1 v 1 z"/></g>'), "transform"),
    "deep": (SVG.format("<g>" * 300 + '<path d="M 0,0 h 1 v 1 z"/>' + "</g>" * 300), "nested"),
    "no area": (SVG.format('<path id="line" d="M 0,0 L 5,5"/>'), "no area"),
    "missing numbers": (SVG.format('<path id="p1" d="M 0,0 L 1"/>'), "needs 2 numbers"),
    "no paths": (SVG.format('<rect width="1" height="1"/>'), "no drawn <path>"),
    "not xml": ("this is not XML", "not well-formed"),
    "empty": ("", "empty"),
}


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_svgs_get_one_line_and_exit_2(tmp_path, capsys, name):
    text, words = HOSTILE[name]
    f = tmp_path / "h.svg"
    f.write_text(text)
    code = main(["plan", str(f), "--start", "100,100", "--goal", "101,100"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and str(f) in err[0] and words in err[0], err


def test_not_drawn_and_other_elements_are_counted_in_a_warning(tmp_path):
    f = write(tmp_path, '<defs><path d="M 0,0 h 9 v 9 z"/></defs><rect/><path d="M 0,0 h 1 v 1 h -1 z"/>')
    imp = import_file(f, ImportOptions(start=(2, 2), goal=(2, 3)))
    assert len(imp.data["obstacles"]) == 1 and "1 <rect>" in imp.warnings[0] and "1 path (not drawn)" in imp.warnings[0]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.integers(-50, 50), st.integers(-50, 50), st.integers(1, 9), st.integers(1, 9),
                          st.booleans()), min_size=1, max_size=5),
       st.tuples(st.integers(-3, 3), st.integers(-3, 3), st.integers(-3, 3), st.integers(-3, 3),
                 st.integers(-99, 99), st.integers(-99, 99)))
def test_rectangles_in_any_encoding_land_where_drawn(rects, mat):
    """Property: each rectangle, written absolute or relative under a random integer matrix, is
    the obstacle its corners mapped by that matrix then y flipped (the oracle computes that)."""
    a, b, c, d, e, f = mat
    if a * d - b * c == 0:
        return
    paths = "".join(f'<path d="M {x},{y} h {w} v {h} h {-w} z"/>' if rel else
                    f'<path d="M {x},{y} L {x + w},{y} L {x + w},{y + h} L {x},{y + h} Z"/>'
                    for x, y, w, h, rel in rects)
    import tempfile, os

    path = os.path.join(tempfile.mkdtemp(), "r.svg")
    open(path, "w").write(SVG.format(f'<g transform="matrix({a},{b},{c},{d},{e},{f})">{paths}</g>'))
    m = parse_transform(f"matrix({a},{b},{c},{d},{e},{f})")
    want = shapely.union_all([shapely.Polygon((np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]], float)
                                               @ m[:2, :2].T + m[:2, 2]) * (1, -1)) for x, y, w, h, _ in rects])
    got = shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", [])) for o in
                             import_file(path, ImportOptions(start=(1e4, 1e4), goal=(1e4, 1e4 + 1))).data["obstacles"]])
    assert same(got, want, 1e-6 * max(1.0, want.area)) and math.isclose(got.area, want.area, rel_tol=1e-9)


@settings(max_examples=150, deadline=None)
@given(st.text(alphabet="MmLlHhVvZzCcAaQqXx0123456789.,-+eE nai\t", max_size=60),
       st.text(alphabet="translatemrixscolw(),.-0123456789 e", max_size=30))
def test_any_path_data_or_transform_is_an_obstacle_or_one_scenario_error(d, transform):
    """Property (fuzz): whatever the path data and the transform, the import returns obstacles or
    raises ScenarioError (one line), never another exception."""
    import os
    import tempfile

    from cspace.io.scenario.messages import ScenarioError

    path = os.path.join(tempfile.mkdtemp(), "f.svg")
    body = f'<g transform="{transform}"><path id="p" d="{d}"/></g>'
    open(path, "w").write(SVG.format(body))
    try:
        import_file(path, ImportOptions(start=(1e6, 1e6), goal=(1e6, 1e6 + 1), flatten_curves=0.1))
    except ScenarioError as exc:
        assert "\n" not in str(exc)


def test_a_curve_needing_too_many_chords_is_refused_before_the_work(tmp_path, capsys):
    f = write(tmp_path, '<path id="big" d="M 0,0 C 0,1e6 1e6,1e6 1e6,0 Z"/>')
    code = main(["plan", f, "--flatten-curves", "1e-9", "--start", "-5,5", "--goal", "-6,5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "path 'big'" in err[0] and "chords" in err[0]


def test_an_arc_between_ends_closer_than_rounding_is_a_point():
    subs, _, _ = parse_path("M 0,0 H 1 V 1 A 1,1 0 0 1 1,1.0000000000000002 Z", flatten=0.01)
    assert len(subs[0]) >= 4 and np.isfinite(subs[0]).all()
