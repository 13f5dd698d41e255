"""OMPL.app problem files (issue 22): a .cfg with COLLADA meshes written here with pycollada
(a robot, an environment with a hole, Y-up and Z-up, node transforms), imported as SE(2)
scenarios and compared with the geometry the meshes were built from.

Skipped without pycollada (the `io` extra; the `test` extra brings it).
"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import shapely

collada = pytest.importorskip("collada")

from cspace.io.importers.imported import ImportOptions, import_file, load_imported  # noqa: E402
from cspace.io.load import load_scenario  # noqa: E402
from planners.cli import main  # noqa: E402


def prism(poly: shapely.Polygon, z0: float = -1.0, z1: float = 1.0) -> np.ndarray:
    """Triangles (N, 3, 3) of ``poly`` extruded from z0 to z1: two caps and the walls."""
    caps = shapely.constrained_delaunay_triangles(poly)
    tris = []
    for t in caps.geoms:
        c = np.asarray(t.exterior.coords)[:3]
        tris.append(np.column_stack((c, np.full(3, z0))))
        tris.append(np.column_stack((c[::-1], np.full(3, z1))))
    for ring in [poly.exterior, *poly.interiors]:
        c = np.asarray(ring.coords)
        for a, b in zip(c[:-1], c[1:]):
            p = [[*a, z0], [*b, z0], [*b, z1], [*a, z1]]
            tris += [np.array([p[0], p[1], p[2]]), np.array([p[0], p[2], p[3]])]
    return np.array(tris, dtype=np.float64)


def lift(tris: np.ndarray, up: str) -> np.ndarray:
    """Plane triangles (x, y, extrusion h) written for a file whose up axis is ``up``: the
    inverse of the loader's turn to Y_UP (Z_UP: the plane is the file's x, z and y = -h)."""
    x, y, h = tris[..., 0], tris[..., 1], tris[..., 2]
    if up == "Z_UP":
        return np.stack((x, -h, y), axis=-1)
    if up == "X_UP":
        return np.stack((y, -x, h), axis=-1)
    return tris


def write_dae(path: str, parts: list, up: str = "Y_UP", unit: float | None = None):
    """A COLLADA file; ``parts`` are (triangles (N, 3, 3), 4x4 node matrix or None), one node each."""
    from collada import geometry, material, scene, source

    mesh = collada.Collada()
    mesh.assetInfo.upaxis = up
    if unit is not None:
        mesh.assetInfo.unitmeter, mesh.assetInfo.unitname = unit, "unit"
    effect = material.Effect("effect0", [], "phong", diffuse=(1, 0, 0))
    mat = material.Material("material0", "mymaterial", effect)
    mesh.effects.append(effect)
    mesh.materials.append(mat)
    nodes = []
    for i, (tris, matrix) in enumerate(parts):
        verts = tris.reshape(-1, 3).astype(np.float64)
        src = source.FloatSource(f"verts{i}", verts.reshape(-1), ("X", "Y", "Z"))
        geom = geometry.Geometry(mesh, f"geom{i}", f"geom{i}", [src])
        ilist = source.InputList()
        ilist.addInput(0, "VERTEX", f"#verts{i}")
        tset = geom.createTriangleSet(np.arange(len(verts)), ilist, "materialref")
        geom.primitives.append(tset)
        mesh.geometries.append(geom)
        mnode = scene.MaterialNode("materialref", mat, inputs=[])
        gnode = scene.GeometryNode(geom, [mnode])
        transforms = [] if matrix is None else [scene.MatrixTransform(np.asarray(matrix, np.float32).reshape(-1))]
        nodes.append(scene.Node(f"node{i}", children=[gnode], transforms=transforms))
    mesh.scenes.append(scene.Scene("scene", nodes))
    mesh.scene = mesh.scenes[0]
    mesh.assetInfo.save()
    mesh.write(path)


ROBOT = shapely.Polygon([(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (0, 3)])  # an L: its vertex mean is not its box's
ROOM = shapely.Polygon([(-20, -20), (20, -20), (20, 20), (-20, 20)],
                       [[(-18, -18), (-18, 18), (18, 18), (18, -18)]])  # a wall with a hole (the room)
PILLAR = shapely.box(-3, -3, 3, 3)


def write_problem(folder, up="Y_UP", control=None, robot_matrix=None, extra="", volume=True, unit=None):
    folder = str(folder)
    robot_tris = prism(ROBOT)
    write_dae(os.path.join(folder, "robot.dae"), [(lift(robot_tris, up), robot_matrix)], up=up, unit=unit)
    write_dae(os.path.join(folder, "env.dae"), [(lift(prism(ROOM), up), None), (lift(prism(PILLAR), up), None)],
              up=up, unit=unit)
    lines = ["[problem]", "name = test problem", "robot = robot.dae", "world = env.dae",
             "start.x = -12.0", "start.y = -12.0", "start.theta = 0.0",
             "goal.x = 12.0", "goal.y = 12.0", "goal.theta = 1.5707963267948966"]
    if volume:
        lines += ["volume.min.x = -20.0", "volume.min.y = -20.0", "volume.max.x = 20.0", "volume.max.y = 20.0"]
    if control:
        lines.append(f"control = {control}")
    lines += [extra, "", "[benchmark]", "time_limit=10.0", "", "[planner]", "rrt=", "rrt="]
    cfg = os.path.join(folder, "problem.cfg")
    open(cfg, "w").write("\n".join(lines) + "\n")
    return cfg


def robot_mean(tris3: np.ndarray) -> np.ndarray:
    """The independent body frame: mean of the distinct (position, face normal) corners."""
    n = np.cross(tris3[:, 1] - tris3[:, 0], tris3[:, 2] - tris3[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    rows = {(tuple(p), tuple(np.round(q, 12))) for t, q in zip(tris3, n) for p in t}
    return np.mean([p for p, _ in rows], axis=0)


@pytest.mark.parametrize("up", ["Y_UP", "Z_UP", "X_UP"])
def test_geometry_matches_the_meshes(tmp_path, up):
    cfg = write_problem(tmp_path, up=up)
    imp = import_file(cfg)
    d = imp.data
    assert d["space"] == "se2" and d["bounds"] == {"xmin": -20.0, "xmax": 20.0, "ymin": -20.0, "ymax": 20.0}
    assert d["start"] == {"x": -12.0, "y": -12.0, "theta": 0.0} and d["goal"]["theta"] == math.pi / 2
    obstacles = [shapely.Polygon(o["polygon"], o.get("holes", [])) for o in d["obstacles"]]
    assert len(obstacles) == 2
    union = shapely.union_all(obstacles)
    assert union.symmetric_difference(ROOM.union(PILLAR)).area < 1e-9
    assert sorted(len(o.get("holes", [])) for o in d["obstacles"]) == [0, 1]
    # the robot in OMPL.app's body frame: the L moved by minus the mean of its mesh vertices
    c = robot_mean(prism(ROBOT))[:2]
    robot = shapely.Polygon(d["robot"]["polygon"])
    expected = shapely.affinity.translate(ROBOT, -c[0], -c[1])
    assert robot.symmetric_difference(expected).area < 1e-9
    assert len(d["robot"]["polygon"]) == 6  # no collinear vertex, no wall left over


def test_node_transforms_and_unit_are_applied(tmp_path):
    # the robot's node turns it by 90 degrees about z and moves it; the unit scales everything by 2
    ang = math.pi / 2
    m = np.array([[math.cos(ang), -math.sin(ang), 0, 5], [math.sin(ang), math.cos(ang), 0, 7], [0, 0, 1, 0],
                  [0, 0, 0, 1]])
    cfg = write_problem(tmp_path, up="Y_UP", robot_matrix=m, unit=2.0)
    d = import_file(cfg).data
    turned = shapely.affinity.scale(shapely.affinity.rotate(ROBOT, 90, origin=(0, 0)), 2, 2, origin=(0, 0))
    c = np.mean([p for p in {tuple(p) for p in np.asarray(turned.exterior.coords)[:-1]}], axis=0)
    robot = shapely.Polygon(d["robot"]["polygon"])
    # the same shape up to the body frame: compare after centring both on their vertex means
    assert abs(robot.area - turned.area) < 1e-6
    a = shapely.affinity.translate(robot, *-np.asarray(robot.exterior.coords)[:-1].mean(axis=0))
    b = shapely.affinity.translate(turned, *-c)
    assert a.symmetric_difference(b).area < 1e-5
    room = shapely.affinity.scale(ROOM, 2, 2, origin=(0, 0))
    union = shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", [])) for o in d["obstacles"]])
    assert abs(union.area - room.union(shapely.affinity.scale(PILLAR, 2, 2, origin=(0, 0))).area) < 1e-6


def test_the_scenario_plans_in_se2(tmp_path):
    from planners import plan

    cfg = write_problem(tmp_path)
    sc = load_scenario(cfg)
    assert sc.space == "se2" and sc.start[2] == 0.0
    res = plan(sc, planner="RRTConnect", time=20.0, seed=1)
    assert res.solved


def test_control_problems_are_marked(tmp_path, capsys):
    cfg = write_problem(tmp_path, control="kinematic_car")
    out = tmp_path / "s.toml"
    assert main(["import", cfg, "--out", str(out)]) == 0
    o = capsys.readouterr()
    assert "kinodynamic" in o.out and "kinematic_car" in o.err
    assert "kinodynamic" in out.read_text().split("\n[")[0]  # in the header comment
    assert load_scenario(out).space == "se2"


def test_bounds_default_to_the_world_box(tmp_path):
    d = import_file(write_problem(tmp_path, volume=False)).data
    assert d["bounds"] == {"xmin": -20.0, "xmax": 20.0, "ymin": -20.0, "ymax": 20.0}


def test_options_override_the_cfg(tmp_path):
    cfg = write_problem(tmp_path)
    sc = load_imported(cfg, options=ImportOptions(robot={"radius": 0.5}, start=(-10.0, -10.0, 0.0)))
    assert sc.robot_kind == "disk" and sc.start[:2] == (-10.0, -10.0) and sc.space == "se2"


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize("case, field", [("missing mesh", "world"), ("no triangles", "robot"), ("3-D", "start.z"),
                                         ("not collada", "robot"), ("no start", "start.x"), ("bad number", "goal.x"),
                                         ("no problem", "problem"), ("twice", "robot")])
def test_bad_problems_are_one_line(tmp_path, capsys, case, field):
    cfg = write_problem(tmp_path)
    text = open(cfg).read()
    if case == "missing mesh":
        os.remove(os.path.join(tmp_path, "env.dae"))
    elif case == "no triangles":
        write_dae(os.path.join(tmp_path, "robot.dae"), [])
    elif case == "3-D":
        text = text.replace("start.x = -12.0", "start.x = -12.0\nstart.z = 0.0")
    elif case == "not collada":
        open(os.path.join(tmp_path, "robot.dae"), "w").write("<not-collada/>")
    elif case == "no start":
        text = text.replace("start.x = -12.0\n", "")
    elif case == "bad number":
        text = text.replace("goal.x = 12.0", "goal.x = twelve")
    elif case == "no problem":
        text = text.replace("[problem]", "[problme]")
    elif case == "twice":
        text = text.replace("robot = robot.dae", "robot = robot.dae\nrobot = other.dae")
    open(cfg, "w").write(text)
    out = tmp_path / "s.toml"
    code = main(["import", cfg, "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("error: ") and len(err[0]) < 300, err
    assert f": {field}: " in err[0], err
    assert not out.exists()


def sketchup_box(x0, x1, y0, y1, z0, z1, matrix: str) -> str:
    """A COLLADA file written the way OMPL.app's resources are (SketchUp 8): Z_UP, a node with a
    scaling matrix inside an outer node, normals inside <vertices>, each face with its own four
    corners, front faces and back faces as two triangle sets of two materials."""
    faces = []  # (corners, normal) of the six faces of the box
    for axis in range(3):
        for side, (lo, hi) in ((0, (x0, x1)), (1, (y0, y1)), (2, (z0, z1)))[axis:axis + 1]:
            for val, sign in ((lo, -1.0), (hi, 1.0)):
                others = [a for a in range(3) if a != axis]
                bounds = [(x0, x1), (y0, y1), (z0, z1)]
                quad = []
                for u, v in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [0.0, 0.0, 0.0]
                    p[axis] = val
                    p[others[0]] = bounds[others[0]][u]
                    p[others[1]] = bounds[others[1]][v]
                    quad.append(p)
                n = [0.0, 0.0, 0.0]
                n[axis] = sign
                faces.append((quad, n))
    pos, nor, front, back = [], [], [], []
    for quad, n in faces:
        k = len(pos) // 3
        for p in quad:  # front face corners
            pos += p
            nor += n
        front += [k, k + 1, k + 2, k, k + 2, k + 3]
        k = len(pos) // 3
        for p in quad:  # the same corners again for the back face, normal reversed
            pos += p
            nor += [-c for c in n]
        back += [k + 2, k + 1, k, k + 3, k + 2, k]
    f = " ".join(f"{v:.7f}" for v in pos)
    g = " ".join(f"{v:.7f}" for v in nor)
    return f"""<?xml version="1.0" encoding="UTF-8" standalone="no" ?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><up_axis>Z_UP</up_axis></asset>
 <library_visual_scenes><visual_scene id="ID1"><node name="SketchUp"><node id="ID2" name="instance_0">
  <matrix>{matrix}</matrix>
  <instance_geometry url="#ID3"><bind_material><technique_common>
   <instance_material symbol="Material2" target="#ID9"><bind_vertex_input semantic="UVSET0" input_semantic="TEXCOORD" input_set="0" /></instance_material>
   <instance_material symbol="Material3" target="#ID4"><bind_vertex_input semantic="UVSET0" input_semantic="TEXCOORD" input_set="0" /></instance_material>
  </technique_common></bind_material></instance_geometry>
 </node></node></visual_scene></library_visual_scenes>
 <library_geometries><geometry id="ID3"><mesh>
  <source id="ID6"><float_array id="ID11" count="{len(pos)}">{f}</float_array><technique_common>
   <accessor count="{len(pos) // 3}" source="#ID11" stride="3"><param name="X" type="float" /><param name="Y" type="float" /><param name="Z" type="float" /></accessor></technique_common></source>
  <source id="ID7"><float_array id="ID12" count="{len(nor)}">{g}</float_array><technique_common>
   <accessor count="{len(nor) // 3}" source="#ID12" stride="3"><param name="X" type="float" /><param name="Y" type="float" /><param name="Z" type="float" /></accessor></technique_common></source>
  <vertices id="ID8"><input semantic="POSITION" source="#ID6" /><input semantic="NORMAL" source="#ID7" /></vertices>
  <triangles count="{len(front) // 3}" material="Material3"><input offset="0" semantic="VERTEX" source="#ID8" /><p>{" ".join(map(str, front))}</p></triangles>
  <triangles count="{len(back) // 3}" material="Material2"><input offset="0" semantic="VERTEX" source="#ID8" /><p>{" ".join(map(str, back))}</p></triangles>
 </mesh></geometry></library_geometries>
 <library_materials><material id="ID4" name="material_0"><instance_effect url="#ID5" /></material>
  <material id="ID9" name="material_1"><instance_effect url="#ID10" /></material></library_materials>
 <library_effects><effect id="ID5"><profile_COMMON><technique sid="COMMON"><lambert><diffuse><color>1 0 0 1</color></diffuse></lambert></technique></profile_COMMON></effect>
  <effect id="ID10"><profile_COMMON><technique sid="COMMON"><lambert><diffuse><color>1 1 1 1</color></diffuse></lambert></technique></profile_COMMON></effect></library_effects>
 <scene><instance_visual_scene url="#ID1" /></scene>
</COLLADA>
"""


def test_a_sketchup_style_problem(tmp_path):
    # The robot: a box 0.05 x 0.0787402 x 0.025 scaled by 100 and moved by -2.475 in x, Z_UP: in the
    # plane (x, z) it is [-2.475, 2.525] x [-1.25, 1.25], its vertex mean (0.025, 0).
    robot = sketchup_box(0, 0.05, -0.0787402, 0, -0.0125, 0.0125,
                         "100 0 0 -2.475 0 100 0 0 0 0 100 0 0 0 0 1")
    # The world: a wall 10 x 2 (plane x from 5 to 15, plane y from -1 to 1) scaled by 10.
    world = sketchup_box(0.5, 1.5, -0.08, 0, -0.1, 0.1, "10 0 0 0 0 10 0 0 0 0 10 0 0 0 0 1")
    (tmp_path / "robot.dae").write_text(robot)
    (tmp_path / "world.dae").write_text(world)
    cfg = tmp_path / "p.cfg"
    cfg.write_text("[problem]\nrobot = robot.dae\nworld = world.dae\nstart.x = -10\nstart.y = 0\nstart.theta = 0\n"
                   "goal.x = 25\ngoal.y = 0\ngoal.theta = 3.14159\nvolume.min.x = -30\nvolume.min.y = -30\n"
                   "volume.max.x = 30\nvolume.max.y = 30\n")
    imp = import_file(cfg)
    r = shapely.Polygon(imp.data["robot"]["polygon"])
    assert r.symmetric_difference(shapely.box(-2.5, -1.25, 2.5, 1.25)).area < 1e-5
    w = shapely.Polygon(imp.data["obstacles"][0]["polygon"])
    assert len(imp.data["obstacles"]) == 1 and w.symmetric_difference(shapely.box(5, -1, 15, 1)).area < 1e-5
    assert any("Z_UP" in line for line in imp.report)
    assert load_scenario(cfg).space == "se2"
