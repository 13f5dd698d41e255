"""Segment queries of the C-space: is every state on a closed segment free, exactly (no sampling),
one segment, a batch, or the motion validator's hot path (compiled when built).

A mixin of :class:`cspace.translation.cspace.CSpace`; the pure path walks a coarser grid
(:attr:`SegmentQueries.coarse`) and tests the pieces it meets exactly.
"""
from __future__ import annotations

import numpy as np

from .broadphase import GridIndex
from .inputs import query_points

SMALL_GRID = 4096  # cells: a grid this small is also the segment walk's grid


class SegmentQueries:
    """:class:`cspace.translation.cspace.CSpace`'s segment queries."""

    @property
    def coarse(self) -> GridIndex:
        """The pure segment walk's grid, built on first use (the compiled walk uses
        :attr:`index` itself, so a default install never builds it): 4x coarser than the
        index, fewer cells per motion, the same exact answer; a grid of at most 64 x 64
        cells (an SE(2) slab's) is walked as it is."""
        if self._coarse is None:
            cells = self.index.nx * self.index.ny
            self._coarse = (self.index if cells <= SMALL_GRID
                            else GridIndex(self.pieces, self.bounds, cells=max(cells // 16, 64), packed=self.packed))
        return self._coarse

    def segment_free(self, a, b=None):
        """Is every state on the closed segment a-b valid? Exact: no sampling along it.

        ``segment_free(a, b)`` with two points gives a bool; ``segment_free(S)`` with an
        ``(N, 2, 2)`` array of segments (or ``a``, ``b`` as two ``(N, 2)`` arrays) gives a
        bool array. Non-finite coordinates and ``(x, y, theta)`` are a ``ValueError``.

        >>> import numpy as np
        >>> from cspace.translation.cspace import CSpace
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
        >>> from cspace.translation.cspace import CSpace
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
