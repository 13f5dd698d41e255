"""What a COLLADA mesh may ask of the reader: the checks :mod:`cspace.io.importers.omplapp` runs on a
mesh before and while pycollada reads it (issue 36).

- The file: at most :data:`MAX_MESH_BYTES`, well-formed XML with no DOCTYPE (so no entity,
  internal or external, can be declared: no "billion laughs", no quadratic blow-up, no local
  file read into the coordinates), elements nested at most :data:`MAX_XML_DEPTH` deep, no NaN
  in a ``<float_array>`` (pycollada would silently read it as 0). This is
  checked with the standard library's expat before pycollada sees the bytes, so it holds
  whether pycollada parses with lxml or with xml.etree.
- The counts: every ``<vcount>`` at least 3, their sum equal to the corners ``<p>`` gives, every
  index inside its source; checked on the parsed integers, before any polygon is triangulated.
- The scene graph: its node instances and triangles are counted on the graph (each node
  once, shared nodes multiplied) before it is expanded; more than :data:`MAX_INSTANCES` node
  instances or :data:`MAX_TRIANGLES` triangles, a cycle or a nesting deeper than
  :data:`MAX_DEPTH` is refused. Node transforms must be finite.
- The numbers: ``<unit meter>`` in :data:`UNIT_RANGE`; every coordinate (after the unit and
  the transforms) finite and within :data:`MAX_COORD`; and the mesh's size (its extent, or
  its distance from its origin: the world's is 0, the robot's its body frame) at most
  :data:`MAX_RANGE` times its spread (the larger interquartile range of its corners' x and
  y). The footprint's cleaning tolerance grows with the size (:mod:`cspace.io.importers.meshes`), so
  one far triangle would otherwise thicken every wall; the spread is what one triangle
  cannot move.

Each fault is a one-line :class:`cspace.io.scenario.messages.ScenarioError` naming the mesh file,
the element and the fault.
"""
from __future__ import annotations

import numpy as np

from ..scenario.messages import ScenarioError

# A mesh file larger than this is refused before it is read (OMPL.app's meshes are well under
# 1 MiB; 2 million triangles written compactly fit).
MAX_MESH_BYTES = 32 * 2**20
# Elements nested deeper than this (COLLADA needs about 10, plus the nodes).
MAX_XML_DEPTH = 256
# Triangles after the scene graph is expanded (each instance counted), and node instances.
MAX_TRIANGLES = 2_000_000
MAX_INSTANCES = 10_000  # pycollada binds about 1000 instances a second
# Nodes nested (through <node> and <instance_node>) deeper than this.
MAX_DEPTH = 64
# <unit meter>: from a micrometre to a thousand kilometres.
UNIT_RANGE = (1e-6, 1e6)
# The largest |coordinate|, in the scene's units after <unit> and the transforms.
MAX_COORD = 1e6
# The mesh's size over its spread (see above).
MAX_RANGE = 1e3


class _Refused(Exception):
    def __init__(self, field: str, message: str):
        super().__init__(message)
        self.field, self.message = field, message


def check_xml(raw: bytes, mesh: str) -> None:
    """Refuse a DOCTYPE (hence any entity), malformed XML, or nesting over :data:`MAX_XML_DEPTH`,
    with expat (any encoding it reads; nothing is expanded or fetched).

    >>> check_xml(b'<?xml version="1.0"?><!DOCTYPE a [<!ENTITY b "c">]><a>&b;</a>', "m.dae")
    Traceback (most recent call last):
    ...
    cspace.io.scenario.messages.ScenarioError: m.dae: <!DOCTYPE>: a DOCTYPE (here 'a') is refused in a mesh: entities could expand or read files
    """
    from xml.parsers import expat

    parser = expat.ParserCreate()
    depth = [0]

    def doctype(name, *_):
        raise _Refused("<!DOCTYPE>", f"a DOCTYPE (here {name!r}) is refused in a mesh: entities could expand or "
                                     "read files")

    def entity(name, *_):
        raise _Refused("<!ENTITY>", f"an entity declaration ({name!r}) is refused in a mesh")

    array = [None, ""]  # the <float_array> being read (its id), and the tail of its text

    def start(name, attrs):
        depth[0] += 1
        if depth[0] > MAX_XML_DEPTH:
            raise _Refused(f"<{name}>", f"elements nested over {MAX_XML_DEPTH} deep")
        if name.rpartition("}")[2].rpartition(" ")[2] == "float_array":
            array[:] = [str(attrs.get("id", "")), ""]

    def end(_name):
        depth[0] -= 1
        array[0] = None

    def text(data):  # pycollada reads a NaN in a float_array as 0: a silent wrong vertex
        if array[0] is not None:
            chunk = array[1] + data.lower()
            if "nan" in chunk:
                raise _Refused(f"<float_array> {array[0]!r}", "holds a NaN (not a number)")
            array[1] = chunk[-2:]

    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler = entity
    parser.UnparsedEntityDeclHandler = entity
    parser.ExternalEntityRefHandler = lambda *a: entity(a[0])
    parser.StartElementHandler, parser.EndElementHandler = start, end
    parser.CharacterDataHandler, parser.buffer_text = text, True
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    try:
        parser.Parse(raw, True)
    except _Refused as exc:
        raise ScenarioError(mesh, exc.field, exc.message) from None
    except (expat.ExpatError, ValueError, LookupError) as exc:  # LookupError: an unknown encoding name
        raise ScenarioError(mesh, "file", f"not well-formed XML ({exc})") from None


def check_unit(unitmeter, mesh: str) -> float:
    """The ``<unit meter>`` scale: 1 if absent, else within :data:`UNIT_RANGE`.

    >>> check_unit(None, "m.dae"), check_unit(0.0254, "m.dae")
    (1.0, 0.0254)
    """
    if unitmeter is None:
        return 1.0
    u = float(unitmeter)
    if not UNIT_RANGE[0] <= u <= UNIT_RANGE[1]:  # NaN fails too
        raise ScenarioError(mesh, "<unit meter>", f"must be a number from {UNIT_RANGE[0]:g} to {UNIT_RANGE[1]:g}, "
                                                  f"got {u!r}")
    return u


def _geometry_triangles(geometry, mesh: str) -> int:
    """Triangles of a geometry's primitives, their counts and indices checked against the data."""
    from collada.polylist import Polylist
    from collada.triangleset import TriangleSet

    field = f"geometry {str(geometry.id)!r}"
    total = 0
    for prim in geometry.primitives:
        if not isinstance(prim, (Polylist, TriangleSet)) or getattr(prim, "vertex", None) is None:
            continue  # lines and points: no area, never triangulated
        corners = len(prim.vertex_index.reshape(-1))
        if isinstance(prim, Polylist):
            vc = np.asarray(prim.vcounts, dtype=np.int64).reshape(-1)
            if len(vc) and vc.min() < 3:
                raise ScenarioError(mesh, field, f"<vcount> has a polygon of {int(vc.min())} corners (at least 3)")
            declared = int(vc.sum())
            if declared != corners:
                raise ScenarioError(mesh, field, f"<vcount> declares {declared} corners, its <p> gives {corners}")
            total += declared - 2 * len(vc)
        else:
            total += corners // 3
        for what, data, index in (("vertex", prim.vertex, prim.vertex_index),
                                  ("normal", prim.normal, prim.normal_index),
                                  *(("texcoord", d, i) for d, i in zip(prim.texcoordset or (),
                                                                      prim.texcoord_indexset or ()))):
            if data is None or index is None or np.size(index) == 0:
                continue
            lo, hi = int(np.min(index)), int(np.max(index))
            if lo < 0 or hi >= len(data):
                raise ScenarioError(mesh, field, f"a {what} index in <p> ({lo if lo < 0 else hi}) is outside its "
                                                 f"source's {len(data)} entries")
    return total


def check_scene(scene, mesh: str) -> int:
    """Count the triangles the scene places (shared nodes counted once per instance) without
    expanding it; check node transforms. Returns the triangle count."""
    from collada.scene import GeometryNode, Node, NodeNode

    memo: dict[int, tuple[int, int]] = {}  # id(node) -> (instances, triangles)
    geoms: dict[int, int] = {}
    active: set[int] = set()
    shared = [False]

    def visit(node, depth: int) -> tuple[int, int]:
        if depth > MAX_DEPTH:
            raise ScenarioError(mesh, "<node>", f"nodes nested over {MAX_DEPTH} deep")
        if isinstance(node, GeometryNode):
            g = node.geometry
            if id(g) not in geoms:
                geoms[id(g)] = _geometry_triangles(g, mesh)
            return 1, geoms[id(g)]
        if isinstance(node, NodeNode):
            shared[0] = True
            target = node.node
            if id(target) in active:
                raise ScenarioError(mesh, "<instance_node>", f"node {str(target.id)!r} instances itself (a cycle)")
            return visit(target, depth + 1)
        if not isinstance(node, Node):
            return 1, 0  # cameras, lights, controllers: no geometry
        if id(node) in memo:
            return memo[id(node)]
        for t in node.transforms:
            if not np.isfinite(np.asarray(t.matrix, dtype=np.float64)).all():
                tag = str(getattr(getattr(t, "xmlnode", None), "tag", type(t).__name__)).rpartition("}")[2]
                raise ScenarioError(mesh, f"<{tag}>", f"of node {str(node.id)!r} is not finite")
        active.add(id(node))
        n, tri = 1, 0
        for child in node.children:
            a, b = visit(child, depth + 1)
            n, tri = n + a, tri + b
        active.discard(id(node))
        memo[id(node)] = (n, tri)
        return n, tri

    instances = triangles = 0
    for node in scene.nodes:
        a, b = visit(node, 1)
        instances, triangles = instances + a, triangles + b
    field = "<instance_node>" if shared[0] else "triangles"
    if instances > MAX_INSTANCES:
        raise ScenarioError(mesh, field, f"the scene places {instances} node instances, over the limit of "
                                         f"{MAX_INSTANCES}")
    if triangles > MAX_TRIANGLES:
        raise ScenarioError(mesh, field, f"the scene places {triangles} triangles, over the limit of "
                                         f"{MAX_TRIANGLES} (2 million)")
    return triangles


def check_coordinates(tri3: np.ndarray, mesh: str, field: str) -> None:
    """Every coordinate of the (N, 3, 3) triangles of one placed geometry is finite and within
    :data:`MAX_COORD`."""
    if tri3.size == 0:
        return
    bad = ~np.isfinite(tri3)
    if bad.any():
        i = int(np.argwhere(bad)[0][0])
        raise ScenarioError(mesh, field, f"triangle {i} has a coordinate that is not finite "
                                         f"({float(tri3[i][bad[i]][0])!r}) after the unit and node transforms")
    big = np.abs(tri3).max(axis=(1, 2))
    if big.max() > MAX_COORD:
        i = int(np.argmax(big))
        raise ScenarioError(mesh, field, f"triangle {i} reaches {big[i]:.3g}, beyond the +-{MAX_COORD:g} limit on "
                                         "coordinates")


def check_range(tri: np.ndarray, owners: list, origin, mesh: str) -> None:
    """The (N, 3, 2) plane triangles' size (extent, or distance from ``origin``) is at most
    :data:`MAX_RANGE` times their spread; ``owners`` are (first triangle, field) of each part.

    >>> small = np.array([[[0, 0], [1, 0], [0, 1]]] * 5, float)
    >>> check_range(small, [(0, "geometry 'g'")], (0, 0), "m.dae") is None
    True
    >>> check_range(np.concatenate((small, small[:1] + 5e4)), [(0, "geometry 'g'")], (0, 0), "m.dae")
    Traceback (most recent call last):
    ...
    cspace.io.scenario.messages.ScenarioError: m.dae: geometry 'g': the mesh spans 5e+04, 5e+04 times the spread of its vertices (1): over the 1000 limit (the farthest: triangle 5 near (5e+04, 5e+04))
    """
    pts = tri.reshape(-1, 2)
    if len(pts) == 0:
        return
    q1, q3 = np.percentile(pts, [25, 75], axis=0)
    spread = float(max(q3 - q1))
    size = float(max(max(pts.max(axis=0) - pts.min(axis=0)), np.abs(pts - np.asarray(origin)).max()))
    if spread <= 0 or size <= MAX_RANGE * spread:
        return
    med = np.median(pts, axis=0)
    far = int(np.argmax(np.abs(tri - med).max(axis=(1, 2))))
    field = [f for first, f in owners if first <= far][-1]
    x, y = tri[far].mean(axis=0)
    raise ScenarioError(mesh, field, f"the mesh spans {size:.3g}, {size / spread:.3g} times the spread of its vertices "
                                     f"({spread:.3g}): over the {MAX_RANGE:g} limit (the farthest: triangle "
                                     f"{far - [a for a, _ in owners if a <= far][-1]} near ({x:.3g}, {y:.3g}))")
