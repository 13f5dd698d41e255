"""The C-space of a robot that translates and rotates (SE(2)), sliced into angle slabs.

This module owns the SE(2) queries (note se2-rotation.md, sections 1 and 2). The
circle of angles is cut into K slabs; slab k holds, for each convex robot piece, its
slab hull H (:func:`cspace.kernel.slabs.slab.slab_hull`, a convex superset of the piece at every
angle of the slab), and is a plain translational :class:`CSpace` of those hulls:

- a reference point free in slab k's C-space is free at EVERY angle of the slab (a
  certificate, not a sample);
- a reference point inside the slab's *inner* C-space (the obstacles summed with each
  robot piece's part that stays inside it through the whole slab,
  :func:`cspace.kernel.slabs.slab.slab_inner`) collides at every angle of the slab (certified blocked);
- anything else gets the exact test at its own angle: the body-frame robot pieces
  rotated by :func:`cspace.kernel.slabs.slab.rotate`, then exactly the translation C-space's
  semantics (is (x, y) in the computed sum obstacle piece ⊕ −(rotated piece), closed).

"The pose (x, y, θ)" always means: θ wrapped into [−π, π) as OMPL does, each robot
piece turned by :func:`rotate_piece`, translated by (x, y). Slabs are built lazily, on
first use, and cached. Everything is deterministic.

Motions (OMPL's SE(2) interpolation, certified) are :mod:`cspace.se2.motion`; a car's
curves (straight segments and turning arcs) are certified by its subclass
:class:`cspace.car.motion.CarCSpace`.
"""
from __future__ import annotations

import itertools
import math
import time

import numpy as np

from ..compiled import fastpath
from ..translation.broadphase import GridIndex
from ..translation.cspace import CSpace
from ..translation.build import check_range, contained_pieces, decompose_obstacles, decompose_robot, inflated, pair_sums
from .pair_filter import pair_filter
from .pose_checks import check_pieces, check_robot, se2_pose
from .slab_build import build_slabs, slab_run
from ..kernel.minkowski.merge import minkowski_sum, reflect
from ..kernel.polygons.polygon import is_convex, point_in_convex
from ..io.load import load_scenario
from ..io.scenario.schema import MAX_ROTATING_VERTICES, MAX_SLABS, Scenario
from .motion import SE2Motions, interpolate  # noqa: F401  (interpolate: part of this module's API)
from ..kernel.slabs.slab import ANGLE_SLACK, edge_planes, typical_gap, default_slabs, robot_radius, slab_hull, slab_inner, slab_of, slab_pad, slab_range
from ..kernel.polygons.rotation import TWO_PI, rotate_piece, wrap_angle

# Grid cells of each slab's C-space (unless grid_cells is given): a quarter of the
# translation C-space's default. The grid build dominates a slab's cost (K of them),
# and the SE(2) hot path reads the slab grid once per state either way.
SLAB_GRID_CELLS = 1 << 12


class SE2CSpace(SE2Motions):
    """C-space of a rotating polygonal robot: K lazily built angle slabs plus exact tests.

    >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    >>> bar = np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])
    >>> cs = SE2CSpace((0, 10, 0, 10), [sq], [bar], slabs=16)
    >>> cs.is_free((3.1, 5, 0.0)), cs.is_free((3.1, 5, math.pi / 2)), cs.is_free((5, 5, 1.0))
    (False, True, False)
    >>> cs.motion_free((2.5, 2, 0), (7.5, 2, 0)), cs.motion_free((3.1, 5, math.pi / 2), (3.1, 5, -math.pi / 2))
    (True, False)
    """

    def __init__(self, bounds, obstacles: list[np.ndarray] | None = None, robot: list[np.ndarray] | None = None,
                 *, obstacle_holes: list[list[np.ndarray]] | None = None, robot_is_disk: bool = False,
                 slabs: int | None = None, grid_cells: int | None = None, margin: list[np.ndarray] | None = None):
        t0 = time.perf_counter()
        self.bounds = tuple(float(v) for v in bounds)
        obstacles = obstacles or []
        check_robot(robot)
        check_range(self.bounds, obstacles + (robot or []))
        self.obstacle_pieces, self.obstacle_of, _ = decompose_obstacles(obstacles, obstacle_holes)
        self.robot_pieces, _ = decompose_robot(robot or [], robot_is_disk)
        # A safety margin (cspace.kernel.minkowski.margin) is summed with each body-frame robot piece in one
        # merge, so it turns with the robot (a disk margin is the same at every angle, up to
        # its polygon, which the slab hulls cover); a point robot becomes the margin itself.
        self.margin = [np.asarray(m, dtype=np.float64) for m in (margin or [])]
        self.body_pieces = self.robot_pieces  # the robot itself, for clearance measures
        # Pieces INSIDE the shapes as written (a disk's inscribed polygon): what a proof that no
        # path exists is made of (from_scenario sets them for disks; polygons: the same pieces).
        self.inner_obstacle_pieces, self.inner_body_pieces = self.obstacle_pieces, self.body_pieces
        if self.margin:
            self.robot_pieces = inflated(self.robot_pieces, self.margin)
        check_pieces(self.robot_pieces, MAX_ROTATING_VERTICES)
        self.grid_cells = grid_cells
        xmin, xmax, ymin, ymax = self.bounds
        self.extent = max(xmax - xmin, ymax - ymin)
        self.radius = robot_radius(self.robot_pieces)
        # Magnitude of every coordinate the slab hulls are summed with (obstacles, bounds,
        # positions along motions): the slab pad scales with it (slab_pad).
        self.scale = max([abs(v) for v in self.bounds]
                         + [float(np.abs(p).max()) for p in self.obstacle_pieces if len(p)])
        self.pad = slab_pad(self.radius * math.sqrt(2.0) + self.scale)
        if slabs is None:
            gap = typical_gap(self.obstacle_pieces, self.extent)
            self.slabs, self.slabs_reason = default_slabs(self.radius, self.extent, gap)
        else:
            if isinstance(slabs, bool) or not isinstance(slabs, int) or not 4 <= slabs <= MAX_SLABS:
                if not (slabs == 1 and not self.robot_pieces):  # a slab's regions cost work: bounded as a file's
                    raise ValueError(f"SE2CSpace: slabs must be an integer from 4 to {MAX_SLABS}, got {slabs!r}")
            self.slabs, self.slabs_reason = slabs, f"K = {slabs}: given"
        if not self.robot_pieces:
            self.slabs, self.slabs_reason = 1, "K = 1: a point robot does not turn"
        K = self.slabs
        # Each slab's angle interval, widened by ANGLE_SLACK: what its hulls are built for.
        self._lo = [slab_range(k, K)[0] - ANGLE_SLACK for k in range(K)] if K > 1 else [-math.inf]
        self._hi = [slab_range(k, K)[1] + ANGLE_SLACK for k in range(K)] if K > 1 else [math.inf]
        self._outer: list = [None] * K  # slab k's CSpace (robot = slab hulls)
        self._inner: list = [None] * K  # slab k's certified-blocked cells (a bool per cell of its grid), or False
        self._tests: list = [None] * K  # (outer point test, None)
        self._grids: list = [None] * K  # the one-lookup grid of each slab (see _combined_grid)
        self._built: list[dict] = []
        self._convex = None
        self._nest = None  # _sums_nest's answer, once
        olo = np.array([p.min(axis=0) for p in self.obstacle_pieces]).reshape(-1, 2)
        ohi = np.array([p.max(axis=0) for p in self.obstacle_pieces]).reshape(-1, 2)
        self._olo, self._ohi = olo, ohi
        # Plain lists for the float filter of the exact test (see :func:`cspace.se2.pair_filter.pair_filter`).
        self.obstacle_lists = [p.tolist() for p in self.obstacle_pieces]
        self._obstacle_edges = [edge_planes(p) for p in self.obstacle_pieces]
        self._robot_lists = [p.tolist() for p in self.robot_pieces]
        self._robot_normals = [[(nx, ny, ln) for nx, ny, _, ln in edge_planes(p)] for p in self.robot_pieces]
        self._pair_grid()
        self._fast = fastpath.se2_handle(self)  # the compiled filter stage (None: pure path)
        self._fast_pose = None if self._fast is None else fastpath.se2_pose()
        self.checks = {"states": 0, "exact_states": 0, "motions": 0, "motion_collisions": 0,
                       "motion_floor": 0, "exact_sums": 0, "slab_certified": 0, "refined": 0, "sweeps": 0, "submotions": 0,
                       "curves": 0, "arcs": 0, "arc_sweeps": 0}
        self._states = itertools.count()
        self._pose = self.pose_test(self._states.__next__)
        self.setup_seconds = time.perf_counter() - t0

    @classmethod
    def from_scenario(cls, scenario, slabs: int | None = None, grid_cells: int | None = None) -> "SE2CSpace":
        """The SE(2) C-space of a :class:`Scenario` (or a file path); ``sc.robot`` is the body frame.

        >>> import os, tempfile
        >>> f = os.path.join(tempfile.mkdtemp(), "s.toml")
        >>> _ = open(f, "w").write("[bounds]\\nxmin=0\\nxmax=4\\nymin=0\\nymax=4\\n[start]\\nx=0.5\\ny=0.5\\n"
        ...     "[goal]\\nx=3.5\\ny=3.5\\n[robot]\\npolygon=[[0,0],[0.2,0],[0,0.2]]\\n"
        ...     "[[obstacles]]\\npolygon=[[1,1],[3,1],[3,3],[1,3]]\\n")
        >>> SE2CSpace.from_scenario(f, slabs=8).is_free((2, 2, 0.3))
        False
        """
        sc = scenario if isinstance(scenario, Scenario) else load_scenario(str(scenario))
        cs = cls(sc.bounds, [o.polygon for o in sc.obstacles], [r.polygon for r in sc.robot],
                 obstacle_holes=[o.holes for o in sc.obstacles], robot_is_disk=sc.robot_kind == "disk",
                 slabs=slabs, grid_cells=grid_cells, margin=sc.margins())
        cs.scenario = sc
        if sc.has_disks:
            from ..translation.build import inner_pieces

            cs.inner_obstacle_pieces, cs.inner_body_pieces = inner_pieces(sc)
        return cs

    # -- slabs -------------------------------------------------------------------------

    def slab(self, k: int) -> CSpace:
        """Slab k's translational C-space (robot pieces = their slab hulls), built on first use."""
        if self._outer[k] is None:
            self._build(k)
        return self._outer[k]

    def _build(self, k: int) -> None:
        t = time.perf_counter()
        if self.slabs == 1:  # point robot: one C-space, the obstacles themselves
            outer = CSpace(self.bounds, self.obstacle_pieces, [], grid_cells=self.grid_cells, normalized=True)
            self._outer[k], self._inner[k] = outer, False
            self._tests[k] = (outer.point_test(), None)
            self._grids[k] = self._combined_grid(k, outer, None)
            self._built.append({"slab": k, "seconds": time.perf_counter() - t, "pieces": len(outer.pieces),
                                "inner_pieces": 0})
            return
        if fastpath.compiled():  # the slabs of k's run at once (cspace.se2.slab_build): the same slabs
            self._build_run(k)
            return
        a, b = self._lo[k], self._hi[k]
        hulls = [slab_hull(p, a, b, scale=self.scale) for p in self.robot_pieces]
        if self._convex is None:  # the pieces' exact convexity, once for all slabs (all True)
            self._convex = [is_convex(p) for p in self.obstacle_pieces]
        outer = CSpace(self.bounds, self.obstacle_pieces, hulls, grid_cells=self.grid_cells or SLAB_GRID_CELLS,
                       normalized=True, obstacle_convex=self._convex, nested=self._sums_nest())  # decomposed, CCW pieces: no input conversion per slab
        t_outer = time.perf_counter() - t
        if len(outer.obstacle_pieces) != len(self.obstacle_pieces) or len(outer.robot_pieces) != len(hulls):
            # piece_pairs index our pieces: the slab must keep them as given (they are convex)
            raise RuntimeError("SE2CSpace: a slab re-decomposed a convex piece")  # pragma: no cover
        inner_pieces = [j for j in (slab_inner(p, a, b, self.pad) for p in self.robot_pieces) if len(j) >= 3]
        g = outer.index
        inner = False
        if inner_pieces and self.obstacle_pieces:
            # Only the inner grid's BLOCKED cells are used (everything else goes to the
            # exact test), so the inner set is a grid over its sums, not a whole CSpace.
            neg = [reflect(p) for p in inner_pieces]
            sums = pair_sums(self.obstacle_pieces, neg)  # minkowski_sum's arrays, pair for pair
            inner = GridIndex.blocked_cells(sums, self.bounds, (g.nx, g.ny))
        self._outer[k], self._inner[k] = outer, inner
        self._tests[k] = (outer.point_test(), None)
        self._grids[k] = self._combined_grid(k, outer, inner)
        self._built.append({"slab": k, "seconds": time.perf_counter() - t, "outer_seconds": t_outer,
                            "pieces": len(outer.pieces), "inner_pieces": len(inner_pieces)})

    def _build_run(self, k: int) -> None:
        """Slab k and the other unbuilt slabs of its run (:func:`slab_run`), built together
        by :func:`build_slabs`: the same C-spaces and grids as :meth:`_build` makes one by one."""
        pairs = len(self.obstacle_pieces) * 2 * len(self.robot_pieces)
        ks = [j for j in slab_run(k, self.slabs, pairs) if self._outer[j] is None]
        built = build_slabs(self.bounds, self.obstacle_pieces, self.robot_pieces, [self._lo[j] for j in ks],
                            [self._hi[j] for j in ks], scale=self.scale, pad=self.pad,
                            grid_cells=self.grid_cells or SLAB_GRID_CELLS, obstacles_checked=True,
                            nested=self._sums_nest())
        for j, (outer, inner, n_inner, seconds, outer_seconds) in zip(ks, built):
            t = time.perf_counter()
            self._outer[j], self._inner[j] = outer, inner
            self._tests[j] = (outer._point_uncounted, None)  # outer.point_test(): the one it made
            self._grids[j] = self._combined_grid(j, outer, inner)
            self._built.append({"slab": j, "seconds": seconds + time.perf_counter() - t, "outer_seconds": outer_seconds,
                                "pieces": len(outer.pieces), "inner_pieces": n_inner})

    def _sums_nest(self) -> bool:
        """May a slab's sums lie inside one another? With one robot piece, only where obstacle
        pieces do (Rådström's cancellation; see :meth:`CSpace._prune`): asked once."""
        if self._nest is None:
            self._nest = len(self.robot_pieces) != 1 or bool(contained_pieces(self.obstacle_pieces))
        return self._nest

    def _combined_grid(self, k: int, outer: CSpace, inner) -> tuple:
        """Slab k's one-lookup grid: per cell 0 (FREE in the slab C-space: free at every
        angle), 2 (BLOCKED in the inner C-space: blocked at every angle) or 1 (the slow
        path: the slab's own point test, then the exact test), one bytes object per row
        with a border cell (3) at its end and a border row after the last, as in
        :meth:`CSpace.point_test`. The inner grid (its BLOCKED cells,
        :meth:`GridIndex.blocked_cells`) shares the outer grid's cells."""
        from ..translation.broadphase import FREE

        g = outer.index
        state = (g.state != FREE).view(np.uint8)
        if inner is not False and inner is not None:
            assert inner.shape == (g.nx * g.ny,)
            state = state + (inner & (state == 1)).view(np.uint8)
        flat = state.tobytes()
        nx, ny = g.nx, g.ny
        rows = [flat[r * nx:(r + 1) * nx] + b"\x03" for r in range(ny)] + [b"\x03" * (nx + 1)]
        outer_test = self._tests[k][0]
        # A point robot's one slab is its exact C-space: its point test is the answer.
        exact = self._exact if self.robot_pieces else (lambda x, y, th, k: False)

        def slow(x: float, y: float, th: float) -> bool:
            if outer_test(x, y):
                return True  # free in the slab: free at every angle of it
            return exact(x, y, th, k)

        slow = fastpath.se2_slow_test(outer._fast, self._fast, slow, self.checks)  # compiled, if built
        return rows, g.inv_w, g.x0 * g.inv_w, g.inv_h, g.y0 * g.inv_h, slow

    def _slab_index(self, th: float) -> int:
        """Slab of an angle already in [−π, π)."""
        return slab_of(th, self.slabs) if self.slabs > 1 else 0

    # -- states ------------------------------------------------------------------------

    def in_bounds(self, x: float, y: float) -> bool:
        xmin, xmax, ymin, ymax = self.bounds
        return xmin <= x <= xmax and ymin <= y <= ymax

    def is_free(self, q) -> bool:
        """Is the pose q = (x, y, θ) valid: reference point in bounds, robot touching nothing?
        (ValueError for a non-finite pose, TypeError or ValueError for a malformed one.)"""
        return self._pose(*se2_pose(q, "q"))

    def pose_test(self, tick=None, state: bool = False):
        """A fast ``(x, y, theta) -> bool`` free-pose test: the validity checker's hot path.

        Slab lookup (two comparisons certify the float slab index), then the slab's
        grid: FREE in the slab C-space is free at every angle of the slab; inside the
        inner C-space is blocked at every angle; anything else goes to the exact test
        at θ. ``tick`` is called once per query; with ``state`` the test takes one
        indexable ``q`` (``q[0], q[1], q[2]``).

        >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
        >>> cs = SE2CSpace((0, 10, 0, 10), [sq], [np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])], slabs=8)
        >>> f = cs.pose_test()
        >>> f(1.0, 1.0, 0.3), f(5.0, 5.0, -2.0), cs.pose_test(state=True)([2.9, 5.0, 1.5707963])
        (True, False, True)
        """
        K = self.slabs
        per = K / TWO_PI
        lo, hi, grids = self._lo, self._hi, self._grids
        build = self._build
        pi, wrap, slab_of_ = math.pi, wrap_angle, self._slab_index
        count = int if tick is None else tick  # int() is a C-level no-op
        floor = math.floor

        def free_q(q) -> bool:
            count()
            x = q[0]
            y = q[1]
            th = q[2]
            if not -pi <= th < pi:
                th = wrap(th)
            k = floor((th + pi) * per)
            if k >= K or not lo[k] <= th <= hi[k]:  # the float index is certified by two comparisons
                k = slab_of_(th)
            g = grids[k]
            if g is None:
                build(k)
                g = grids[k]
            rows, iw, a0, ih, b0, slow = g
            i = x * iw - a0
            j = y * ih - b0
            if i >= 0.0 and j >= 0.0:  # also False for NaN
                try:
                    c = rows[floor(j)][floor(i)]
                except (IndexError, OverflowError):
                    return slow(x, y, th)  # off the grid's top or right
                if not c:
                    return True  # FREE in the slab C-space
                if c == 2:
                    return False  # BLOCKED in the inner C-space
            return slow(x, y, th)

        if state:
            return free_q

        def free(x: float, y: float, th: float) -> bool:
            return free_q((x, y, th))

        return free

    def _exact(self, x: float, y: float, th: float, k: int) -> bool:
        """The exact test at θ (already wrapped): (x, y) against the sums obstacle piece ⊕
        −(robot piece at θ) of the pairs near (x, y); a pair whose obstacle box is farther
        than the robot piece's (grown) radius is skipped, the others go through the float
        filter, and only an undecided pair builds its sum."""
        self.checks["exact_states"] += 1
        if not self.in_bounds(x, y):
            return False
        c, sn = math.cos(th), math.sin(th)
        if self._fast is not None:  # compiled: the same filter, certified answers only
            r = self._fast_pose(self._fast, x, y, c, sn)
            if r >= 0:
                return r == 1
        rotated: dict = {}
        margin = self.pad
        for i, j, o_edges, o_pts, r_normals, bx0, by0, bx1, by1 in self._cell_pairs(k, x, y):
            if x < bx0 or x > bx1 or y < by0 or y > by1:
                continue  # beyond the robot piece's reach of this obstacle's box
            got = rotated.get(j)
            if got is None:  # rotate() in scalars: the same IEEE operations, the same doubles
                r = [(vx * c - vy * sn + 0.0, vx * sn + vy * c + 0.0) for vx, vy in self._robot_lists[j]]
                # −R''s outward normals: minus R''s (the body normals turned); edge e ends at vertex e.
                axes = [(-(bx * c - by * sn), -(bx * sn + by * c), r[e][0], r[e][1], ln)
                        for e, (bx, by, ln) in enumerate(r_normals)]
                got = rotated[j] = (r, axes)
            side = pair_filter(o_edges, o_pts, got[0], got[1], x, y, margin)
            if side < 0:
                return False  # inside the sum by more than its rounding: the exact answer too
            if side > 0:
                continue  # outside by more than the rounding
            self.checks["exact_sums"] += 1
            neg = reflect(rotate_piece(self.robot_pieces[j], th))
            if point_in_convex(minkowski_sum(self.obstacle_pieces[i], neg), x, y) >= 0:
                return False
        return True

    def _pair_grid(self) -> None:
        """A coarse grid over the bounds (at most 64 x 64, one for all slabs): per cell, the
        (obstacle piece, robot piece) pairs whose sum may hold a point of the cell, with
        the filter's data. The sum O ⊕ −R_θ lies in O's box grown by R's radius r_j at
        every θ (grown further by 2^-40 r_j and the pad for the rotation's rounding)."""
        xmin, xmax, ymin, ymax = self.bounds
        n = 64
        self._pg_n, self._pg_x0, self._pg_y0 = n, xmin, ymin
        self._pg_iw, self._pg_ih = n / (xmax - xmin), n / (ymax - ymin)
        cells: list[list] = [[] for _ in range(n * n)]
        for j, p in enumerate(self.robot_pieces):
            grow = float(np.hypot(p[:, 0], p[:, 1]).max()) * (1.0 + 2.0**-40) + self.pad
            for i in range(len(self.obstacle_pieces)):
                lo, hi = self._olo[i] - grow, self._ohi[i] + grow
                i0 = max(math.floor((lo[0] - xmin) * self._pg_iw) - 1, 0)
                i1 = min(math.floor((hi[0] - xmin) * self._pg_iw) + 1, n - 1)
                j0 = max(math.floor((lo[1] - ymin) * self._pg_ih) - 1, 0)
                j1 = min(math.floor((hi[1] - ymin) * self._pg_ih) + 1, n - 1)
                entry = (i, j, self._obstacle_edges[i], self.obstacle_lists[i], self._robot_normals[j],
                         float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
                for cj in range(j0, j1 + 1):
                    for ci in range(i0, i1 + 1):
                        cells[cj * n + ci].append(entry)
        self._pg_cells = cells

    def _cell_pairs(self, k: int, x: float, y: float) -> list:
        """The pairs whose sum may hold (x, y) at an angle of slab k (see :meth:`_pair_grid`;
        the cells are widened by one on each side against the rounding of the cell index)."""
        n = self._pg_n
        ci = min(max(math.floor((x - self._pg_x0) * self._pg_iw), 0), n - 1)
        cj = min(max(math.floor((y - self._pg_y0) * self._pg_ih), 0), n - 1)
        return self._pg_cells[cj * n + ci]

    def robot_at(self, q) -> list[np.ndarray]:
        """The robot pieces at pose q (the exact test's robot: rotated, then translated).

        >>> cs = SE2CSpace((0, 4, 0, 4), [], [np.array([[0., 0], [1, 0], [0, 1]])], slabs=4)
        >>> cs.robot_at((1, 1, 0))[0].tolist()
        [[1.0, 1.0], [2.0, 1.0], [1.0, 2.0]]
        """
        th = wrap_angle(float(q[2]))
        return [rotate_piece(p, th) + np.array([float(q[0]), float(q[1])]) for p in self.robot_pieces]

    # -- report ------------------------------------------------------------------------

    def state_count(self) -> int:
        """Pose tests made so far (the ``states`` counter of :meth:`report`, without the report).

        >>> cs = SE2CSpace((0, 4, 0, 4), [], [np.array([[0., 0], [1, 0], [0, 1]])], slabs=4)
        >>> n = cs.state_count(); _ = cs.is_free((2.0, 2.0, 0.0)); cs.state_count() - n
        1
        """
        self.checks["states"] = int(self._states.__reduce__()[1][0])
        return self.checks["states"]

    def slabs_built(self) -> tuple[int, float]:
        """How many slabs are built so far (each on its first use) and the seconds they took.

        >>> cs = SE2CSpace((0, 4, 0, 4), [], [np.array([[0., 0], [1, 0], [0, 1]])], slabs=4)
        >>> cs.slabs_built()[0], cs.is_free((2.0, 2.0, 0.0)), cs.slabs_built()[0] > 0
        (0, True, True)
        """
        return len(self._built), sum(d["seconds"] for d in self._built)

    def report(self) -> dict:
        """K and its reason, the slabs built (seconds, piece counts) and the query counters."""
        self.state_count()
        return {
            "slabs": self.slabs,
            "slabs_reason": self.slabs_reason,
            "robot_radius": self.radius,
            "pad": self.pad,
            "robot_pieces": len(self.robot_pieces),
            "obstacle_pieces": len(self.obstacle_pieces),
            "setup_seconds": self.setup_seconds,
            "slabs_built": sorted(self._built, key=lambda d: d["slab"]),
            "build_seconds": sum(d["seconds"] for d in self._built),
            "checks": dict(self.checks),
        }
