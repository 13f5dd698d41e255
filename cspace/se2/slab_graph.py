"""Per-slab FREE and POSSIBLE regions of a rotating robot, their components and links.

The geometry of note se2-exact.md, sections 1-3, for one angle slab S = [a, b] (any width
up to π/4; slabs need not come from a uniform partition). P_i are the convex robot pieces
in the body frame, O_j the convex obstacle pieces, B the reference point's bounds.

- FREE(S) = B − ⋃ O_j ⊕ (−H_i), H_i = :func:`slab_hull` of P_i over [a − s, b + s]
  (s = ``ANGLE_SLACK``, as :class:`cspace.se2.cspace.SE2CSpace` builds its slabs): H_i holds
  R_θ P_i for every θ of S, so a reference point in FREE(S) is free at every angle of S.
  For a zero-width slab (a single angle θ, the start's or the goal's) H_i is
  ``rotate_piece(P_i, θ)`` summed with the square [−δ, δ]² (δ = the slab pad): the exact
  translation C-space of the turned robot, shrunk by δ, so that a shortest path, which may
  run along the boundary, still keeps the robot off the obstacles (touching is collision).
- POSSIBLE(S) = B − ⋃ O_j ⊕ (−C_i), C_i = :func:`slab_inner` of P_i over [a − c, b + c]
  (c = ``CORE_SLACK``; the *core*: inside R_θ P_i for every θ of S); a piece whose core is
  empty contributes nothing. A
  pose (x, y, θ), θ in S, whose (x, y) is outside POSSIBLE(S) collides.

Reflection: O ⊕ (−R) is the set of reference points q where R + q meets O (q ∈ O − R), so the
robot-side operand is always reflected (``reflect``) before :func:`pair_sums`, as
:class:`cspace.translation.cspace.CSpace` does internally.

Erring toward MORE possible space (what a proof of "no path" needs). The core C_i is
already padded inward by ``slab_inner`` (4 pads per edge, for the float rotation and
clipping). POSSIBLE is then computed with the core shrunk by a further ε (every edge moved
inward by ε: the erosion of C_i by the disk of radius ε, up to rounding far below ε):
ε = 64 u, u = 2^-40 · S, S = max coordinate magnitude of the bounds and the proof's obstacles +
r√2 (r the proof's robot radius), i.e. 64 × the checked tolerance of the GEOS union
(:mod:`cspace.kernel.minkowski.union`, 2^-40 of the coordinates, or the snap-rounding grid 2^-42).
S and u are the independent checker's too (:mod:`planners.core.proof_geometry` has the table:
its cores need ≥ u, its sums shrink by 16 u, it links within 512 u), so every proof the planner
writes is one the checker accepts, at any offset and feature size. The union of O ⊕ (−(C ⊖ ε))
grown by ε lies inside the union of O ⊕ (−C), so as long as GEOS moves no boundary by
more than ε (its checked tolerance is 64 × smaller) the computed obstacle union lies
inside the true one and the computed POSSIBLE contains the true POSSIBLE of the cores C_i.
The proof stores the un-shrunk cores C_i (the checker's cores), so its components cover
the POSSIBLE the checker derives from them. Links between POSSIBLE components err
toward more links: closures within ``proof_tol`` = 1024 u count as meeting.

FREE only needs to be a subset up to rounding: every point the planner uses is certified
again exactly (:func:`point_free`; translations by :func:`cspace.paths.shortest.shortest_path`,
which checks its path against the pieces with exact predicates).

Regions are built on first use and cached by their (a, b); links between the components
of two slabs are cached by the two slabs' keys. Everything is deterministic.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..kernel.minkowski.merge import minkowski_sum, reflect
from ..kernel.polygons.polygon import piece_boxes as box_pairs, point_in_convex
from ..kernel.slabs.slab import ANGLE_SLACK, robot_radius, slab_hull, slab_inner, slab_pad
from ..kernel.polygons.rotation import rotate_piece
from ..translation.build import pair_sums
from ..paths.shortest import free_space
from .link_points import deep_in_both, deep_point, inner_point

UNIT_REL = 2.0**-40  # the proof side's unit u, relative to S (see SlabRegions)
EPS_UNITS = 64.0  # POSSIBLE's extra shrink of the cores (the checker's sums: 16 u)
TOL_UNITS = 1024.0  # POSSIBLE links and end nodes within this (the checker's: 512 u)
# A core is computed over [a - CORE_SLACK, b + CORE_SLACK]: inside the robot at every angle of the
# wider interval, so inside it on the slab (a smaller core: more POSSIBLE, the proof's side), and
# still inside where an independent check unsure of an angle's last bits looks just past a slab's
# end (planners.core.proof_check counts a sinusoid's peak within 1e-9 rad of the slab: a core
# vertex touching the robot's edge at the slab's end, inside by the pads only, failed it there).
CORE_SLACK = 1e-8
# ... and with its edges moved in by ε / 16 more than the slab pad (16 u at 4 pads per edge): far
# above the independent check's margin (u), which a core at its pads alone met only just.
CORE_PAD = 1.0 / 16.0
TOL_REL = 2.0**-30  # FREE: the depth of a certified link point (relative to S' of FREE's pieces)


@dataclass
class Region:
    """FREE or POSSIBLE of one slab: its C-obstacle pieces and its components (shapely
    Polygons, deterministic order), with their boxes (n, 4: minx, miny, maxx, maxy).
    ``cores``: POSSIBLE only, the un-shrunk cores (one per robot piece, (0, 2) if empty)."""

    a: float
    b: float
    kind: str
    pieces: list
    components: list
    boxes: np.ndarray
    cores: list = field(default_factory=list)
    seconds: float = 0.0
    piece_boxes: np.ndarray | None = None  # (len(pieces), 4) boxes of the pieces, for point_free


class SlabRegions:
    """Builds and caches FREE / POSSIBLE regions of slabs and the links between them.

    >>> wall = np.array([[4., 0], [5, 0], [5, 10], [4, 10]])
    >>> bar = np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])
    >>> sr = SlabRegions([wall], [bar], (0, 10, 0, 10))
    >>> f, p = sr.free(0.0, 0.5), sr.possible(0.0, 0.5)
    >>> len(f.components), len(p.components), p.components[0].area > f.components[0].area
    (2, 2, True)
    """

    def __init__(self, obstacle_pieces: list, robot_pieces: list, bounds, *, hull_pieces: list | None = None,
                 inner_obstacles: list | None = None, inner_robot: list | None = None):
        self.obstacles = [np.asarray(o, dtype=np.float64) for o in obstacle_pieces]
        self.robot = [np.asarray(r, dtype=np.float64) for r in robot_pieces]
        # POSSIBLE (the proof's side) is built of shapes INSIDE the scene as written: for a disk,
        # the polygon inscribed in it, not the circumscribed one FREE keeps clear of (a proof must
        # hold for the disk itself). Polygons are the same pieces either way.
        self.core_obstacles = self.obstacles if inner_obstacles is None else \
            [np.asarray(o, dtype=np.float64) for o in inner_obstacles]
        self.core_robot = self.robot if inner_robot is None else [np.asarray(r, dtype=np.float64) for r in inner_robot]
        # The pieces FREE's hulls are built from (the robot inflated by a margin, if any):
        # FREE shrinks and POSSIBLE, built from the body itself, only grows: FREE ⊆ POSSIBLE.
        self.hull_robot = self.robot if hull_pieces is None else [np.asarray(r, dtype=np.float64) for r in hull_pieces]
        self.bounds = tuple(float(v) for v in bounds)
        self.radius = max(robot_radius(self.robot), robot_radius(self.hull_robot))
        self.scale = max([abs(v) for v in self.bounds] + [float(np.abs(o).max()) for o in self.obstacles if len(o)])
        s2 = self.scale + self.radius * math.sqrt(2.0)
        self.hull_pad = slab_pad(max(self.radius * math.sqrt(2.0), self.scale))
        self.tol = TOL_REL * s2  # FREE's link depth
        # The proof side's numbers, from the one quantity the independent checker derives too
        # (planners.core.proof_geometry.scene_unit): S = the largest coordinate of the bounds and
        # the proof's obstacles + √2 × the proof's robot radius; u = 2^-40 S.
        ps = max([abs(v) for v in self.bounds] + [float(np.abs(o).max()) for o in self.core_obstacles if len(o)]) \
            + robot_radius(self.core_robot) * math.sqrt(2.0)
        self.unit = UNIT_REL * ps
        self.pad = slab_pad(ps)  # slab_inner's pad (u / 16)
        self.eps = EPS_UNITS * self.unit
        self.proof_tol = TOL_UNITS * self.unit
        # FREE's union checked as POSSIBLE's is (cspace.kernel.minkowski.union); off for a search
        # that only looks for a path (every point and motion of it certified again exactly) and
        # states nothing from FREE's shape (no "undecided" resolution is read from it)
        self.free_checked = True
        # links found without the overlay where one component's deep point is deep in the other
        # (:func:`cspace.se2.link_points.deep_in_both`; another link point, so another path: on for a
        # car's search with room, whose path turns where it is, not at the link points)
        self.quick_links, self._deep = False, {}
        # the slabs (a, b) whose FREE carried a walk's crossing translation (exact_path.near_links:
        # the next walks cross there first, where the mesh is kept); so a path may depend on the
        # queries these regions answered before, each certified the same way
        self.carriers: set = set()
        self._free: dict = {}
        self._possible: dict = {}
        self._links: dict = {}
        self.counts = {"free_built": 0, "possible_built": 0, "links_built": 0}
        # what the resolution statement adds to r·Δ (cspace.se2.exact_report): the margin's reach
        # and the disks' polygon error (set by cspace.se2.exact.slab_regions)
        self.margin_reach, self.excess = 0.0, 0.0

    # -- regions -----------------------------------------------------------------------

    def free(self, a: float, b: float) -> Region:
        """FREE of the slab [a, b] (``a == b``: the single angle a, shrunk by δ)."""
        key = (float(a), float(b))
        if key not in self._free:
            t = time.perf_counter()
            a, b = key
            if a == b:
                d = self.hull_pad
                square = np.array([[-d, -d], [d, -d], [d, d], [-d, d]])
                hulls = [minkowski_sum(rotate_piece(p, a), square) for p in self.hull_robot]
            else:
                hulls = [slab_hull(p, a - ANGLE_SLACK, b + ANGLE_SLACK, scale=self.scale) for p in self.hull_robot]
            self._free[key] = self._region(a, b, "free", hulls, [], t)
            self.counts["free_built"] += 1
        return self._free[key]

    def free_at(self, theta: float) -> Region:
        """FREE at one angle (the zero-width slab [θ, θ]).

        >>> sr = SlabRegions([np.array([[4., 0], [5, 0], [5, 10], [4, 10]])], [np.array([[0., 0], [1, 0], [0, 1]])],
        ...                  (0, 10, 0, 10))
        >>> round(sr.free_at(0.0).components[0].bounds[2], 9)  # the triangle's tip touches x = 4 at x = 3
        3.0
        """
        return self.free(theta, theta)

    def pose_free(self, x: float, y: float, theta: float) -> bool:
        """The exact pose test: (x, y) in the bounds and outside every O_j ⊕ −rotate_piece(P_i, θ)
        (the hull pieces: the robot with its margin, if any).

        >>> sr = SlabRegions([np.array([[4., 0], [5, 0], [5, 10], [4, 10]])], [np.array([[0., 0], [1, 0], [0, 1]])],
        ...                  (0, 10, 0, 10))
        >>> sr.pose_free(3.0, 1.0, 0.0), sr.pose_free(2.9, 1.0, 0.0), sr.pose_free(3.5, 1.0, math.pi)
        (False, True, True)
        """
        turned = [reflect(rotate_piece(p, float(theta))) for p in self.hull_robot]
        pieces = pair_sums(self.obstacles, turned) if self.obstacles else []
        return point_free(pieces, self.bounds, float(x), float(y))

    def possible(self, a: float, b: float) -> Region:
        """POSSIBLE of the slab [a, b] (cores shrunk by ε more: see the module docstring)."""
        key = (float(a), float(b))
        if key not in self._possible:
            t = time.perf_counter()
            a, b = key
            cores, used = [], []
            lo, hi, pad = a - CORE_SLACK, b + CORE_SLACK, self.pad + CORE_PAD * self.eps
            for p in self.core_robot:
                c = slab_inner(p, lo, hi, pad)
                cores.append(c if len(c) >= 3 else np.zeros((0, 2)))
                if len(c) >= 3:
                    # slab_inner lowers every offset by 4·pad·|n|: pad + ε/4 moves each edge ε further in.
                    s = slab_inner(p, lo, hi, pad + 0.25 * self.eps)
                    if len(s) >= 3:
                        used.append(s)
            self._possible[key] = self._region(a, b, "possible", used, cores, t, self.core_obstacles)
            self.counts["possible_built"] += 1
        return self._possible[key]

    def _region(self, a: float, b: float, kind: str, robot_side: list, cores: list, t: float,
                obstacles: list | None = None) -> Region:
        import shapely

        obstacles = self.obstacles if obstacles is None else obstacles
        pieces = pair_sums(obstacles, [reflect(h) for h in robot_side]) if robot_side and obstacles else []
        F = free_space(pieces, self.bounds, checked=kind == "possible" or self.free_checked)
        comps = [p for p in shapely.get_parts(F) if p.geom_type == "Polygon" and not p.is_empty]
        boxes = np.array([p.bounds for p in comps], dtype=np.float64).reshape(-1, 4)
        order = sorted(range(len(comps)), key=lambda i: (tuple(boxes[i]), -comps[i].area))
        comps = [comps[i] for i in order]
        for c in comps:
            shapely.prepare(c)
        return Region(a, b, kind, pieces, comps, boxes[order].reshape(-1, 4), cores, time.perf_counter() - t,
                      piece_boxes(pieces))

    def share_possible(self, other: "SlabRegions") -> bool:
        """Read and build POSSIBLE in ``other``'s cache from now on, where both have the same body,
        obstacles and proof numbers (POSSIBLE does not depend on the margin FREE keeps: a search
        asking for more room reuses the body's regions); False (nothing shared) otherwise."""
        same = (self.unit, self.pad, self.eps, len(self.core_robot), len(self.core_obstacles)) == \
            (other.unit, other.pad, other.eps, len(other.core_robot), len(other.core_obstacles)) and \
            all(np.array_equal(a, b) for a, b in zip(self.core_robot + self.core_obstacles,
                                                     other.core_robot + other.core_obstacles))
        if same:
            self._possible = other._possible
        return same

    # -- links ---------------------------------------------------------------------------

    def free_links(self, r1: Region, r2: Region) -> list[tuple[int, int, tuple[float, float]]]:
        """(i, j, point): FREE components i of r1 and j of r2 whose intersection has an
        interior, with a point deep inside it (more than ``tol`` from its boundary), or, where
        the overlap is thinner than that (bounds of any thinness: a rail), a point inside it
        (the path's assembly re-checks every link point exactly against both slabs)."""
        key = ("free", r1.a, r1.b, r2.a, r2.b)
        if key not in self._links:
            import shapely

            out = []
            for i, j in _box_pairs(r1.boxes, r2.boxes, 0.0):
                pt = deep_in_both(r1, i, r2, j, self.tol, self._deep) if self.quick_links else None
                if pt is None:
                    inter = shapely.intersection(r1.components[i], r2.components[j])
                    pt = deep_point(inter, self.tol)
                if pt is None:
                    pt = inner_point(inter)
                if pt is not None:
                    out.append((i, j, pt))
            self._links[key] = out
            self.counts["links_built"] += 1
        return self._links[key]

    def link_near(self, r1: Region, i: int, r2: Region, j: int, x: float, y: float) -> tuple[float, float] | None:
        """A point deep inside FREE component i of r1 and j of r2 (as deep as :meth:`free_links`'
        points) near (x, y): (x, y) itself where it is one, else one of their overlap inside a
        square round it (2, 8, 32, 128 robot radii wide, the first that holds one; within it, of
        the overlap's part nearest to (x, y)); None where none is that near. Per query: a walk
        then turns where it is, not at the one point :meth:`free_links` keeps for the pair,
        which on a large map may be a hundred metres away.

        >>> sr = SlabRegions([np.array([[4., 0], [5, 0], [5, 10], [4, 10]])], [np.array([[0., 0], [.2, 0], [0, .2]])],
        ...                  (0, 10, 0, 10))
        >>> f1, f2 = sr.free(0.0, 0.5), sr.free(0.5, 1.0)
        >>> x, y = sr.link_near(f1, 0, f2, 0, 4.5, 5.0)  # in the wall: a point of the left side near it
        >>> sr.link_near(f1, 0, f2, 0, 1.0, 1.0), bool(x < 4 and abs(y - 5) < 3)
        ((1.0, 1.0), True)
        """
        import shapely

        c1, c2, pt = r1.components[i], r2.components[j], shapely.Point(float(x), float(y))
        for w in (2.0, 8.0, 32.0, 128.0):
            w *= self.radius
            box = shapely.box(x - w, y - w, x + w, y + w)
            try:
                local = shapely.intersection(shapely.intersection(c1, box), c2)
            except shapely.errors.GEOSException:  # (an overlay GEOS refuses: the kept point serves)
                return None
            parts = [p for p in shapely.get_parts(local) if p.geom_type == "Polygon" and p.area > 0.0]
            if w == 2.0 * self.radius and any(shapely.intersects_xy(p, x, y) and p.boundary.distance(pt) > self.tol
                                              for p in parts):
                return float(x), float(y)
            for p in sorted(parts, key=lambda q: (q.distance(pt), q.bounds)):
                found = deep_point(p, self.tol)
                if found is not None:
                    return found
        return None

    def possible_links(self, r1: Region, r2: Region) -> list[tuple[int, int]]:
        """(i, j): POSSIBLE components of r1 and r2 whose closures meet or come within ``proof_tol``."""
        key = ("possible", r1.a, r1.b, r2.a, r2.b)
        if key not in self._links:
            import shapely

            # (components that overlap, the usual case between neighbouring slabs, are at distance
            # 0: the prepared intersects test answers them without measuring)
            out = [(i, j) for i, j in _box_pairs(r1.boxes, r2.boxes, self.proof_tol)
                   if shapely.intersects(r1.components[i], r2.components[j])
                   or shapely.distance(r1.components[i], r2.components[j]) <= self.proof_tol]
            self._links[key] = out
            self.counts["links_built"] += 1
        return self._links[key]

    def near(self, region: Region, x: float, y: float) -> list[int]:
        """Components of ``region`` whose closure is within ``proof_tol`` of (x, y).

        >>> sr = SlabRegions([np.array([[4., 0], [5, 0], [5, 10], [4, 10]])], [np.array([[0., 0], [1, 0], [0, 1]])],
        ...                  (0, 10, 0, 10))
        >>> sr.near(sr.possible(0.0, 0.1), 1.0, 1.0), sr.near(sr.possible(0.0, 0.1), 4.5, 1.0)
        ([0], [])
        """
        import shapely

        pt = shapely.Point(float(x), float(y))
        return [i for i in range(len(region.components))
                if _box_near(region.boxes[i], x, y, self.proof_tol)
                and (shapely.intersects_xy(region.components[i], float(x), float(y))
                     or shapely.distance(region.components[i], pt) <= self.proof_tol)]

    def containing(self, region: Region, x: float, y: float) -> int | None:
        """The component of ``region`` that covers (x, y), or None.

        >>> sr = SlabRegions([], [np.array([[0., 0], [1, 0], [0, 1]])], (0, 10, 0, 10))
        >>> sr.containing(sr.free_at(0.0), 5.0, 5.0), sr.containing(sr.free_at(0.0), 11.0, 5.0)
        (0, None)
        """
        import shapely

        for i, c in enumerate(region.components):
            if _box_near(region.boxes[i], x, y, 0.0) and shapely.intersects_xy(c, float(x), float(y)):
                return i
        return None

    def owner(self, free: Region, possible: Region) -> list[int]:
        """For each FREE component of a slab, the POSSIBLE component of the same slab that
        holds it (FREE ⊆ POSSIBLE: the one nearest to an inner point of it)."""
        key = ("owner", free.a, free.b)
        if key not in self._links:
            import shapely

            out = []
            for c in free.components:
                pt = c.representative_point()
                d = [shapely.distance(p, pt) for p in possible.components]
                out.append(int(np.argmin(d)) if d else -1)
            self._links[key] = out
        return self._links[key]


def point_free(pieces: list, bounds, x: float, y: float, boxes: np.ndarray | None = None) -> bool:
    """Is (x, y) in the bounds and outside every closed piece (exact predicates)? ``boxes``:
    the pieces' :func:`piece_boxes`, when the caller keeps them (a region's ``piece_boxes``).

    >>> point_free([np.array([[1., 1], [2, 1], [2, 2], [1, 2]])], (0, 3, 0, 3), 1.0, 1.5)
    False
    >>> point_free([np.array([[1., 1], [2, 1], [2, 2], [1, 2]])], (0, 3, 0, 3), 0.5, 1.5)
    True
    """
    xmin, xmax, ymin, ymax = bounds
    if not (xmin <= x <= xmax and ymin <= y <= ymax):
        return False
    if boxes is None:
        boxes = piece_boxes(pieces)
    near = np.flatnonzero((boxes[:, 0] <= x) & (x <= boxes[:, 2]) & (boxes[:, 1] <= y) & (y <= boxes[:, 3]))
    return not any(point_in_convex(pieces[k], x, y) >= 0 for k in near.tolist())


def piece_boxes(pieces: list) -> np.ndarray:
    """The pieces' boxes, (len(pieces), 4): min x, min y, max x, max y (an empty piece's box
    holds no point).

    >>> piece_boxes([np.array([[1., 1], [2, 1], [2, 3]])]).tolist()
    [[1.0, 1.0, 2.0, 3.0]]
    """
    lo, hi = box_pairs(pieces)  # the kernel's (lo, hi), side by side
    return np.hstack([lo, hi]).reshape(-1, 4)


def _box_pairs(b1: np.ndarray, b2: np.ndarray, grow: float) -> list[tuple[int, int]]:
    """Index pairs (i, j), in order, whose boxes (grown by ``grow``) overlap."""
    if not len(b1) or not len(b2):
        return []
    m = ((b1[:, None, 0] <= b2[None, :, 2] + grow) & (b2[None, :, 0] <= b1[:, None, 2] + grow)
         & (b1[:, None, 1] <= b2[None, :, 3] + grow) & (b2[None, :, 1] <= b1[:, None, 3] + grow))
    i, j = np.nonzero(m)
    return list(zip(i.tolist(), j.tolist()))


def _box_near(box: np.ndarray, x: float, y: float, grow: float) -> bool:
    return box[0] - grow <= x <= box[2] + grow and box[1] - grow <= y <= box[3] + grow
