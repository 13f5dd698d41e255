"""An independent checker of SE(2) "no path" proofs (format ``cspace-se2-proof/1``).

A proof (note se2-exact.md, section 3) cuts the circle of angles into slabs, gives per slab and
robot piece a *core* (inside the turned piece at every angle of the slab) and the components of
POSSIBLE_k = bounds minus the union of O_j (+) (-core); start and goal must lie in components that
the graph of intersecting components of adjacent slabs keeps apart. :func:`check_proof` re-derives
everything it relies on, with none of the project's geometry (nothing from ``cspace.kernel`` or
``cspace.spaces``): an exact orientation predicate of its own (:func:`orient`, ``Fraction`` on the
stored floats), its own core containment test (:func:`core_inside`) and shapely for the polygon
algebra. Steps, in order (the first that fails is reported): format, query, robot, cover, cores,
regions, nodes, edges, separation (see :func:`check_proof`).

Soundness does not rest on the proof's component polygons: they only name the checker's own
components (a one-to-one match); nodes, edges and the search use the recomputed geometry.

Tolerances (each errs toward refusing a proof):

- angles of start/goal equal the scenario's modulo 2 pi within 1e-12 (1 + |theta|); node look-up
  then uses the scenario's angle, and a slab holds it if within ANGLE_SLACK = 1e-9 rad of it;
- cover: exact rational comparisons with bounds of pi: width <= a number below pi/2, last b - first
  a >= a number above 2 pi, and the wrap-around stays below 2 pi (a_{K-1} - a_0, b_{K-1} - b_0);
  all slab angles within +-64 rad;
- cores: each vertex must stay inside each edge half-plane with a margin of CORE_MARGIN = 1e-12
  (|e| |c| + |p| |q|) (e the edge q - p, c the vertex), far above the float error of the sums
  (about 1e-15 of that); the minimum of the sinusoid counts its trough when within 1e-9 rad of the
  slab; anything not finite fails;
- regions: every convex sum is shrunk by SHRINK = 1e-10 M (M the largest coordinate magnitude of
  bounds, obstacles and cores) and the bounds box grown by it, so rounding of the sums and of
  shapely's overlay (snapping works at about 1e-12 of the extent) never closes a passage: the
  recomputed POSSIBLE only grows. Triangles of a non-convex obstacle that the obstacle does not
  cover are dropped (smaller obstacles). A proof component matches a recomputed one when their
  symmetric difference is at most 1e-9 of the bounds' area + 4 SHRINK (both perimeters);
  unlisted recomputed components must be under that area and then join the search as the
  checker's own nodes with their own edges;
- nodes, edges: closures within TOUCH = 1e-9 M of the point or of each other count as touching;
  components of one slab that touch are linked too (the proof's graph only gets more edges).
"""
from __future__ import annotations

import json
import math
from collections import deque
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import shapely

from cspace.io.scenario.files import read_input, utf8_text
from cspace.io.load import ScenarioError, load_scenario
from ..errors import InputError

FORMAT = "cspace-se2-proof/1"
KEYS = ("format", "start", "goal", "bounds", "robot_pieces", "slabs", "start_nodes", "goal_nodes", "edges")
HALF_PI_LO = Fraction("1.5707963267948966192313216916397514")  # < pi/2
TWO_PI_LO = Fraction("6.2831853071795864769252867665590057")  # < 2 pi
TWO_PI_HI = Fraction("6.2831853071795864769252867665590058")  # > 2 pi
TWO_PI = 2.0 * math.pi
MAX_ANGLE = 64.0
QUERY_ANGLE_REL = 1e-12
ANGLE_SLACK = 1e-9
PEAK_SLACK = 1e-9
CORE_MARGIN = 1e-12
SHRINK_REL = 1e-10
TOUCH_REL = 1e-9
MATCH_REL = 1e-9
ERRBOUND = 3.3306690738754716e-16  # Shewchuk's ccwerrboundA


@dataclass(frozen=True)
class CheckResult:
    """The verdict: ``valid``, the step that failed (``"ok"`` when valid) and one line of detail."""

    valid: bool
    step: str
    detail: str


class Refused(Exception):
    """A failed step (internal to :func:`check_proof`)."""

    def __init__(self, step: str, detail: str):
        super().__init__(detail)
        self.step, self.detail = step, detail


def need(ok, step: str, detail: str):
    """Refuse at ``step`` unless ``ok`` (``detail`` is built eagerly: it must not fail)."""
    if not ok:
        raise Refused(step, detail)


def orient(a, b, c) -> int:
    """The exact sign of the turn a -> b -> c (1 left, -1 right, 0 collinear) of float points.

    >>> orient((0, 0), (1, 0), (0, 1)), orient((0.1, 0.1), (0.2, 0.2), (0.3, 0.3))
    (1, 0)
    """
    dl = (b[0] - a[0]) * (c[1] - a[1])
    dr = (b[1] - a[1]) * (c[0] - a[0])
    det, total = dl - dr, abs(dl) + abs(dr)
    if math.isfinite(total) and total > 1e-250 and abs(det) > ERRBOUND * total:
        return 1 if det > 0 else -1
    f = [Fraction(v) for v in (*a, *b, *c)]
    d = (f[2] - f[0]) * (f[5] - f[1]) - (f[3] - f[1]) * (f[4] - f[0])
    return (d > 0) - (d < 0)


def strictly_convex_ccw(pts) -> bool:
    """Whether the ring ``pts`` (not closed) is a strictly convex CCW polygon, decided exactly:
    every turn strictly left and the edge directions going round exactly once."""
    n = len(pts)
    if n < 3 or any(orient(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) <= 0 for i in range(n)):
        return False

    def half(i):  # the sign of a float difference is exact
        dx, dy = pts[(i + 1) % n][0] - pts[i][0], pts[(i + 1) % n][1] - pts[i][1]
        return 0 if dy > 0 or (dy == 0 and dx > 0) else 1

    return sum(half(i) == 1 and half((i + 1) % n) == 0 for i in range(n)) == 1


def in_arc(t: float, a: float, b: float, slack: float) -> bool:
    """Whether the angle t (modulo 2 pi) lies in [a - slack, b + slack]."""
    d = math.fmod(t - a, TWO_PI)
    d = d + TWO_PI if d < 0 else d
    return d <= (b - a) + slack or d >= TWO_PI - slack


def core_inside(core, piece, a: float, b: float):
    """None if every vertex c of ``core`` satisfies R_(-theta) c in ``piece`` (convex, CCW) for
    all theta in [a, b], with the safety margin; else ``(vertex index, edge index)`` of a failure.

    Edge p -> q holds w inside when cross(e, w) + cross(p, q) >= 0 (e = q - p); with w = R_(-theta) c,
    cross(e, w) = |e| |c| sin(gamma - theta - beta), smallest at an end of [a, b] or at its trough."""
    ends = [(math.cos(t), math.sin(t)) for t in (a, b)]
    n = len(piece)
    for j in range(n):
        p, q = piece[j], piece[(j + 1) % n]
        ex, ey = q[0] - p[0], q[1] - p[1]
        pq = p[0] * q[1] - p[1] * q[0]
        ne, beta = math.hypot(ex, ey), math.atan2(ey, ex)
        for i, (cx, cy) in enumerate(core):
            nc = math.hypot(cx, cy)
            low = min(ex * (-cx * s + cy * co) - ey * (cx * co + cy * s) for co, s in ends)
            if nc > 0 and in_arc(math.atan2(cy, cx) - beta + math.pi / 2, a, b, PEAK_SLACK):
                low = min(low, -ne * nc)
            value, margin = low + pq, CORE_MARGIN * (ne * nc + math.hypot(*p) * math.hypot(*q))
            if not (math.isfinite(value) and math.isfinite(margin) and value >= margin):
                return i, j
    return None


def num(x, what: str) -> float:
    """A JSON number that is a finite double (an integer only if a double holds it exactly)."""
    need(isinstance(x, (int, float)) and not isinstance(x, bool), "format", f"{what}: not a number")
    f = float(x) if isinstance(x, float) or abs(x) < 2**1000 else math.inf
    need(math.isfinite(f) and f == x, "format", f"{what}: not a finite double")
    return f


def ring(pts, what: str, allow_empty: bool = False) -> list:
    """A list of >= 3 points [x, y] (a repeated closing point dropped); [] if allowed."""
    need(isinstance(pts, list) and (pts or allow_empty), "format", f"{what}: not a non-empty list of points")
    out = []
    for i, p in enumerate(pts):
        need(isinstance(p, list) and len(p) == 2, "format", f"{what}[{i}]: not a point [x, y]")
        out.append((num(p[0], f"{what}[{i}]"), num(p[1], f"{what}[{i}]")))
    if len(out) > 1 and out[0] == out[-1]:
        out.pop()
    need(not out or len(out) >= 3, "format", f"{what}: fewer than 3 distinct points")
    return out


def index_list(items, what: str, width: int, sizes) -> list:
    need(isinstance(items, list), "format", f"{what}: not a list")
    for i, t in enumerate(items):
        need(isinstance(t, list) and len(t) == width and all(type(v) is int for v in t), "format",
             f"{what}[{i}]: not a list of {width} integers")
        for k, c in zip(t[::2], t[1::2]):
            need(0 <= k < len(sizes) and 0 <= c < sizes[k], "format", f"{what}[{i}]: no component {c} in slab {k}")
        need(width == 2 or t[2] == (t[0] + 1) % len(sizes), "format",
             f"{what}[{i}]: slab {t[-2]} does not follow slab {t[0]}")
    return [tuple(t) for t in items]


def parse(proof) -> dict:
    """Step "format": the proof's fields as floats, point tuples and index tuples."""
    need(isinstance(proof, dict), "format", "the proof is not a JSON object")
    need(set(proof) == set(KEYS), "format", f"keys {sorted(map(str, proof))} are not {sorted(KEYS)}")
    need(proof["format"] == FORMAT, "format", f"format is not {FORMAT!r}")
    out = {}
    for key, n in (("start", 3), ("goal", 3), ("bounds", 4)):
        need(isinstance(proof[key], list) and len(proof[key]) == n, "format", f"{key}: not a list of {n} numbers")
        out[key] = [num(v, key) for v in proof[key]]
    pieces = proof["robot_pieces"]
    need(isinstance(pieces, list) and pieces, "format", "robot_pieces: not a non-empty list")
    out["pieces"] = [ring(p, f"robot_pieces[{i}]") for i, p in enumerate(pieces)]
    need(isinstance(proof["slabs"], list) and proof["slabs"], "format", "slabs: not a non-empty list")
    out["slabs"] = []
    for k, s in enumerate(proof["slabs"]):
        w = f"slabs[{k}]"
        need(isinstance(s, dict) and set(s) == {"a", "b", "cores", "components"}, "format",
             f"{w}: not an object of a, b, cores, components")
        need(isinstance(s["cores"], list) and len(s["cores"]) == len(pieces), "format",
             f"{w}.cores: not one core per robot piece")
        need(isinstance(s["components"], list), "format", f"{w}.components: not a list")
        comps = []
        for c, comp in enumerate(s["components"]):
            need(isinstance(comp, dict) and set(comp) == {"shell", "holes"} and isinstance(comp.get("holes"), list),
                 "format", f"{w}.components[{c}]: not an object of shell and holes")
            comps.append((ring(comp["shell"], f"{w}.components[{c}].shell"),
                          [ring(h, f"{w}.components[{c}].holes[{i}]") for i, h in enumerate(comp["holes"])]))
        out["slabs"].append({"a": num(s["a"], f"{w}.a"), "b": num(s["b"], f"{w}.b"), "components": comps,
                             "cores": [ring(c, f"{w}.cores[{i}]", True) for i, c in enumerate(s["cores"])]})
    sizes = [len(s["components"]) for s in out["slabs"]]
    out["start_nodes"] = index_list(proof["start_nodes"], "start_nodes", 2, sizes)
    out["goal_nodes"] = index_list(proof["goal_nodes"], "goal_nodes", 2, sizes)
    out["edges"] = index_list(proof["edges"], "edges", 4, sizes)
    return out


def check_query(scenario, p: dict, query_index: int):
    """Step "query": an SE(2) scenario; start, goal and bounds equal to the scenario's."""
    need(scenario.rotates, "query", f"the scenario's space is {scenario.space!r}, not a rotating one")
    queries = scenario.all_queries()
    need(0 <= query_index < len(queries), "query", f"no query {query_index} (the scenario has {len(queries)})")
    q = queries[query_index]
    for key, pose in (("start", q.start), ("goal", q.goal)):
        mine = p[key]
        need(mine[:2] == [pose[0], pose[1]], "query", f"{key} {mine[:2]} is not the scenario's {list(pose[:2])}")
        need(abs(math.remainder(mine[2] - pose[2], TWO_PI)) <= QUERY_ANGLE_REL * (1 + abs(mine[2])), "query",
             f"{key} angle {mine[2]} is not the scenario's {pose[2]} modulo 2 pi")
    need(p["bounds"] == [float(v) for v in scenario.bounds], "query",
         f"bounds {p['bounds']} are not the scenario's {list(scenario.bounds)}")
    return q


def check_robot(scenario, pieces):
    """Step "robot": each piece strictly convex CCW and covered by the scenario's robot."""
    need(scenario.robot, "robot", "the scenario's robot is a point")
    parts = [s.to_shapely() for s in scenario.robot]
    for i, piece in enumerate(pieces):
        need(strictly_convex_ccw(piece), "robot", f"robot_pieces[{i}] is not strictly convex and counter-clockwise")
        poly = shapely.Polygon(piece)  # inside one part needs no constructed union
        need(any(part.covers(poly) for part in parts) or shapely.union_all(parts).covers(poly), "robot",
             f"robot_pieces[{i}] is not inside the scenario's robot")


def check_cover(slabs):
    """Step "cover": consecutive slabs of width in (0, pi/2] going once round the circle."""
    for k, s in enumerate(slabs):
        a, b = s["a"], s["b"]
        need(abs(a) <= MAX_ANGLE and abs(b) <= MAX_ANGLE, "cover", f"slab {k}: an angle beyond +-{MAX_ANGLE}")
        need(a < b and Fraction(b) - Fraction(a) <= HALF_PI_LO, "cover", f"slab {k}: width {b - a} is not in (0, pi/2]")
        need(k + 1 == len(slabs) or b == slabs[k + 1]["a"], "cover",
             f"slab {k} ends at {b}, the next does not start there")
    a0, b0, al, bl = (Fraction(v) for v in (slabs[0]["a"], slabs[0]["b"], slabs[-1]["a"], slabs[-1]["b"]))
    need(bl - a0 >= TWO_PI_HI, "cover", f"the slabs cover {float(bl - a0)!r} rad, less than 2 pi")
    need(al - a0 <= TWO_PI_LO and bl - b0 <= TWO_PI_LO, "cover", "the slabs wrap round the circle more than once")


def check_cores(slabs, pieces):
    """Step "cores": every core strictly convex CCW and inside its turned piece on its slab."""
    for k, s in enumerate(slabs):
        for i, core in enumerate(s["cores"]):
            need(not core or strictly_convex_ccw(core), "cores",
                 f"slab {k} piece {i}: the core is not strictly convex and counter-clockwise")
            bad = core_inside(core, pieces[i], s["a"], s["b"]) if core else None
            need(bad is None, "cores", f"slab {k} piece {i}: core vertex {bad and bad[0]} leaves edge "
                                       f"{bad and bad[1]} of the piece turned by some angle in [{s['a']}, {s['b']}]")


def convex_obstacles(scenario) -> list:
    """The obstacles as convex parts (vertex arrays): convex ones as they are, others triangulated."""
    parts = []
    for ob in scenario.obstacles:
        pts = [(float(x), float(y)) for x, y in np.asarray(ob.polygon, dtype=float)]
        if len(pts) > 1 and pts[0] == pts[-1]:
            pts.pop()
        if not len(ob.holes) and (strictly_convex_ccw(pts) or strictly_convex_ccw(pts[::-1])):
            parts.append(np.array(pts))
            continue
        poly = shapely.Polygon(ob.polygon, [h for h in ob.holes])
        tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
        for t in tris[shapely.covers(poly, tris) & (shapely.area(tris) > 0)]:
            parts.append(np.asarray(t.exterior.coords)[:-1])
    return parts


def possible_components(slab, parts, box, shrink) -> list:
    """The components of POSSIBLE for a slab, each sum shrunk by ``shrink``, the box grown by it."""
    coords, index = [], []
    for core in slab["cores"]:
        if core:
            c = np.asarray(core)
            for o in parts:
                coords.append((o[:, None, :] - c[None, :, :]).reshape(-1, 2))
                index.append(len(coords[-1]))
    if not coords:
        return [box]
    points = shapely.multipoints(np.concatenate(coords), indices=np.repeat(np.arange(len(index)), index))
    sums = shapely.buffer(shapely.convex_hull(points), -shrink, join_style="mitre")
    rest = shapely.difference(box, shapely.union_all(sums[~shapely.is_empty(sums)]))
    return [g for g in shapely.get_parts(rest) if g.geom_type == "Polygon" and g.area > 0]


def match(k, slab, comps, tol_area, shrink) -> list:
    """Step "regions" for a slab: for each recomputed component, the proof's index or None."""
    owner, tree = [None] * len(comps), shapely.STRtree(comps)
    for c, (shell, holes) in enumerate(slab["components"]):
        poly = shapely.Polygon(shell, holes)
        need(poly.is_valid, "regions", f"slab {k} component {c} is not a valid polygon")
        hits = [int(r) for r in tree.query(poly, predicate="intersects")
                if poly.area + comps[r].area - 2 * poly.intersection(comps[r]).area
                <= tol_area + 4 * shrink * (poly.length + comps[r].length)]
        need(len(hits) == 1, "regions", f"slab {k} component {c} matches {len(hits)} recomputed components")
        need(owner[hits[0]] is None, "regions", f"slab {k} components {owner[hits[0]]} and {c} are the same")
        owner[hits[0]] = c
    for r, c in enumerate(owner):
        if c is None and comps[r].area > tol_area:
            pt = comps[r].representative_point()
            raise Refused("regions", f"slab {k}: the component at ({pt.x:.6g}, {pt.y:.6g}) of area "
                                     f"{comps[r].area:.3g} is not listed")
    return owner


def regions(scenario, p):
    """Step "regions": the recomputed components per slab, the proof's index of each, the touch distance."""
    xmin, xmax, ymin, ymax = (float(v) for v in scenario.bounds)
    parts = convex_obstacles(scenario)
    scale = max([abs(v) for v in scenario.bounds] + [float(np.abs(o).max()) for o in parts] +
                [abs(v) for s in p["slabs"] for c in s["cores"] for pt in c for v in pt])
    shrink = SHRINK_REL * scale
    box = shapely.box(xmin - shrink, ymin - shrink, xmax + shrink, ymax + shrink)
    comps = [possible_components(s, parts, box, shrink) for s in p["slabs"]]
    tol_area = MATCH_REL * (xmax - xmin) * (ymax - ymin)
    return comps, [match(k, s, comps[k], tol_area, shrink) for k, s in enumerate(p["slabs"])], TOUCH_REL * scale


def check_proof(scenario, proof: dict, query_index: int = 0) -> CheckResult:
    """Check a proof that no path joins query ``query_index`` of ``scenario`` (a loaded
    :class:`cspace.io.load.Scenario`): the first failing step, or ``valid`` (step ``"ok"``)."""
    step = "format"
    try:
        p = parse(proof)
        step = "query"
        q = check_query(scenario, p, query_index)
        step = "robot"
        check_robot(scenario, p["pieces"])
        step = "cover"
        check_cover(p["slabs"])
        step = "cores"
        check_cores(p["slabs"], p["pieces"])
        step = "regions"
        comps, owners, touch = regions(scenario, p)

        def node(k, r):  # the proof's node, or the checker's own for an unlisted sliver
            return (k, owners[k][r]) if owners[k][r] is not None else ("own", k, r)

        step, ends, graph = "nodes", {}, {}
        for key, pose, listed in (("start", q.start, p["start_nodes"]), ("goal", q.goal, p["goal_nodes"])):
            point, found = shapely.Point(pose[0], pose[1]), set()
            for k, s in enumerate(p["slabs"]):
                if in_arc(pose[2], s["a"], s["b"], ANGLE_SLACK):
                    found |= {node(k, r) for r, g in enumerate(comps[k]) if shapely.dwithin(g, point, touch)}
            need(found, "nodes", f"the {key} lies in no component of POSSIBLE")
            missing = sorted(n for n in found if n[0] != "own" and n not in set(listed))
            need(not missing, "nodes",
                 f"{key}_nodes lacks {list(missing[0]) if missing else ''}, a component holding the {key}")
            ends[key] = set(listed) | found
        step, given, extra = "edges", set(p["edges"]), []
        for k in range(len(comps)):
            for k2 in (k, (k + 1) % len(comps)):  # the same slab (the checker's own links), the next one
                if comps[k] and comps[k2]:
                    left, right = shapely.STRtree(comps[k2]).query(comps[k], predicate="dwithin", distance=touch)
                    for u, v in ((node(k, r), node(k2, r2)) for r, r2 in zip(left.tolist(), right.tolist())):
                        if k2 == k or "own" in (u[0], v[0]):
                            extra.append((u, v))
                        else:
                            need((*u, *v) in given, "edges", f"edges lacks {[*u, *v]}: the components touch")
        step = "separation"
        for u, v in extra + [((k, c), (k2, c2)) for k, c, k2, c2 in given]:
            graph.setdefault(u, set()).add(v)
            graph.setdefault(v, set()).add(u)
        seen, todo = set(ends["start"]), deque(ends["start"])
        while todo:
            for v in graph.get(todo.popleft(), ()):
                if v not in seen:
                    seen.add(v)
                    todo.append(v)
        hit = sorted(seen & ends["goal"], key=repr)
        need(not hit, "separation", f"goal node {list(hit[0]) if hit else ''} is reachable from the start")
        return CheckResult(True, "ok", f"{len(comps)} slabs, {sum(map(len, comps))} components, {len(given)} "
                                       "edges; no start node reaches a goal node")
    except Refused as r:
        return CheckResult(False, r.step, r.detail)
    except Exception as exc:  # a checker never accepts what it could not check
        return CheckResult(False, step, f"could not be checked ({type(exc).__name__}: {exc})"[:300])


def load_proof(path) -> dict:
    """The proof in the JSON file ``path``: a regular file within the size limit, UTF-8, strict
    JSON (no NaN or Infinity), an object; any fault is one :class:`InputError` line."""
    try:
        text = utf8_text(read_input(path), str(path))
    except ScenarioError as exc:
        raise InputError(exc.file, exc.field, exc.message.replace("scenario file", "proof file")) from None

    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    try:
        proof = json.loads(text, parse_constant=refuse)
    except (ValueError, RecursionError) as exc:  # JSONDecodeError is a ValueError
        raise InputError(str(path), "json", f"invalid JSON ({str(exc) or type(exc).__name__})") from None
    if not isinstance(proof, dict):
        raise InputError(str(path), "json", "the proof is not a JSON object")
    return proof
