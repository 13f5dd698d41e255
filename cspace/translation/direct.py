"""Robot-vs-obstacle queries without the C-space: GJK on the placed robot, per query.

This module owns the materialisation-free route: a state q is tested by placing the
robot's convex pieces at q and asking GJK whether any meets an obstacle's convex
piece. No Minkowski sum is built. It answers the same questions as
:class:`cspace.translation.cspace.CSpace` (``is_free``, ``clearance``) and one more
(``penetration``, by EPA), at a much higher cost per query (see
``scripts/bench_direct.py``), which is why the C-space is materialised.

Frame. Robot pieces R are given relative to the reference point; the robot at q is
R + q, and q is blocked iff some pair meets: (R_i + q) ∩ O_j ≠ ∅, i.e.
R_i ∩ (O_j − q) ≠ ∅. The test is run in the robot's frame: the robot pieces stay
exact and only the obstacle vertices are shifted, o − q, rounded once. Near a
contact o − q is close to a robot vertex, so the rounding is relative to the
robot's size, not to |q| (an offset of 1e8 costs nothing; o − q is even exact when
o and q agree within a factor 2 per coordinate, Sterbenz, or are integers below
2^53). GJK then decides the shifted pair exactly (touching counts as collision).

Tolerance. Each shifted vertex moves by at most u·|o − q| per coordinate
(u = 2^-53), so the shifted piece is within ``band(q) = √2·u·max|o − q|∞`` (over
the obstacle vertices) of the true one: the answer is exact unless q lies within
band(q) of the C-obstacle boundary. The C-space route rounds its piece vertices
o − r once instead, so it is exact up to √2·u·max|o − r|∞. The two routes can
disagree only for states within the sum of these bands of the C-obstacle boundary.
"""
from __future__ import annotations

import math
import os

import numpy as np

from ..kernel.distance.epa import epa_penetration
from ..kernel.distance.gjk import gjk_distance
from ..kernel.polygons.polygon import as_array

U = 2.0**-53  # unit roundoff of float64
_TINY = 2.0**-1074 * 4  # absolute error of a subnormal result, for completeness


class DirectChecker:
    """Free-state tests by GJK between the robot's pieces at q and the obstacles' pieces.

    ``robot_pieces`` and ``obstacle_pieces`` are convex (K, 2) arrays (a robot
    without pieces is a point). ``bounds`` (xmin, xmax, ymin, ymax), if given, makes
    states outside it not free and drops pairs whose C-obstacle piece cannot meet it
    (as the C-space's pruning does).

    >>> square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    >>> dc = DirectChecker([square], [[[3, 0], [4, 0], [4, 1], [3, 1]]])
    >>> dc.is_free((1, 0)), dc.is_free((2, 0)), dc.clearance((1, 0)), dc.penetration((2.5, 0))
    (True, False, 1.0, 0.5)
    """

    def __init__(self, robot_pieces, obstacle_pieces, bounds=None):
        rob = [as_array(p) for p in robot_pieces] or [np.zeros((1, 2))]
        self.robot_pieces: list[np.ndarray] = rob
        self.obstacle_pieces: list[np.ndarray] = [as_array(p) for p in obstacle_pieces]
        self.bounds = None if bounds is None else tuple(float(v) for v in bounds)
        self.rlo = np.array([p.min(axis=0) for p in rob])
        self.rhi = np.array([p.max(axis=0) for p in rob])
        obs = self.obstacle_pieces
        self.olo = np.array([p.min(axis=0) for p in obs]).reshape(-1, 2)
        self.ohi = np.array([p.max(axis=0) for p in obs]).reshape(-1, 2)
        # The robot's whole box, for the first, per-obstacle cull.
        self.box_lo = self.rlo.min(axis=0)
        self.box_hi = self.rhi.max(axis=0)
        # Pairs (robot piece i, obstacle piece j) whose C-obstacle piece O_j ⊕ (−R_i) has
        # a box [olo − rhi, ohi − rlo] meeting the bounds: the others never matter.
        self.pairs = np.ones((len(rob), len(obs)), dtype=bool)
        if self.bounds is not None and len(obs):
            xmin, xmax, ymin, ymax = self.bounds
            clo = self.olo[None, :, :] - self.rhi[:, None, :]
            chi = self.ohi[None, :, :] - self.rlo[:, None, :]
            self.pairs = ((clo[..., 0] <= xmax) & (chi[..., 0] >= xmin)
                          & (clo[..., 1] <= ymax) & (chi[..., 1] >= ymin))
        self._pair_lists = [np.flatnonzero(self.pairs[:, j]).tolist() for j in range(len(obs))]
        self._rbox = list(zip(self.rlo.tolist(), self.rhi.tolist()))

    # -- construction --------------------------------------------------------------

    @classmethod
    def from_cspace(cls, cs) -> "DirectChecker":
        """Reuse the convex pieces (and bounds) a :class:`cspace.translation.cspace.CSpace` decomposed
        (the robot pieces summed with its margin, if it has one).

        >>> from cspace.translation.cspace import CSpace
        >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
        >>> DirectChecker.from_cspace(cs).is_free((5, 5))
        False
        """
        from ..kernel.minkowski.margin import inflated_pieces

        return cls(inflated_pieces(cs.robot_pieces, getattr(cs, "margin", [])), cs.obstacle_pieces, cs.bounds)

    @classmethod
    def from_scenario(cls, scenario) -> "DirectChecker":
        """Decompose a :class:`Scenario` (or scenario file) into convex pieces; no sums (but
        a margin, if the scene has one, is summed with each robot piece, as the C-space does).

        >>> import os, tempfile
        >>> f = os.path.join(tempfile.mkdtemp(), "s.toml")
        >>> _ = open(f, "w").write("[bounds]\\nxmin=0\\nxmax=4\\nymin=0\\nymax=4\\n[start]\\nx=0.5\\ny=0.5\\n"
        ...     "[goal]\\nx=3.5\\ny=3.5\\n[[obstacles]]\\npolygon=[[1,1],[3,1],[3,3],[1,3]]\\n")
        >>> DirectChecker.from_scenario(f).is_free((2, 2))
        False
        """
        from ..kernel.polygons.decompose import convex_decompose  # a convex shape comes back whole
        from ..io.load import load_scenario
        from ..io.scenario.schema import Scenario

        sc = scenario if isinstance(scenario, Scenario) else load_scenario(os.fspath(scenario))
        obstacles = [p for o in sc.obstacles for p in convex_decompose(o.polygon, o.holes)]
        robot = [p for r in sc.robot for p in convex_decompose(r.polygon)]
        from ..kernel.minkowski.margin import inflated_pieces

        return cls(inflated_pieces(robot, sc.margins()), obstacles, sc.bounds)  # with the scene's margin

    # -- queries ---------------------------------------------------------------------

    def in_bounds(self, x: float, y: float) -> bool:
        """Is (x, y) inside the closed bounds (always, without bounds)?"""
        if self.bounds is None:
            return True
        xmin, xmax, ymin, ymax = self.bounds
        return xmin <= x <= xmax and ymin <= y <= ymax

    def _near(self, x: float, y: float, margin: float = 0.0):
        """Pairs (i, j, O_j − q) whose boxes lie within ``margin`` of each other (robot frame).

        The box of the shifted piece is the shifted box: rounding is monotone, so
        min fl(o − q) = fl(min o − q), and comparing it with the exact robot box never
        drops a pair that meets in the shifted geometry.
        """
        if not len(self.obstacle_pieces):
            return
        lo = self.olo - (x, y)
        hi = self.ohi - (x, y)
        bl, bh = self.box_lo - margin, self.box_hi + margin
        hit = (lo[:, 0] <= bh[0]) & (hi[:, 0] >= bl[0]) & (lo[:, 1] <= bh[1]) & (hi[:, 1] >= bl[1])
        q = np.array((x, y))
        for j in np.flatnonzero(hit).tolist():
            (lx, ly), (hx, hy) = lo[j].tolist(), hi[j].tolist()
            shifted = None
            for i in self._pair_lists[j]:
                (rlx, rly), (rhx, rhy) = self._rbox[i]
                if lx <= rhx + margin and hx >= rlx - margin and ly <= rhy + margin and hy >= rly - margin:
                    if shifted is None:
                        shifted = self.obstacle_pieces[j] - q
                    yield i, j, shifted

    def is_free(self, q) -> bool:
        """Is q a valid state: in bounds, and the robot at q touching no obstacle?

        >>> dc = DirectChecker([[[0, 0], [1, 0], [0, 1]]], [[[1, 0], [2, 0], [2, 1]]])
        >>> dc.is_free((0, 0)), dc.is_free((0.5, 0)), dc.is_free((-0.5, 0))
        (False, False, True)
        """
        x, y = float(q[0]), float(q[1])
        if not self.in_bounds(x, y):
            return False
        for i, _, shifted in self._near(x, y):
            if gjk_distance(self.robot_pieces[i], shifted).status != "separated":
                return False
        return True

    def clearance(self, q) -> float:
        """Distance from the robot at q to the nearest obstacle (0 when not free).

        This is the distance from q to the nearest C-obstacle piece, as
        :meth:`cspace.translation.cspace.CSpace.clearance` measures it (the bounds are not an
        obstacle; inf without obstacle pieces). Pairs are visited in order of their
        box distance, a lower bound, until it exceeds the best distance found.

        >>> DirectChecker([[[0, 0], [1, 0], [0, 1]]], [[[3, 4], [5, 4], [3, 6]]]).clearance((0, 0))
        4.242640687119285
        """
        x, y = float(q[0]), float(q[1])
        if not self.in_bounds(x, y):
            return 0.0
        if not self.pairs.any():
            return math.inf
        if not self.is_free((x, y)):
            return 0.0
        lb = self._pair_box_distance(x, y)
        order = np.argsort(lb, axis=None, kind="stable")
        best = math.inf
        qa = np.array((x, y))
        nobs = len(self.obstacle_pieces)
        for k in order.tolist():
            if lb.flat[k] >= best:
                break
            i, j = divmod(k, nobs)
            best = min(best, gjk_distance(self.robot_pieces[i], self.obstacle_pieces[j] - qa).distance)
        return best

    def _pair_box_distance(self, x: float, y: float) -> np.ndarray:
        """(robot pieces, obstacle pieces) lower bounds: distance between the pair's boxes (inf if pruned)."""
        lo = self.olo - (x, y)
        hi = self.ohi - (x, y)
        dx = np.maximum(np.maximum(lo[None, :, 0] - self.rhi[:, None, 0], self.rlo[:, None, 0] - hi[None, :, 0]), 0.0)
        dy = np.maximum(np.maximum(lo[None, :, 1] - self.rhi[:, None, 1], self.rlo[:, None, 1] - hi[None, :, 1]), 0.0)
        return np.where(self.pairs, np.hypot(dx, dy), np.inf)

    def penetration(self, q) -> float:
        """Largest EPA depth over the overlapping (robot piece, obstacle piece) pairs, else 0.

        A per-pair depth: the translation that frees the robot from that one piece,
        a lower bound on the translation that frees it from all of them.

        >>> DirectChecker([[[0, 0], [2, 0], [2, 2], [0, 2]]], [[[1.5, 0.5], [3, 0.5], [3, 1.5], [1.5, 1.5]]]).penetration((0, 0))
        0.5
        """
        x, y = float(q[0]), float(q[1])
        depth = 0.0
        for i, _, shifted in self._near(x, y):
            p = epa_penetration(self.robot_pieces[i], shifted)
            if p.status == "overlapping":
                depth = max(depth, float(p.depth))
        return depth

    def band(self, q) -> float:
        """Rounding band of the answer at q: the shift o − q moves no obstacle vertex further.

        √2·u·max|o − q|∞ over all obstacle vertices (a bound through their boxes), plus
        a subnormal's error. 0 when every o − q is exact is not detected: a bound.

        >>> DirectChecker([[[0, 0], [1, 0], [0, 1]]], [[[3, 0], [4, 0], [4, 1]]]).band((0, 0)) < 1e-15
        True
        """
        if not len(self.obstacle_pieces):
            return 0.0
        x, y = float(q[0]), float(q[1])
        m = max(float(np.abs(self.olo - (x, y)).max()), float(np.abs(self.ohi - (x, y)).max()))
        return math.sqrt(2.0) * U * m * (1.0 + 2.0 * U) + _TINY


def cspace_band(cs) -> float:
    """Rounding band of the C-space route: its piece vertices fl(o − r) move at most this far.

    √2·u·max|o − r|∞ over obstacle vertices o and robot vertices r (through their boxes).

    >>> from cspace.translation.cspace import CSpace
    >>> cspace_band(CSpace((0, 8, 0, 8), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])) < 1e-14
    True
    """
    if not len(cs.obstacle_pieces):
        return 0.0
    olo = np.array([p.min(axis=0) for p in cs.obstacle_pieces])
    ohi = np.array([p.max(axis=0) for p in cs.obstacle_pieces])
    from ..kernel.minkowski.margin import inflated_pieces

    rob = inflated_pieces(cs.robot_pieces, getattr(cs, "margin", [])) or [np.zeros((1, 2))]
    rlo = np.array([p.min(axis=0) for p in rob]).min(axis=0)
    rhi = np.array([p.max(axis=0) for p in rob]).max(axis=0)
    m = max(float(np.abs(olo - rhi).max()), float(np.abs(olo - rlo).max()),
            float(np.abs(ohi - rhi).max()), float(np.abs(ohi - rlo).max()))
    return math.sqrt(2.0) * U * m * (1.0 + 2.0 * U) + _TINY
