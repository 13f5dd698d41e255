"""The independent checker of SE(2) "no path" proofs (planners.core.proof_check), on proofs built by hand.

The scene: a bar 4 x 0.3 shut in a room 4.6 x 0.6 whose only exit is a gap in the ceiling. With a
gap of width 1 the bar cannot turn to pass it (a proof exists); with a gap of 4.4 it slides out
flat (no proof can be valid). Cores are built here by a construction of the test's own: the
intersection of the piece turned at many angles of the slab, eroded by r h / 2 (h the sampling
step), which lies inside the turned piece at every angle of the slab.
"""
from __future__ import annotations

import ast
import copy
import functools
import json
import math
import os
from fractions import Fraction

import numpy as np
import pytest
import shapely
import shapely.affinity
from hypothesis import example, given, settings
from hypothesis import strategies as st

from cspace.io.load import load_scenario
from planners.core import proof_check, proof_geometry
from planners.core.proof_check import FORMAT, check_proof, core_inside, load_proof, orient, strictly_convex_ccw
from planners.core.proof_geometry import Piece
from planners.cli import main as cli_main


def main(argv):
    return cli_main(["check-proof", *argv])

BAR = [(-2.0, -0.15), (2.0, -0.15), (2.0, 0.15), (-2.0, 0.15)]


def room_toml(gap: float) -> str:
    lo, hi = 2.3 - gap / 2, 2.3 + gap / 2
    return f"""
space = "se2"
[bounds]
xmin = -3.0
xmax = 8.0
ymin = -3.0
ymax = 5.0
[robot]
polygon = {[list(p) for p in BAR]}
[[obstacles]]   # floor and side walls: one U-shaped (non-convex) obstacle
polygon = [[-0.5, -0.5], [5.1, -0.5], [5.1, 0.6], [4.6, 0.6], [4.6, 0.0], [0.0, 0.0], [0.0, 0.6], [-0.5, 0.6]]
[[obstacles]]
polygon = [[-0.5, 0.6], [{lo}, 0.6], [{lo}, 1.1], [-0.5, 1.1]]
[[obstacles]]
polygon = [[{hi}, 0.6], [5.1, 0.6], [5.1, 1.1], [{hi}, 1.1]]
[start]
x = 2.3
y = 0.3
theta = 0.0
[goal]
x = 2.3
y = 3.5
theta = 0.5
"""


def rotate(pts, t):
    c, s = math.cos(t), math.sin(t)
    return [(x * c - y * s, x * s + y * c) for x, y in pts]


@functools.lru_cache(maxsize=None)
def slab_core(piece, a, b, samples=200):
    """A core of ``piece`` on [a, b]: sampled intersection eroded by the largest motion between
    samples, then simplified (a subset of a convex polygon's vertices spans a part of it)."""
    inter = shapely.intersection_all([shapely.Polygon(rotate(piece, t)) for t in np.linspace(a, b, samples)])
    r = max(math.hypot(*p) for p in piece)
    core = inter.buffer(-(r * (b - a) / (samples - 1) / 2 + 1e-9), join_style="mitre").convex_hull
    core = core.simplify(1e-5, preserve_topology=False).convex_hull
    if core.is_empty or core.area == 0:
        return []
    core = shapely.orient_polygons(core)
    return [list(p) for p in core.exterior.coords[:-1]]


def in_arc(t, a, b):
    d = (t - a) % (2 * math.pi)
    return d <= (b - a) + 1e-9 or d >= 2 * math.pi - 1e-9


def build_proof(scenario, slabs=32, samples=200):
    """A proof in the fixed format, computed with shapely alone (no shrink, plain unions)."""
    xmin, xmax, ymin, ymax = scenario.bounds
    box = shapely.box(xmin, ymin, xmax, ymax)
    obstacles = [s.to_shapely() for s in scenario.obstacles]
    w = 2 * math.pi / slabs
    angles = [-math.pi + k * w for k in range(slabs)] + [math.nextafter(math.pi, math.inf)]
    out, comps = [], []
    for k in range(slabs):
        a, b = angles[k], angles[k + 1]
        core = slab_core(tuple(BAR), a, b, samples)
        sums = []
        if core:
            for ob in obstacles:  # O (+) (-C) for a non-convex O: union over its triangles
                for tri in shapely.get_parts(shapely.constrained_delaunay_triangles(ob)):
                    pts = [(ox - cx, oy - cy) for ox, oy in tri.exterior.coords[:-1] for cx, cy in core]
                    sums.append(shapely.MultiPoint(pts).convex_hull)
        rest = box.difference(shapely.union_all(sums)) if sums else box
        parts = [g for g in shapely.get_parts(rest) if g.geom_type == "Polygon" and g.area > 0]
        comps.append(parts)
        out.append({"a": a, "b": b, "cores": [core], "components": [
            {"shell": [list(p) for p in g.exterior.coords], "holes": [[list(p) for p in h.coords] for h in g.interiors]}
            for g in parts]})

    def nodes(pose):
        pt = shapely.Point(pose[0], pose[1])
        return [[k, c] for k, s in enumerate(out) if in_arc(pose[2], s["a"], s["b"])
                for c, g in enumerate(comps[k]) if g.distance(pt) <= 1e-9]

    edges = [[k, c, (k + 1) % slabs, c2] for k in range(slabs) for c, g in enumerate(comps[k])
             for c2, g2 in enumerate(comps[(k + 1) % slabs]) if g.distance(g2) <= 1e-9]
    return {"format": FORMAT, "start": list(scenario.start), "goal": list(scenario.goal),
            "bounds": list(scenario.bounds), "robot_pieces": [[list(p) for p in BAR]], "slabs": out,
            "start_nodes": nodes(scenario.start), "goal_nodes": nodes(scenario.goal), "edges": edges}


@pytest.fixture(scope="module")
def narrow(tmp_path_factory):
    path = tmp_path_factory.mktemp("narrow") / "room.toml"
    path.write_text(room_toml(1.0))
    scenario = load_scenario(str(path))
    return str(path), scenario, build_proof(scenario)


@pytest.fixture(scope="module")
def wide(tmp_path_factory):
    path = tmp_path_factory.mktemp("wide") / "room.toml"
    path.write_text(room_toml(4.4))
    scenario = load_scenario(str(path))
    return scenario, build_proof(scenario)


def verdict(scenario, proof):
    r = check_proof(scenario, proof)
    return r.step if not r.valid else "valid"


# --- predicates -------------------------------------------------------------------------------

def test_orient_is_exact_where_floats_are_not():
    a, b = (0.5, 0.5), (12.0, 12.0)
    for i in range(1, 200):
        c = (24.0 + i * 2**-50, 24.0)  # nearly on the line y = x: the float determinant misleads
        f = [Fraction(v) for v in (*a, *b, *c)]
        d = (f[2] - f[0]) * (f[5] - f[1]) - (f[3] - f[1]) * (f[4] - f[0])
        assert orient(a, b, c) == (d > 0) - (d < 0)
    assert orient((0.1, 0.1), (0.2, 0.2), (0.3, 0.3)) == 0
    assert orient((1e-300, 0), (0, 1e-300), (0, 0)) == 1  # underflowing products
    assert orient((1e300, 0), (0, 1e300), (-1e300, -1e300)) == 1  # overflowing products


def test_strict_convexity():
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    star = [(math.cos(4 * math.pi * i / 5), math.sin(4 * math.pi * i / 5)) for i in range(5)]
    assert strictly_convex_ccw(square)
    assert not strictly_convex_ccw(square[::-1])
    assert not strictly_convex_ccw([(0, 0), (0.5, 0), (1, 0), (1, 1), (0, 1)])  # collinear
    assert not strictly_convex_ccw(star)  # all turns left, but it winds twice
    assert not strictly_convex_ccw([(0, 0), (1, 0), (0, 1), (0, 1)])  # a repeated vertex


def test_disk_core_of_the_bar():
    r = 0.1499  # the bar's inscribed disk (radius 0.15), as an inscribed 32-gon: inside at every angle
    disk = [(r * math.cos(2 * math.pi * i / 32), r * math.sin(2 * math.pi * i / 32)) for i in range(32)]
    bar = Piece(BAR)
    assert core_inside(disk, bar, -3.0, -3.0 + math.pi / 2, 1e-12) is None
    grown = [(1.01 * x, 1.01 * y) for x, y in disk]
    assert core_inside(grown, bar, -3.0, -3.0 + math.pi / 2, 1e-12) is not None
    exact_edge = [(-1.0, 0.15), (1.0, 0.15), (0.0, 0.0)]  # on the edge at theta = 0: no margin, refused
    assert core_inside(exact_edge, bar, 0.0, 0.0, 1e-12) is not None


coord = st.floats(-3, 3, allow_nan=False, allow_infinity=False)


@example([(0.0, 0.0), (0.0, 2.220446049250313e-16), (1.0, 0.0), (1.0, 1.0)], 0.25, 0.0, (0.0, 0.0), 0.0, 1.0)
@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(coord, coord), min_size=3, max_size=8), st.floats(0.01, 1.1), st.floats(-math.pi, math.pi),
       st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3)), st.floats(-4, 4), st.floats(1e-6, math.pi / 2))
def test_core_containment_against_dense_sampling(points, scale, turn, shift, a, width):
    hull = shapely.MultiPoint(points).convex_hull
    if hull.geom_type != "Polygon" or hull.area < 0.05:
        return
    centre = hull.centroid  # the reference point inside the piece: small cores fit at every angle
    piece = [(x - centre.x, y - centre.y) for x, y in shapely.orient_polygons(hull).exterior.coords[:-1]]
    if not strictly_convex_ccw(piece):
        return
    if min(math.dist(p, q) for p, q in zip(piece, piece[1:] + piece[:1])) < 1e-9:
        return  # a vertex 2e-16 from another: the checker may refuse it; completeness is for sane pieces
    core = [(scale * x + shift[0], scale * y + shift[1]) for x, y in rotate(piece, turn)]
    b = a + width
    bad = core_inside(core, Piece(piece), a, b, 1e-12)
    thetas = np.concatenate([np.linspace(a, b, 2001), [a, b]])
    c = np.asarray(core)
    co, si = np.cos(thetas)[:, None], np.sin(thetas)[:, None]
    pts = shapely.points(c[None, :, 0] * co + c[None, :, 1] * si, -c[None, :, 0] * si + c[None, :, 1] * co)
    poly = shapely.Polygon(piece)
    if bad is None:  # accepted: inside at every sampled angle
        assert shapely.covers(poly.buffer(1e-9), pts).all()
    else:  # refused: some sampled vertex is not well inside
        assert not shapely.covers(poly.buffer(-1e-5), pts).all()


@pytest.mark.slow
@settings(max_examples=120, deadline=None)
@given(st.integers(9, 300), st.floats(0.2, 3.0), st.floats(0.0, 0.45), st.integers(0, 2**32 - 1),
       st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)), st.floats(-4, 4), st.floats(1e-6, math.pi / 2),
       st.sampled_from([0.0, 1e3, 1e6]))
def test_core_containment_of_many_gons_matches_every_edge_against_every_vertex(n, aspect, jitter, seed, ref, a,
                                                                               width, far):
    """Pieces of 9-300 vertices (the binary-search path), far from the origin or not: the verdict is
    that of the O(n m) test (every core vertex against every edge at both ends and at each trough)
    with the margin of the unit, except within a few units of the margin (either answer is sound)."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * math.pi, n))
    pts = np.column_stack([aspect * np.cos(t), np.sin(t)]) + np.array(ref) + np.array([far, 0.0])
    hull = shapely.MultiPoint(pts).convex_hull
    piece = [tuple(p) for p in shapely.orient_polygons(hull).exterior.coords[:-1]]
    if len(piece) < 9 or not strictly_convex_ccw(piece):
        return
    unit = 2.0**-40 * (far + 4)
    core = [(x * (1 - jitter) + far * jitter, y * (1 - jitter)) for x, y in
            (rotate([p], rng.uniform(-0.3, 0.3))[0] for p in piece[:: max(1, n // 12)])]
    b = a + width
    P, C = np.array(piece), np.array(core)
    e = np.roll(P, -1, axis=0) - P
    le = np.hypot(e[:, 0], e[:, 1])
    worst = np.inf
    for th in np.concatenate([[a, b], np.linspace(a, b, 4001)]):
        w = np.column_stack([C[:, 0] * math.cos(th) + C[:, 1] * math.sin(th),
                             -C[:, 0] * math.sin(th) + C[:, 1] * math.cos(th)])
        d = (e[None, :, 0] * (w[:, None, 1] - P[None, :, 1]) - e[None, :, 1] * (w[:, None, 0] - P[None, :, 0])) / le
        worst = min(worst, float(d.min()))
    bad = core_inside(core, Piece(piece), a, b, unit)
    if bad is None:
        assert worst >= -1e-9 * (far + 1)  # sound (up to the sampling of the arc)
    elif worst > 1e-6 * (far + 1):  # clearly inside at every sampled angle: completeness
        pytest.fail(f"refused vertex {bad} although every sampled angle keeps {worst} inside")


# --- whole proofs ----------------------------------------------------------------------------

def test_valid_proof(narrow):
    _, scenario, proof = narrow
    r = check_proof(scenario, json.loads(json.dumps(proof)))  # through JSON, as a file holds it
    assert r.valid and r.step == "ok", r
    assert len(proof["start_nodes"]) == 2  # the start's angle 0 is a slab boundary: both slabs


def tampered(proof, how):
    p = copy.deepcopy(proof)
    how(p)
    return p


def grow_core(p):
    k = 16
    p["slabs"][k]["cores"][0] = [[1.01 * x, 1.01 * y] for x, y in p["slabs"][k]["cores"][0]]


def drop_best_edge(p):
    slabs = p["slabs"]

    def poly(k, c):
        comp = slabs[k]["components"][c]
        return shapely.Polygon(comp["shell"], comp["holes"])

    best = max(p["edges"], key=lambda e: poly(e[0], e[1]).intersection(poly(e[2], e[3])).area)
    p["edges"].remove(best)


def shrink_component(p):
    comp = p["slabs"][3]["components"][0]
    g = shapely.affinity.scale(shapely.Polygon(comp["shell"], comp["holes"]), 0.99, 0.99)
    comp["shell"] = [list(q) for q in g.exterior.coords]
    comp["holes"] = [[list(q) for q in h.coords] for h in g.interiors]


def drop_component(p):
    """Forget slab 5's last component and every node and edge naming it."""
    c = len(p["slabs"][5]["components"]) - 1
    p["slabs"][5]["components"].pop()
    for key in ("start_nodes", "goal_nodes", "edges"):
        p[key] = [t for t in p[key] if [5, c] not in (t[:2], t[2:])]


def set_(path, value):
    def how(p):
        obj = p
        for key in path[:-1]:
            obj = obj[key]
        obj[path[-1]] = value
    return how


@pytest.mark.parametrize("how, step", [
    (grow_core, "cores"),
    (drop_best_edge, "edges"),
    (lambda p: p["start_nodes"].pop(), "nodes"),
    (lambda p: p["goal_nodes"].clear(), "nodes"),
    (set_(["slabs", -1, "b"], math.pi - 0.01), "cover"),  # the slabs stop short of 2 pi
    (set_(["slabs", -1, "b"], math.pi), "cover"),  # short by less than an ulp: -pi and pi as doubles
    (set_(["slabs", 4, "b"], -2.0), "cover"),  # a gap between slabs 4 and 5
    (lambda p: p["slabs"][3]["cores"][0].reverse(), "cores"),  # clockwise
    (shrink_component, "regions"),
    (lambda p: p["slabs"][5]["components"].append(p["slabs"][5]["components"][0]), "regions"),
    (drop_component, "regions"),
    (set_(["start", 0], 2.31), "query"),
    (set_(["bounds", 0], -3.5), "query"),
    (set_(["robot_pieces", 0], [[-2.0, -0.15], [2.0, -0.15], [2.0, 0.16], [-2.0, 0.15]]), "robot"),
    (lambda p: p["robot_pieces"][0].reverse(), "robot"),
    (lambda p: p.pop("edges"), "format"),
    (set_(["slabs", 0, "a"], float("nan")), "format"),
    (set_(["slabs", 0, "a"], True), "format"),
    (set_(["slabs", 0, "cores"], []), "format"),
    (set_(["edges", 0, 2], 7), "format"),
    (set_(["start_nodes", 0, 1], 99), "format"),
    (set_(["format"], "cspace-se2-proof/2"), "format"),
])
def test_tampered_proof_is_refused_at_its_step(narrow, how, step):
    _, scenario, proof = narrow
    assert verdict(scenario, tampered(proof, how)) == step


def test_harmless_changes_stay_valid(narrow):
    _, scenario, proof = narrow
    assert verdict(scenario, tampered(proof, set_(["goal", 2], 0.5 + 2 * math.pi))) == "valid"
    assert verdict(scenario, tampered(proof, lambda p: p["edges"].append(p["edges"][0]))) == "valid"
    # an empty core is a valid (weakest) core: POSSIBLE becomes the whole box, which slab 7 does not list
    assert verdict(scenario, tampered(proof, set_(["slabs", 7, "cores", 0], []))) == "regions"
    assert check_proof(scenario, proof, query_index=1).step == "query"


def test_a_translation_scenario_is_refused(narrow, tmp_path):
    _, _, proof = narrow
    path = tmp_path / "flat.toml"
    text = room_toml(1.0).replace('space = "se2"', 'space = "translation"').replace("theta = 0.5", "theta = 0.0")
    path.write_text(text)
    assert verdict(load_scenario(str(path)), proof) == "query"


def test_open_room_has_no_valid_proof(wide):
    scenario, proof = wide
    assert verdict(scenario, proof) == "separation"
    # cut every edge of the start's side of the graph: the search separates, the edges step refuses
    adj = {}
    for k, c, k2, c2 in proof["edges"]:
        adj.setdefault((k, c), set()).add((k2, c2))
        adj.setdefault((k2, c2), set()).add((k, c))
    seen, todo = set(map(tuple, proof["start_nodes"])), list(map(tuple, proof["start_nodes"]))
    while todo:
        for v in adj.get(todo.pop(), ()):
            if v not in seen:
                seen.add(v)
                todo.append(v)
    cut = tampered(proof, set_(["edges"], [e for e in proof["edges"] if (e[0], e[1]) not in seen]))
    assert verdict(scenario, cut) == "edges"
    # a start node "forgotten" instead: the nodes step refuses
    assert verdict(scenario, tampered(cut, set_(["start_nodes"], []))) == "nodes"


# --- files and the command -------------------------------------------------------------------

def test_main_and_load_proof(narrow, tmp_path, capsys):
    scen, _, proof = narrow
    good = tmp_path / "good.json"
    good.write_text(json.dumps(proof))
    assert load_proof(str(good)) == json.loads(json.dumps(proof))
    assert main([scen, str(good)]) == 0
    assert capsys.readouterr().out.startswith("proof valid: 32 slabs")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(tampered(proof, lambda p: p["start_nodes"].pop())))
    assert main([scen, str(bad)]) == 1
    out = capsys.readouterr().out
    assert out.startswith("proof invalid: step nodes: ") and out.count("\n") == 1
    (tmp_path / "nan.json").write_text('{"format": NaN}')
    (tmp_path / "list.json").write_text("[1, 2]")
    (tmp_path / "junk.json").write_text("{not json")
    (tmp_path / "bytes.json").write_bytes(b"{\xff}")
    for name in ("nan.json", "list.json", "junk.json", "bytes.json", "missing.json", ""):
        path = str(tmp_path / name)
        assert main([scen, path]) == 2, name
        err = capsys.readouterr().err
        assert err.startswith(f"error: {path}: ") and err.count("\n") == 1, err
    assert main([scen, str(good), "--query", "3"]) == 2  # the command refuses a query the scenario lacks
    assert "--query: must be from 0 to" in capsys.readouterr().err
    from cspace.io.load import load_scenario

    assert check_proof(load_scenario(scen), json.loads(good.read_text()), 3).step == "query"  # the API: invalid
    assert main([str(tmp_path / "nope.toml"), str(good)]) == 2
    assert "nope.toml" in capsys.readouterr().err


@pytest.mark.parametrize("module", [proof_check, proof_geometry])
def test_checker_is_independent_of_the_geometry_code(module):
    tree = ast.parse(open(module.__file__).read())
    modules = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            modules.add(node.module)
            assert not any(a.name.startswith("_") for a in node.names)
        elif isinstance(node, ast.Import):
            modules.update(a.name for a in node.names)
    assert not any(m.startswith(("cspace.kernel", "cspace.spaces")) for m in modules), modules
    assert {m for m in modules if m.startswith(("cspace", "planners"))} <= {
        "cspace.io.scenario.files", "cspace.io.load", "planners.errors"}
    assert modules & {"proof_geometry", None} <= {"proof_geometry"}  # its own geometry, relative
    assert os.path.getsize(module.__file__) < 40000


def test_a_query_the_scenario_lacks_is_bad_input(tmp_path, capsys):
    import os

    from conftest import SCENARIOS

    trap = os.path.join(SCENARIOS, "se2", "bug_trap_l.toml")
    for q in ("-1", "1"):
        assert main([trap, str(tmp_path / "p.json"), "--query", q]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--query: must be from 0 to 0" in err, err
