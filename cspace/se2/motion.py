"""Certified SE(2) motions: OMPL's interpolation, split at slab boundaries, refined by swept hulls.

This module owns "is every pose of the motion q0 -> q1 free?" for :class:`cspace.se2.cspace.SE2CSpace`
(note se2-rotation.md, section 2). The motion is OMPL's SE(2) interpolation
(:func:`interpolate`). It is split where its angle crosses a slab boundary; on a
sub-motion whose angles stay in slab k the robot is in p(t) + H (H the slab hulls), so
the reference segment being free in slab k's C-space certifies the whole sub-motion.
Otherwise the sub-motion is refined: its own hull (over its own, smaller angle range)
swept along its segment, H' ⊕ seg, is tested exactly (separating axes, exact
predicate) against the obstacle pieces near it, and halved on a hit, until an exact
pose in collision is found (False) or the sweep is under a floor of size or the
budget of sweeps is spent (False, counted as ``motion_floor``: conservative, never a
false "free"). A motion at one fixed angle is decided exactly: the segment against
the sums obstacle piece ⊕ −(robot piece at θ), the translation C-space's semantics.
"""
from __future__ import annotations

import math

import numpy as np

from ..compiled import motions
from .pose_checks import se2_pose
from ..kernel.distance.gjk import exact_relation
from ..kernel.minkowski.merge import minkowski_sum, reflect
from ..kernel.polygons.pieces import PieceSet
from ..kernel.slabs.slab import ANGLE_SLACK, slab_hull
from ..kernel.polygons.rotation import TWO_PI, rotate_piece, wrap_angle

# Refinement of a motion stops (answer "not free", counted) when the sub-motion's
# sweep is smaller than this fraction of the scene's extent...
FLOOR_REL = 1e-9
# ... or after this many swept hulls for one motion (never a hang).
MAX_REFINE = 2048


def interpolate(q0, q1, t: float) -> tuple[float, float, float]:
    """The pose at fraction t of the motion q0 -> q1, exactly as OMPL's SE2StateSpace computes it.

    x and y: ``from + (to - from) * t`` (RealVectorStateSpace). θ (SO2StateSpace):
    ``diff = to - from``; if ``|diff| <= π`` then ``from + diff * t``; otherwise along
    the shorter arc the other way, ``from - d * t`` with ``d = 2π - diff`` (diff > 0)
    or ``-2π - diff``, then wrapped back by one turn if it left [−π, π]. Both ends
    must already be in [−π, π] (OMPL's states are).

    >>> interpolate((0, 0, 3.0), (2, 4, -3.0), 0.75)  # through π, the shorter way
    (1.5, 3.0, -3.0707963267948966)
    """
    x0, y0, a = float(q0[0]), float(q0[1]), float(q0[2])
    x1, y1, b = float(q1[0]), float(q1[1]), float(q1[2])
    t = float(t)
    diff = b - a
    if abs(diff) <= math.pi:
        th = a + diff * t
    else:
        diff = TWO_PI - diff if diff > 0.0 else -TWO_PI - diff
        th = a - diff * t
        if th > math.pi:
            th -= TWO_PI
        elif th < -math.pi:
            th += TWO_PI
    return x0 + (x1 - x0) * t, y0 + (y1 - y0) * t, th


def turn_arc(a: float, b: float) -> float:
    """The signed angle swept by OMPL's interpolation from a to b (|result| <= π)."""
    diff = b - a
    if abs(diff) <= math.pi:
        return diff
    return diff - TWO_PI if diff > 0.0 else diff + TWO_PI


class SE2Motions:
    """The motion queries of :class:`cspace.se2.cspace.SE2CSpace` (a mixin: it reads the C-space's
    pieces, slabs, pose test and counters)."""

    # The compiled motion check (motions.se2_motion), made on the first motion; None: pure.
    _motion_fast = False

    def motion_free(self, q0, q1) -> bool:
        """Is every pose of OMPL's SE(2) interpolation from q0 to q1 free? Certified.

        True only if every pose is free (slab certificates or exact sweeps); False on
        an exact pose in collision, or (counted in ``checks["motion_floor"]``) when
        refinement reaches its floor without deciding.
        """
        (x0, y0, a0), (x1, y1, a1) = se2_pose(q0, "q0"), se2_pose(q1, "q1")  # raises on junk
        self.checks["motions"] += 1
        a0, a1 = wrap_angle(a0), wrap_angle(a1)
        if not (self._pose(x1, y1, a1) and self._pose(x0, y0, a0)):
            self.checks["motion_collisions"] += 1
            return False
        fast = self._motion_fast
        if fast is False:  # first motion: the compiled check, or None on the pure path
            fast = self._motion_fast = motions.se2_motion(self, MAX_REFINE, FLOOR_REL)
            self._motion_grids = [None] * self.slabs
        if fast is not None:
            grids = self._motion_grids
            while True:  # one call; a slab not built yet is built and the call repeated
                r = fast(grids, x0, y0, a0, x1, y1, a1)
                if r >= 0:
                    return r == 1  # certified (see cspace/compiled/_se2motion.c), counted there
                if r == -1:
                    break  # undecided: the pure path below decides, from the start
                k = -2 - r
                handle = self.slab(k)._fast
                if handle is None:
                    break
                grids[k] = handle
        return self._motion_pure(x0, y0, a0, x1, y1, a1)

    def _motion_pure(self, x0: float, y0: float, a0: float, x1: float, y1: float, a1: float) -> bool:
        """:meth:`motion_free` after its end poses, on the pure path (the oracle)."""
        D = turn_arc(a0, a1)
        budget = [MAX_REFINE]
        for ta, tb in self._split(a0, D):
            self.checks["submotions"] += 1
            pa = (x0, y0) if ta == 0.0 else (x0 + (x1 - x0) * ta, y0 + (y1 - y0) * ta)
            pb = (x1, y1) if tb == 1.0 else (x0 + (x1 - x0) * tb, y0 + (y1 - y0) * tb)
            mid = wrap_angle(a0 + D * (0.5 * (ta + tb)))
            k = self._slab_index(mid)
            if self.slab(k).segment_free(pa, pb):
                self.checks["slab_certified"] += 1
                continue
            if not self.robot_pieces:  # a point robot: the one slab is the exact C-space
                self.checks["motion_collisions"] += 1
                return False
            ok = self._refine((x0, y0, a0), (x1, y1), D, ta, tb, budget)
            if not ok:
                return False
        return True

    def _split(self, a0: float, D: float) -> list[tuple[float, float]]:
        """Fractions [ta, tb] of the motion whose angles a0 + D t each stay in one slab."""
        K = self.slabs
        if D == 0.0 or K == 1:
            return [(0.0, 1.0)]
        w = TWO_PI / K
        a1 = a0 + D
        lo, hi = min(a0, a1), max(a0, a1)
        j0, j1 = math.floor((lo + math.pi) / w) + 1, math.ceil((hi + math.pi) / w) - 1
        cuts = sorted({min(max((-math.pi + j * w - a0) / D, 0.0), 1.0) for j in range(j0, j1 + 1)})
        ts = [0.0] + [c for c in cuts if 0.0 < c < 1.0] + [1.0]
        return list(zip(ts[:-1], ts[1:]))

    def _refine(self, p0, p1, D: float, ta: float, tb: float, budget: list) -> bool:
        """Decide the sub-motion [ta, tb] with swept hulls, halving on a hit (see module doc)."""
        x0, y0, a0 = p0
        x1, y1 = p1
        self.checks["refined"] += 1
        floor_len = FLOOR_REL * self.extent
        stack = [(ta, tb)]
        while stack:
            sa, sb = stack.pop()
            pa = (x0, y0) if sa == 0.0 else (x0 + (x1 - x0) * sa, y0 + (y1 - y0) * sa)
            pb = (x1, y1) if sb == 1.0 else (x0 + (x1 - x0) * sb, y0 + (y1 - y0) * sb)
            if D == 0.0:
                if self._translation_hits(pa, pb, a0):
                    self.checks["motion_collisions"] += 1
                    return False  # the exact translational answer at a0
                continue
            fa, fb = a0 + D * sa, a0 + D * sb
            lo, hi = min(fa, fb) - ANGLE_SLACK, max(fa, fb) + ANGLE_SLACK
            budget[0] -= 1
            self.checks["sweeps"] += 1
            if not self._sweep_hits(pa, pb, lo, hi):
                continue
            sm = 0.5 * (sa + sb)
            xm, ym, am = x0 + (x1 - x0) * sm, y0 + (y1 - y0) * sm, wrap_angle(a0 + D * sm)
            if not self._pose(xm, ym, am):
                self.checks["motion_collisions"] += 1
                return False  # a real collision
            size = self.radius * (hi - lo) + math.hypot(pb[0] - pa[0], pb[1] - pa[1])
            if size <= floor_len or budget[0] <= 0 or not (sa < sm < sb):
                self.checks["motion_floor"] += 1
                return False  # undecided at the floor: conservative
            stack.append((sm, sb))
            stack.append((sa, sm))
        return True

    def _sweep_hits(self, pa, pb, lo: float, hi: float) -> bool:
        """Does some robot piece's hull over [lo, hi], swept along pa-pb, meet an obstacle piece?
        Exact on the computed sweep (separating axes with the exact predicate)."""
        seg = np.array([pa, pb], dtype=np.float64)
        for p in self.robot_pieces:
            # The hull of a sub-range of a slab is built in unwrapped angles; the rotation
            # by lo is the rotation by lo ± 2π up to rounding, which the pad covers.
            sweep = minkowski_sum(slab_hull(p, lo, hi, scale=self.scale), seg)
            smin, smax = sweep.min(axis=0), sweep.max(axis=0)
            cand = np.flatnonzero((self._olo[:, 0] <= smax[0]) & (self._ohi[:, 0] >= smin[0])
                                  & (self._olo[:, 1] <= smax[1]) & (self._ohi[:, 1] >= smin[1]))
            for i in cand.tolist():
                if exact_relation(sweep, self.obstacle_pieces[i]) != "separated":
                    return True
        return False

    def _translation_hits(self, pa, pb, th: float) -> bool:
        """Does the segment pa-pb meet a sum obstacle piece ⊕ −(robot piece at θ)? Exact:
        the translation C-space's own segment semantics at the angle θ."""
        r = self.radius * (1.0 + 2.0**-40) + self.pad  # rotated vertices may round past r
        lo = np.minimum(pa, pb) - r
        hi = np.maximum(pa, pb) + r
        cand = np.flatnonzero((self._olo[:, 0] <= hi[0]) & (self._ohi[:, 0] >= lo[0])
                              & (self._olo[:, 1] <= hi[1]) & (self._ohi[:, 1] >= lo[1]))
        if not cand.size:
            return False
        neg = [reflect(rotate_piece(p, th)) for p in self.robot_pieces]
        sums = [minkowski_sum(self.obstacle_pieces[i], n) for i in cand.tolist() for n in neg]
        ps = PieceSet(sums)
        return bool(ps.segment_hits_many(np.arange(len(sums)), pa, pb).any())
