"""Fuzzing the imported OMPL.app problems (issue 36): a .cfg and COLLADA meshes, written
malformed by hypothesis strategies and run through ``cspace import`` and ``cspace plan`` under
the contract of tests/helpers/fuzzing.py (exit 0, 1 or 2, never 3; exit 2 one line; inputs
unchanged; no temporaries; valid JSON; a hang alarm). The valid meshes the strategies start
from: tests/helpers/import_files.py. ROS maps: tests/io/test_fuzz_maps.py.

The budget is small by default; ``CSPACE_FUZZ_EXAMPLES=N`` runs N examples per test and
``CSPACE_FUZZ_REPORT=FILE`` writes the figures of every fuzz case run in this process (the
last test here: maps and scenarios too when test_fuzz_maps.py and test_fuzz_cli.py ran before
it). ``scripts/fuzz_inputs.py`` runs the large campaign. With ``CSPACE_FUZZ_KEEP=FOLDER`` a
broken contract does not stop the run: the case's files are copied to FOLDER, counted, and the
last test fails if any was kept.
"""
from __future__ import annotations

import json
import os
import re

import pytest
from hypothesis import given, strategies as st

from fuzzing import EXAMPLES, FAILURES, FILES, STATS, budget, check_case, mutate_bytes, run, workdir
from import_files import ROBOT_BOXES, WORLD_BOXES, dae_text, has_collada, write_problem

pytest.importorskip("PIL")


# ------------------------------------------------------------------ COLLADA meshes

BAD_NUMBER = st.sampled_from(["nan", "NaN", "inf", "-inf", "INF", "1e308", "-1e308", "1e309", "-0", "-0.0",
                              "99999999999999999999999", "1e-320", "abc", "", "0x1p3", "1,5", "1e", "--1",
                              "1e6", "2e6", "1e5", "3"])
BAD_COUNT = st.sampled_from(["0", "-1", "-8", "1", "2", "7", "9", "25", "1000000", "4294967296", "99999999999999",
                             "abc", "", "1.5", "nan", "3e0"])


def _sub_nth(pattern, text, draw, repl_fn):
    hits = list(re.finditer(pattern, text))
    if not hits:
        return text
    m = hits[draw(st.integers(0, len(hits) - 1))]
    return text[:m.start()] + repl_fn(m) + text[m.end():]


@st.composite
def dae_mutation(draw, text: str) -> bytes:
    for _ in range(draw(st.sampled_from([0, 1, 1, 1, 2, 3]))):
        kind = draw(st.sampled_from(["number", "number", "count", "stride", "index", "index", "vcount", "delete",
                                     "unit", "transform", "up", "instance_node", "doctype", "empty array",
                                     "dup id", "url", "namespace", "comment"]))
        if kind == "number":
            text = _sub_nth(r"(?<=[ >])-?\d+(\.\d+)?(?=[ <])", text, draw, lambda m: draw(BAD_NUMBER))
        elif kind == "count":
            text = _sub_nth(r'count="\d+"', text, draw, lambda m: f'count="{draw(BAD_COUNT)}"')
        elif kind == "stride":
            text = _sub_nth(r'stride="\d+"', text, draw, lambda m: f'stride="{draw(BAD_COUNT)}"')
        elif kind == "index":
            def _idx(m):
                return m.group(1) + draw(st.sampled_from(["8", "9", "-1", "100", "4294967296", "99999999999999999999",
                                                          "x", "1.5", "", "7 7"])) + m.group(3)
            text = _sub_nth(r"(<p>(?:\d+ )*)(\d+)((?: \d+)*</p>)", text, draw, _idx)
        elif kind == "vcount":
            text = text.replace("<triangles", "<polylist").replace("</triangles>", "</polylist>")
            text = _sub_nth(r"<p>", text, draw, lambda m: "<vcount>" + draw(st.sampled_from(
                ["3 3 3", "2 4", "0", "-3 9", "3 " * 12, "3 " * 13, "1000000", "", "x", "4 4 4 4 4 4 4 4 4"]))
                + "</vcount><p>")
        elif kind == "delete":
            tag = draw(st.sampled_from(["float_array", "accessor", "vertices", "triangles", "p", "matrix",
                                        "instance_geometry", "source", "mesh", "scene", "asset", "up_axis",
                                        "library_geometries", "visual_scene", "input", "technique_common"]))
            text = _sub_nth(rf"<{tag}\b[^>]*?/>|<{tag}\b[^>]*>.*?</{tag}>", text, draw, lambda m: "")
        elif kind == "unit":
            u = draw(st.sampled_from(["0", "-1", "nan", "inf", "1e-9", "1e9", "abc", "", "1e308", "0.001", "100",
                                      "1e-6", "1e6"]))
            text = re.sub(r"<unit [^>]*/>", "", text).replace("<asset>", f'<asset><unit meter="{u}" name="u"/>', 1)
        elif kind == "transform":
            el = draw(st.sampled_from([
                "<matrix>nan 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix>", "<matrix>1 0 0</matrix>",
                "<matrix>1e308 0 0 0 0 1e308 0 0 0 0 1e308 0 0 0 0 1</matrix>", "<matrix>0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0</matrix>",
                "<matrix>1 0 0 1e7 0 1 0 0 0 0 1 0 0 0 0 1</matrix>", "<matrix>abc</matrix>", "<matrix/>",
                "<rotate>0 0 1 nan</rotate>", "<rotate>0 0 0 90</rotate>", "<rotate>0 0 1 1e308</rotate>",
                "<rotate>1 0 0 90</rotate>", "<rotate>0 0 1</rotate>", "<translate>inf 0 0</translate>",
                "<translate>1e300 0 0</translate>", "<translate>1 2</translate>", "<scale>0 0 0</scale>",
                "<scale>1e200 1e200 1e200</scale>", "<scale>-1 1 1</scale>", "<scale>1e-300 1 1</scale>",
                "<lookat>0 0 0 0 0 0 0 0 0</lookat>", "<skew>45 1 0 0 0 1 0</skew>", "<translate>2 0 0</translate>"]))
            text = _sub_nth(r"<matrix>[^<]*</matrix>", text, draw, lambda m: draw(st.sampled_from(
                [el, m.group(0) + el, el + m.group(0)])))
        elif kind == "up":
            text = re.sub(r"<up_axis>[^<]*</up_axis>", f"<up_axis>{draw(st.sampled_from(['Z_UP', 'X_UP', 'W_UP', '', 'y_up', 'Z_UP Y_UP']))}</up_axis>", text)
        elif kind == "instance_node":
            depth = draw(st.integers(1, 70))
            cyclic = draw(st.sampled_from([False, False, True]))
            fan = draw(st.sampled_from([1, 1, 2, 3, 10]))
            libs = []
            for k in range(depth):
                child = (f'<instance_node url="#L{k + 1}"/>' * fan) if k + 1 < depth else (
                    '<instance_node url="#L0"/>' if cyclic else '<instance_geometry url="#g0"/>')
                libs.append(f'<node id="L{k}">{child}</node>')
            lib = f'<library_nodes>{"".join(libs)}</library_nodes>\n'
            text = text.replace("<library_visual_scenes>", lib + "<library_visual_scenes>", 1)
            text = text.replace("</visual_scene>", '<node id="top"><instance_node url="#L0"/></node></visual_scene>', 1)
        elif kind == "doctype":
            decl = draw(st.sampled_from([
                '<!DOCTYPE COLLADA [<!ENTITY a "1 2 3">]>', '<!DOCTYPE COLLADA SYSTEM "file:///etc/passwd">',
                '<!DOCTYPE COLLADA [<!ENTITY x SYSTEM "file:///etc/hostname">]>',
                '<!DOCTYPE l [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>']))
            text = text.replace("\n", "\n" + decl + "\n", 1)
            if "ENTITY" in decl and draw(st.booleans()):
                ent = re.search(r"ENTITY (\w+)", decl).group(1)
                text = text.replace("</float_array>", f" &{ent};</float_array>", 1)
        elif kind == "empty array":
            text = _sub_nth(r"(<float_array[^>]*>)[^<]*(</float_array>)", text, draw, lambda m: m.group(1) + m.group(2))
        elif kind == "dup id":
            text = text.replace('id="g1"', 'id="g0"')
        elif kind == "url":
            text = _sub_nth(r'(url|source)="#\w+"', text, draw, lambda m: m.group(1) + '="' + draw(st.sampled_from(
                ["#nothing", "", "#", "file:///etc/passwd", "other.dae#g0", "#vs", "#a0", "#n0"])) + '"')
        elif kind == "namespace":
            text = text.replace('xmlns="http://www.collada.org/2005/11/COLLADASchema"', draw(st.sampled_from(
                ['', 'xmlns="http://www.collada.org/2008/03/COLLADASchema"', 'xmlns="urn:x"'])))
        else:
            text = text.replace("<asset>", "<!-- " + "c" * draw(st.integers(0, 3000)) + " --><asset>", 1)
    data = text.encode("utf-8")
    how = draw(st.sampled_from(["text"] * 24 + ["cut", "bytes", "latin1", "utf16", "nonutf8", "random", "empty",
                                                "deep"]))
    if how == "cut":
        data = data[:draw(st.integers(0, len(data) - 1))]
    elif how == "bytes":
        data = mutate_bytes(data, draw)
    elif how == "latin1":
        data = data.replace(b"utf-8", b"iso-8859-1").replace(b'name="n0"', b'name="n\xe90"')
    elif how == "utf16":
        data = text.replace('encoding="utf-8"', 'encoding="utf-16"').encode("utf-16")
    elif how == "nonutf8":
        data = data.replace(b'name="n0"', b'name="n\xff\xfe0"')
    elif how == "random":
        data = draw(st.binary(max_size=300))
    elif how == "empty":
        data = b""
    elif how == "deep":
        k = draw(st.sampled_from([100, 255, 257, 2000]))
        data = data.replace(b"</asset>", b"<extra>" + b"<a>" * k + b"</a>" * k + b"</extra></asset>", 1)
    return data


@st.composite
def mesh_problem(draw):
    """(cfg bytes, robot dae bytes, world dae bytes)."""
    opts = dict(up="Y_UP", polylist=draw(st.booleans()))
    if draw(st.booleans()):
        opts["unit"] = draw(st.sampled_from(["1", "0.01", "1"]))
    robot = dae_text(ROBOT_BOXES, **opts)
    world = dae_text(WORLD_BOXES, **opts)
    which = draw(st.sampled_from(["robot", "robot", "world", "world", "both", "neither"]))
    rb = draw(dae_mutation(robot)) if which in ("robot", "both") else robot.encode()
    wb = draw(dae_mutation(world)) if which in ("world", "both") else world.encode()
    unit = float(opts.get("unit", "1"))
    s = 1.0 if unit == 1 else unit
    keys = {"robot": "robot.dae", "world": "world.dae", "start.x": f"{-5 * s:g}", "start.y": "0", "start.theta": "0",
            "goal.x": f"{5 * s:g}", "goal.y": "0", "goal.theta": "1.57", "volume.min.x": f"{-10 * s:g}",
            "volume.min.y": f"{-10 * s:g}", "volume.max.x": f"{10 * s:g}", "volume.max.y": f"{10 * s:g}"}
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 2]))):
        k = draw(st.sampled_from(sorted(keys) + ["start.z", "volume.min.z", "control", "objective", "zz", "name"]))
        act = draw(st.sampled_from(["value", "value", "delete"]))
        if act == "delete":
            keys.pop(k, None)
        else:
            keys[k] = draw(st.sampled_from(["nan", "inf", "-inf", "1e308", "0", "-0", "abc", "", "1e400", "10", "-10",
                                            "100", "robot.dae", "world.dae", "missing.dae", os.path.join(os.pardir, "x.dae"), "/dev/zero",
                                            "p.cfg", "kinematic_car", "dynamic_car", "blimp", "3.14159", "1,2",
                                            "5 # comment", "x" * 300]))
    lines = ["[problem]", "name = fuzz"] + [f"{k} = {v}" for k, v in keys.items()]
    lines += draw(st.sampled_from([[], [], ["", "[benchmark]", "time_limit=10.0", "", "[planner]", "rrt=", "rrt="],
                                   ["robot = robot.dae"], ["no equals sign"], ["[problem"], ["[problem]"],
                                   ["[]", "a=b"], ["start.x = 1"]]))
    cfg = ("\n".join(lines) + "\n").encode()
    how = draw(st.sampled_from(["text"] * 20 + ["bytes", "bom", "latin1", "random", "nofirst"]))
    if how == "bytes":
        cfg = mutate_bytes(cfg, draw)
    elif how == "bom":
        cfg = b"\xef\xbb\xbf" + cfg
    elif how == "latin1":
        cfg = cfg.replace(b"fuzz", b"f\xfczz")
    elif how == "random":
        cfg = draw(st.binary(max_size=200))
    elif how == "nofirst":
        cfg = cfg.replace(b"[problem]\n", b"", 1)
    return cfg, rb, wb


MESH_FLAGS = st.sampled_from([[]] * 10 + [["--start", "-5,0,0"], ["--goal", "5,0"], ["--goal", "nan,0,0"],
                                          ["--radius", "0.3"], ["--start", "0,0,0"], ["--polygon", "0,0;1,0;0,1"],
                                          ["--tolerance", "0.1"], ["--unknown", "free"]])


needs_collada = pytest.mark.skipif(not has_collada(), reason="pycollada (the io extra) is not installed")


@needs_collada
@budget(30)
@given(case=mesh_problem(), flags=MESH_FLAGS)
def test_fuzz_mesh_import(case, flags):
    with workdir() as d:
        cfg, inputs = write_problem(d, case)
        run(["import", cfg, "--out", os.path.join(d, "out.toml")] + flags, d, inputs, "mesh import", "mesh")


@needs_collada
@budget(10)
@given(case=mesh_problem(), flags=MESH_FLAGS, planner=st.sampled_from([None, None, "RRTConnect", "exact"]))
def test_fuzz_mesh_plan(case, flags, planner):
    with workdir() as d:
        cfg, inputs = write_problem(d, case)
        js = os.path.join(d, "out.json")
        argv = ["plan", cfg, "--json", js, "--time", "0.2"] + flags
        if planner:
            argv += ["--planner", planner]
        run(argv, d, inputs, "mesh plan", "mesh", json_out=js)


@needs_collada
def test_found_an_unknown_xml_encoding(tmp_path):
    """Found by the campaign: ``<?xml encoding="ut8"?>`` raised LookupError in expat (exit 3)."""
    cfg = ("[problem]\nrobot = robot.dae\nworld = world.dae\nstart.x = -5\nstart.y = 0\nstart.theta = 0\n"
           "goal.x = 5\ngoal.y = 0\ngoal.theta = 1.57\n").encode()
    robot = dae_text(ROBOT_BOXES).replace('encoding="utf-8"', 'encoding="ut8"').encode()
    c, inputs = write_problem(str(tmp_path), (cfg, robot, dae_text(WORLD_BOXES).encode()))
    assert check_case(["import", c, "--out", str(tmp_path / "o.toml")], str(tmp_path), inputs, "found") == 2


def test_zz_imports_report():
    """The figures (scenario cases too when test_fuzz_cli ran in the same process) where
    CSPACE_FUZZ_REPORT says; fails if a kept case broke the contract."""
    path = os.environ.get("CSPACE_FUZZ_REPORT")
    if path:
        rep = {**STATS, "exit": dict(STATS["exit"]), "by_test": dict(STATS["by_test"]),
               "examples_per_test": EXAMPLES or "default", "files": dict(FILES),
               "contract_broken": len(FAILURES), "failures": FAILURES[:50],
               "exit_3": STATS["exit"].get("3", 0),
               "inputs_modified": sum("changed by" in why for _, why, _ in FAILURES)}
        with open(path, "w") as fh:
            json.dump(rep, fh, indent=1)
    assert not FAILURES, FAILURES[:5]
    assert STATS["exit"].get("3", 0) == 0
