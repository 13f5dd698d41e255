"""The configuration space of a translating robot, kept as convex pieces.

This module owns the C-space: C_obs = union over obstacles O and robot parts R of
O ⊕ (−R), stored as convex pieces (convex obstacle piece ⊕ reflected convex robot
piece), pruned, and indexed by a grid broad phase. Obstacles are closed sets: a
state whose robot touches an obstacle is not free (so a passage exactly as wide as
the robot is closed, consistently, by every query).

Only the stages a scene needs run, and each is recorded with its cost:

- ``decompose_obstacles`` / ``decompose_robot``: convex shapes are kept as they are;
- ``minkowski``: skipped for a point robot (C_obs is the obstacles themselves);
  a disk robot is its circumscribed polygon, convex, so never decomposed;
- ``prune``: pieces that cannot meet the bounds are dropped, and pieces inside
  another piece (exact test) are removed;
- ``index``: the grid broad phase of :mod:`cspace.translation.broadphase`.

The stages are functions shared with the SE(2) C-space (:mod:`cspace.translation.build`);
the queries are the point queries (:mod:`cspace.translation.points`: validity, the
validator's hot path, clearance) and the segment queries (:mod:`cspace.translation.segments`).
This module owns the class: its construction, stage by stage, and its report.
"""
from __future__ import annotations

import itertools
import os
import time

import numpy as np

from ..compiled import fastpath
from .broadphase import GridIndex
from ..kernel.polygons.pieces import PieceSet
from ..kernel.polygons.polygon import pack, piece_boxes
from ..io.load import load_scenario
from ..io.scenario.schema import Scenario
# decompose_obstacles and decompose_robot are public here too (``cspace`` lists them).
from .build import (Stage, check_range, contained_pieces, decompose_obstacles, decompose_robot, inflated,
                           pair_sums)
from .points import PointQueries
from .segments import SegmentQueries


class CSpace(PointQueries, SegmentQueries):
    """Convex C-obstacle pieces of a scenario behind a broad phase.

    >>> import numpy as np
    >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
    >>> cs.is_free((1, 1)), cs.is_free((5, 5)), cs.segment_free((1, 5), (9, 5))
    (True, False, False)
    """

    def __init__(
        self,
        bounds,
        obstacles: list[np.ndarray] | None = None,
        robot: list[np.ndarray] | None = None,
        *,
        obstacle_holes: list[list[np.ndarray]] | None = None,
        robot_is_disk: bool = False,
        grid_cells: int | None = None,
        normalized: bool = False,
        obstacle_convex: list[bool] | None = None,
        margin: list[np.ndarray] | None = None,
        nested: bool = True,
    ):
        # Obstacles and robot parts: (N, 2) arrays in either orientation or shapely Polygons /
        # MultiPolygons (cspace.translation.inputs); ``normalized`` says they are already the loader's
        # CCW, cleaned, validated arrays (from_scenario), so that work is not done twice;
        # ``obstacle_convex`` then gives their exact convexity (Shape.convex). ``nested=False``: the
        # caller knows no sum lies inside another but by rounding (see :meth:`_prune`).
        self._nested = nested
        self.bounds = tuple(float(v) for v in bounds)
        self.stages: list[Stage] = []
        owner = None
        if normalized:
            obstacles, robot = list(obstacles or []), list(robot or [])
            holes = obstacle_holes or [[] for _ in obstacles]
        else:
            from .inputs import obstacle_shapes, robot_parts

            obstacles, holes, owner = obstacle_shapes(obstacles, obstacle_holes)
            robot = robot_parts(robot)
        # Safety margin (cspace.kernel.minkowski.margin): convex operands summed with every robot piece in the
        # same merge as the obstacle piece; none (the default) is the plain C-space, same code.
        self.margin = [np.asarray(m, dtype=np.float64) for m in (margin or [])]
        check_range(self.bounds, obstacles + robot + self.margin)
        convex = obstacle_convex if normalized else None
        self.obstacle_pieces, self.obstacle_of = self._decompose_obstacles(obstacles, holes, owner, convex)
        self.robot_pieces = self._decompose_robot(robot, robot_is_disk)
        self._finish(*self._sum(), grid_cells)

    def _finish(self, raw: list, raw_owner: np.ndarray, grid_cells: int | None) -> None:
        """The build after the sums: prune, index, the compiled handle, the query closures."""
        self.pieces, self.piece_obstacle = self._prune(raw, raw_owner)
        t = time.perf_counter()
        self.packed = PieceSet(self.pieces, self._boxes, self._packing)  # the prune's boxes and packing
        self.index = GridIndex(self.pieces, self.bounds, cells=grid_cells, packed=self.packed)
        self._coarse = None
        # The compiled fast path's copy of the grid and pieces (None on the pure path): part of the index.
        self._fast = fastpath.grid_handle(self.index, self.packed, self.bounds)
        self.stages.append(Stage("index", True, time.perf_counter() - t, self.index.stats()))
        self.checks = {"points": 0, "segments": 0, "exact_points": 0, "exact_segments": 0}
        self._points = itertools.count()
        self._batch_points = 0  # points answered by is_free on arrays
        self.is_free_xy = self.point_test(self._points.__next__)
        self._is_free_q = self.is_free_xy.by_state  # the same test, on one indexable (x, y)
        self._point_uncounted = self.point_test(None)
        self._segment = fastpath.segment_test(self._fast, self._segment_pure, self.checks)

    # -- construction --------------------------------------------------------------

    @classmethod
    def from_scenario(cls, scenario, grid_cells: int | None = None) -> "CSpace":
        """Build the C-space of a :class:`Scenario` (or of a scenario file path).

        >>> import os, tempfile
        >>> f = os.path.join(tempfile.mkdtemp(), "s.toml")
        >>> _ = open(f, "w").write("[bounds]\\nxmin=0\\nxmax=4\\nymin=0\\nymax=4\\n[start]\\nx=0.5\\ny=0.5\\n"
        ...     "[goal]\\nx=3.5\\ny=3.5\\n[[obstacles]]\\npolygon=[[1,1],[3,1],[3,3],[1,3]]\\n")
        >>> CSpace.from_scenario(f).is_free((2, 2))
        False
        """
        t0 = time.perf_counter()
        sc = scenario if isinstance(scenario, Scenario) else load_scenario(os.fspath(scenario))
        load_s = time.perf_counter() - t0
        cs = cls(
            sc.bounds,
            [o.polygon for o in sc.obstacles],
            [r.polygon for r in sc.robot],
            obstacle_holes=[o.holes for o in sc.obstacles],
            robot_is_disk=sc.robot_kind == "disk",
            grid_cells=grid_cells,
            normalized=True,
            obstacle_convex=[o.convex for o in sc.obstacles],
            margin=sc.margins(),
        )
        cs.scenario = sc
        if not isinstance(scenario, Scenario):
            cs.stages.insert(0, Stage("load", True, load_s, {"obstacles": len(sc.obstacles)}))
        return cs

    def _decompose_obstacles(self, obstacles, holes, of=None, convex=None):
        t = time.perf_counter()
        pieces, owner, split = decompose_obstacles(obstacles, holes, of, convex)
        self.stages.append(
            Stage("decompose_obstacles", split > 0, time.perf_counter() - t,
                  {"obstacles": len(obstacles), "decomposed": split, "pieces": len(pieces)},
                  "" if split else "all obstacles convex: nothing to decompose")
        )
        return pieces, owner

    def _decompose_robot(self, robot, is_disk):
        t = time.perf_counter()
        if not robot:
            self.stages.append(Stage("decompose_robot", False, 0.0, {"parts": 0}, "point robot"))
            return []
        pieces, split = decompose_robot(robot, is_disk)
        note = "disk robot: its polygon is convex" if is_disk else ("" if split else "robot parts convex")
        self.stages.append(Stage("decompose_robot", split > 0, time.perf_counter() - t,
                                 {"parts": len(robot), "pieces": len(pieces)}, note))
        return pieces

    def _sum(self):
        """obstacle piece ⊕ −(robot piece ⊕ margin) for every pair, batched (:func:`pair_sums`).

        A margin inflates each robot piece once, in one k-way merge with its operands
        (:func:`cspace.kernel.minkowski.margin.inflated_pieces`, as the SE(2) C-space does; the margin
        alone for a point robot); the inflated pieces then meet the obstacle pieces in
        the same batched pair sums as a plain robot."""
        t = time.perf_counter()
        if not self.robot_pieces and not self.margin:
            self.stages.append(Stage("minkowski", False, 0.0, {"pieces": len(self.obstacle_pieces)},
                                     "point robot: C-obstacles are the obstacles"))
            n = len(self.obstacle_pieces)
            self._raw_pairs = [(i, -1) for i in range(n)]
            return list(self.obstacle_pieces), self.obstacle_of
        from ..kernel.minkowski.merge import reflect

        neg = [reflect(r) for r in inflated(self.robot_pieces, self.margin)]
        out = pair_sums(self.obstacle_pieces, neg)
        nr = len(neg)
        owner = np.repeat(np.asarray(self.obstacle_of, dtype=np.int64), nr)
        self._raw_pairs = [(i, j if self.robot_pieces else -1)
                           for i in range(len(self.obstacle_pieces)) for j in range(nr)]
        counts = {"pairs": len(out), "robot_pieces": len(self.robot_pieces)}
        if self.margin:
            counts["margin_vertices"] = [len(m) for m in self.margin]
        self.stages.append(Stage("minkowski", True, time.perf_counter() - t, counts))
        return out, owner

    @classmethod
    def from_sums(cls, bounds, obstacle_pieces: list[np.ndarray], robot_pieces: list[np.ndarray], sums: list[np.ndarray],
                  *, grid_cells: int | None = None, seconds: float = 0.0, checked: bool = False,
                  nested: bool = True) -> "CSpace":
        """The C-space ``CSpace(bounds, obstacle_pieces, robot_pieces, normalized=True)`` builds when
        every obstacle and robot piece is convex (kept as it is) and ``sums`` are their pair
        sums obstacle piece ⊕ −(robot piece), obstacle-major, as :func:`pair_sums` gives them
        (the caller computed them, for several C-spaces at once: the SE(2) slabs): the same
        pieces, pairs, grid and answers, the same stages in the report (``seconds``: the
        sums' share of the caller's time). ``checked``: the caller has run
        :func:`cspace.translation.build.check_range` on these bounds and pieces (the SE(2)
        slabs: once for the obstacles and every slab's hulls).

        >>> sq, tri = np.array([[4., 4], [6, 4], [6, 6], [4, 6]]), np.array([[-1., -1], [0, -1], [-1, 0]])
        >>> a = CSpace((0, 10, 0, 10), [sq], [-tri], normalized=True)
        >>> b = CSpace.from_sums((0, 10, 0, 10), [sq], [-tri], pair_sums([sq], [tri]))
        >>> [p.tolist() for p in a.pieces] == [p.tolist() for p in b.pieces], b.is_free((3.5, 3.5))
        (True, False)
        """
        self = cls.__new__(cls)
        self._nested = nested
        self.bounds = tuple(float(v) for v in bounds)
        if not checked:
            check_range(self.bounds, list(obstacle_pieces) + list(robot_pieces))
        no, nr = len(obstacle_pieces), len(robot_pieces)
        self.stages = [Stage("decompose_obstacles", False, 0.0, {"obstacles": no, "decomposed": 0, "pieces": no},
                             "all obstacles convex: nothing to decompose")]
        self.margin = []
        self.obstacle_pieces, self.obstacle_of = list(obstacle_pieces), np.arange(no, dtype=np.int64)
        self.robot_pieces = list(robot_pieces)
        if not nr:
            raise ValueError("CSpace.from_sums: needs robot pieces")
        self.stages.append(Stage("decompose_robot", False, 0.0, {"parts": nr, "pieces": nr}, "robot parts convex"))
        if len(sums) != no * nr:
            raise ValueError(f"CSpace.from_sums: {len(sums)} sums for {no} x {nr} pairs")
        self._raw_pairs = [(i, j) for i in range(no) for j in range(nr)]
        self.stages.append(Stage("minkowski", True, seconds, {"pairs": len(sums), "robot_pieces": nr}))
        self._finish(list(sums), np.repeat(self.obstacle_of, nr), grid_cells)
        return self

    def _prune(self, pieces, owner):
        """Drop pieces that cannot meet the bounds, and pieces inside another piece (unless the
        C-space was made with ``nested=False``: an SE(2) slab of one robot piece whose obstacle
        pieces do not nest. For convex sets A ⊕ C ⊆ B ⊕ C implies A ⊆ B (Rådström's
        cancellation), so such sums nest only by rounding, and a piece inside another changes
        no answer when it is kept: the test of thousands of a map's pieces is skipped).

        ``self.piece_pairs[k]`` lists the (obstacle piece, robot piece) pairs whose sum
        is kept piece k or lies inside it (robot piece -1 for a point robot): a point in
        the sum of a pair is in the piece the pair is listed under.
        """
        t = time.perf_counter()
        xmin, xmax, ymin, ymax = self.bounds
        before = len(pieces)
        got = fastpath.pack_boxes(pieces)  # compiled: the same packing and boxes in one pass
        if got is not None:
            pts, off, lo, hi, _ = got
            sizes = np.diff(off)
        else:
            pts, sizes = pack(pieces)  # kept for the index's PieceSet
            lo, hi = piece_boxes(pieces, (pts, sizes))  # an empty piece: lo = inf, hi = -inf, dropped
        meets = (lo[:, 0] <= xmax) & (hi[:, 0] >= xmin) & (lo[:, 1] <= ymax) & (hi[:, 1] >= ymin)
        if meets.all():  # (mostly) every piece meets the bounds: nothing to copy
            keep = range(before)
            pieces, pairs = list(pieces), [[pr] for pr in self._raw_pairs]
        else:
            keep = np.flatnonzero(meets).tolist()
            pieces = [pieces[k] for k in keep]
            pairs = [[self._raw_pairs[k]] for k in keep]
            owner = owner[keep] if len(owner) else owner
            lo, hi = lo[keep], hi[keep]  # the kept pieces' boxes, for the containment test and the index
        outside = before - len(keep)
        contained = contained_pieces(pieces, (lo, hi), (pts, sizes) if len(keep) == before else None) \
            if getattr(self, "_nested", True) else {}
        if contained:
            for p in sorted(contained):
                q = contained[p]
                while q in contained:  # a container may itself lie in another piece
                    q = contained[q]
                pairs[q] += pairs[p]
            mask = np.ones(len(pieces), dtype=bool)
            mask[list(contained)] = False
            pieces = [p for p, m in zip(pieces, mask) if m]
            pairs = [pr for pr, m in zip(pairs, mask) if m]
            owner = owner[mask]
            lo, hi = lo[mask], hi[mask]
            keep = [k for k, m in zip(keep, mask.tolist()) if m]
        if len(keep) < before:  # the kept pieces' vertices, from the packing
            kept = np.zeros(before, dtype=bool)
            kept[keep] = True
            pts, sizes = pts[np.repeat(kept, sizes)], sizes[kept]
        self.piece_pairs = pairs
        self._boxes = (lo, hi)
        self._packing = (pts, sizes)
        self.stages.append(Stage("prune", True, time.perf_counter() - t,
                                 {"pieces_before": before, "outside_bounds": outside,
                                  "inside_another": len(contained), "pieces_after": len(pieces)}))
        return pieces, owner

    def report(self) -> dict:
        """The stages that ran, with counts and times, and the query counters."""
        self.checks["points"] = self.point_count()
        return {
            "stages": [s.as_dict() for s in self.stages],
            "pieces": len(self.pieces),
            "robot_pieces": len(self.robot_pieces),
            "obstacle_pieces": len(self.obstacle_pieces),
            "build_seconds": sum(s.seconds for s in self.stages),
            "checks": dict(self.checks),
        }
