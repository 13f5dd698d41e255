"""Packed convex pieces and the exact narrow phase against them.

This module owns the exact answers to "does point q / segment a-b meet closed
convex piece k?". The pieces are packed into flat edge arrays so that one call
tests many pieces at once; every side-of-line decision goes through the exact
predicate, so the answers are exact for any finite input.

Geometry: a closed convex polygon P (CCW) and a closed segment S are disjoint iff a
line separates them strictly, and such a line can be taken along an edge of P or
along S itself (the separating axis theorem in the plane; a point is a segment of
length zero).
"""
from __future__ import annotations

from functools import cached_property

import numpy as np

from .polygon import pack, piece_boxes, ring_neighbours
from .predicates import orient2d_cols, orient2d_xy


class PieceSet:
    """Convex CCW pieces packed as edges ``start[e] -> end[e]`` of piece ``owner[e]``.

    >>> ps = PieceSet([np.array([[0., 0], [2, 0], [2, 2], [0, 2]])])
    >>> ps.point_hits(0, 2.0, 1.0), ps.segment_hits(0, (3.0, 0.0), (3.0, 5.0))
    (True, False)
    """

    def __init__(self, pieces: list[np.ndarray], boxes: tuple[np.ndarray, np.ndarray] | None = None,
                 packing: tuple[np.ndarray, np.ndarray] | None = None):
        # ``boxes``: the pieces' (lo, hi) (:func:`piece_boxes`) and ``packing`` their
        # :func:`pack` (float64 vertices, sizes), when the caller has them.
        self.pieces = list(pieces)
        start, sizes = pack(pieces) if packing is None else packing  # one pass (a scene may hold 10^5 pieces)
        start = np.ascontiguousarray(start, dtype=np.float64)
        self.offsets = np.zeros(len(sizes) + 1, dtype=np.int64)
        np.cumsum(sizes, out=self.offsets[1:])
        self.start = start
        if boxes is not None:
            lo, hi = boxes
        elif not len(sizes):
            lo = hi = np.zeros((0, 2))
        else:  # the boxes from the packed vertices (piece_boxes' answer, without packing again)
            lo, hi = piece_boxes(self.pieces, (start, sizes))
        self._sizes = sizes
        self.lo, self.hi = lo, hi
        self._scalar = None

    @cached_property
    def owner(self) -> np.ndarray:
        """Each edge's piece (made on first use)."""
        return np.repeat(np.arange(len(self.pieces)), self._sizes)

    @cached_property
    def end(self) -> np.ndarray:
        """Each edge's end vertex (the next vertex of its piece), made on first use: the
        compiled fast path never asks for it."""
        return self.start[ring_neighbours(self._sizes)[1]] if len(self.start) else np.zeros((0, 2))

    @property
    def _lists(self) -> list[list]:
        """Scalar copies of the pieces (lists of [x, y]) for the one-piece hot path, made
        on first use: the compiled fast path never asks for them."""
        if self._scalar is None:
            flat, cut = self.start.tolist(), self.offsets.tolist()
            self._scalar = [flat[cut[k]:cut[k + 1]] for k in range(len(self.pieces))]
        return self._scalar

    def __len__(self) -> int:
        return len(self.pieces)

    def point_hits(self, k: int, x: float, y: float) -> bool:
        """Is (x, y) in closed piece k? Exact."""
        pts = self._lists[k]
        px, py = pts[-1]
        for qx, qy in pts:
            if orient2d_xy(px, py, qx, qy, x, y) < 0:
                return False
            px, py = qx, qy
        return True

    def segment_hits_xy(self, k: int, ax: float, ay: float, bx: float, by: float) -> bool:
        """Does closed segment a-b meet closed piece k? Exact, in scalars: the same
        separating axes as :meth:`segment_hits_many`, cheaper for a few pieces (no numpy
        call overhead), stopping at the first separating axis.

        >>> PieceSet([np.array([[0., 0], [2, 0], [2, 2], [0, 2]])]).segment_hits_xy(0, 3.0, 0.0, 2.0, 2.0)
        True
        """
        pts = self._lists[k]
        px, py = pts[-1]
        for qx, qy in pts:  # an edge with both ends strictly outside it
            if orient2d_xy(px, py, qx, qy, ax, ay) < 0 and orient2d_xy(px, py, qx, qy, bx, by) < 0:
                return False
            px, py = qx, qy
        if ax == bx and ay == by:
            return True  # a point: the piece's edges are the only axes
        left = right = True  # the segment's line with every vertex strictly on one side
        for qx, qy in pts:
            s = orient2d_xy(ax, ay, bx, by, qx, qy)
            left = left and s > 0
            right = right and s < 0
            if not (left or right):
                return True
        return False

    def segment_hits(self, k: int, a, b) -> bool:
        """Does closed segment a-b meet closed piece k? Exact."""
        return bool(self.segment_hits_many(np.array([k]), a, b)[0])

    def segment_hits_many(self, ks: np.ndarray, a, b) -> np.ndarray:
        """For each piece in ``ks``, does the closed segment a-b meet it? Exact, vectorised."""
        ks = np.asarray(ks, dtype=np.int64)
        if ks.size == 0:
            return np.zeros(0, dtype=bool)
        counts = self.offsets[ks + 1] - self.offsets[ks]
        first = np.repeat(self.offsets[ks], counts)
        idx = first + (np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts))
        s, e = self.start[idx], self.end[idx]
        ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
        sx, sy, ex, ey = s[:, 0], s[:, 1], e[:, 0], e[:, 1]
        seg_start = np.cumsum(counts) - counts
        # Axis 1: an edge of the piece with both segment ends strictly outside it.
        oa = orient2d_cols(sx, sy, ex, ey, ax, ay)
        ob = orient2d_cols(sx, sy, ex, ey, bx, by)
        edge_sep = np.logical_or.reduceat((oa < 0) & (ob < 0), seg_start)
        if ax == bx and ay == by:
            return ~edge_sep  # a point: the piece's edges are the only axes
        # Axis 2: the segment's own line with every vertex of the piece strictly on one side.
        side = orient2d_cols(ax, ay, bx, by, sx, sy)
        line_sep = np.logical_and.reduceat(side > 0, seg_start) | np.logical_and.reduceat(side < 0, seg_start)
        return ~(edge_sep | line_sep)

    def boxes_near_segment(self, a, b) -> np.ndarray:
        """Pieces whose bounding box meets the segment's bounding box."""
        lo = np.minimum(a, b)
        hi = np.maximum(a, b)
        m = (self.lo[:, 0] <= hi[0]) & (self.hi[:, 0] >= lo[0]) & (self.lo[:, 1] <= hi[1]) & (self.hi[:, 1] >= lo[1])
        return np.flatnonzero(m)

    def box_distance(self, x: float, y: float) -> np.ndarray:
        """Distance from (x, y) to each piece's bounding box: a lower bound on the true distance."""
        dx = np.maximum(np.maximum(self.lo[:, 0] - x, x - self.hi[:, 0]), 0.0)
        dy = np.maximum(np.maximum(self.lo[:, 1] - y, y - self.hi[:, 1]), 0.0)
        return np.hypot(dx, dy)
