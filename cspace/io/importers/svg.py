"""SVG drawings (Bench-MR's polygon worlds, Inkscape files) as scenarios, and an SVG path as a robot.

Every drawn ``<path>`` is an obstacle: its path data (:mod:`cspace.io.importers.svg_path`:
lines absolute and relative, several subpaths, curves refused unless flattened) mapped by
the ``transform`` of the path and of every group above it, then into the plane with y
pointing up: (x, y) in the drawing's user units becomes (x, -y), as Bench-MR reads its
files (``SvgPolygonLoader``: the group's translation added, y negated; the root
``viewBox`` and the ``mm`` page size are not applied), so its published start and goal
poses land where its paper puts them. A path's filled area follows its ``fill-rule``
(nonzero by default, evenodd): subpaths nested with opposite turns are holes, crossing
rings are split at their crossings and each face kept by its winding number. With
``convex_hulls`` each path is replaced by the convex hull of its points, as Bench-MR does
with every non-convex polygon. The bounds are the obstacles' box, as Bench-MR sets them.

Paths under ``<defs>``, ``<clipPath>``, ``<mask>``, ``<marker>``, ``<pattern>``,
``<symbol>`` or outside the SVG namespace are not drawn and not read; other shapes
(``<rect>``, ``<circle>``, ``<use>``...) are not read either, and a warning counts them.

The file is read with expat, refusing any DOCTYPE (hence every entity: nothing expands or
is fetched), nesting over :data:`MAX_DEPTH`, and malformed XML; a fault is one
:class:`ScenarioError` line naming the file and the element (``path 'id'``).
"""
from __future__ import annotations

import os
import re

import numpy as np

from ..scenario.files import read_input
from ..scenario.messages import ScenarioError
from ..scenario.schema import MAX_MAGNITUDE
from .import_record import Imported, ImportOptions, robot_and_queries
from .svg_path import PathDataError, apply, parse_path, parse_transform

SVG_NS = "http://www.w3.org/2000/svg"
MAX_DEPTH = 256
NOT_DRAWN = {"defs", "clipPath", "mask", "marker", "pattern", "symbol", "metadata", "title", "desc", "style",
             "script", "linearGradient", "radialGradient", "filter", "font", "foreignObject"}
OTHER_SHAPES = {"rect", "circle", "ellipse", "line", "polyline", "polygon", "use", "text", "image"}
FLIP = np.diag([1.0, -1.0, 1.0])  # y up: Bench-MR's reading of a drawing
_FILL_RULE = re.compile(r"(?:^|;)\s*fill-rule\s*:\s*([a-z]+)")


class _Refused(Exception):
    def __init__(self, field: str, message: str):
        super().__init__(message)
        self.field, self.message = field, message


def read_drawing(raw: bytes, path: str) -> tuple[list[dict], dict]:
    """The drawn paths of an SVG file, in document order: ``{"name", "d", "matrix", "fill_rule"}``
    (``matrix``: the path's transform and its groups', composed, y flipped), and the counts of
    what was not read (``{element: count}``).

    >>> paths, skipped = read_drawing(b'<svg xmlns="http://www.w3.org/2000/svg"><g transform="translate(1,2)">'
    ...                               b'<path id="a" d="m 0,0 h 1 v 1 z"/><rect/></g></svg>', "w.svg")
    >>> paths[0]["name"], paths[0]["matrix"].tolist(), skipped
    ("path 'a'", [[1.0, 0.0, 1.0], [0.0, -1.0, -2.0], [0.0, 0.0, 1.0]], {'rect': 1})
    """
    from xml.parsers import expat

    parser = expat.ParserCreate(namespace_separator=" ")
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[tuple[np.ndarray, str, bool]] = [(FLIP, "nonzero", True)]  # matrix, fill rule, drawn
    paths: list[dict] = []
    skipped: dict[str, int] = {}
    count: dict[str, int] = {}  # elements of each kind so far: an unnamed one is named by its rank and line

    def doctype(name, *_):
        raise _Refused("<!DOCTYPE>", f"a DOCTYPE (here {name!r}) is refused: entities could expand or read files")

    def entity(name, *_):
        raise _Refused("<!ENTITY>", f"an entity declaration ({name!r}) is refused")

    def start(name, attrs):
        ns, _, local = name.rpartition(" ")
        matrix, rule, drawn = stack[-1]
        count[local] = count.get(local, 0) + 1
        if len(stack) > MAX_DEPTH:
            raise _Refused(f"<{local}>", f"elements nested over {MAX_DEPTH} deep")
        label = _label(local, attrs, count[local], parser.CurrentLineNumber)
        drawn = drawn and ns in ("", SVG_NS) and local not in NOT_DRAWN
        if drawn and local == "svg" and len(stack) > 1:
            raise _Refused(label, "a nested <svg> (its own viewport) is not read: draw its paths in the main one")
        if drawn and "transform" in attrs:
            try:
                matrix = matrix @ parse_transform(attrs["transform"])
            except PathDataError as exc:
                raise _Refused(label, str(exc)) from None
        rule = _fill_rule(attrs, rule)
        if drawn and local == "path":
            paths.append({"name": label, "d": attrs.get("d", ""), "matrix": matrix, "fill_rule": rule})
        elif drawn and local in OTHER_SHAPES:
            skipped[local] = skipped.get(local, 0) + 1
        elif not drawn and local == "path":
            skipped["path (not drawn)"] = skipped.get("path (not drawn)", 0) + 1
        stack.append((matrix, rule, drawn))

    def end(_name):
        stack.pop()

    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler = entity
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(raw, True)
    except _Refused as exc:
        raise ScenarioError(path, exc.field, exc.message) from None
    except expat.ExpatError as exc:
        raise ScenarioError(path, f"line {exc.lineno}", f"not well-formed XML ({expat.errors.messages[exc.code]})"
                            ) from None
    return paths, skipped


def _label(local: str, attrs: dict, n: int, line: int) -> str:
    """How a message names an element: by its id, else as the n-th of its kind, at its line.

    >>> _label("path", {"id": "wall"}, 3, 9), _label("path", {}, 3, 9)
    ("path 'wall'", 'path #3 (line 9)')
    """
    ident = attrs.get("id")
    return f"{local} {ident[:60]!r}" if ident else f"{local} #{n} (line {line})"


def _fill_rule(attrs: dict, inherited: str) -> str:
    rule = attrs.get("fill-rule")
    m = _FILL_RULE.search(attrs.get("style", ""))
    if m:
        rule = m.group(1)
    return rule if rule in ("nonzero", "evenodd") else inherited


def path_shapes(p: dict, path: str, flatten: float | None, hull: bool):
    """One drawn path as shapely polygons (its filled area, or the hull of its points), its
    points as Bench-MR lists them (the ends of its moves and lines, mapped) and its number of
    curves flattened. Faults name the file and the path."""
    import shapely

    m = p["matrix"]
    norm = float(np.linalg.norm(m[:2, :2], 2))
    try:
        subs, ends, curves = parse_path(p["d"], flatten, norm)
    except PathDataError as exc:
        raise ScenarioError(path, p["name"], str(exc)) from None
    rings = [apply(m, s) for s in subs]
    ends = apply(m, ends)
    pts = np.concatenate(rings) if rings else np.zeros((0, 2))
    if len(pts) and not (np.isfinite(pts).all() and np.abs(pts).max() <= MAX_MAGNITUDE):
        raise ScenarioError(path, p["name"], "a coordinate beyond the supported magnitude 2^400 once transformed")
    if hull:
        geom = shapely.convex_hull(shapely.multipoints(pts)) if len(pts) else shapely.Polygon()
    else:
        geom = filled_area(rings, p["fill_rule"])
    if curves and flatten:  # chords cut inside a convex bulge: grown by the tolerance, the curve is inside
        geom = shapely.buffer(geom, flatten, join_style="mitre", mitre_limit=2.0)
    polys = [g for g in _polygons(geom) if g.area > 0]
    if not polys:
        raise ScenarioError(path, p["name"], f"covers no area ({len(pts)} points on a line or a point): an "
                                             "obstacle is an area")
    return polys, ends, curves


def filled_area(rings: list[np.ndarray], rule: str = "nonzero"):
    """The area the rings fill under an SVG fill rule: a single simple ring is its polygon;
    otherwise the rings' edges are split at their crossings and each face is kept when its
    winding number is nonzero (``"nonzero"``) or odd (``"evenodd"``).

    >>> sq = lambda a, b: np.array([[a, a], [b, a], [b, b], [a, b]], float)
    >>> filled_area([sq(0, 4), sq(1, 2)[::-1]]).area, filled_area([sq(0, 4), sq(1, 2)]).area
    (15.0, 16.0)
    >>> filled_area([sq(0, 4), sq(1, 2)], "evenodd").area
    15.0
    """
    import shapely

    rings = [r for r in rings if len(r) >= 3]
    if not rings:
        return shapely.Polygon()
    if len(rings) == 1:
        poly = shapely.Polygon(rings[0])
        if poly.is_valid:
            return poly
    lines = shapely.union_all([shapely.LineString(np.vstack((r, r[:1]))) for r in rings])
    faces = list(shapely.get_parts(shapely.polygonize(shapely.get_parts(lines))))
    keep = []
    for f in faces:
        q = np.asarray(shapely.point_on_surface(f).coords)[0]
        w = sum(winding(q, r) for r in rings)
        if (w % 2 == 1) if rule == "evenodd" else (w != 0):
            keep.append(f)
    return shapely.union_all(keep) if keep else shapely.Polygon()


def winding(q: np.ndarray, ring: np.ndarray) -> int:
    """The winding number of a closed ring about a point not on it (crossings of the ray to +x).

    >>> winding(np.array([0.5, 0.5]), np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float))
    1
    """
    a, b = ring, np.roll(ring, -1, axis=0)
    up = (a[:, 1] <= q[1]) & (b[:, 1] > q[1])
    down = (a[:, 1] > q[1]) & (b[:, 1] <= q[1])
    side = (b[:, 0] - a[:, 0]) * (q[1] - a[:, 1]) - (q[0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    return int(np.sum(up & (side > 0)) - np.sum(down & (side < 0)))


def _polygons(geom) -> list:
    return list(geom.geoms) if hasattr(geom, "geoms") else [geom]


def _ring(coords) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in np.asarray(coords)[:-1]]


def read_svg(path: str) -> tuple[list[dict], dict]:
    """The drawn paths of an SVG file (:func:`read_drawing`), the file read within the size limit."""
    raw = read_input(path)
    if not raw.strip():
        raise ScenarioError(path, "file", "empty: an SVG drawing is an XML file")
    return read_drawing(raw, path)


def import_svg(path: str, options: ImportOptions) -> Imported:
    """An SVG drawing as a scenario dict: every drawn path an obstacle, y up, bounds the obstacles' box.

    >>> import tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "w.svg")
    >>> _ = open(f, "w").write('<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0,0 H 4 V 4 H 0 Z '
    ...                        'M 1,1 V 3 H 3 V 1 Z"/></svg>')
    >>> imp = import_svg(f, ImportOptions(start=(0.5, -0.5), goal=(1.5, -1.5)))
    >>> imp.data["bounds"], len(imp.data["obstacles"][0]["holes"])
    ({'xmin': 0.0, 'xmax': 4.0, 'ymin': -4.0, 'ymax': 0.0}, 1)
    """
    path = os.fspath(path)
    paths, skipped = read_svg(path)
    if not paths:
        raise ScenarioError(path, "path", "no drawn <path> in the file: every path is an obstacle")
    obstacles, curves, nonconvex = [], 0, 0
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for p in paths:
        polys, _, n = path_shapes(p, path, options.flatten_curves, options.convex_hulls)
        curves += n
        for g in polys:
            ob = {"polygon": _ring(g.exterior.coords)}
            if g.interiors:
                ob["holes"] = [_ring(r.coords) for r in g.interiors]
            obstacles.append(ob)
            b = np.asarray(g.bounds)
            lo, hi = np.minimum(lo, b[:2]), np.maximum(hi, b[2:])
            nonconvex += (not options.convex_hulls) and g.area < g.convex_hull.area
    bounds = {"xmin": float(lo[0]), "xmax": float(hi[0]), "ymin": float(lo[1]), "ymax": float(hi[1])}
    data = {"name": os.path.splitext(os.path.basename(path))[0], "bounds": bounds, "obstacles": obstacles}
    imp = Imported(data, inputs=[path])
    robot_and_queries(imp, options, path)
    grown = _extend(bounds, [imp.data["start"], imp.data["goal"]])
    verts = sum(len(o["polygon"]) + sum(len(h) for h in o.get("holes", [])) for o in obstacles)
    shape = ("convex hulls of the paths (--convex-hulls, as Bench-MR)" if options.convex_hulls else
             f"true shapes ({nonconvex} non-convex; --convex-hulls for Bench-MR's hulls)")
    imp.report += [
        f"read {path}: {len(paths)} drawn paths -> {len(obstacles)} obstacles, {verts} vertices; {shape}",
        "frame: the drawing's user units, y up (x, -y), as Bench-MR reads it; bounds the obstacles' box"
        f"{' and the start and goal' if grown else ''} x [{bounds['xmin']:.6g}, {bounds['xmax']:.6g}], "
        f"y [{bounds['ymin']:.6g}, {bounds['ymax']:.6g}]",
    ]
    if curves:
        imp.report.append(f"curves: {curves} flattened within {options.flatten_curves:g} (the obstacles grown by "
                          "that much contain them)")
    if skipped:
        imp.warnings.append(f"{path}: not read: " + ", ".join(f"{n} <{k}>" if not k.startswith("path ")
                                                              else f"{n} {k}" for k, n in skipped.items())
                            + " (only drawn <path> elements are obstacles)")
    imp.comments += [f"imported from {os.path.basename(path)} (SVG drawing: every path an obstacle, y up as "
                     "Bench-MR reads it)"]
    return imp


def _extend(bounds: dict, poses: list) -> bool:
    """Grow ``bounds`` (in place) to hold the poses' points; whether it grew. Bench-MR's
    bounds are the obstacles' box, and some of its published poses lie just outside it."""
    grew = False
    for pose in poses:
        for k, lo, hi in (("x", "xmin", "xmax"), ("y", "ymin", "ymax")):
            v = float(pose[k])
            if v < bounds[lo] or v > bounds[hi]:
                bounds[lo], bounds[hi], grew = min(bounds[lo], v), max(bounds[hi], v), True
    return grew


def svg_robot(path: str, convex_hull: bool = False, flatten: float | None = None) -> tuple[dict, np.ndarray, list]:
    """The robot of an SVG file: its first drawn path, centred on the mean of that path's points
    as Bench-MR centres its robot (the ends of its moves and lines, repeats included); a
    ``[robot]`` table, that centre (in the drawing's y-up frame) and warnings.

    >>> import tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "car.svg")
    >>> _ = open(f, "w").write('<svg xmlns="http://www.w3.org/2000/svg"><path d="m 1,1 h 4 v 2 h -4 z"/></svg>')
    >>> robot, centre, _ = svg_robot(f)
    >>> sorted(map(tuple, robot["polygon"])), centre.tolist()
    ([(-2.0, -1.0), (-2.0, 1.0), (2.0, -1.0), (2.0, 1.0)], [3.0, -2.0])
    """
    path = os.fspath(path)
    paths, _ = read_svg(path)
    if not paths:
        raise ScenarioError(path, "path", "no drawn <path>: the robot is the file's first path")
    polys, ends, _ = path_shapes(paths[0], path, flatten, convex_hull)
    centre = ends.mean(axis=0)
    warnings = []
    if any(g.interiors for g in polys):
        warnings.append(f"{path}: {paths[0]['name']}: holes in the robot filled (a robot polygon has none)")
    parts = [(np.asarray(g.exterior.coords)[:-1] - centre).tolist() for g in polys]
    robot = {"polygon": parts[0]} if len(parts) == 1 else {"parts": [{"polygon": q} for q in parts]}
    return robot, centre, warnings
