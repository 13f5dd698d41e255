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

Tolerances: one unit u = 2^-40 S shared with the planner (:mod:`planners.core.proof_geometry`
has the table); each errs toward refusing a proof:

- angles of start/goal equal the scenario's modulo 2 pi within 1e-12 (1 + |theta|); node look-up
  then uses the scenario's angle, and a slab holds it if within ANGLE_SLACK = 1e-9 rad of it;
- cover: exact rational comparisons with bounds of pi: width <= a number below pi/2, last b - first
  a >= a number above 2 pi, and the wrap-around stays below 2 pi (a_{K-1} - a_0, b_{K-1} - b_0);
  all slab angles within +-64 rad;
- robot: pieces covered by the robot's polygons, or strictly inside one of its TRUE disks (exact);
- cores: each vertex at least u inside the piece turned by every angle of its slab
  (:func:`planners.core.proof_geometry.core_inside`, O((n + m) log(n + m)));
- regions: obstacles as written (a disk by a polygon inside it, checked exactly); the union of the
  convex sums eroded by 16 u and the bounds box grown by it; a proof component matches a recomputed one when
  their symmetric difference is at most 1e-9 of the bounds' area + 256 u (both perimeters); a
  proof component may match none (the planner's POSSIBLE is the larger: a sliver only it has), and a
  recomputed one that lies in a listed one (which the checker's smaller POSSIBLE split) takes its node;
  unlisted recomputed components must be under that area and then join the search as the
  checker's own nodes with their own edges; regions are built and matched slab by slab;
- nodes, edges: closures within 512 u of the point or of each other count as touching;
  components of one slab that touch are linked too (the proof's graph only gets more edges).

Work is bounded before it is done (:data:`LIMITS`, what the planner can write): slabs, robot
pieces and their vertices, core vertices, component vertices per slab against the recomputed
ones, edges against the components (adjacent slabs' components form a planar bipartite graph:
fewer than 2 edges a component); a file's lists and numbers are counted before JSON is parsed.
Past a limit: a one-line refusal (``cspace check-proof``: exit 2).
"""
from __future__ import annotations

import itertools
import json
import math
from collections import deque
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import shapely

from cspace.io.scenario.files import read_input, utf8_text
from cspace.io.load import ScenarioError, load_scenario  # noqa: F401  (re-exported)
from ..errors import InputError
from .proof_geometry import (ANGLE_SLACK, MATCH_UNITS, SHRINK_UNITS, TOUCH_UNITS, Graph, Obstacles, Piece,
                             convex_obstacles,  # noqa: F401
                             core_inside, in_arc, in_disk, orient, possible_components, scene_unit,
                             strictly_convex_ccw)  # (orient: re-exported for the tests and callers)

FORMAT = "cspace-se2-proof/1"
KEYS = ("format", "start", "goal", "bounds", "robot_pieces", "slabs", "start_nodes", "goal_nodes", "edges")
HALF_PI_LO = Fraction("1.5707963267948966192313216916397514")  # < pi/2
TWO_PI_LO = Fraction("6.2831853071795864769252867665590057")  # < 2 pi
TWO_PI_HI = Fraction("6.2831853071795864769252867665590058")  # > 2 pi
TWO_PI = 2.0 * math.pi
MAX_ANGLE = 64.0
QUERY_ANGLE_REL = 1e-12
MATCH_REL = 1e-9
# What the planner can write (cspace.se2.exact): at most 4096 slabs (its floor keeps fewer), robot
# pieces of at most 256 vertices (cspace.io.scenario.schema.MAX_ROTATING_VERTICES) and no more
# pieces than the robot has vertices, cores of at most 3 n + 4 vertices (three half-planes per
# edge of an n-gon piece, clipped from a box; 3 n + 1024 allowed, for cores built otherwise); a slab's components have at most 4x the vertices
# of the recomputed ones + 1024; a file at most 2 million lists and 6 million values.
# The regions' work: slabs x (obstacle vertices + the slab's core vertices + 64, its fixed cost),
# at most 600 000 (about 7 s of one core: 4096 slabs of a small scene, 420 slabs of 800-gon
# cores, or 500 slabs of a 1 000-vertex scene).
LIMITS = {"slabs": 4096, "piece_vertices": 256, "file_lists": 2_000_000, "file_values": 6_000_000,
          "work": 600_000}


class TooBig(Exception):
    """A proof asking for more work than any the planner writes (one line; exit 2)."""


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


def num(x, what: str) -> float:
    """A JSON number that is a finite double (an integer only if a double holds it exactly)."""
    need(isinstance(x, (int, float)) and not isinstance(x, bool), "format", f"{what}: not a number")
    f = float(x) if isinstance(x, float) or abs(x) < 2**1000 else math.inf
    need(math.isfinite(f) and f == x, "format", f"{what}: not a finite double")
    return f


def ring(pts, what: str, allow_empty: bool = False) -> list:
    """A list of >= 3 points [x, y] (a repeated closing point dropped); [] if allowed."""
    need(isinstance(pts, list) and (pts or allow_empty), "format", f"{what}: not a non-empty list of points")
    out = _plain_ring(pts)
    for i, p in enumerate(pts if out is None else ()):  # one number at a time: to name the fault
        if i == 0:
            out = []
        need(isinstance(p, list) and len(p) == 2, "format", f"{what}[{i}]: not a point [x, y]")
        out.append((num(p[0], f"{what}[{i}]"), num(p[1], f"{what}[{i}]")))
    out = out or []
    if len(out) > 1 and out[0] == out[-1]:
        out.pop()
    need(not out or len(out) >= 3, "format", f"{what}: fewer than 3 distinct points")
    return out


def _plain_ring(pts) -> list | None:
    """The points as float pairs when every one is a list of two finite floats (the JSON a
    planner writes), read in a few passes at C speed; None for anything else (then read one by one)."""
    if not pts or set(map(type, pts)) != {list} or set(map(len, pts)) != {2}:
        return None
    flat = list(itertools.chain.from_iterable(pts))
    if set(map(type, flat)) != {float} or not np.isfinite(np.array(flat)).all():
        return None
    return list(map(tuple, pts))


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


def parse_header(proof, keys, fmt: str) -> dict:
    """Step "format", what every proof format shares: a JSON object of exactly ``keys`` in format
    ``fmt``; its start, goal and bounds as floats, its robot pieces as rings."""
    need(isinstance(proof, dict), "format", "the proof is not a JSON object")
    need(set(proof) == set(keys), "format", f"keys {sorted(map(str, proof))} are not {sorted(keys)}")
    need(proof["format"] == fmt, "format", f"format is not {fmt!r}")
    out = {}
    for key, n in (("start", 3), ("goal", 3), ("bounds", 4)):
        need(isinstance(proof[key], list) and len(proof[key]) == n, "format", f"{key}: not a list of {n} numbers")
        out[key] = [num(v, key) for v in proof[key]]
    pieces = proof["robot_pieces"]
    need(isinstance(pieces, list) and pieces, "format", "robot_pieces: not a non-empty list")
    out["pieces"] = [ring(p, f"robot_pieces[{i}]") for i, p in enumerate(pieces)]
    return out


def parse(proof) -> dict:
    """Step "format": the proof's fields as floats, point tuples and index tuples."""
    out = parse_header(proof, KEYS, FORMAT)
    pieces = proof["robot_pieces"]
    big = max(len(p) for p in out["pieces"])
    if big > LIMITS["piece_vertices"]:
        raise TooBig(f"a robot piece of {big} vertices (the planner's have at most {LIMITS['piece_vertices']})")
    need(isinstance(proof["slabs"], list) and proof["slabs"], "format", "slabs: not a non-empty list")
    if len(proof["slabs"]) > LIMITS["slabs"]:
        raise TooBig(f"{len(proof['slabs'])} slabs (the planner writes at most {LIMITS['slabs']})")
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
        cores = [ring(c, f"{w}.cores[{i}]", True) for i, c in enumerate(s["cores"])]
        for i, c in enumerate(cores):
            if len(c) > 3 * len(out["pieces"][i]) + 1024:
                raise TooBig(f"{w}.cores[{i}] has {len(c)} vertices (the planner's core of a "
                             f"{len(out['pieces'][i])}-gon has at most {3 * len(out['pieces'][i]) + 4}; "
                             f"allowed: {3 * len(out['pieces'][i]) + 1024})")
        out["slabs"].append({"a": num(s["a"], f"{w}.a"), "b": num(s["b"], f"{w}.b"), "components": comps,
                             "cores": cores})
    sizes = [len(s["components"]) for s in out["slabs"]]
    for key in ("edges", "start_nodes", "goal_nodes"):  # a planar graph has fewer than 2 edges a node
        if isinstance(proof[key], list) and len(proof[key]) > 2 * sum(sizes) + 8:
            raise TooBig(f"{len(proof[key])} {key} for {sum(sizes)} components (at most {2 * sum(sizes) + 8})")
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
    """Step "robot": each piece strictly convex CCW and inside the scenario's robot as written:
    covered by its polygon parts, or strictly inside one of its disks (the true disk, decided
    exactly: a disk part's polygon circumscribes it)."""
    need(scenario.robot, "robot", "the scenario's robot is a point")
    most = sum(len(s.polygon) for s in scenario.robot)
    if len(pieces) > most:
        raise TooBig(f"{len(pieces)} robot pieces (the robot has {most} vertices: at most as many convex pieces)")
    polys = [s.to_shapely() for s in scenario.robot if s.disk is None]
    disks = [s.disk for s in scenario.robot if s.disk is not None]
    for i, piece in enumerate(pieces):
        need(strictly_convex_ccw(piece), "robot", f"robot_pieces[{i}] is not strictly convex and counter-clockwise")
        poly = shapely.Polygon(piece)  # inside one part needs no constructed union
        need(any(in_disk(piece, d) for d in disks) or any(part.covers(poly) for part in polys)
             or (len(polys) > 1 and shapely.union_all(polys).covers(poly)), "robot",
             f"robot_pieces[{i}] is not inside the scenario's robot")


def check_cover(slabs):
    """Step "cover": consecutive slabs of width in [0, pi/2] going once round the circle (a zero-width
    slab [phi, phi] is a single angle: a path crossing phi is in it and in both its neighbours)."""
    for k, s in enumerate(slabs):
        a, b = s["a"], s["b"]
        need(abs(a) <= MAX_ANGLE and abs(b) <= MAX_ANGLE, "cover", f"slab {k}: an angle beyond +-{MAX_ANGLE}")
        need(a <= b and Fraction(b) - Fraction(a) <= HALF_PI_LO, "cover", f"slab {k}: width {b - a} is not in [0, pi/2]")
        need(k + 1 == len(slabs) or b == slabs[k + 1]["a"], "cover",
             f"slab {k} ends at {b}, the next does not start there")
    a0, b0, al, bl = (Fraction(v) for v in (slabs[0]["a"], slabs[0]["b"], slabs[-1]["a"], slabs[-1]["b"]))
    need(bl - a0 >= TWO_PI_HI, "cover", f"the slabs cover {float(bl - a0)!r} rad, less than 2 pi")
    need(al - a0 <= TWO_PI_LO and bl - b0 <= TWO_PI_LO, "cover", "the slabs wrap round the circle more than once")


def check_cores(slabs, pieces, unit: float):
    """Step "cores": every core strictly convex CCW and at least ``unit`` inside its turned piece
    on its slab (:func:`planners.core.proof_geometry.core_inside`)."""
    prepared = [Piece(p) for p in pieces]
    for k, s in enumerate(slabs):
        for i, core in enumerate(s["cores"]):
            need(not core or strictly_convex_ccw(core), "cores",
                 f"slab {k} piece {i}: the core is not strictly convex and counter-clockwise")
            bad = core_inside(core, prepared[i], s["a"], s["b"], unit) if core else None
            need(bad is None, "cores", f"slab {k} piece {i}: core vertex {bad} leaves the piece turned by some "
                                       f"angle in [{s['a']}, {s['b']}] (or comes within {unit:.3g} of its edges)")


def match(k, slab, comps, tol_area, band) -> list:
    """Step "regions" for a slab: for each recomputed component, the proof's index or None."""
    n_mine = sum(len(g.exterior.coords) + sum(len(r.coords) for r in g.interiors) for g in comps)
    n_given = sum(len(sh) + sum(map(len, hs)) for sh, hs in slab["components"])
    if n_given > 4 * n_mine + 1024:
        raise TooBig(f"slab {k}: components of {n_given} vertices where the scene's have {n_mine}")
    owner, tree, polys = [None] * len(comps), shapely.STRtree(comps), []
    for c, (shell, holes) in enumerate(slab["components"]):
        poly = shapely.polygons(shapely.linearrings(shell), [shapely.linearrings(h) for h in holes] or None)
        need(poly.is_valid, "regions", f"slab {k} component {c} is not a valid polygon")
        polys.append(poly)
        hits = [int(r) for r in tree.query(poly, predicate="intersects")
                if poly.area + comps[r].area - 2 * poly.intersection(comps[r]).area
                <= tol_area + band * (poly.length + comps[r].length)]
        # none: a component the planner's larger POSSIBLE has (cores shrunk by 64 u, not 16) and
        # the checker's has not: a node no recomputed component needs (the search ignores it)
        need(len(hits) <= 1, "regions", f"slab {k} component {c} matches {len(hits)} recomputed components")
        if not hits:
            continue
        need(owner[hits[0]] is None, "regions", f"slab {k} components {owner[hits[0]]} and {c} are the same")
        owner[hits[0]] = c
    ptree = shapely.STRtree(polys) if polys else None
    for r, c in enumerate(owner):
        if c is not None or comps[r].area <= tol_area:
            continue
        # a piece of a listed component that the checker's smaller POSSIBLE cut off: it joins that
        # component's node (more links, never fewer: the search can only find more paths)
        inside = [int(i) for i in (ptree.query(comps[r], predicate="intersects") if ptree else [])
                  if comps[r].area - polys[i].intersection(comps[r]).area <= tol_area + band * comps[r].length]
        if inside:
            owner[r] = min(inside)
            continue
        pt = comps[r].representative_point()
        raise Refused("regions", f"slab {k}: the component at ({pt.x:.6g}, {pt.y:.6g}) of area "
                                 f"{comps[r].area:.3g} is not listed")
    return owner



def regions(scenario, p, q, unit):
    """Steps "regions", "nodes" and "edges": each slab's POSSIBLE recomputed, matched and linked to
    the previous slab's (then dropped); the graph for the separation step."""
    xmin, xmax, ymin, ymax = (float(v) for v in scenario.bounds)
    parts = Obstacles(convex_obstacles(scenario))
    shrink = SHRINK_UNITS * unit
    box = shapely.box(xmin - shrink, ymin - shrink, xmax + shrink, ymax + shrink)
    tol_area = MATCH_REL * (xmax - xmin) * (ymax - ymin)
    graph, K = Graph(p, q, TOUCH_UNITS * unit), len(p["slabs"])
    first = prev = None
    for k, s in enumerate(p["slabs"]):
        comps = possible_components(s["cores"], parts, box, shrink)
        node = graph.slab(k, comps, match(k, s, comps, tol_area, MATCH_UNITS * unit))
        graph.link(k, comps, node, k, comps, node)
        if prev is not None:
            graph.link(k - 1, prev[0], prev[1], k, comps, node)
        prev = (comps, node)
        first = first or prev
    if K > 1:
        graph.link(K - 1, prev[0], prev[1], 0, first[0], first[1])
    return graph


def proof_work(obstacles, slabs) -> int:
    """The regions' work a proof asks for: slabs x (obstacle vertices + the slab's core vertices + 64).

    >>> proof_work([[(0, 0), (1, 0), (0, 1)]], [{"cores": [[(0, 0)] * 5]}] * 2)
    144
    """
    n = sum(map(len, obstacles))
    return sum(n + sum(map(len, s["cores"])) + 64 for s in slabs)


def check_proof(scenario, proof: dict, query_index: int = 0) -> CheckResult:
    """Check a proof that no path joins query ``query_index`` of ``scenario`` (a loaded
    :class:`cspace.io.load.Scenario`): the first failing step, or ``valid`` (step ``"ok"``).
    A proof asking for more work than the planner's can (:data:`LIMITS`) raises :class:`TooBig`."""
    def steps(at: list) -> CheckResult:
        p = parse(proof)
        obstacles = convex_obstacles(scenario)
        work = proof_work(obstacles, p["slabs"])
        if work > LIMITS["work"]:
            raise TooBig(f"{len(p['slabs'])} slabs over {sum(map(len, obstacles))} obstacle vertices: {work} units "
                         f"of work (at most {LIMITS['work']})")
        q, unit = shared_steps(scenario, p, query_index, obstacles, p["slabs"], at)
        at[0] = "regions"
        graph = regions(scenario, p, q, unit)
        at[0] = "nodes"
        for key in ("start", "goal"):
            need(graph.ends[key], "nodes", f"the {key} lies in no component of POSSIBLE")
        for step in ("nodes", "edges"):
            at[0] = step
            need(step not in graph.faults, step, graph.faults.get(step, ""))
        ends = {key: set(p[f"{key}_nodes"]) | graph.ends[key] for key in ("start", "goal")}
        at[0], adj = "separation", {}
        for u, v in graph.extra + [((k, c), (k2, c2)) for k, c, k2, c2 in graph.given]:
            adj.setdefault(u, set()).add(v)
            adj.setdefault(v, set()).add(u)
        seen, todo = set(ends["start"]), deque(ends["start"])
        while todo:
            for v in adj.get(todo.popleft(), ()):
                if v not in seen:
                    seen.add(v)
                    todo.append(v)
        hit = sorted(seen & ends["goal"], key=repr)
        need(not hit, "separation", f"goal node {list(hit[0]) if hit else ''} is reachable from the start")
        n_comps = sum(len(s["components"]) for s in p["slabs"])
        return CheckResult(True, "ok", f"{len(p['slabs'])} slabs, {n_comps} components, {len(graph.given)} "
                                       "edges; no start node reaches a goal node")

    return run_steps(steps)


def shared_steps(scenario, p: dict, query_index: int, obstacles, cored: list, at: list) -> tuple:
    """Steps "query", "robot", "cover" and "cores", as every proof format has them (``cored``: the
    slabs whose cores are given); ``at[0]`` follows the step. The query's poses and the unit."""
    at[0] = "query"
    q = check_query(scenario, p, query_index)
    at[0] = "robot"
    check_robot(scenario, p["pieces"])
    at[0] = "cover"
    check_cover(p["slabs"])
    unit = scene_unit(scenario.bounds, obstacles, p["pieces"])
    at[0] = "cores"
    check_cores(cored, p["pieces"], unit)
    return q, unit


def run_steps(steps) -> CheckResult:
    """A checker's steps, ``steps(at)`` (``at[0]``: the step it is at): a refusal names its step,
    a proof past the limits raises :class:`TooBig`, and anything else it could not check is not
    accepted (a checker never accepts what it could not check)."""
    at = ["format"]
    try:
        return steps(at)
    except TooBig:
        raise
    except Refused as r:
        return CheckResult(False, r.step, r.detail)
    except MemoryError:
        raise TooBig("more memory than the machine has") from None
    except Exception as exc:
        return CheckResult(False, at[0], f"could not be checked ({type(exc).__name__}: {exc})"[:300])


def load_proof(path) -> dict:
    """The proof in the JSON file ``path``: a regular file within the size limit, UTF-8, strict
    JSON (no NaN or Infinity), an object; any fault is one :class:`InputError` line."""
    try:
        text = utf8_text(read_input(path), str(path))
    except ScenarioError as exc:
        raise InputError(exc.file, exc.field, exc.message.replace("scenario file", "proof file")) from None

    lists, values = text.count("["), text.count(",")
    if lists > LIMITS["file_lists"] or values > LIMITS["file_values"]:
        raise InputError(str(path), "size", f"{lists} lists and {values} commas: more than any proof the planner "
                                            f"writes (at most {LIMITS['file_lists']} and {LIMITS['file_values']})")

    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    try:
        proof = json.loads(text, parse_constant=refuse)
    except (ValueError, RecursionError) as exc:  # JSONDecodeError is a ValueError
        raise InputError(str(path), "json", f"invalid JSON ({str(exc) or type(exc).__name__})") from None
    if not isinstance(proof, dict):
        raise InputError(str(path), "json", "the proof is not a JSON object")
    return proof
