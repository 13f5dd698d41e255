"""Certified motions of a car-like robot: straight segments and arcs of its turning circle.

A Dubins or Reeds–Shepp motion (:mod:`cspace.car.curves`) is a chain of segments
from the start pose: "S" drives straight at a fixed heading, "L" / "R" turn about
the centre c of the turning circle on that side. This module answers "is every
pose of the chain free?" for :class:`cspace.se2.cspace.SE2CSpace`, never by sampling
(note se2-rotation.md, section 3):

- a straight segment is a translation at one fixed angle: the SE(2) C-space's exact
  fixed-angle motion test (:meth:`SE2Motions.motion_free` with equal angles);
- an arc is a rotation of the whole robot about c: in a frame centred at c the
  robot's convex pieces P_c (placed at the arc's start) turn by α over an interval
  [a, b], so they stay inside the padded hull H of the triangles T(v) (the slab
  bound with radii measured from c). H is separated from the obstacle pieces near
  it by separating axes with a margin above the rounding (:meth:`_turn_hits`): a
  certificate. Otherwise [a, b] is halved and the pose at the middle angle tested
  exactly. The answer is False on an exact pose in collision, or, counted in
  ``checks["motion_floor"]``, when an interval shrinks below a floor or a budget of
  bounds is spent (conservative, never a false "free").
- The reference point stays within the bounds: each arc's box (its end points and
  the axis-extreme points of the circle it passes) must lie inside them.

The certified set is the union of the exact primitive motions started from the
float knots (:func:`cspace.car.curves.advance`); consecutive knots meet within
rounding, which the hull's pad (hundreds of units of roundoff of the coordinates)
covers, and the curve's end is joined to the goal pose by a certified SE(2) motion.

On the compiled path (:func:`cspace.compiled.motions.car_curve`, cspace/compiled/_carmotion.c)
the probe, the straight segments and the arcs' halving run in one C call per curve with the
same doubles; it answers "free" only where this path would (a separating axis needs this
path's gap plus ~2048 roundoffs), "not free" only on a pose in collision, and hands
anything else ("undecided") to this path, the oracle. The planners' motion test joins the
curve's end to q1 in that call too, where one slab's segment test certifies the join or, at one
heading, the robot swept along it is separated with that margin, as a straight segment is
(near an obstacle the slab's hull is too coarse; the exact translational test here would
say free too); else the join is this path's.
"""
from __future__ import annotations

import math

import numpy as np

from ..compiled import motions
from .curves import advance, dubins_segments, reeds_shepp_segments, turning_centre
from ..se2.cspace import SE2CSpace
from ..se2.pose_checks import MAX_ARC_TURNS, MAX_SEGMENT_EXTENTS, curve_radius, curve_segments, se2_pose
from ..kernel.slabs.slab import slab_pad
from ..kernel.polygons.rotation import rotate_piece, wrap_angle

# Initial split of an arc: intervals of at most this angle (the bound's excess over
# the swept set grows as radius · Δ²/4, so a quarter turn would be loose).
ARC_CHUNK = math.pi / 8
# Refinement stops (answer "not free", counted) when an interval's sweep is below
# this fraction of the scene's extent, or after this many hulls for one curve.
FLOOR_REL = 1e-9
MAX_HULLS = 4096


def _normals(p: np.ndarray) -> np.ndarray:
    """Outward normals (dy, −dx) of a CCW convex polygon's edges (zero rows for a point)."""
    e = np.roll(p, -1, axis=0) - p
    return np.column_stack([e[:, 1], -e[:, 0]])


def _unit_planes(pieces: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every piece's edge lines as unit outward normals and offsets, padded to the largest
    edge count with copies of the piece's first line: arrays of shape (pieces, edges)."""
    k = max((len(p) for p in pieces), default=0)
    ux = np.zeros((len(pieces), k))
    uy = np.zeros((len(pieces), k))
    off = np.zeros((len(pieces), k))
    for i, p in enumerate(pieces):
        n = _normals(p)
        ln = np.hypot(n[:, 0], n[:, 1])
        ln[ln == 0.0] = 1.0
        nx, ny = n[:, 0] / ln, n[:, 1] / ln
        o = nx * p[:, 0] + ny * p[:, 1]
        m = len(p)
        ux[i, :m], uy[i, :m], off[i, :m] = nx, ny, o
        ux[i, m:], uy[i, m:], off[i, m:] = nx[0], ny[0], o[0]
    return ux, uy, off


class CarCSpace(SE2CSpace):
    """The C-space of a car-like robot: the sliced SE(2) C-space of
    :class:`cspace.se2.cspace.SE2CSpace` (poses, straight motions, slabs) that also certifies
    the car's curves: :meth:`curve_free` (a chain of straight segments and arcs) and
    :meth:`car_motion_free` (the shortest Dubins or Reeds–Shepp curve between two poses).

    >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    >>> cs = CarCSpace((0, 10, 0, 10), [sq], [box], slabs=16)
    >>> cs.is_free((2.0, 2.0, 0.0)), cs.curve_free((2.0, 2.0, 0.0), [("L", math.pi / 2), ("S", 1.0)], 1.0)
    (True, True)
    """

    _car_planes = None
    # The compiled curve check (motions.car_curve) and motion check (motions.car_motion) on
    # one handle, made on the first curve; None: pure.
    _car_fast = False
    _car_motion = None

    def car_motion_free(self, q0, q1, kind: str, radius: float) -> bool:
        """Is the car free along the shortest curve of ``kind`` ("dubins" or "reeds-shepp") from q0
        to q1? :meth:`curve_free` of :mod:`cspace.car.curves`' segments, joined to q1.

        On the compiled path the segments are computed and checked in one call, with the same
        doubles (cspace/compiled/_carwords.c, _carmotion.c); anything it declines runs here.

        >>> import numpy as np
        >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
        >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
        >>> cs = CarCSpace((0, 10, 0, 10), [sq], [box], slabs=16)
        >>> cs.car_motion_free((1.0, 1.0, 0.0), (8.0, 1.0, 0.0), "reeds-shepp", 1.0)  # along y = 1
        True
        >>> cs.car_motion_free((1.0, 5.0, 0.0), (8.0, 5.0, 0.0), "dubins", 1.0)  # through the square
        False
        """
        dubins = kind == "dubins"
        if not dubins and kind != "reeds-shepp":
            raise ValueError(f"kind: 'dubins' or 'reeds-shepp', got {kind!r}")
        if self._car_fast is not None and type(q0) is tuple and type(q1) is tuple:
            got = self._car_motion_call(q0, q1, dubins, radius)
            if got is not None:
                return got
        segments = (dubins_segments if dubins else reeds_shepp_segments)(q0, q1, radius)
        return self.curve_free(q0, segments, radius, q1=q1)

    def car_motion_test(self, kind: str, radius: float):
        """``(q0, q1) -> bool``: :meth:`car_motion_free` for one kind and radius, checked once
        here (the planners' motion validator calls it for every motion). Poses that are tuples
        go to the compiled motion (cspace/compiled/_carmotion.c: non-finite values decline);
        whatever it does not decide, the curve and its join to q1 both, takes the full path.

        >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
        >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
        >>> test = CarCSpace((0, 10, 0, 10), [sq], [box], slabs=16).car_motion_test("reeds-shepp", 1.0)
        >>> test((1.0, 1.0, 0.0), (8.0, 1.0, 0.0)), test((1.0, 5.0, 0.0), (8.0, 5.0, 0.0))
        (True, False)
        """
        if kind not in ("dubins", "reeds-shepp"):
            raise ValueError(f"kind: 'dubins' or 'reeds-shepp', got {kind!r}")
        radius, dubins, full = curve_radius(radius, self.extent), kind == "dubins", self.car_motion_free
        if self._car_fast is False:
            self._compile_car()
        if self._car_fast is None:
            return lambda q0, q1: full(q0, q1, kind, radius)
        motion, grids, checks = self._car_motion, self._car_grids, self.checks
        longest, turns = MAX_SEGMENT_EXTENTS * self.extent, MAX_ARC_TURNS * 2.0 * math.pi * radius

        def test(q0, q1) -> bool:
            if type(q0) is tuple and type(q1) is tuple and len(q0) == len(q1) == 3:
                r = motion(grids, *q0, *q1, radius, dubins, longest, turns, True)[0]
                if r == 2 or r == 0:  # decided, the join included (else: the full path, from scratch)
                    checks["curves"] += 1
                    return r == 2
            return full(q0, q1, kind, radius)

        return test

    def _car_motion_call(self, q0, q1, dubins: bool, radius):
        """:meth:`car_motion_free` in one compiled call (motions.car_motion), or None when it
        cannot decide (or the arguments are not the usual floats: the full path checks them)."""
        q0, q1 = se2_pose(q0, "q0"), se2_pose(q1, "q1")
        radius = curve_radius(radius, self.extent)
        if self._car_fast is False and self._compile_car() is None:
            return None
        self.checks["curves"] += 1
        motion, longest = self._car_motion, MAX_SEGMENT_EXTENTS * self.extent
        turns = MAX_ARC_TURNS * 2.0 * math.pi * radius
        got = self._compiled(lambda grids: motion(grids, *q0, *q1, radius, dubins, longest, turns, True), q1)
        if got is None:
            self.checks["curves"] -= 1  # the full path counts it
        return got

    def curve_free(self, q0, segments, radius: float, q1=None) -> bool:
        """Is every pose of the segment chain from q0 free? Certified (see module doc).

        ``segments`` are ``(kind, signed length)`` pairs (``"L"``, ``"S"``, ``"R"``;
        length < 0 drives in reverse), ``radius`` the turning radius. With ``q1`` the
        chain's end is joined to q1 by a certified SE(2) motion (it differs only by
        rounding when the segments were computed from q0 to q1).

        >>> import numpy as np
        >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
        >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
        >>> cs = CarCSpace((0, 10, 0, 10), [sq], [box], slabs=16)
        >>> cs.curve_free((2, 2, 0), [("L", math.pi / 2), ("S", 5)], 1.0)  # quarter turn, then up x = 3
        True
        >>> cs.curve_free((2, 2, 0), [("S", 3), ("L", math.pi / 2), ("S", 5)], 1.0)  # up x = 6: hits
        False
        """
        x, y, th = se2_pose(q0, "q0")  # junk raises (pose_checks); so do unbounded segments
        radius = curve_radius(radius, self.extent)
        segments = curve_segments(segments, radius, self.extent)
        if q1 is not None:
            q1 = se2_pose(q1, "q1")
        self.checks["curves"] += 1
        pose = (x, y, wrap_angle(th))
        fast = self._car_fast
        if fast is False:
            fast = self._compile_car()
        if fast is not None:
            got = self._curve_fast(fast, pose, segments, radius, q1)
            if got is not None:
                return got
        return self._curve_pure(pose, segments, radius, q1)

    def _compile_car(self):
        """The first curve: the compiled checks on one handle, or None on the pure path."""
        self._car_fast = motions.car_curve(self, MAX_HULLS, FLOOR_REL, ARC_CHUNK)
        self._car_grids = [None] * self.slabs
        if self._car_fast is not None:
            self._car_motion = motions.car_motion(self._car_fast)
        return self._car_fast

    def _curve_fast(self, fast, pose, segments, radius: float, q1):
        """:meth:`curve_free` by the compiled check (cspace/compiled/_carmotion.c: its "free" and
        "not free" are the pure path's), or None when it cannot decide."""
        return self._compiled(lambda grids: fast(grids, pose[0], pose[1], pose[2], segments, radius), q1)

    def _compiled(self, call, q1):
        """A compiled car call (``grids -> (r, x, y, th)``: 1 free, 0 not, -1 undecided, -2 - k slab
        k not built, 2 free and joined to q1 in the call) run to its answer, building the slabs
        it asks for; a free chain's end (x, y, th) is then joined to q1 by a certified SE(2)
        motion. None: undecided."""
        grids = self._car_grids
        while True:  # one call; a slab not built yet is built and the call repeated
            r, x, y, th = call(grids)
            if r == 0:
                return False
            if r == 2:
                return True
            if r == 1:
                break
            if r == -1 or (handle := self.slab(-2 - r)._fast) is None:
                return None
            grids[-2 - r] = handle
        if q1 is not None:
            q1 = (float(q1[0]), float(q1[1]), wrap_angle(float(q1[2])))
            if (x, y, th) != q1 and not self.motion_free((x, y, th), q1):
                return False
        return True

    def _curve_pure(self, pose, segments, radius: float, q1) -> bool:
        """:meth:`curve_free` after its counter, on the pure path (the oracle)."""
        if not self._pose(*pose):
            self.checks["motion_collisions"] += 1
            return False
        budget = [MAX_HULLS]
        # The knots (segment ends, wrapped) and, first, a probe of a few exact poses (each
        # knot and each segment's middle): a colliding curve is usually refused here at
        # the cost of a handful of pose tests. The probe only ever answers "not free".
        chain = []
        for kind, length in segments:
            length = float(length)
            if length == 0.0:
                continue
            end = advance(pose, kind, length, radius)
            chain.append((pose, kind, length, (end[0], end[1], wrap_angle(end[2]))))
            pose = chain[-1][3]
        for start, kind, length, end in chain:
            mid = advance(start, kind, 0.5 * length, radius)
            if not (self._pose(*end) and self._pose(mid[0], mid[1], wrap_angle(mid[2]))):
                self.checks["motion_collisions"] += 1
                return False
        # Then the certificates: straight segments (exact, cheap) before arcs.
        for start, kind, length, end in chain:
            if kind == "S" and not self.motion_free(start, (end[0], end[1], start[2])):  # one fixed angle
                return False
        for start, kind, length, end in chain:
            if kind != "S" and not self._arc_free(start, kind, length, radius, budget):
                return False
        if q1 is not None:
            q1 = (float(q1[0]), float(q1[1]), wrap_angle(float(q1[2])))
            if pose != q1 and not self.motion_free(pose, q1):
                return False
        return True

    def _arc_free(self, pose, kind: str, length: float, radius: float, budget: list) -> bool:
        """The arc of one turn segment, certified by hulls about the turning centre."""
        self.checks["arcs"] += 1
        x, y, th = pose
        cx, cy = turning_centre(pose, kind, radius)
        A = length / radius if kind == "L" else -length / radius  # signed turn about c (CCW > 0)
        rx, ry = x - cx, y - cy
        # The robot's pieces at the arc's start, in the frame centred at c (a point robot: the point).
        rel = np.array([[rx, ry]])
        arrays = [rotate_piece(p, th) + rel for p in self.robot_pieces] or [rel]
        pieces = [p.tolist() for p in arrays]
        normals = [_normals(p).tolist() for p in arrays]
        reach = math.hypot(rx, ry) + self.radius
        scale = self.scale + abs(cx) + abs(cy) + reach
        # The robot stays within `reach` of c while it turns: only obstacle pieces nearer
        # than that (a lower bound of the distance, see _within) can be met.
        near = self._within(cx, cy, reach, scale)
        lo, hi = min(0.0, A), max(0.0, A)
        n = max(1, math.ceil((hi - lo) / ARC_CHUNK))
        stack = [(lo + (hi - lo) * (i / n), lo + (hi - lo) * ((i + 1) / n)) for i in range(n - 1, -1, -1)]
        floor_len = FLOOR_REL * self.extent
        while stack:
            a, b = stack.pop()
            if not self._arc_in_bounds(cx, cy, rx, ry, a, b):
                self.checks["motion_collisions"] += 1
                return False  # the reference point leaves the bounds
            budget[0] -= 1
            self.checks["arc_sweeps"] += 1
            if not near.size or not any(self._turn_hits(p, nrm, cx, cy, a, b, scale, near)
                                        for p, nrm in zip(pieces, normals)):
                continue
            m = 0.5 * (a + b)
            c, s = math.cos(m), math.sin(m)
            if not self._pose(cx + rx * c - ry * s, cy + rx * s + ry * c, wrap_angle(th + m)):
                self.checks["motion_collisions"] += 1
                return False  # an exact pose in collision
            if reach * (b - a) <= floor_len or budget[0] <= 0 or not (a < m < b):
                self.checks["motion_floor"] += 1
                return False  # undecided at the floor: conservative
            stack.append((m, b))
            stack.append((a, m))
        return True

    def _within(self, cx: float, cy: float, reach: float, scale: float) -> np.ndarray:
        """Indices of the obstacle pieces that may come within ``reach`` of (cx, cy).

        A piece is out of reach when one of its edge lines has the point on its outer
        side farther than ``reach``: the distance to that line bounds the distance to
        the piece from below. The margin 2δ (:func:`cspace.kernel.slabs.slab.slab_pad` of the
        coordinates) covers the rounding of the unit normals and the products."""
        planes = self._car_planes
        if planes is None:
            planes = self._car_planes = _unit_planes(self.obstacle_pieces)
        ux, uy, off = planes
        if not len(off):
            return np.zeros(0, dtype=np.intp)
        gap = (ux * cx + uy * cy - off).max(axis=1)
        return np.flatnonzero(gap <= reach + 2.0 * slab_pad(scale))

    def _turn_hits(self, piece: list, normals: list, cx: float, cy: float, a: float, b: float, scale: float,
                   near: np.ndarray) -> bool:
        """Might the convex piece (vertex list about the centre c), turned through every
        angle of [a, b] (b − a ≤ π/4), meet an obstacle piece? False is a certificate;
        True may be wrong (it only costs a refinement).

        Every turned vertex lies in its triangle T(v) = {R_a v, R_b v, R_m v / cos(Δ/2)}
        (note, section 1), so the turned piece lies in H = conv ⋃ T(v), padded by δ
        (:func:`cspace.kernel.slabs.slab.slab_pad`) for the rounding of the rotations. H is never
        built: a separating axis needs only H's support, the largest projection of the
        3n triangle points (plus δ·(|nx| + |ny|) for the pad). The axes tried are the
        obstacle piece's edge normals and the piece's own edge normals turned to a, m
        and b; an axis separates only with a gap above a further δ·|n|, which covers
        the rounding of the projections. Plain floats: the pieces are small.
        """
        h = 0.5 * (b - a)
        m = a + h
        k = 1.0 / math.cos(h)
        ca, sa, cb, sb, cm, sm = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(m), math.sin(m)
        pts = []
        for x, y in piece:
            pts.append((x * ca - y * sa + cx, x * sa + y * ca + cy))
            pts.append((x * cb - y * sb + cx, x * sb + y * cb + cy))
            pts.append(((x * cm - y * sm) * k + cx, (x * sm + y * cm) * k + cy))
        xs = [p[0] for p in pts]
        ys = [p[1] for p in pts]
        x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
        d = slab_pad(max(max(-x0, x1, -y0, y1) * 1.5, scale))
        olo, ohi = self._olo[near], self._ohi[near]
        cand = near[(olo[:, 0] <= x1 + d) & (ohi[:, 0] >= x0 - d) & (olo[:, 1] <= y1 + d) & (ohi[:, 1] >= y0 - d)]
        if not cand.size:
            return False
        axes = None
        for i in cand.tolist():
            separated = False
            for nx, ny, off, ln in self._obstacle_edges[i]:  # beyond one of the obstacle's edges?
                lo = min(nx * px + ny * py for px, py in pts)
                if lo - off > d * (abs(nx) + abs(ny) + ln):
                    separated = True
                    break
            if separated:
                continue
            if axes is None:  # the piece's normals turned to a, m and b, with H's support along them
                axes = []
                for nx, ny in normals:
                    for c, s in ((ca, sa), (cm, sm), (cb, sb)):
                        ax, ay = nx * c - ny * s, nx * s + ny * c
                        g = d * (abs(ax) + abs(ay) + math.hypot(ax, ay))
                        axes.append((ax, ay, max(ax * px + ay * py for px, py in pts) + g, g))
            obst = self.obstacle_lists[i]
            for ax, ay, top, g in axes:  # the obstacle beyond H along a turned normal?
                if min(ax * ox + ay * oy for ox, oy in obst) - top > g:
                    separated = True
                    break
            if not separated:
                return True
        return False

    def _arc_in_bounds(self, cx: float, cy: float, rx: float, ry: float, a: float, b: float) -> bool:
        """Does the reference point's arc (about c, from c + R_a r to c + R_b r) stay in bounds?

        The arc's box is spanned by its end points and by the circle's axis-extreme
        points whose angles it passes, computed in floats: the bounds are the state
        space's (OMPL's), checked in floats as OMPL checks states, not an obstacle."""
        xmin, xmax, ymin, ymax = self.bounds
        rho = math.hypot(rx, ry)
        phi0 = math.atan2(ry, rx)
        xs, ys = [], []
        for ang in (a, b):
            c, s = math.cos(ang), math.sin(ang)
            xs.append(cx + rx * c - ry * s)
            ys.append(cy + rx * s + ry * c)
        # Circle angles φ0 + α for α in [a, b]: which of 0, π/2, π, 3π/2 (mod 2π) lie inside?
        for q, (dx, dy) in enumerate(((1, 0), (0, 1), (-1, 0), (0, -1))):
            target = q * 0.5 * math.pi
            k = math.ceil((phi0 + a - target) / (2 * math.pi))
            if target + 2 * math.pi * k <= phi0 + b:
                xs.append(cx + dx * rho)
                ys.append(cy + dy * rho)
        return xmin <= min(xs) and max(xs) <= xmax and ymin <= min(ys) and max(ys) <= ymax


def as_car(cs: SE2CSpace) -> CarCSpace:
    """``cs`` as a :class:`CarCSpace`: itself if it is one, else a car C-space that shares its
    slabs, grids and counters (built once, used by both).

    >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    >>> se2 = SE2CSpace((0, 10, 0, 10), [sq], [np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2]])], slabs=8)
    >>> car = as_car(se2)
    >>> car.checks is se2.checks, as_car(car) is car
    (True, True)
    """
    if isinstance(cs, CarCSpace):
        return cs
    car = CarCSpace.__new__(CarCSpace)
    car.__dict__.update(cs.__dict__)
    return car
