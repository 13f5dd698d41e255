"""A deterministic exact SE(2) planner: the slab graph (note se2-exact.md, sections 2-4).

The circle of angles [−π, π] is cut into slabs (8 equal ones first). For each slab,
:class:`cspace.se2.slab_graph.SlabRegions` gives FREE (reference points free at every
angle of the slab) and POSSIBLE (every free pose of the slab has its (x, y) there), as
polygons with holes, and their connected components.

- FREE graph: nodes (slab, component); components of adjacent slabs are linked when they
  overlap with an interior (the robot turns in place at a point deep inside the overlap,
  through the shared boundary angle). The start pose joins the FREE component of a slab
  holding θs that contains its (x, y) (free at every angle of the slab); where none does,
  it joins through the FREE region at its own angle (a zero-width slab): its component
  there is linked to the FREE components of the slab(s) holding θs that overlap it. The
  goal likewise. A walk from start to goal is a certified path: translations at a fixed angle
  (short paths inside one component, checked exactly: :mod:`cspace.se2.exact_path`) and rotations in place.
- POSSIBLE graph: nodes (slab, component); components of adjacent slabs are linked when their
  closures meet (within a tolerance, toward more links); start and goal belong to every
  POSSIBLE component of their slab(s) whose closure is within the tolerance of their (x, y).
  If no walk joins them, no collision-free path exists at any resolution: the proof.
- Each round builds FREE first and stops at its walk; POSSIBLE is built, and the proof
  looked for, only when FREE does not join start and goal.
- Otherwise slabs are bisected: those on a cheapest POSSIBLE walk from start to goal whose
  nodes or links FREE does not yet reproduce ("FREE breaks there"), else those anywhere in
  the start's POSSIBLE component where it breaks, else all (slabs on the cheapest walk even below
  the floor, to 2^-6 of it). After two rounds, zero-width slabs at the critical angles (a robot
  edge parallel to an obstacle edge, :mod:`cspace.se2.critical`: a door just wider than the robot)
  and at the start's and goal's own angles (a translation at an end's angle through a passage no
  slab's FREE holds) join the partition. The search stops at ``min_width`` or at ``time_limit``
  (checked before every region is built): "undecided", with the resolution D = r·Δmax + the
  margin's reach + the disks' polygon error (no path with clearance above D exists, since such a
  path would lie in FREE; note section 4, :mod:`cspace.se2.exact_report`).

Angles are OMPL's, wrapped to [−π, π); a pose on the boundary ±π belongs to the first and
the last slab. Nothing depends on randomness or on the iteration order of a set.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..kernel.polygons.rotation import TWO_PI, wrap_angle
from .slab_graph import SlabRegions, point_free
from .exact_path import AssemblyError, assemble, holding
from .critical import bisected, critical_angles, initial_partition, with_zero_slabs  # noqa: F401 (initial_partition: the API)
from .exact_report import PROOF_FORMAT, disk_excess, margin_reach, proof_json, resolution  # noqa: F401
from ..kernel.slabs.slab import ANGLE_SLACK
from .walks import G_NODE, S_NODE, cheapest_walk, labels, reach, shortest_walk

# A proof's start and goal join the POSSIBLE components of every slab within this many radians of
# their angle (more nodes: a weaker claim), 10 x the independent checker's angle tolerance.
ANGLE_NEAR = 1e-8
NO_PROOF_FOUND = "POSSIBLE graph only: no proof found"  # the reason a proof-only search ends without one


@dataclass
class SE2ExactResult:
    """What :func:`exact_se2_search` found. ``status``: "solved" (``path``, an (N, 3) array of
    poses; consecutive poses differ only in position or only in angle), "unsolvable"
    (``proof``) or "undecided" (``resolution``: no path with clearance above it exists).
    ``length``: the path's length in (x, y); ``rotation``: its total turning (radians)."""

    status: str
    path: np.ndarray | None = None
    length: float = math.inf
    rotation: float = math.inf
    resolution: float = math.inf
    stats: dict = field(default_factory=dict)
    proof: dict | None = None


class _Timeout(Exception):
    pass


def exact_se2_search(obstacle_pieces: list, robot_pieces: list, bounds, start, goal, *,
                     time_limit: float | None = None, min_width: float = TWO_PI / 2048, initial_slabs: int = 8,
                     margin: list | None = None, possible_only: bool = False, refine: bool = True,
                     regions: SlabRegions | None = None, inner_obstacles: list | None = None,
                     inner_robot: list | None = None, excess: float = 0.0, near: bool = False) -> SE2ExactResult:
    """Plan for a robot of convex ``robot_pieces`` (body frame) among convex ``obstacle_pieces``:
    a certified path, a proof that none exists, or "undecided" at the resolution reached.

    ``bounds`` = (xmin, xmax, ymin, ymax) of the reference point; ``start``, ``goal`` = (x, y, θ).
    ``margin``: convex operands the robot is inflated by for the path (a clearance); the proof
    is made for the body itself (a stronger statement). ``possible_only``: look for a proof
    only (no FREE regions, no path: a car, or the check before sampling); its refinement
    bisects every slab; ``refine=False`` stops after the first partition ("undecided").
    ``regions``: a :class:`SlabRegions` of the same pieces, bounds and margin from an earlier
    search (its regions and links are cached: queries on one scene share them).
    ``inner_obstacles``, ``inner_robot``: convex pieces INSIDE the scene's shapes as written
    (a disk's inscribed polygon where ``obstacle_pieces`` / ``robot_pieces`` hold its
    circumscribed one): POSSIBLE and the proof are built of them, so that a proof holds for the
    disks themselves (None: the same pieces, polygons only); ``excess``: their polygons' error,
    for the resolution statement. ``near``: a walk's link points moved where the path is first
    (:func:`cspace.se2.exact_path.near_links`; its own points where that assembly fails).

    >>> wall = [np.array([[4., 0], [5, 0], [5, 4], [4, 4]]), np.array([[4., 6], [5, 6], [5, 10], [4, 10]])]
    >>> bar = [np.array([[-1.5, -0.2], [1.5, -0.2], [1.5, 0.2], [-1.5, 0.2]])]
    >>> r = exact_se2_search(wall, bar, (0, 10, 0, 10), (2, 5, math.pi / 2), (8, 5, math.pi / 2))
    >>> r.status, r.path[0].tolist(), r.path[-1].tolist()
    ('solved', [2.0, 5.0, 1.5707963267948966], [8.0, 5.0, 1.5707963267948966])
    >>> exact_se2_search(wall, [np.array([[-1.2, -1.2], [1.2, -1.2], [1.2, 1.2], [-1.2, 1.2]])], (0, 10, 0, 10),
    ...                  (2, 5, 0.0), (8, 5, 0.0)).status
    'unsolvable'
    """
    if isinstance(initial_slabs, bool) or not isinstance(initial_slabs, int) or initial_slabs < 8:
        raise ValueError(f"exact_se2_search: initial_slabs must be an integer >= 8 (slabs of at most pi/4), "
                         f"got {initial_slabs!r}")
    robot = [np.asarray(p, dtype=np.float64) for p in robot_pieces]
    if not robot:
        raise ValueError("exact_se2_search: needs a robot of at least one convex piece (a point robot does not turn)")
    if regions is None:
        regions = slab_regions(obstacle_pieces, robot, bounds, margin, inner_obstacles=inner_obstacles,
                               inner_robot=inner_robot, excess=excess)
    search = _Search(regions, start, goal, time_limit, float(min_width), initial_slabs)
    search.possible_only, search.refine, search.near = bool(possible_only), bool(refine), bool(near)
    return search.run()


def slab_regions(obstacle_pieces: list, robot_pieces: list, bounds, margin: list | None = None, *,
                 inner_obstacles: list | None = None, inner_robot: list | None = None,
                 excess: float = 0.0) -> SlabRegions:
    """The :class:`SlabRegions` :func:`exact_se2_search` works on (FREE with the robot inflated by
    ``margin``, POSSIBLE with the body, of the ``inner_*`` pieces if given), to keep and pass to
    several searches. ``excess``: the disks' circumscribed-polygon error (robot's + obstacles'),
    which the resolution statement adds (:func:`cspace.se2.exact_report.disk_excess`)."""
    robot = [np.asarray(p, dtype=np.float64) for p in robot_pieces]
    hull = None
    if margin:
        from ..translation.build import inflated

        hull = inflated(robot, [np.asarray(m, dtype=np.float64) for m in margin])
    out = SlabRegions(obstacle_pieces, robot, bounds, hull_pieces=hull, inner_obstacles=inner_obstacles,
                      inner_robot=inner_robot)
    out.margin_reach, out.excess = margin_reach(margin), float(excess)
    return out


def from_scenario(scenario, query_index: int = 0, **kwargs) -> SE2ExactResult:
    """:func:`exact_se2_search` on a loaded scenario (or a file path), query ``query_index``
    of ``scenario.all_queries()``; keyword arguments are passed on.

    >>> import os, tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "s.toml")
    >>> _ = open(f, "w").write('space = "se2"\\n[bounds]\\nxmin=0\\nxmax=4\\nymin=0\\nymax=4\\n'
    ...     "[start]\\nx=0.5\\ny=0.5\\n[goal]\\nx=3.5\\ny=3.5\\n[robot]\\npolygon=[[0,0],[0.2,0],[0,0.2]]\\n"
    ...     "[[obstacles]]\\npolygon=[[1,1],[3,1],[3,3],[1,3]]\\n")
    >>> from_scenario(f).status
    'solved'
    """
    from ..io.load import load_scenario
    from ..io.scenario.schema import Scenario
    from ..translation.build import decompose_obstacles, decompose_robot, inner_pieces

    sc = scenario if isinstance(scenario, Scenario) else load_scenario(str(scenario))
    if not sc.rotates:
        raise ValueError(f"from_scenario: the scenario's space is {sc.space!r}, not a rotating one")
    obstacles, _, _ = decompose_obstacles([o.polygon for o in sc.obstacles], [o.holes for o in sc.obstacles],
                                          convex=[o.convex for o in sc.obstacles])
    robot, _ = decompose_robot([r.polygon for r in sc.robot], sc.robot_kind == "disk")
    q = sc.all_queries()[query_index]
    kwargs.setdefault("margin", sc.margins() or None)
    if sc.has_disks and "regions" not in kwargs:
        kwargs["inner_obstacles"], kwargs["inner_robot"] = inner_pieces(sc)
        kwargs.setdefault("excess", disk_excess(sc))
    return exact_se2_search(obstacles, robot, sc.bounds, q.start, q.goal, **kwargs)


class _Search:
    """One run of the refinement loop (state kept for the stats)."""

    def __init__(self, regions: SlabRegions, start, goal, time_limit, min_width, initial_slabs):
        self.R = regions
        self.start = (float(start[0]), float(start[1]), wrap_angle(float(start[2])))
        self.goal = (float(goal[0]), float(goal[1]), wrap_angle(float(goal[2])))
        self.t0, self.c0 = time.perf_counter(), time.process_time()
        self.deadline = None if time_limit is None else self.t0 + float(time_limit)
        self.min_width = min_width
        self.part = initial_partition(initial_slabs)
        self.times = {"regions": 0.0, "graphs": 0.0, "path": 0.0}
        self.possible_only, self.refine, self.near = False, True, False
        self.refinements = 0
        self.graph_sizes: dict = {}
        self.banned: set = set()  # FREE links a failed assembly ruled out (by _key)
        self.force: set = set()  # slabs (a, b) to bisect at the next refinement
        self.repairs: list = []
        self.searched = None  # the widest slab of the last partition whose FREE graph joined nothing: D's Δ

    # -- the loop ------------------------------------------------------------------------

    def run(self) -> SE2ExactResult:
        for name, (x, y, t) in (("start", self.start), ("goal", self.goal)):
            if not self.R.pose_free(x, y, t):
                raise ValueError(f"exact_se2_search: the {name} pose {(x, y, t)} is not free")
        try:
            while True:
                # FREE first: where its graph already joins start and goal (most solvable scenes, at
                # the first slabs) the POSSIBLE regions are never built; they are built, and the
                # proof looked for, only when it does not.
                freg = None if self.possible_only else self._regions("free")
                if freg is not None:
                    t = time.perf_counter()
                    fadj = self._free_graph(freg)
                    walk = shortest_walk(fadj, S_NODE, G_NODE, self.start[:2], self.goal[:2], self._turn_cost)
                    self.times["graphs"] += time.perf_counter() - t
                    if walk is None and not self.banned:  # (a ban may hide a walk FREE has: no statement then)
                        self.searched = max(b - a for a, b in self.part)
                    if walk is not None:
                        t = time.perf_counter()
                        try:
                            path = assemble(walk, self.part, freg, self.R, self.start, self.goal, near=self.near)
                        except AssemblyError as exc:  # a certified walk whose exact re-check failed
                            self.times["path"] += time.perf_counter() - t
                            self._repair(walk, exc)
                            continue
                        self.times["path"] += time.perf_counter() - t
                        return self._result("solved", path=path)
                preg = self._regions("possible")
                t = time.perf_counter()
                padj, s_p, g_p, p_edges = self._possible_graph(preg)
                reached = reach(padj, [S_NODE])
                self.times["graphs"] += time.perf_counter() - t
                if G_NODE not in reached:
                    return self._result("unsolvable", proof=self._proof(preg, s_p, g_p, p_edges))
                if freg is None:
                    if not self._split(self._wide()):
                        return self._result("undecided", reason=NO_PROOF_FOUND)
                    continue
                t = time.perf_counter()
                split = self._select(preg, freg, padj, fadj, reached) | self._forced()
                self.times["graphs"] += time.perf_counter() - t
                if not self._split(split):
                    return self._result("undecided", reason="minimum slab width reached")
                if self.refinements == 2:  # after two rounds: zero-width slabs at the critical angles, the ends' own
                    self.part = with_zero_slabs(self.part, critical_angles(self.R.hull_robot, self.R.obstacles)
                                                + [self.start[2], self.goal[2]])
        except _Timeout:
            return self._result("undecided", reason="time limit")

    def _key(self, n):
        """A FREE node by its slab's angles (stable across refinements), S and G as they are."""
        return n if n[0] < 0 else (*self.part[n[0]], n[1])

    def _repair(self, walk: list, exc: AssemblyError) -> None:
        """A walk whose exact re-check failed at node i (a rounding of the overlay at a vertex, a
        turn point on a boundary): its links into and out of node i are dropped from the FREE
        graph (the next walk goes round them, or through other link points), and node i's slab
        is marked to be bisected at the next refinement (its halves' regions differ), even below
        the floor (down to 2^-10 of it). Never an "undecided" while time is left."""
        nodes = [n for n, _ in walk]
        i = min(max(exc.index, 0), len(nodes) - 1)
        for j in (i - 1, i):
            if 0 <= j < len(nodes) - 1:
                self.banned.add(frozenset((self._key(nodes[j]), self._key(nodes[j + 1]))))
        self.repairs.append(str(exc)[:200])
        if nodes[i][0] >= 0:
            self.force.add(self.part[nodes[i][0]])

    def _forced(self) -> set:
        """The slabs marked by :meth:`_repair` still in the partition and wider than 2^-10 × the floor."""
        out = {k for k, ab in enumerate(self.part) if ab in self.force
               and 0.5 * (ab[1] - ab[0]) >= self.min_width / 1024}
        self.force.clear()
        return out

    def _wide(self) -> set:
        """The slabs that may still be bisected (half as wide stays above the floor)."""
        return {k for k, (a, b) in enumerate(self.part) if 0.5 * (b - a) >= self.min_width}

    def _split(self, split: set) -> bool:
        """Bisect the slabs ``split``; False (nothing done) if there are none or refining is off."""
        if not split or not self.refine:
            return False
        self.refinements += 1
        self.part = bisected(self.part, split)
        return True

    def _regions(self, kind: str) -> list:
        t = time.perf_counter()
        out = []
        build = self.R.possible if kind == "possible" else self.R.free
        for a, b in self.part:
            if self.deadline is not None and time.perf_counter() > self.deadline:
                raise _Timeout
            out.append(build(a, b))
        self.times["regions"] += time.perf_counter() - t
        return out

    # -- graphs --------------------------------------------------------------------------

    def _possible_graph(self, preg: list):
        K = len(self.part)
        adj: dict = {S_NODE: set(), G_NODE: set()}
        edges = []
        for k in range(K):
            for c in range(len(preg[k].components)):
                adj[(k, c)] = set()
        for k in range(K):
            k2 = (k + 1) % K
            for i, j in self.R.possible_links(preg[k], preg[k2]):
                edges.append([k, i, k2, j])
                adj[(k, i)].add((k2, j))
                adj[(k2, j)].add((k, i))
        ends = []
        for virtual, (x, y, th) in ((S_NODE, self.start), (G_NODE, self.goal)):
            nodes = [(k, c) for k in holding(self.part, th, ANGLE_NEAR) for c in self.R.near(preg[k], x, y)]
            for n in nodes:
                adj[virtual].add(n)
                adj[n].add(virtual)
            ends.append(nodes)
        self.graph_sizes["possible"] = {"nodes": len(adj) - 2, "edges": len(edges)}
        return adj, ends[0], ends[1], edges

    def _free_graph(self, freg: list) -> dict:
        """Adjacency: node -> sorted list of (neighbour, link point); S_NODE / G_NODE stand
        for the start's / goal's component of FREE at their own angle."""
        K = len(self.part)
        adj: dict = {S_NODE: [], G_NODE: []}
        n_edges = 0
        for k in range(K):
            for c in range(len(freg[k].components)):
                adj[(k, c)] = []
        for k in range(K):
            k2 = (k + 1) % K
            for i, j, pt in self.R.free_links(freg[k], freg[k2]):
                adj[(k, i)].append(((k2, j), pt))
                adj[(k2, j)].append(((k, i), pt))
                n_edges += 1
        same = self.start[2] == self.goal[2]
        ends = {}
        for virtual, (x, y, th) in ((S_NODE, self.start), (G_NODE, self.goal)):
            # An end whose (x, y) is free at every angle of a slab holding its angle joins that
            # slab's component there, with the end itself as the link point (no translation at
            # its own angle first): the FREE at its angle alone is built only when none holds it.
            direct = [] if same else [(k, c) for k in holding(self.part, th)
                                      for c in [self.R.containing(freg[k], x, y)]
                                      if c is not None
                                      and point_free(freg[k].pieces, self.R.bounds, x, y, freg[k].piece_boxes)]
            for k, c in direct:
                adj[virtual].append(((k, c), (x, y)))
                adj[(k, c)].append((virtual, (x, y)))
                n_edges += 1
            if direct:
                continue
            zero = self.R.free_at(th)
            c0 = self.R.containing(zero, x, y)
            ends[virtual] = c0
            if c0 is None:
                continue
            for k in holding(self.part, th):
                for i, j, pt in self.R.free_links(zero, freg[k]):
                    if i == c0:
                        adj[virtual].append(((k, j), pt))
                        adj[(k, j)].append((virtual, pt))
                        n_edges += 1
        if same and ends[S_NODE] is not None and ends[S_NODE] == ends[G_NODE]:
            adj[S_NODE].append((G_NODE, None))  # one translation at the common angle
        if self.banned:
            for n in adj:
                kn = self._key(n)
                adj[n] = [e for e in adj[n] if frozenset((kn, self._key(e[0]))) not in self.banned]
        for n in adj:
            adj[n].sort(key=lambda e: e[0])
        self.graph_sizes["free"] = {"nodes": len(adj) - 2, "edges": n_edges}
        return adj

    def _turn_cost(self, n, m) -> float:
        """The robot radius times the turn from node n's angle to node m's (middles; 0 at S, G)."""
        w = [0.0 if k < 0 else self.part[k][1] - self.part[k][0] for k in (n[0], m[0])]
        return self.R.radius * 0.5 * (w[0] + w[1])

    # -- refinement ----------------------------------------------------------------------

    def _select(self, preg, freg, padj, fadj, reached) -> set:
        """The slabs to bisect (see the module docstring)."""
        K = len(self.part)
        label = labels(fadj)
        owner = {k: self.R.owner(freg[k], preg[k]) for k in range(K)}
        seen: dict = {}
        for (k, f), lab in label.items():
            if k >= 0:
                seen.setdefault((k, owner[k][f]), set()).add(lab)
        bad_node = {n for n in padj if n[0] >= 0 and len(seen.get(n, ())) != 1}
        good_edge = set()
        for n, nbrs in fadj.items():
            for m, _ in nbrs:
                pn = n if n[0] < 0 else (n[0], owner[n[0]][n[1]])
                pm = m if m[0] < 0 else (m[0], owner[m[0]][m[1]])
                good_edge.add((pn, pm))
        # Virtual nodes: FREE's start node stands for the POSSIBLE start node.
        walk = cheapest_walk(padj, bad_node, good_edge)
        wide = self._wide()
        pick = set()
        for u, v in zip(walk, walk[1:]):
            for n in (u, v):
                if n in bad_node:
                    pick.add(n[0])
            if (u, v) not in good_edge:
                pick |= {n[0] for n in (u, v) if n[0] >= 0}
        # along the cheapest walk slabs go below the floor (to 2^-6 of it): as narrow as the room there
        pick = {k for k in pick if 0.5 * (self.part[k][1] - self.part[k][0]) >= self.min_width / 64}
        if not pick:
            pick = {n[0] for n in bad_node if n in reached} & wide
        if not pick:
            pick = wide
        return pick

    # -- results -------------------------------------------------------------------------

    def _proof(self, preg, s_p, g_p, edges) -> dict:
        return proof_json(self.part, preg, self.R, self.start, self.goal, s_p, g_p, edges)

    def _result(self, status: str, path=None, proof=None, **extra) -> SE2ExactResult:
        widest = max(b - a for a, b in self.part)
        # "undecided": D from the last partition whose FREE graph was searched and joined nothing (a
        # partition refined since, whose FREE the time limit cut, establishes nothing yet)
        D, words = resolution(self.R, widest if status != "undecided" else
                              math.inf if self.searched is None else self.searched, ANGLE_SLACK)
        stats = {"slabs": len(self.part), "refinements": self.refinements, "regions_built": dict(self.R.counts),
                 "repairs": len(self.repairs),
                 "graphs": dict(self.graph_sizes), "seconds": dict(self.times),
                 "wall_seconds": time.perf_counter() - self.t0, "cpu_seconds": time.process_time() - self.c0,
                 "partition": [[float(a), float(b)] for a, b in self.part], "widest_slab": widest, "resolution": D,
                 **extra}
        out = SE2ExactResult(status, resolution=D, stats=stats, proof=proof)
        if status == "undecided":
            stats["statement"] = words
        if path is not None:
            out.path = path
            d = np.diff(path, axis=0)
            out.length = float(np.hypot(d[:, 0], d[:, 1]).sum())
            turn = np.abs((d[:, 2] + math.pi) % TWO_PI - math.pi)
            out.rotation = float(turn.sum())
        return out

