"""OMPL.app problem files (``.cfg``) and their COLLADA meshes, as SE(2) scenarios.

A 2-D OMPL.app problem is an INI-style file::

    [problem]
    robot = car1_planar_robot.dae      # mesh files, relative to the cfg's folder
    world = Maze_planar_env.dae
    start.x = 0.0, start.y = 0.0, start.theta = 0.0     (one key per line)
    goal.x, goal.y, goal.theta
    volume.min.x, volume.min.y, volume.max.x, volume.max.y   (optional: the world's box)
    control = kinematic_car            (optional: a kinodynamic problem)

Other sections (``[benchmark]``, ``[planner]``) and keys (``name``, ``objective``) are
ignored and listed in the report. A problem with ``start.z`` or ``volume.min.z`` is
3-D and refused.

Meshes are read with pycollada (the optional extra ``pip install -e ".[io]"``), the
way OMPL.app's Assimp loader sees them: every geometry instance under the scene's
nodes with its node transforms, the ``<unit meter>`` scale, and the up axis turned
to Y_UP (:func:`cspace.io.importers.meshes.to_plane`). The robot's body frame is OMPL.app's:
its reference point is the mean of the robot's mesh vertices (Assimp's
``sceneCenter`` after ``JoinIdenticalVertices``: each distinct (position, normal,
texture coordinate) corner of a primitive counted once; the normal of a corner
without one is its triangle's, as ``GenNormals`` makes them), and the robot turns
about it. The import is an SE(2) scenario (``space = "se2"``); a ``control``
problem is planned as its geometric problem, and says so. Every mesh first passes the limits of
:mod:`cspace.io.importers.collada_guard` (size, no DOCTYPE, declared counts, instancing, finite and bounded
numbers): a hostile file is one line, never a blow-up or a silently wrong obstacle.
"""
from __future__ import annotations

import os
import warnings

import numpy as np

from .import_record import Imported, ImportOptions, robot_and_queries
from ..scenario.files import check_input, read_input, utf8_text
from ..scenario.messages import ScenarioError

IO_HINT = 'pip install -e ".[io]"  (or pip install pycollada)'
PROBLEM_KEYS = {"robot", "world", "start.x", "start.y", "start.theta", "goal.x", "goal.y", "goal.theta",
                "volume.min.x", "volume.min.y", "volume.max.x", "volume.max.y", "control", "name", "objective",
                "objective.threshold"}
THREE_D = ("start.z", "goal.z", "volume.min.z", "volume.max.z", "start.axis.x", "start.axis.y", "start.axis.z")


def read_cfg(path) -> dict[str, dict[str, str]]:
    """The sections of a cfg as ``{section: {key: value}}`` (strings; a key repeated
    in ``[problem]`` is an error, elsewhere the last one is kept).

    >>> import tempfile
    >>> d = tempfile.mkdtemp(); f = os.path.join(d, "p.cfg")
    >>> _ = open(f, "w").write("[problem]\\nrobot = r.dae\\nstart.x = 1\\n# note\\n[planner]\\nrrt=\\nrrt=\\n")
    >>> read_cfg(f)
    {'problem': {'robot': 'r.dae', 'start.x': '1'}, 'planner': {'rrt': ''}}
    """
    path = os.fspath(path)
    text = utf8_text(read_input(path), path)
    out: dict[str, dict[str, str]] = {}
    section = None
    for n, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith(("#", ";")):
            continue
        if s.startswith("[") and s.endswith("]"):
            section = s[1:-1].strip()
            out.setdefault(section, {})
            continue
        if "=" not in s or section is None:
            raise ScenarioError(path, f"line {n}", f"expected [section] or key = value, got {s[:60]!r}")
        key, _, value = s.partition("=")
        key, value = key.strip(), value.split("#")[0].strip()
        if section == "problem" and key in out[section]:
            raise ScenarioError(path, key, f"given twice (line {n})")
        out[section][key] = value
    return out


def _number(problem: dict, key: str, path: str, default=None) -> float:
    import math

    if key not in problem:
        if default is not None:
            return default
        raise ScenarioError(path, key, "missing (a 2-D OMPL.app problem gives start.x, start.y, goal.x, goal.y)")
    try:
        v = float(problem[key])
    except ValueError:
        raise ScenarioError(path, key, f"must be a number, got {problem[key][:60]!r}") from None
    if not math.isfinite(v):
        raise ScenarioError(path, key, f"must be finite, got {problem[key]!r}")
    return v


def read_mesh(cfg_path: str, key: str, name: str):
    """The triangles of mesh ``name`` (the cfg's ``key``: robot or world) in the plane,
    (N, 3, 2), the plane coordinates of its distinct corners (for the centre), its up
    axis and unit. A missing file is a one-line error naming the cfg's field:

    >>> read_mesh("p.cfg", "world", "no_such_mesh.dae")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    cspace.io.scenario.messages.ScenarioError: p.cfg: world: mesh file no_such_mesh.dae not found (looked in ...)
    """
    mesh = name if os.path.isabs(name) else os.path.join(os.path.dirname(os.path.abspath(cfg_path)), name)
    if not os.path.exists(mesh):
        raise ScenarioError(cfg_path, key, f"mesh file {name} not found (looked in {os.path.dirname(mesh)})")
    if not mesh.lower().endswith(".dae"):
        raise ScenarioError(cfg_path, key, f"{name}: only COLLADA (.dae) meshes are read")
    try:
        import collada
    except ImportError:
        raise ScenarioError(cfg_path, key, f"reading COLLADA meshes needs pycollada: {IO_HINT}") from None
    from . import collada_guard as guard

    size = check_input(mesh).st_size
    raw = read_input(mesh) if size <= guard.MAX_MESH_BYTES else b""
    if size > guard.MAX_MESH_BYTES or len(raw) > guard.MAX_MESH_BYTES:  # (it may grow in between)
        raise ScenarioError(mesh, "file", f"is {max(size, len(raw))} bytes, over the {guard.MAX_MESH_BYTES} byte "
                                          "limit on a mesh")
    guard.check_xml(raw, mesh)  # no DOCTYPE or entity reaches pycollada, whichever parser it uses
    with warnings.catch_warnings():  # pycollada's numpy.matrix use warns on every load
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        return _read_collada(collada, raw, cfg_path, mesh, key)


def _read_collada(collada, raw: bytes, cfg_path: str, mesh: str, key: str):
    from . import collada_guard as guard
    from .meshes import to_plane

    try:
        import io

        dae = collada.Collada(io.BytesIO(raw), ignore=[collada.common.DaeUnsupportedError,
                                                      collada.common.DaeBrokenRefError])
    except Exception as exc:  # pycollada raises DaeError, lxml/ElementTree errors, ValueError...
        raise ScenarioError(mesh, key, f"cannot read the COLLADA file ({type(exc).__name__}: "
                                       f"{str(exc)[:120]})") from None
    up = str(getattr(dae.assetInfo, "upaxis", "Y_UP") or "Y_UP")
    unit = guard.check_unit(getattr(dae.assetInfo, "unitmeter", None), mesh)
    tris, corners, owners = [], [], []
    scene = dae.scene
    if scene is None:
        raise ScenarioError(mesh, key, "no <scene> in the COLLADA file (nothing is placed)")
    guard.check_scene(scene, mesh)  # counts, indices and transforms, before the graph is expanded
    for geom in scene.objects("geometry"):
        field = f"geometry {str(geom.original.id)!r}"
        for prim in geom.primitives():
            if isinstance(prim, collada.polylist.BoundPolylist):
                prim = prim.triangleset()
            if not isinstance(prim, collada.triangleset.BoundTriangleSet) or prim.vertex is None:
                continue  # lines and points cover no area
            idx = np.asarray(prim.vertex_index, dtype=np.int64).reshape(-1, 3)
            if len(idx) == 0:
                continue
            with np.errstate(over="ignore", invalid="ignore"):
                tri3 = np.asarray(prim.vertex, dtype=np.float64)[idx] * unit  # (N, 3, 3)
            guard.check_coordinates(tri3, mesh, field)
            owners.append((sum(len(t) for t in tris), field))
            tris.append(to_plane(tri3.reshape(-1, 3), up).reshape(-1, 3, 2))
            corners.append(_distinct_corners(prim, tri3, idx, up))
    if not tris or sum(len(t) for t in tris) == 0:
        raise ScenarioError(mesh, key, "the mesh has no triangles")
    tri, corner = np.concatenate(tris), np.concatenate(corners)
    guard.check_range(tri, owners, corner.mean(axis=0) if key == "robot" else (0.0, 0.0), mesh)
    return tri, corner, up, unit


def _distinct_corners(prim, tri3: np.ndarray, idx: np.ndarray, up: str) -> np.ndarray:
    """Plane coordinates of a primitive's corners, each distinct (position, normal,
    texture coordinates) once, as Assimp's JoinIdenticalVertices leaves them."""
    from .meshes import to_plane

    n = len(idx)
    cols = [tri3.reshape(-1, 3)]
    if prim.normal is not None and prim.normal_index is not None and len(prim.normal):
        cols.append(np.asarray(prim.normal, dtype=np.float64)[np.asarray(prim.normal_index).reshape(-1)])
    else:  # GenNormals: the face normal at each of its corners
        fn = np.cross(tri3[:, 1] - tri3[:, 0], tri3[:, 2] - tri3[:, 0])
        norm = np.linalg.norm(fn, axis=1, keepdims=True)
        fn = np.divide(fn, norm, out=np.zeros_like(fn), where=norm > 0)
        cols.append(np.repeat(fn, 3, axis=0))
    for tset, tidx in zip(prim.texcoordset or (), prim.texcoord_indexset or ()):
        cols.append(np.asarray(tset, dtype=np.float64)[np.asarray(tidx).reshape(-1)])
    key = np.concatenate(cols, axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    assert key.shape[0] == 3 * n
    return to_plane(cols[0][np.sort(first)], up)


def import_cfg(path: str, options: ImportOptions) -> Imported:
    """An OMPL.app 2-D problem as an SE(2) scenario dict and a report.

    >>> import tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "p.cfg"); _ = open(f, "w").write("[problem]\\nrobot = r.dae\\n")
    >>> import_cfg(f, ImportOptions())  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    cspace.io.scenario.messages.ScenarioError: ...p.cfg: world: missing (the mesh file of the robot and of the world)
    """
    from .meshes import footprint, polygons

    cfg = read_cfg(path)
    if "problem" not in cfg:
        raise ScenarioError(path, "problem", "missing: an OMPL.app problem file has a [problem] section")
    pb = cfg["problem"]
    for k in THREE_D:
        if k in pb:
            raise ScenarioError(path, k, "a 3-D (SE(3)) problem: cspace plans 2-D problems")
    for k in ("robot", "world"):
        if not pb.get(k):
            raise ScenarioError(path, k, "missing (the mesh file of the robot and of the world)")
    robot_tri, robot_corners, robot_up, _ = read_mesh(path, "robot", pb["robot"])
    world_tri, world_corners, world_up, _ = read_mesh(path, "world", pb["world"])
    center = robot_corners.mean(axis=0)
    robot_geom, rinfo = footprint(robot_tri - center)
    world_geom, winfo = footprint(world_tri)
    robot_polys = polygons(robot_geom)
    world_polys = polygons(world_geom)
    if not robot_polys:
        raise ScenarioError(path, "robot", f"{pb['robot']}: its triangles cover no area in the x-y plane")
    if not world_polys:  # triangles, all flat: a singular transform or a wrong up axis, not an empty world
        raise ScenarioError(path, "world", f"{pb['world']}: its {winfo['triangles']} triangles cover no area in the "
                                           "x-y plane")
    pose = {}
    for end in ("start", "goal"):
        pose[end] = {"x": _number(pb, f"{end}.x", path), "y": _number(pb, f"{end}.y", path),
                     "theta": _number(pb, f"{end}.theta", path, 0.0)}
    if "volume.min.x" in pb or "volume.max.x" in pb:
        bounds = {"xmin": _number(pb, "volume.min.x", path), "xmax": _number(pb, "volume.max.x", path),
                  "ymin": _number(pb, "volume.min.y", path), "ymax": _number(pb, "volume.max.y", path)}
        bounds_from = "the cfg's volume"
    else:  # OMPL.app infers the bounds from the world's vertices
        lo, hi = world_tri.reshape(-1, 2).min(axis=0), world_tri.reshape(-1, 2).max(axis=0)
        bounds = {"xmin": float(lo[0]), "xmax": float(hi[0]), "ymin": float(lo[1]), "ymax": float(hi[1])}
        bounds_from = "the world mesh's box (no volume in the cfg)"
    holes_dropped = sum(len(h) for _, h in robot_polys)
    if len(robot_polys) == 1:
        robot = {"polygon": robot_polys[0][0].tolist()}
    else:
        robot = {"parts": [{"polygon": s.tolist()} for s, _ in robot_polys]}
    obstacles = []
    for shell, holes in world_polys:
        ob = {"polygon": shell.tolist()}
        if holes:
            ob["holes"] = [h.tolist() for h in holes]
        obstacles.append(ob)
    name = pb.get("name") or os.path.splitext(os.path.basename(path))[0]
    data = {"name": name, "space": "se2", "bounds": bounds, "robot": robot, "obstacles": obstacles,
            "start": pose["start"], "goal": pose["goal"]}
    world_mesh = os.path.join(os.path.dirname(os.path.abspath(path)), pb["world"])
    robot_mesh = os.path.join(os.path.dirname(os.path.abspath(path)), pb["robot"])
    imp = Imported(data, inputs=[path, robot_mesh, world_mesh])
    if options.robot is not None or options.start is not None or options.goal is not None:
        robot_and_queries(imp, options, path)
        imp.data["space"] = "se2"
    control = pb.get("control")
    ignored = sorted(k for k in pb if k not in PROBLEM_KEYS) + [f"[{s}]" for s in cfg if s != "problem"]
    imp.report += [
        f"read {path}: robot {pb['robot']} ({rinfo['triangles']} triangles, {robot_up}), world {pb['world']} "
        f"({winfo['triangles']} triangles, {world_up}); bounds from {bounds_from}",
        f"robot: {len(robot_polys)} polygon{'s' if len(robot_polys) != 1 else ''}, {rinfo['vertices_after']} "
        f"vertices; body frame at the mean of its {len(robot_corners)} mesh vertices "
        f"({center[0]:.9g}, {center[1]:.9g}), as OMPL.app places and turns it",
        f"world: {winfo['vertices_before']} vertices in the union of triangles -> {len(world_polys)} obstacles, "
        f"{winfo['vertices_after']} vertices ({winfo['flat']} flat triangles left out, "
        f"{winfo['holes_filled']} slit holes filled)",
        f"largest change of a boundary by the cleaning: robot {rinfo['max_shift']:.3g}, world {winfo['max_shift']:.3g} "
        "(outward)",
        "space: se2 (start " + ", ".join(f"{pose['start'][k]:g}" for k in ("x", "y", "theta")) + "; goal " +
        ", ".join(f"{pose['goal'][k]:g}" for k in ("x", "y", "theta")) + ")",
    ]
    if control:
        imp.report.append(f"control = {control}: a kinodynamic problem in OMPL.app; imported as its geometric "
                          "SE(2) problem (no dynamics)")
        imp.warnings.append(f"{path}: control: {control} is a kinodynamic problem; planned without its dynamics")
    if ignored:
        imp.report.append("ignored: " + ", ".join(ignored))
    if holes_dropped:
        imp.warnings.append(f"{path}: robot: {holes_dropped} holes in the robot's footprint filled (a robot "
                            "polygon has none)")
    imp.comments += [f"imported from {os.path.basename(path)} (OMPL.app 2-D problem: robot {pb['robot']}, "
                     f"world {pb['world']})",
                     f"robot body frame: mean of its mesh vertices ({float(center[0])!r}, {float(center[1])!r}) in the mesh frame"]
    if control:
        imp.comments.append(f"kinodynamic in OMPL.app (control = {control}): here its geometric SE(2) problem")
    return imp


def mesh_files(path) -> list[str]:
    """The mesh files a cfg names (robot, then world), resolved as :func:`read_mesh` resolves
    them, neither checked nor read: the inputs an output must not overwrite. Reads the cfg
    only (its faults are :class:`ScenarioError` s, as the import's).

    >>> import tempfile
    >>> d = tempfile.mkdtemp(); f = os.path.join(d, "p.cfg")
    >>> _ = open(f, "w").write("[problem]\\nrobot = r.dae\\nworld = /m/w.dae\\n")
    >>> [os.path.relpath(m, d) if not m.startswith("/m") else m for m in mesh_files(f)]
    ['r.dae', '/m/w.dae']
    """
    path = os.fspath(path)
    problem = read_cfg(path).get("problem", {})
    folder = os.path.dirname(os.path.abspath(path))
    return [name if os.path.isabs(name) else os.path.join(folder, name)
            for name in (problem.get(k) for k in ("robot", "world")) if name]
