"""Exact shortest paths for a translating robot: A* over the reduced visibility graph.

The free C-space is F = B − int(∪ C_i): the bounds B minus the interior of the union
of the C-obstacle pieces. The shortest start–goal path in the closure of F is a
polygonal chain that bends only at reflex vertices of F (convex corners of the
obstacle union), and each of its inner edges is *bitangent*: the line through it
touches the obstacle at both ends without entering it (Lozano-Pérez & Wesley 1979;
Latombe, ch. 4). So the graph has the reflex vertices plus start and goal as nodes
and the bitangent segments as edges.

Search (:func:`cspace.paths.visibility.mesh_astar`): A* with the Euclidean heuristic over
that graph, where a node's edges are computed only when it is settled, by exact
triangular expansion in a verified constrained triangulation of F
(:mod:`cspace.paths.freemesh`), inside the node's two tangent wedges. The visibility
region of a corner in a maze is a few triangles, so OMPL's env2 (4647 reflex
corners) takes about a second, not minutes. Zero-area pieces (outside F's area) or
a triangulation that fails its exact checks use the older lazy search
(:mod:`cspace.paths.shortest_lazy`: every bitangent candidate pushed, each tested with
GEOS's ``covers`` when popped), which gives the same lengths. ``time_limit`` bounds
either search and says so when it stops. Queries on the same pieces and bounds
share F, its corners and its mesh (the 64 most recent scenes, keyed by content:
the exact SE(2) planner translates in one slab's scene after another).

``method="channel"`` asks for a certified short path instead, for callers that shorten
it themselves: the shortest path within a channel of mesh triangles
(:mod:`cspace.paths.channel`), checked exactly like the others.

Tolerance: F's vertices come from GEOS's union, whose new vertices (edge crossings
of overlapping pieces) are rounded to doubles; the length is exact for that F,
within ~1e-15 relative of the true one. Start and goal are connected iff they lie
in the same polygon of F, so an unsolvable query is *proven* unsolvable.
"""
from __future__ import annotations

import collections
import gc
import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..kernel.minkowski.union import union


@dataclass
class ShortestPath:
    """The result of :func:`shortest_path`. ``path`` runs from start to goal."""

    solved: bool
    path: np.ndarray
    length: float
    proven_unsolvable: bool = False
    stats: dict = field(default_factory=dict)


def free_space(pieces: list, bounds, checked: bool = True) -> "object":
    """The free C-space F = bounds minus the union of the pieces, a shapely geometry.
    ``checked=False``: GEOS's union as it comes, without its check (:mod:`cspace.kernel.minkowski.union`),
    for a caller that certifies every point and path it takes from F exactly against the pieces
    and states nothing from F's shape alone.

    >>> F = free_space([np.array([[1., 1], [2, 1], [2, 2], [1, 2]])], (0, 3, 0, 3))
    >>> F.area
    8.0
    """
    import shapely

    from .pathcheck import split_pieces

    xmin, xmax, ymin, ymax = map(float, bounds)
    box = shapely.box(xmin, ymin, xmax, ymax)
    # Zero-area pieces (points, segments) have no area to subtract: they are handled
    # by the search (cspace.paths.pathcheck.Degenerate), not here.
    proper = split_pieces(pieces)[0]
    if not proper:
        return box
    # every piece at once: one array of rings (each closed by its first vertex), then polygons
    closed = [np.vstack([p, p[:1]]) for p in proper]
    rings = shapely.linearrings(np.concatenate(closed), indices=np.repeat(np.arange(len(closed)),
                                                                            [len(c) for c in closed]))
    polys = shapely.polygons(rings)
    # checked (cspace.kernel.minkowski.union): GEOS's float overlay can drop a piece
    taken = union(polys) if checked else shapely.union_all(polys)
    return shapely.orient_polygons(box.difference(taken)) if hasattr(shapely, "orient_polygons") \
        else _orient(box.difference(taken))


def _orient(geom):
    import shapely
    from shapely.geometry.polygon import orient

    parts = [orient(p, 1.0) for p in shapely.get_parts(geom) if p.geom_type == "Polygon"]
    return shapely.MultiPolygon(parts) if len(parts) != 1 else parts[0]


def shortest_path(pieces: list, bounds, start, goal, time_limit: float | None = None,
                  on_progress: Callable[[int, int, float], None] | None = None,
                  method: str = "auto", free: list | None = None) -> ShortestPath:
    """The shortest path from start to goal through the free C-space.

    ``method``: "auto" (the mesh search, the lazy one where there is no mesh), "mesh", "lazy",
    or "channel": a certified short path, not always the shortest, for callers that shorten it
    themselves: the shortest path inside the triangle channel that A* over F's mesh picks
    (:mod:`cspace.paths.channel`; a large open map in milliseconds, where the visibility search
    settles hundreds of corners), checked exactly like the others; where there is no mesh, or its
    path fails the check, the "auto" search. ``length`` is then that path's length.
    ``free``: the polygons of F (as :func:`free_space` makes them for these pieces and bounds)
    when the caller has them, used instead of a new union where the scene is not cached
    (every path is still checked against the pieces themselves).
    ``time_limit`` (seconds) bounds the search: past it the result is unsolved with
    ``stats["reason"] == "time limit"`` (never a silent wrong answer, never a hang).
    ``on_progress(settled, nodes, bound)``, when given, is called every
    :data:`PROGRESS_EVERY` settled nodes and once at the end: nodes settled so far,
    nodes of the graph, and a lower bound on the shortest length (the f value of the
    last settled node, which never decreases with a consistent heuristic).

    >>> sq = np.array([[1., 0], [2, 0], [2, 2], [1, 2]])
    >>> sp = shortest_path([sq], (0, 3, 0, 3), (0, 1), (3, 1))
    >>> sp.solved, round(sp.length, 12), sp.path.tolist()
    (True, 3.828427124746, [[0.0, 1.0], [1.0, 2.0], [2.0, 2.0], [3.0, 1.0]])
    >>> calls = []
    >>> _ = shortest_path([sq], (0, 3, 0, 3), (0, 1), (3, 1), on_progress=lambda *a: calls.append(a))
    >>> calls[-1][:2], round(calls[-1][2], 12)  # all 4 nodes settled; the bound reached the length
    ((4, 4), 3.828427124746)
    """
    if method not in ("auto", "mesh", "lazy", "channel"):
        raise ValueError(f"shortest_path: method: expected 'auto', 'mesh', 'lazy' or 'channel', got {method!r}")

    # The search makes many small tuples and no cycles: the cyclic collector, which would
    # rescan them over and over (~15 % of the time), is paused while it runs.
    paused = gc.isenabled()
    gc.disable()
    try:
        return _shortest(pieces, bounds, start, goal, time_limit, on_progress, method, free)
    finally:
        if paused:
            gc.enable()


def _shortest(pieces, bounds, start, goal, time_limit, on_progress, method, free) -> ShortestPath:
    from .pathcheck import Degenerate, path_violations, split_pieces
    from ..kernel.polygons.polygon import as_array
    from .shortest_lazy import lazy_astar

    t0 = time.perf_counter()
    pieces = [as_array(p, copy=False, nonempty=True) for p in pieces]  # the one input gate: finite (N, 2) reals
    s, g = _point(start, "start"), _point(goal, "goal")
    bounds = tuple(_point(bounds[:2], "bounds")) + tuple(_point(bounds[2:], "bounds"))
    scene = _scene(pieces, bounds, free)
    parts = scene.parts
    comp_s, comp_g = _components(parts, s, g)
    stats = {"counts": {"free_components": len(parts)}}
    degenerate = split_pieces(pieces)[1]
    deg = Degenerate(degenerate, parts[comp_s] if comp_s is not None else None) if degenerate else None
    if comp_s is None or comp_g is None or (deg is not None and (deg.contains(s) or deg.contains(g))):
        stats["reason"] = "start or goal is not in the free C-space"
        stats["time"] = time.perf_counter() - t0
        return ShortestPath(False, np.zeros((0, 2)), math.inf, False, stats)
    if comp_s != comp_g:
        stats["reason"] = "start and goal lie in different free components"
        stats["time"] = time.perf_counter() - t0
        return ShortestPath(False, np.zeros((0, 2)), math.inf, True, stats)
    region = parts[comp_s]
    if s == g:
        return ShortestPath(True, np.array([s]), 0.0, False, {**stats, "time": time.perf_counter() - t0})
    nodes, tangent_dirs = scene.reflex(comp_s)
    if deg is not None:  # the free tips of zero-area pieces: the path may bend around them
        stats["counts"]["degenerate_pieces"] = len(degenerate)
        for tip in deg.wraps:
            nodes.append(tip)
            tangent_dirs.append((np.array(tip), np.array(tip)))  # any direction is tangent
    pts = np.array([s, g] + nodes, dtype=np.float64).reshape(-1, 2)
    deadline = None if time_limit is None else t0 + float(time_limit)
    path = None
    if method == "channel" and deg is None:
        found = _channel(scene, comp_s, s, g, pieces, bounds, deadline)
        if found is not None:
            stats["method"] = "channel"
            stats["counts"]["corners"] = len(found) - 2
            stats["time"] = time.perf_counter() - t0
            return ShortestPath(True, found, float(np.hypot(*np.diff(found, axis=0).T).sum()), False, stats)
    if method != "lazy" and deg is None:  # zero-area pieces are outside F's mesh: the lazy search
        from .freemesh import MeshError
        from .visibility import mesh_astar

        try:
            mesh = scene.mesh(comp_s)
        except MeshError as exc:  # GEOS's triangulation failed an exact check
            stats["mesh_error"] = str(exc)
        else:
            path, length, counts = mesh_astar(mesh, pts, tangent_dirs, deadline, on_progress, PROGRESS_EVERY)
            stats["method"] = "mesh"
    if "method" not in stats:
        if method == "mesh":
            raise ValueError(f"shortest_path: no mesh search here ({stats.get('mesh_error', 'zero-area pieces')})")
        path, length, counts = lazy_astar(pts, tangent_dirs, region, deadline, on_progress, deg, PROGRESS_EVERY)
        stats["method"] = "lazy"
    stats["counts"].update(counts, nodes=len(pts))
    stats["time"] = time.perf_counter() - t0
    if path is None:  # a connected region has a path, unless zero-area pieces cut it
        stats["reason"] = stats["counts"].pop("stopped", "search exhausted")
        return ShortestPath(False, np.zeros((0, 2)), math.inf, False, stats)
    # The answer must agree with the pieces' own exact predicates, segment by segment.
    bad = path_violations(pts[path], pieces, bounds)
    if bad:
        stats["reason"] = f"the path failed the exact check against the pieces (edge {bad[0][0]}, piece {bad[0][1]})"
        return ShortestPath(False, np.zeros((0, 2)), math.inf, False, stats)
    return ShortestPath(True, pts[path], length, False, stats)


def _components(parts: list, s: tuple, g: tuple) -> tuple:
    """The indices of F's components (closed: a boundary point counts) holding s and g (None: in
    no component, so not in the free C-space)."""
    import shapely

    ps, pg = shapely.Point(s), shapely.Point(g)
    return (next((k for k, p in enumerate(parts) if p.covers(ps)), None),
            next((k for k, p in enumerate(parts) if p.covers(pg)), None))


def separated(pieces: list, bounds, start, goal) -> bool:
    """Do start and goal lie in different components of the free C-space F (a proof that no
    path joins them, the one :func:`shortest_path` gives)? Builds F only (no reflex corners,
    no mesh; kept for the searches on the same pieces). False when they share a component or
    one of them is not free.

    >>> wall = np.array([[1., 0], [2, 0], [2, 3], [1, 3]])
    >>> separated([wall], (0, 3, 0, 3), (0.5, 1), (2.5, 1)), separated([wall], (0, 3, 0, 4), (0.5, 1), (2.5, 1))
    (True, False)
    """
    from ..kernel.polygons.polygon import as_array

    pieces = [as_array(p, copy=False, nonempty=True) for p in pieces]
    s, g = _point(start, "start"), _point(goal, "goal")
    bounds = tuple(_point(bounds[:2], "bounds")) + tuple(_point(bounds[2:], "bounds"))
    comp_s, comp_g = _components(_scene(pieces, bounds).parts, s, g)
    return comp_s is not None and comp_g is not None and comp_s != comp_g


def _channel(scene, comp: int, s, g, pieces, bounds, deadline) -> np.ndarray | None:
    """The channel path (:func:`cspace.paths.channel.channel_path`) in component ``comp``, if
    there is a mesh and the path passes the exact check against the pieces; else None."""
    from .channel import channel_path
    from .freemesh import MeshError
    from .pathcheck import path_violations

    try:
        mesh = scene.mesh(comp)
    except MeshError:
        return None
    found = channel_path(mesh, s, g, deadline)
    if found is None:
        return None
    pts = np.array(found, dtype=np.float64)
    return None if path_violations(pts, pieces, bounds) else pts


class _Scene:
    """F's components for one set of pieces and bounds, with each component's reflex
    corners and mesh made on first use (queries on one C-space share them)."""

    def __init__(self, pieces: list, bounds: tuple, free: list | None = None):
        import shapely

        parts = shapely.get_parts(free_space(pieces, bounds)) if free is None else free
        self.parts = [p for p in parts if p.geom_type == "Polygon" and not p.is_empty]
        for p in self.parts:
            shapely.prepare(p)
        self._reflex: dict = {}
        self._mesh: dict = {}

    def reflex(self, k: int) -> tuple[list, list]:
        if k not in self._reflex:
            self._reflex[k] = _reflex_vertices(self.parts[k])
        nodes, nbrs = self._reflex[k]
        return list(nodes), list(nbrs)  # callers append the tips of zero-area pieces

    def mesh(self, k: int):
        from .freemesh import FreeMesh, MeshError

        if k not in self._mesh:
            try:
                self._mesh[k] = FreeMesh(self.parts[k])
            except MeshError as exc:
                self._mesh[k] = exc
        if isinstance(self._mesh[k], MeshError):
            raise self._mesh[k]
        return self._mesh[k]


# The scenes searched lately, most recent last, keyed by content. More than one: the exact SE(2)
# planner translates inside the slabs of one scene in turn (8 slabs or more per query), and each
# slab's pieces are another scene; a cache of one rebuilt F and its mesh at every slab change.
_SCENES: "collections.OrderedDict[bytes, _Scene]" = collections.OrderedDict()
SCENES_KEPT = 64


def _scene(pieces: list, bounds: tuple, free: list | None = None) -> _Scene:
    """The :class:`_Scene` of these pieces and bounds, reused when a recent call had the same
    ones (compared by content: a digest of every coordinate and piece size); the
    :data:`SCENES_KEPT` most recently used are kept."""
    import hashlib

    h = hashlib.blake2b(np.asarray(bounds, dtype=np.float64).tobytes(), digest_size=20)
    h.update(np.array([len(p) for p in pieces], dtype=np.int64).tobytes())
    for p in pieces:
        h.update(np.ascontiguousarray(p, dtype=np.float64).tobytes())
    key = h.digest()
    scene = _SCENES.get(key)
    if scene is None:
        scene = _SCENES[key] = _Scene(pieces, bounds, free)
        while len(_SCENES) > SCENES_KEPT:
            _SCENES.popitem(last=False)
    else:
        _SCENES.move_to_end(key)
    return scene


def warm(pieces: list, bounds, free: list | None = None) -> int:
    """Build and keep F of these pieces and bounds and every component's mesh (``free``: F's
    polygons, when the caller has them), so that the next searches on them pay for neither;
    returns the number of meshes built (a component GEOS cannot mesh keeps the lazy search).

    >>> warm([np.array([[1., 1], [2, 1], [2, 2], [1, 2]])], (0, 3, 0, 3))
    1
    """
    from .freemesh import MeshError

    scene = _scene([np.asarray(p, dtype=np.float64) for p in pieces], tuple(map(float, bounds)), free)
    built = 0
    for k in range(len(scene.parts)):
        try:
            scene.mesh(k)
            built += 1
        except MeshError:
            pass
    return built


def clear_cache() -> None:
    """Forget the scenes' F and meshes (benchmarks time the preparation with it).

    >>> clear_cache()
    """
    _SCENES.clear()


def _point(p, what: str) -> tuple[float, float]:
    """(x, y) as two finite floats, else ValueError (NaN and inf never reach the search)."""
    from ..kernel.polygons.polygon import as_point

    try:
        return as_point(p)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"shortest_path: {what}: {exc}") from None


def _reflex_vertices(region) -> tuple[list, list]:
    """Reflex vertices of F (free side on the left of every ring) and their two edges.

    For each vertex v with ring neighbours a (before) and b (after), a right turn
    a -> v -> b means F's interior angle at v exceeds pi: an obstacle corner the
    shortest path can wrap around. The neighbours are kept for the tangency test.
    """
    from .freemesh import ring_turns

    C, prev, nxt, turn, _ = ring_turns(region)
    # Exterior rings of F are CCW and holes CW (orient_polygons), so F is on the left.
    k = np.flatnonzero(turn < 0)
    nodes = [tuple(v) for v in C[k].tolist()]
    nbrs = list(zip(map(tuple, C[prev[k]].tolist()), map(tuple, C[nxt[k]].tolist())))
    return nodes, nbrs


PROGRESS_EVERY = 64  # settled nodes between two progress reports


