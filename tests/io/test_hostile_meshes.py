"""Hostile OMPL.app meshes (issue 36, items 1, 3 and 4): one bad triangle, unit or transform; huge
declared counts and instancing; XML entities. Each is refused through the CLI with one line
naming the file and the field (exit 2, nothing written), whichever XML backend pycollada uses.

The meshes are written here as COLLADA text: a Y_UP world (the plane is x, y) holding a wall
between the start and the goal, and a small square robot.
"""
from __future__ import annotations

import numpy as np
import pytest

collada = pytest.importorskip("collada")

from conftest import ROOT  # noqa: E402
from cspace.io.importers import collada_guard  # noqa: E402
from cspace.io.importers.imported import import_file  # noqa: E402
from cspace.io.importers.meshes import footprint  # noqa: E402
from planners.cli import main  # noqa: E402


def box(x0, x1, y0, y1, z0=-1.0, z1=1.0) -> list:
    """The two caps (4 triangles) of a box prism and one of its walls (2 flat triangles), as 18 corners."""
    b = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)]
    t = [(x, y, z1) for x, y, _ in b]
    return [b[0], b[1], b[2], b[0], b[2], b[3], t[0], t[2], t[1], t[0], t[3], t[2],
            b[0], b[1], t[1], b[0], t[1], t[0]]


WALL = box(-1, 1, -10, 10)  # between start (-5, 0) and goal (5, 0)


def num(c: float) -> str:
    return repr(float(c)) if np.isfinite(c) else str(float(c))  # 'inf', 'nan'


def dae(verts, *, unit="1", prolog="", transform="", prim=None, library_nodes="", node_body=None) -> str:
    """A COLLADA file: one geometry of triangles ``verts`` (corners, 3 per triangle) under one node."""
    n = len(verts)
    flat = " ".join(num(c) for v in verts for c in v)
    if prim is None:
        prim = (f'<triangles count="{n // 3}"><input semantic="VERTEX" source="#V" offset="0"/>'
                f'<p>{" ".join(map(str, range(n)))}</p></triangles>')
    if node_body is None:
        node_body = f'{transform}<instance_geometry url="#G"/>'
    return f"""<?xml version="1.0" encoding="utf-8"?>
{prolog}<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit meter="{unit}" name="u"/><up_axis>Y_UP</up_axis></asset>
<library_geometries><geometry id="G"><mesh>
<source id="P"><float_array id="PA" count="{3 * n}">{flat}</float_array><technique_common>
<accessor source="#PA" count="{n}" stride="3"><param name="X" type="float"/><param name="Y" type="float"/>
<param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="V"><input semantic="POSITION" source="#P"/></vertices>
{prim}
</mesh></geometry></library_geometries>
{library_nodes}
<library_visual_scenes><visual_scene id="S"><node id="N">{node_body}</node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#S"/></scene></COLLADA>
"""


def problem(tmp_path, world: str | None = None, robot: str | None = None) -> str:
    (tmp_path / "world.dae").write_text(world if world is not None else dae(WALL))
    (tmp_path / "robot.dae").write_text(robot if robot is not None else dae(box(-0.5, 0.5, -0.5, 0.5)))
    cfg = tmp_path / "p.cfg"
    cfg.write_text("[problem]\nrobot = robot.dae\nworld = world.dae\nstart.x = -5\nstart.y = 0\nstart.theta = 0\n"
                   "goal.x = 5\ngoal.y = 0\ngoal.theta = 0\nvolume.min.x = -20\nvolume.min.y = -20\n"
                   "volume.max.x = 20\nvolume.max.y = 20\n")
    return str(cfg)


def refused(capsys, tmp_path, cfg: str, file: str, field: str, command: str = "import") -> str:
    """Run the CLI on ``cfg``: exit 2, one stderr line naming ``file`` and ``field``, nothing written."""
    out = tmp_path / ("s.toml" if command == "import" else "r.json")
    args = ["import", cfg, "--out", str(out)] if command == "import" else \
        ["plan", cfg, "--time", "1", "--json", str(out)]
    code = main(args)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and len(err[0]) < 400, (code, err)
    assert file in err[0] and field in err[0], err
    assert not out.exists()
    return err[0]


# ------------------------------------------------------------------ the honest problem


def test_the_honest_problem_imports_and_plans_around_the_wall(tmp_path, capsys):
    cfg = problem(tmp_path)
    d = import_file(cfg).data
    assert len(d["obstacles"]) == 1
    xs = [p[0] for p in d["obstacles"][0]["polygon"]]
    ys = [p[1] for p in d["obstacles"][0]["polygon"]]
    assert (min(xs), max(xs), min(ys), max(ys)) == (-1, 1, -10, 10)
    out = tmp_path / "r.json"
    assert main(["plan", cfg, "--time", "2", "--json", str(out)]) == 0
    assert out.exists()


# ------------------------------------------------------------------ item 1: one bad number


FAR = [(3e12, 3e12, 0.0), (3e12 + 1, 3e12, 0.0), (3e12, 3e12 + 1, 0.0)]


@pytest.mark.parametrize("case, field", [
    ("inf vertex", "geometry 'G'"),
    ("nan vertex", "<float_array> 'PA'"),
    ("far triangle 3e12", "geometry 'G'"),
    ("triangle at 1e9", "geometry 'G'"),
    ("triangle 1e5 out (range)", "geometry 'G'"),
    ("unit nan", "<unit meter>"),
    ("unit 1e308", "<unit meter>"),
    ("unit 0", "<unit meter>"),
    ("matrix nan", "<matrix>"),
    ("rotate nan", "<rotate>"),
])
@pytest.mark.parametrize("command", ["import", "plan"])
def test_one_bad_number_is_refused(tmp_path, capsys, case, field, command):
    verts, kw = list(WALL), {}
    if case == "inf vertex":
        verts[0] = (float("inf"), -10.0, -1.0)
    elif case == "nan vertex":
        verts[4] = (1.0, float("nan"), -1.0)
    elif case == "far triangle 3e12":
        verts += FAR
    elif case == "triangle at 1e9":
        verts += [(1e9, 0.0, 0.0), (1e9 + 1, 0.0, 0.0), (1e9, 1.0, 0.0)]
    elif case == "triangle 1e5 out (range)":  # inside the absolute limit, 1e4 times the scene's spread
        verts += [(1e5, 0.0, 0.0), (1e5 + 1, 0.0, 0.0), (1e5, 1.0, 0.0)]
    elif case.startswith("unit"):
        kw["unit"] = {"unit nan": "nan", "unit 1e308": "1e308", "unit 0": "0"}[case]
    elif case == "matrix nan":
        kw["transform"] = "<matrix>1 0 0 nan 0 1 0 0 0 0 1 0 0 0 0 1</matrix>"
    elif case == "rotate nan":
        kw["transform"] = "<rotate>0 0 1 nan</rotate>"
    cfg = problem(tmp_path, world=dae(verts, **kw))
    refused(capsys, tmp_path, cfg, "world.dae", field, command)


def test_a_world_flattened_by_its_transform_is_refused(tmp_path, capsys):
    # every triangle flat (here a zero matrix): not an empty world
    cfg = problem(tmp_path, world=dae(WALL, transform="<matrix>0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1</matrix>"))
    assert "p.cfg: world: world.dae: its 6 triangles cover no area" in refused(capsys, tmp_path, cfg, "world.dae",
                                                                                  "world")


def test_a_bad_robot_mesh_is_refused_too(tmp_path, capsys):
    cfg = problem(tmp_path, robot=dae(box(-0.5, 0.5, -0.5, 0.5) + FAR))
    refused(capsys, tmp_path, cfg, "robot.dae", "geometry 'G'")


def test_one_far_triangle_cannot_make_the_others_flat():
    # footprint's flatness is judged per triangle: a huge one far away leaves the small ones alone
    # (it used to take the scene's size, 3e12 here, and drop every triangle under 9 square units)
    small = np.array(box(-0.05, 0.05, -0.05, 0.05))[:12, :2].reshape(-1, 3, 2)
    far = np.array([[3e12, 3e12], [3e12 + 1e6, 3e12], [3e12, 3e12 + 1e6]]).reshape(1, 3, 2)
    alone, info = footprint(small)
    both, info2 = footprint(np.concatenate((small, far)))
    assert info["flat"] == info2["flat"] == 0 and abs(alone.area - 0.01) < 1e-12
    assert abs(both.intersection(alone).area - alone.area) < 1e-12


# ------------------------------------------------------------------ item 3: unbounded work


def polylist(vcount: str, p: str, count: int = 1) -> str:
    return (f'<polylist count="{count}"><input semantic="VERTEX" source="#V" offset="0"/>'
            f'<vcount>{vcount}</vcount><p>{p}</p></polylist>')


@pytest.mark.parametrize("vcount, p, field, fault", [
    ("1000000000", "0 1 2", "geometry 'G'", "declares 1000000000 corners"),
    ("-4", "0 1 2 3", "geometry 'G'", "vcount"),
    ("4 4", "0 1 2 3", "geometry 'G'", "declares 8 corners"),
    ("2 3", "0 1 2 3 4", "geometry 'G'", "vcount"),  # a polygon of 2 corners
    ("3", "0 1 99", "world", "99"),  # an index past the vertices (pycollada's own check)
    ("3", "0 -1 2", "geometry 'G'", "-1"),  # a negative index (numpy would wrap it)
])
def test_declared_counts_are_checked_against_the_data(tmp_path, capsys, vcount, p, field, fault):
    cfg = problem(tmp_path, world=dae(WALL, prim=polylist(vcount, p)))
    msg = refused(capsys, tmp_path, cfg, "world.dae", field)
    assert fault in msg


def test_a_polylist_within_its_counts_is_read(tmp_path):
    # the wall's bottom cap as one quad (vcount 4) and the top cap as two triangles
    prim = polylist("4 3 3", "0 1 2 5 6 7 8 9 10 11", count=3)
    d = import_file(problem(tmp_path, world=dae(WALL, prim=prim))).data
    assert len(d["obstacles"]) == 1


def nested(levels: int) -> tuple[str, str]:
    """``levels`` library nodes, each instancing the one below twice: 2^levels copies of the wall."""
    lib = ['<node id="L0"><instance_geometry url="#G"/></node>']
    for i in range(1, levels + 1):
        lib.append(f'<node id="L{i}"><instance_node url="#L{i - 1}"/><instance_node url="#L{i - 1}"/></node>')
    return "<library_nodes>" + "".join(lib) + "</library_nodes>", f'<instance_node url="#L{levels}"/>'


def test_instancing_is_counted_before_it_is_expanded(tmp_path, capsys):
    lib, body = nested(20)  # 2^20 walls: 2 million node instances from 2.4 KB
    cfg = problem(tmp_path, world=dae(WALL, library_nodes=lib, node_body=body))
    msg = refused(capsys, tmp_path, cfg, "world.dae", "<instance_node>")
    assert f"limit of {collada_guard.MAX_INSTANCES}" in msg


def test_instanced_triangles_are_bounded(tmp_path, capsys):
    lib, body = nested(10)  # 1024 copies of 2100 triangles: 2.15 million
    cfg = problem(tmp_path, world=dae(WALL * 350, library_nodes=lib, node_body=body))
    msg = refused(capsys, tmp_path, cfg, "world.dae", "<instance_node>")
    assert f"{1024 * 2100} triangles" in msg and f"limit of {collada_guard.MAX_TRIANGLES}" in msg


def test_moderate_instancing_is_read(tmp_path):
    lib, body = nested(3)  # 8 copies of the wall, on top of each other
    d = import_file(problem(tmp_path, world=dae(WALL, library_nodes=lib, node_body=body))).data
    assert len(d["obstacles"]) == 1


def test_an_instancing_cycle_is_refused(tmp_path, capsys):
    lib = '<library_nodes><node id="A"><instance_node url="#B"/></node><node id="B"><instance_node url="#A"/>' \
          '<instance_geometry url="#G"/></node></library_nodes>'
    cfg = problem(tmp_path, world=dae(WALL, library_nodes=lib, node_body='<instance_node url="#A"/>'))
    refused(capsys, tmp_path, cfg, "world.dae", "world")  # pycollada finds no node before its definition


def test_a_file_over_the_mesh_size_limit_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(collada_guard, "MAX_MESH_BYTES", 8000)
    cfg = problem(tmp_path, world=dae(WALL, prolog="<!--" + "x" * 8000 + "-->\n"))
    assert "8000 byte" in refused(capsys, tmp_path, cfg, "world.dae", "file")


# ------------------------------------------------------------------ item 4: XML entities


LAUGHS = '<!DOCTYPE lolz [<!ENTITY lol "lol">' + "".join(
    f'<!ENTITY lol{i} "{("&lol" + (str(i - 1) if i > 1 else "") + ";") * 10}">' for i in range(1, 10)) + "]>\n"


@pytest.mark.parametrize("prolog, where", [
    (LAUGHS, "billion laughs"),
    ('<!DOCTYPE c [<!ENTITY x SYSTEM "file:///etc/hostname">]>\n', "external entity"),
    ('<!DOCTYPE COLLADA>\n', "bare doctype"),
    ('<!DOCTYPE c [<!ENTITY a "' + "x" * 5000 + '">]>\n', "quadratic blow-up"),
])
def test_doctypes_and_entities_are_refused(tmp_path, capsys, prolog, where):
    text = dae(WALL, prolog=prolog)
    if "lol9" in prolog:
        text = text.replace('name="u"', 'name="&lol9;"')
    elif "SYSTEM" in prolog:
        text = text.replace("<up_axis>", "<up_axis>&x;")
    elif "x" * 50 in prolog:
        text = text.replace('name="u"', 'name="' + "&a;" * 5000 + '"')
    cfg = problem(tmp_path, world=text)
    msg = refused(capsys, tmp_path, cfg, "world.dae", "DOCTYPE")
    assert "entit" in msg or "DOCTYPE" in msg


def test_a_doctype_in_utf16_is_refused(tmp_path, capsys):
    text = dae(WALL, prolog='<!DOCTYPE c [<!ENTITY x SYSTEM "file:///etc/hostname">]>\n')
    text = text.replace('encoding="utf-8"', 'encoding="utf-16"')
    cfg = problem(tmp_path)
    (tmp_path / "world.dae").write_bytes(text.encode("utf-16"))
    refused(capsys, tmp_path, cfg, "world.dae", "DOCTYPE")


@pytest.mark.parametrize("backend", ["etree", "lxml"])
def test_the_backend_does_not_matter(tmp_path, backend):
    # the check runs with the stdlib's expat before pycollada parses (with lxml if installed, else
    # xml.etree): in a fresh process with lxml hidden, and with it if it is installed
    import subprocess
    import sys

    if backend == "lxml":
        pytest.importorskip("lxml")
    hide = "sys.modules['lxml'] = None; " if backend == "etree" else ""
    code = ("import sys; " + hide + "from planners.cli import main; import collada.xmlutil as x; "
            "print(x.etree.__name__); raise SystemExit(main(sys.argv[1:]))")
    good = problem(tmp_path)
    (tmp_path / "bad.dae").write_text(dae(WALL, prolog='<!DOCTYPE c [<!ENTITY x SYSTEM "file:///etc/hostname">]>\n')
                                      .replace("<up_axis>", "<up_axis>&x;"))
    bad = tmp_path / "bad.cfg"
    bad.write_text(open(good).read().replace("world.dae", "bad.dae"))
    expected = "lxml.etree" if backend == "lxml" else "xml.etree.ElementTree"
    for cfg, rc in ((good, 0), (str(bad), 2)):
        out = tmp_path / f"{rc}.toml"
        r = subprocess.run([sys.executable, "-c", code, "import", cfg, "--out", str(out)], capture_output=True,
                           text=True, timeout=120, cwd=ROOT)
        assert r.stdout.splitlines()[0] == expected and r.returncode == rc, (r.stdout, r.stderr)
        assert out.exists() == (rc == 0)
        if rc:
            err = r.stderr.strip().splitlines()
            assert len(err) == 1 and "bad.dae: <!DOCTYPE>:" in err[0], err
