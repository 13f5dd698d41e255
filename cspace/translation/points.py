"""Point queries of the C-space: is a state free (one, a batch, the validator's hot path with its
inlined exact narrow phase and the compiled fast path), and its clearance.

A mixin of :class:`cspace.translation.cspace.CSpace`, which builds the grid (``index``), the packed
pieces (``packed``) and the compiled handle (``_fast``) these queries read.
"""
from __future__ import annotations

import math

import numpy as np

from ..compiled import fastpath
from .broadphase import BLOCKED, FREE, WIDE_MASK
from .inputs import query_points


class PointQueries:
    """:class:`cspace.translation.cspace.CSpace`'s point queries."""

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
        >>> from cspace.translation.cspace import CSpace
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
        >>> from cspace.translation.cspace import CSpace
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
        from ..kernel.polygons.predicates import UNDERFLOW_GUARD, CCW_ERRBOUND_A, orient2d_xy

        index = self.index  # its scalar lists are made when this first runs (edges_near)
        packed = self.packed
        edge_mask, pieces = self.index.edge_mask, self.pieces
        by_cell: dict = {}  # cell -> per candidate piece, its edges named by the cell's mask
        checks = self.checks
        tiny = CCW_ERRBOUND_A * UNDERFLOW_GUARD

        def edges_near(cell: int) -> list:
            # Only the edges whose line passes near this cell: the cell lies well
            # inside every other edge's half-plane (certified at build, with margin).
            groups = []
            starts, cand, masks = index._starts_list, index._cand_list, index.cand_masks_list
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

    def clearance(self, q):
        """Distance from q to the nearest C-obstacle piece (0 when not free), via GJK.

        Pieces are visited in order of their bounding-box distance, a lower bound,
        and the search stops once that bound exceeds the best distance found.
        ``q`` is ``(x, y)`` (a float) or an ``(N, 2)`` array (a float array); non-finite
        coordinates and ``(x, y, theta)`` are a ``ValueError``.

        >>> import numpy as np
        >>> from cspace.translation.cspace import CSpace
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
        from ..kernel.distance.gjk import gjk_distance

        lb = self.packed.box_distance(x, y)
        order = np.argsort(lb, kind="stable")
        best = float("inf")
        point = np.array([[x, y]])
        for k in order.tolist():
            if lb[k] >= best:
                break
            best = min(best, gjk_distance(self.pieces[k], point).distance)
        return best
