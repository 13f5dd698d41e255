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
- ``index``: the grid broad phase of :mod:`cspace.spaces.broadphase`.
"""
from __future__ import annotations

import itertools
import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from . import fastpath
from .broadphase import BLOCKED, FREE, WIDE_MASK, GridIndex
from ..kernel.pieces import PieceSet
from .inputs import query_points
from ..kernel.polygon import piece_boxes
from ..kernel.predicates import orient2d_many
from ..io.scenario import load_scenario
from ..io.schema import MAX_MAGNITUDE, MIN_EXTENT, Scenario


@dataclass
class Stage:
    """One build stage: whether it ran, what it counted and what it cost."""

    name: str
    ran: bool
    seconds: float = 0.0
    counts: dict = field(default_factory=dict)
    note: str = ""

    def as_dict(self) -> dict:
        return {"stage": self.name, "ran": self.ran, "seconds": self.seconds, **self.counts, "note": self.note}


SMALL_GRID = 4096  # cells: a grid this small is also the segment walk's grid
# Minkowski sums of pieces of at most PAIR_BATCH_EDGES vertices are batched, about
# PAIR_BATCH_CELLS (obstacle edge, robot edge) comparisons per batch.
PAIR_BATCH_EDGES = 128  # a robot piece with a margin's rounded corners (~75 edges) is still batched
PAIR_BATCH_CELLS = 1 << 20


def _check_range(bounds: tuple, shapes: list) -> None:
    """ValueError unless the scene lies in the range the C-space supports (its
    classification multiplies two coordinates): see :data:`cspace.io.schema.MAX_MAGNITUDE`."""
    xmin, xmax, ymin, ymax = bounds
    if not (xmin < xmax and ymin < ymax):
        raise ValueError(f"CSpace: bounds {bounds} are empty (need xmin < xmax and ymin < ymax)")
    pts = [p for p in shapes if len(p)]
    big = max([abs(v) for v in bounds] + ([float(np.abs(np.concatenate(pts)).max())] if pts else []))
    if not big <= MAX_MAGNITUDE:
        raise ValueError(f"CSpace: a coordinate of magnitude {big:.3g} is beyond the supported 2^400")
    if max(xmax - xmin, ymax - ymin) < MIN_EXTENT:
        raise ValueError(f"CSpace: the bounds' extent {max(xmax - xmin, ymax - ymin):.3g} is below the supported 2^-400")


def decompose_obstacles(obstacles: list[np.ndarray], holes: list[list[np.ndarray]] | None = None,
                        of: list[int] | None = None,
                        convex: list[bool] | None = None) -> tuple[list[np.ndarray], np.ndarray, int]:
    """Convex pieces of the obstacles: (pieces, owning obstacle of each piece, obstacles split).

    Convex obstacles without holes are kept as they are; the others go through
    :func:`cspace.kernel.decompose.convex_decompose`. ``of[k]``, if given, is the input obstacle
    shell k came from (a MultiPolygon gives several shells); ``convex[k]``, if given, is
    the loader's exact :func:`cspace.kernel.polygon.is_convex` of shell k (not computed again).
    Shared by :class:`CSpace` and the SE(2) C-space, which decomposes once for all its slabs.

    >>> p, owner, split = decompose_obstacles([np.array([[0., 0], [2, 0], [2, 2], [0, 2]])])
    >>> len(p), owner.tolist(), split
    (1, [0], 0)
    """
    from ..kernel.polygon import is_convex

    holes = holes or [[] for _ in obstacles]
    pieces, owner, split = [], [], 0
    for k, (poly, hs) in enumerate(zip(obstacles, holes)):
        i = k if of is None else of[k]
        if not hs and (convex[k] if convex is not None else is_convex(poly)):
            parts = [np.asarray(poly, dtype=np.float64)]
        else:
            from ..kernel.decompose import convex_decompose

            parts = convex_decompose(poly, hs)
            split += 1
        pieces += parts
        owner += [i] * len(parts)
    return pieces, np.array(owner, dtype=np.int64), split


def decompose_robot(robot: list[np.ndarray], is_disk: bool = False) -> tuple[list[np.ndarray], int]:
    """Convex pieces of the robot parts: (pieces, parts split). A disk's polygon is convex.

    >>> p, split = decompose_robot([np.array([[0., 0], [2, 0], [2, 2], [1, 1], [0, 2]])])
    >>> len(p) > 1, split
    (True, 1)
    """
    from ..kernel.polygon import is_convex

    pieces, split = [], 0
    for part in robot:
        if is_disk or is_convex(part):
            pieces.append(np.asarray(part, dtype=np.float64))
        else:
            from ..kernel.decompose import convex_decompose

            pieces += convex_decompose(part)
            split += 1
    return pieces, split


class CSpace:
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
    ):
        # Obstacles and robot parts: (N, 2) arrays in either orientation or shapely Polygons /
        # MultiPolygons (cspace.spaces.inputs); ``normalized`` says they are already the loader's
        # CCW, cleaned, validated arrays (from_scenario), so that work is not done twice;
        # ``obstacle_convex`` then gives their exact convexity (Shape.convex).
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
        # Safety margin (cspace.kernel.margin): convex operands summed with every robot piece in the
        # same merge as the obstacle piece; none (the default) is the plain C-space, same code.
        self.margin = [np.asarray(m, dtype=np.float64) for m in (margin or [])]
        _check_range(self.bounds, obstacles + robot + self.margin)
        convex = obstacle_convex if normalized else None
        self.obstacle_pieces, self.obstacle_of = self._decompose_obstacles(obstacles, holes, owner, convex)
        self.robot_pieces = self._decompose_robot(robot, robot_is_disk)
        raw, raw_owner = self._sum()
        self.pieces, self.piece_obstacle = self._prune(raw, raw_owner)
        t = time.perf_counter()
        self.packed = PieceSet(self.pieces)
        self.index = GridIndex(self.pieces, self.bounds, cells=grid_cells)
        self._coarse = None
        self.stages.append(Stage("index", True, time.perf_counter() - t, self.index.stats()))
        # The compiled fast path's copy of the grid and pieces (None on the pure path).
        self._fast = fastpath.grid_handle(self.index, self.packed, self.bounds)
        self.checks = {"points": 0, "segments": 0, "exact_points": 0, "exact_segments": 0}
        self._points = itertools.count()
        self._batch_points = 0  # points answered by is_free on arrays
        self.is_free_xy = self.point_test(self._points.__next__)
        self._is_free_q = self.is_free_xy.by_state  # the same test, on one indexable (x, y)
        self._point_uncounted = self.point_test(None)
        self._segment = fastpath.segment_test(self._fast, self._segment_pure, self.checks)

    @property
    def coarse(self) -> GridIndex:
        """The pure segment walk's grid, built on first use (the compiled walk uses
        :attr:`index` itself, so a default install never builds it): 4x coarser than the
        index, fewer cells per motion, the same exact answer; a grid of at most 64 x 64
        cells (an SE(2) slab's) is walked as it is."""
        if self._coarse is None:
            cells = self.index.nx * self.index.ny
            self._coarse = (self.index if cells <= SMALL_GRID
                            else GridIndex(self.pieces, self.bounds, cells=max(cells // 16, 64)))
        return self._coarse

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
        (:func:`cspace.kernel.margin.inflated_pieces`, as the SE(2) C-space does; the margin
        alone for a point robot); the inflated pieces then meet the obstacle pieces in
        the same batched pair sums as a plain robot."""
        t = time.perf_counter()
        if not self.robot_pieces and not self.margin:
            self.stages.append(Stage("minkowski", False, 0.0, {"pieces": len(self.obstacle_pieces)},
                                     "point robot: C-obstacles are the obstacles"))
            n = len(self.obstacle_pieces)
            self._raw_pairs = [(i, -1) for i in range(n)]
            return list(self.obstacle_pieces), self.obstacle_of
        from ..kernel.margin import inflated_pieces
        from ..kernel.minkowski import reflect

        neg = [reflect(r) for r in inflated_pieces(self.robot_pieces, self.margin)]
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

    def _prune(self, pieces, owner):
        """Drop pieces that cannot meet the bounds, and pieces inside another piece.

        ``self.piece_pairs[k]`` lists the (obstacle piece, robot piece) pairs whose sum
        is kept piece k or lies inside it (robot piece -1 for a point robot): a point in
        the sum of a pair is in the piece the pair is listed under.
        """
        t = time.perf_counter()
        xmin, xmax, ymin, ymax = self.bounds
        before = len(pieces)
        lo, hi = piece_boxes(pieces)  # an empty piece: lo = inf, hi = -inf, dropped
        keep = np.flatnonzero((lo[:, 0] <= xmax) & (hi[:, 0] >= xmin) & (lo[:, 1] <= ymax) & (hi[:, 1] >= ymin)).tolist()
        outside = before - len(keep)
        pieces = [pieces[k] for k in keep]
        pairs = [[self._raw_pairs[k]] for k in keep]
        owner = owner[keep] if len(owner) else owner
        contained = _contained_pieces(pieces)
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
        self.piece_pairs = pairs
        self.stages.append(Stage("prune", True, time.perf_counter() - t,
                                 {"pieces_before": before, "outside_bounds": outside,
                                  "inside_another": len(contained), "pieces_after": len(pieces)}))
        return pieces, owner

    # -- queries ---------------------------------------------------------------------

    def in_bounds(self, x: float, y: float) -> bool:
        xmin, xmax, ymin, ymax = self.bounds
        return xmin <= x <= xmax and ymin <= y <= ymax

    def is_free(self, q):
        """Is the reference point at q a valid state (in bounds, robot touching nothing)?

        ``q`` is ``(x, y)`` (a bool comes back) or an ``(N, 2)`` array of states (a bool
        array comes back; FREE and BLOCKED grid cells answered vectorised, the others
        exactly, one by one). NaN or infinite coordinates, and ``(x, y, theta)`` (the
        orientation is fixed when the C-space is built), are a ``ValueError``.

        >>> import numpy as np
        >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
        >>> cs.is_free((1, 1)), cs.is_free([[1, 1], [5, 5]]).tolist()
        (True, [True, False])
        """
        try:
            if type(q) is tuple and len(q) == 2:  # the common call: straight to the hot path
                free = self._is_free_q(q)
            else:
                x, y = q  # three numbers (x, y, theta) do not unpack
                free = self.is_free_xy(float(x), float(y))
        except (TypeError, ValueError):  # rows (a batch), or a fault query_points names
            return self._is_free_many(q)
        if free:
            return True
        x, y = q
        if x - x == 0.0 and y - y == 0.0:  # NaN or inf: checked off the free path only
            return False
        query_points(q, 2, "is_free")  # raises

    def _is_free_many(self, q) -> np.ndarray:
        """:meth:`is_free` of an (N, 2) batch: the grid's FREE/BLOCKED cells at once,
        the same per-point arithmetic as :meth:`point_test`, so the same answers."""
        pts = query_points(q, 2, "is_free")
        self._batch_points += len(pts)
        idx = self.index
        x, y = pts[:, 0], pts[:, 1]
        i = x * idx.inv_w - idx.x0 * idx.inv_w
        j = y * idx.inv_h - idx.y0 * idx.inv_h
        on_grid = (i >= 0.0) & (j >= 0.0) & (i < idx.nx) & (j < idx.ny)
        cell = np.where(on_grid, np.floor(j) * idx.nx + np.floor(i), 0).astype(np.int64)
        state = np.where(on_grid, idx.state[cell], -1)
        out = state == FREE
        rest = np.flatnonzero((state != FREE) & (state != BLOCKED))
        test = self._point_uncounted
        for k in rest.tolist():
            out[k] = test(float(x[k]), float(y[k]))
        return out

    def point_test(self, tick=None, state: bool = False):
        """A fast ``(x, y) -> bool`` free-state test: the validity checker's hot path.

        The grid answers FREE and BLOCKED cells with a few float operations; MIXED
        cells go to an inlined exact narrow phase (:meth:`_mixed_cell_test`); the
        bounds' edges and anything outside go to :meth:`_is_free_exact`.
        The cell index is computed as ``x * (1 / cell width) - offset``: its rounding
        error (a few ulps of |x|) is far below the classification margin, so a
        point is never answered from a cell it is not within the margin of.
        ``tick``, if given, is called once per query (a counter). With ``state`` the
        test takes one indexable ``q`` (``q[0], q[1]``, e.g. an OMPL state) instead
        of ``x, y``: one Python call less per state inside OMPL.

        >>> import numpy as np
        >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
        >>> cs.point_test()(5.0, 5.0), cs.point_test(state=True)([1.0, 1.0])
        (False, True)
        """
        idx = self.index
        iw, ih = idx.inv_w, idx.inv_h
        a0, b0 = idx.x0 * iw, idx.y0 * ih
        nx, ny = idx.nx, idx.ny
        # One byte per cell (FREE 0, MIXED 1, BLOCKED 2), one bytes object per row:
        # compact enough to stay in cache, and rows[j][i] saves the j * nx + i of a
        # flat index on the FREE and BLOCKED states, which are most of them. Each row
        # ends with a border cell (3) and a border row follows the last: a point up
        # to a cell past the top or right edge reads a border cell, one further raises
        # IndexError (inf: OverflowError), so only the lower edges need a comparison.
        rows = idx.state_rows()
        exact = self._is_free_exact
        mixed = self._mixed_cell_test()
        if self._fast is not None:  # compiled: certified answers only, else the Python narrow phase
            mixed = fastpath.mixed_cell_test(self._fast, mixed, self.checks)
        xmin, xmax, ymin, ymax = self.bounds
        count = int if tick is None else tick  # int() is a C-level no-op: no branch per query
        floor = math.floor  # on floats about 3x cheaper than int() (a type call); equal for i >= 0

        def is_free_q(q) -> bool:
            count()
            x = q[0]
            y = q[1]
            i = x * iw - a0
            j = y * ih - b0
            if i >= 0.0 and j >= 0.0:  # also False for NaN
                try:
                    c = rows[floor(j)][floor(i)]
                except (IndexError, OverflowError):
                    return exact(x, y)  # off the grid's top or right
                if not c:
                    return True  # FREE
                if c == 2:
                    return False  # BLOCKED
                if c == 1 and xmin <= x <= xmax and ymin <= y <= ymax:
                    # MIXED, inside the bounds: the inlined narrow phase
                    return mixed(floor(j) * nx + floor(i), x, y)
            return exact(x, y)  # the bounds' edges, the border and anything outside

        if state:
            return is_free_q

        def is_free_xy(x: float, y: float) -> bool:
            return is_free_q((x, y))

        is_free_xy.by_state = is_free_q
        return is_free_xy

    def _mixed_cell_test(self):
        """``(cell, x, y) -> bool``: the narrow phase of a point in a MIXED grid cell.

        The same answer as :meth:`_is_free_exact` (the cell's candidates are every
        piece within the classification margin of it, so the rounded cell index is
        safe), inlined for the validity checker: each edge p->q of a candidate gets
        Shewchuk's filtered orient2d(p, q, x) written out, (q - p) x ((x, y) - p) with
        ``q - p`` precomputed (the same rounded difference the filter's bound covers);
        only uncertified signs call the exact :func:`orient2d_xy`.
        """
        from ..kernel.predicates import _UNDERFLOW_GUARD, CCW_ERRBOUND_A, orient2d_xy

        starts, cand = self.index._starts_list, self.index._cand_list
        masks = self.index.cand_masks_list
        packed = self.packed
        edge_mask, pieces = self.index.edge_mask, self.pieces
        by_cell: dict = {}  # cell -> per candidate piece, its edges named by the cell's mask
        checks = self.checks
        tiny = CCW_ERRBOUND_A * _UNDERFLOW_GUARD

        def edges_near(cell: int) -> list:
            # Only the edges whose line passes near this cell: the cell lies well
            # inside every other edge's half-plane (certified at build, with margin).
            groups = []
            for t in range(starts[cell], starts[cell + 1]):
                pts, mask = packed._lists[cand[t]], masks[t]
                if mask == WIDE_MASK:  # a wide piece: its mask in this cell, once
                    mask = edge_mask(pieces[cand[t]], cell)
                edges = []
                px, py = pts[-1]
                for e, (qx, qy) in enumerate(pts):
                    if (mask >> e) & 1:
                        edges.append((px, py, qx, qy, qx - px, qy - py))
                    px, py = qx, qy
                groups.append(edges)
            by_cell[cell] = groups
            return groups

        def free_in_cell(cell: int, x: float, y: float) -> bool:
            checks["exact_points"] += 1
            for edges in by_cell.get(cell) or edges_near(cell):
                for px, py, qx, qy, ex, ey in edges:
                    left = ex * (y - py)
                    right = ey * (x - px)
                    det = left - right
                    # bound > tiny: no underflow; an infinite detsum gives an infinite
                    # bound that no det exceeds, and NaN fails every comparison.
                    bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
                    if det > bound > tiny:
                        continue  # strictly left of this edge
                    if -det > bound > tiny:
                        break  # strictly right: outside this piece
                    if orient2d_xy(px, py, qx, qy, x, y) < 0:
                        break
                else:
                    return False  # on or left of every edge: in this closed piece
            return True

        return free_in_cell

    def point_count(self) -> int:
        """Point queries answered so far."""
        n = self._points.__reduce__()[1][0]
        return int(n) + self._batch_points

    def _is_free_exact(self, x: float, y: float) -> bool:
        """Bounds check, then the exact test against the cell's candidate pieces."""
        xmin, xmax, ymin, ymax = self.bounds
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return False
        cell = self.index.cell_of(x, y)
        s = self.index.state_list[cell]
        if s == FREE:
            return True
        if s == BLOCKED:
            return False
        self.checks["exact_points"] += 1
        hits = self.packed.point_hits
        for k in self.index.candidates(cell).tolist():
            if hits(k, x, y):
                return False
        return True

    def segment_free(self, a, b=None):
        """Is every state on the closed segment a-b valid? Exact: no sampling along it.

        ``segment_free(a, b)`` with two points gives a bool; ``segment_free(S)`` with an
        ``(N, 2, 2)`` array of segments (or ``a``, ``b`` as two ``(N, 2)`` arrays) gives a
        bool array. Non-finite coordinates and ``(x, y, theta)`` are a ``ValueError``.

        >>> import numpy as np
        >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
        >>> cs.segment_free((1, 1), (9, 1)), cs.segment_free([[(1, 1), (9, 1)], [(1, 5), (9, 5)]]).tolist()
        (True, [True, False])
        """
        if b is None:
            return self._segments_free(a)
        try:
            ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
        except (TypeError, IndexError):  # rows: a batch
            return self._segments_free(np.stack([np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)], 1))
        if len(a) != 2 or len(b) != 2:
            query_points([a, b], 2, "segment_free")  # raises: (x, y, theta) or a wrong length
        return self._segment(ax, ay, bx, by)

    def segment_test(self):
        """A fast ``(ax, ay, bx, by) -> bool`` closed-segment test on four floats: the motion
        validator's hot path, the same answers as :meth:`segment_free` (counted alike).

        >>> import numpy as np
        >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
        >>> f = cs.segment_test()
        >>> f(1.0, 1.0, 9.0, 1.0), f(1.0, 5.0, 9.0, 5.0)
        (True, False)
        """
        return self._segment

    def _segment_pure(self, ax: float, ay: float, bx: float, by: float) -> bool:
        """The exact segment test on four floats (the pure path, and the oracle)."""
        self.checks["segments"] += 1
        if not (self.in_bounds(ax, ay) and self.in_bounds(bx, by)):
            if not (ax - ax == 0.0 and ay - ay == 0.0 and bx - bx == 0.0 and by - by == 0.0):
                query_points([(ax, ay), (bx, by)], 2, "segment_free")  # raises: NaN or inf
            return False  # the bounds box is convex: both ends inside => whole segment inside
        # Motions mostly fail at their far end (an RRT extension into an obstacle).
        if not (self._point_uncounted(bx, by) and self._point_uncounted(ax, ay)):
            return False
        one = self.packed.segment_hits_xy
        found = self.coarse.segment_candidates(ax, ay, bx, by, on_blocker=lambda k: one(k, ax, ay, bx, by))
        if found is None:
            self.checks["exact_segments"] += 1
            return False
        blockers, cands = found
        if not cands:
            return True  # blockers, if any, were each tested (and missed) as they were found
        self.checks["exact_segments"] += 1
        cands -= blockers  # each candidate tested once: scalars for a few, numpy for many
        if len(cands) <= 8:
            return not any(one(k, ax, ay, bx, by) for k in sorted(cands))
        hits = self.packed.segment_hits_many
        return not hits(np.fromiter(cands, np.int64, len(cands)), (ax, ay), (bx, by)).any()

    def _segments_free(self, s) -> np.ndarray:
        """:meth:`segment_free` of an (N, 2, 2) batch, each segment by the exact scalar test."""
        arr = np.asarray(s, dtype=np.float64)
        if arr.ndim != 3 or arr.shape[1] != 2:
            raise ValueError(f"segment_free: expected two points or an (N, 2, 2) array of segments, "
                             f"got shape {arr.shape}")
        pts = query_points(arr.reshape(-1, arr.shape[2]), 2, "segment_free").reshape(-1, 2, 2)
        one = self.segment_free
        return np.array([one((a[0], a[1]), (b[0], b[1])) for a, b in pts.tolist()], dtype=bool)

    def clearance(self, q):
        """Distance from q to the nearest C-obstacle piece (0 when not free), via GJK.

        Pieces are visited in order of their bounding-box distance, a lower bound,
        and the search stops once that bound exceeds the best distance found.
        ``q`` is ``(x, y)`` (a float) or an ``(N, 2)`` array (a float array); non-finite
        coordinates and ``(x, y, theta)`` are a ``ValueError``.

        >>> import numpy as np
        >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
        >>> cs.clearance((1, 5)), cs.clearance([[1, 5], [5, 5]]).tolist()
        (3.0, [3.0, 0.0])
        """
        try:
            x, y = float(q[0]), float(q[1])
        except (TypeError, IndexError):  # rows: a batch
            return np.array([self.clearance(p) for p in query_points(q, 2, "clearance").tolist()], dtype=np.float64)
        if len(q) != 2 or not (x - x == 0.0 and y - y == 0.0):
            query_points(q, 2, "clearance")  # raises: (x, y, theta), a wrong length, NaN or inf
        if not self.is_free_xy(x, y) or not len(self.pieces):
            return 0.0 if len(self.pieces) or not self.in_bounds(x, y) else float("inf")
        from ..kernel.gjk import gjk_distance

        lb = self.packed.box_distance(x, y)
        order = np.argsort(lb, kind="stable")
        best = float("inf")
        point = np.array([[x, y]])
        for k in order.tolist():
            if lb[k] >= best:
                break
            best = min(best, gjk_distance(self.pieces[k], point).distance)
        return best

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


def _contained_pieces(pieces: list[np.ndarray]) -> dict[int, int]:
    """Convex pieces lying inside another piece (exact containment test): removed -> container.

    Candidate pairs come from bounding-box containment; a convex piece P lies in a
    convex piece Q iff every vertex of P is on or left of every edge of Q. Of two
    identical pieces only the later one is removed.
    """
    n = len(pieces)
    if n < 2:
        return {}
    lo, hi = piece_boxes(pieces)
    order = np.argsort(lo[:, 0], kind="stable")
    removed: dict[int, int] = {}
    # Pairs (q, p), p != q, whose box lies inside q's box (closed), each q's in the order of
    # ``order``. A piece inside q has its first vertex in q: an STRtree of the pieces
    # proposes the pieces holding each first vertex (near-linear, where boxes of long
    # thin pieces overlap by the thousand), the exact box comparisons and the exact
    # vertex test below decide. (Pieces of fewer than 3 vertices: boxes covering boxes.)
    import shapely

    sizes = np.fromiter((len(p) for p in pieces), np.int64, n)
    if (sizes >= 3).all():
        rings = shapely.linearrings(np.concatenate(pieces), indices=np.repeat(np.arange(n), sizes))
        firsts = shapely.points(np.array([p[0] for p in pieces]))
        # The pieces are the (prepared) query geometries, the points the tree: a piece of
        # 10^5 vertices is indexed once, not walked once per point near it.
        qs, ps = shapely.STRtree(firsts).query(shapely.polygons(rings), predicate="intersects")
    else:
        boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
        qs, ps = shapely.STRtree(boxes).query(boxes, predicate="covers")
    inside = (ps != qs) & (lo[ps, 0] >= lo[qs, 0]) & (hi[ps, 0] <= hi[qs, 0]) & (lo[ps, 1] >= lo[qs, 1]) & \
        (hi[ps, 1] <= hi[qs, 1])
    qs, ps = qs[inside], ps[inside]
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    by = np.lexsort((rank[ps], qs))
    qs, ps = qs[by], ps[by]
    cut = np.flatnonzero(np.diff(qs)) + 1
    for q, cand in zip(qs[np.r_[0, cut]].tolist() if len(qs) else [], np.split(ps, cut) if len(qs) else []):
        if q in removed:
            continue
        Q = pieces[q]
        s, e = Q, np.roll(Q, -1, axis=0)
        for p in cand.tolist():
            if p in removed:
                continue
            P = pieces[p]
            if P.shape == Q.shape and p < q and np.array_equal(P, Q):
                continue  # identical: keep the earlier one, drop q when it is visited as p
            sides = orient2d_many(s[None, :, :], e[None, :, :], P[:, None, :])
            if (sides >= 0).all():
                removed[p] = q
    return removed


def pair_sums(obstacle_pieces: list[np.ndarray], robot_pieces: list[np.ndarray]) -> list[np.ndarray]:
    """``[minkowski_sum(p, r) for p in obstacle_pieces for r in robot_pieces]``: pairs of
    small pieces in batches (:func:`cspace.kernel.pairsums.pairwise_sums`, equal array for
    array), large ones one by one (a batch compares every edge with every edge).

    >>> sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    >>> [s.tolist() for s in pair_sums([sq], [sq - 1])]
    [[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]]
    """
    from ..kernel.minkowski import minkowski_sum
    from ..kernel.pairsums import pairwise_sums

    nr = len(robot_pieces)
    out: list = [None] * (len(obstacle_pieces) * nr)
    small_r = [j for j, r in enumerate(robot_pieces) if len(r) <= PAIR_BATCH_EDGES]
    small_o = [i for i, p in enumerate(obstacle_pieces) if len(p) <= PAIR_BATCH_EDGES]
    if small_r and small_o:
        rb = [robot_pieces[j] for j in small_r]
        redges = sum(len(r) for r in rb)
        start = 0
        while start < len(small_o):  # chunks of about PAIR_BATCH_CELLS edge comparisons
            stop, used = start, 0
            while stop < len(small_o) and (stop == start or (used + len(obstacle_pieces[small_o[stop]])) * redges
                                           <= PAIR_BATCH_CELLS):
                used += len(obstacle_pieces[small_o[stop]])
                stop += 1
            chunk = small_o[start:stop]
            sums = pairwise_sums([obstacle_pieces[c] for c in chunk], rb)
            for a, c in enumerate(chunk):
                for b, j in enumerate(small_r):
                    out[c * nr + j] = sums[a * len(rb) + b]
            start = stop
    for k in range(len(out)):
        if out[k] is None:
            out[k] = minkowski_sum(obstacle_pieces[k // nr], robot_pieces[k % nr])
    return out
