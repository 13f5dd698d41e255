"""Classifying grid cells against convex pieces: the build of the grid broad phase.

This module owns the question "which cells of a uniform grid may a closed convex piece
meet, and which lie inside it?", answered once per piece at build time for
:class:`cspace.translation.broadphase.GridIndex`. Each edge of a piece is a half-plane
n . x <= c (n the outward unit normal); over a cell the signed distance n . corner - c
is largest and smallest at the two corners the signs of n pick, so a cell is inside
when every edge has it strictly inside by the grid's margin, separated when one edge
has it strictly outside by the margin, and may meet the piece otherwise. For the
cells that may meet, a bit mask names the edges whose line passes near the cell (the
narrow phase tests only those).

Pieces are classified together in padded (piece, cell, edge) blocks; boxes wider than
SCAN_COLUMNS cells row by row, where each edge's tests flip once along a row (found
exactly by bisection on the same float expression, started from the column solved in
reals). Pieces of more than MASK_EDGES edges go through their chord polygons
(:func:`cspace.kernel.polygons.chords.chord_polygons`) and have their masks computed per cell on
demand (:meth:`CellClassifier.edge_mask`). On the compiled path, ``_fast.entries``
(cspace/compiled/_cells.c) does all of it piece by piece from the packed vertices, with the
same doubles: this numpy route is its oracle, and takes the pieces it leaves (more than
_BLOCK_EDGES edges, boxes of more than 2^20 cells).
"""
from __future__ import annotations

import math

import numpy as np

from ..kernel.polygons.chords import chord_polygons
from ..kernel.polygons.pieces import PieceSet
from ..compiled import fastpath

# Boxes wider than this many cells are classified row by row (GridIndex._scan_rows).
SCAN_COLUMNS = 8

# Pieces of at most this many edges get their edge masks at build time (int64 bits);
# wider ones (a margin's rounded corners, big disks) store WIDE_MASK and have a cell's
# mask computed when a point first lands there (GridIndex.edge_mask), by the same test.
MASK_EDGES = 62
WIDE_MASK = -1  # every bit set: "test every edge" is always a valid mask

# Pieces up to this many edges are classified in padded (piece, cell, edge) blocks;
# wider ones one by one (a 10^6-gon must not pad every other piece to its size).
_BLOCK_EDGES = 1024


def _runs(rows: np.ndarray, jj: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """The cells (row, i, j) of the column runs [lo, hi] of each row (empty where lo > hi).

    >>> [x.tolist() for x in _runs(np.array([5, 6]), np.array([0, 1]), np.array([2, 4]), np.array([3, 3]))]
    [[5, 5], [2, 3], [0, 0]]
    """
    n = np.maximum(hi - lo + 1, 0)
    total = int(n.sum())
    k = np.repeat(np.arange(len(n)), n)
    i = lo[k] + (np.arange(total) - np.repeat(np.cumsum(n) - n, n))
    return rows[k], i, jj[k]



class CellClassifier:
    """The cell classification of a grid (a mixin of
    :class:`cspace.translation.broadphase.GridIndex`): it reads the grid's frame (``x0``,
    ``y0``, ``cw``, ``ch``, ``inv_w``, ``inv_h``, ``nx``, ``ny``, the local origin ``ox``,
    ``oy``, the certified ``margin``) and the pieces' boxes ``_lo``, ``_hi``. With the
    compiled fast path, boxes are evaluated in C (``compiled``; False forces numpy).
    """

    compiled = True

    def _classify_all(self, pieces: list[np.ndarray], packed: PieceSet | None = None):
        """Every (cell, piece) pair that may meet: ``(cells, pieces, masks, inside)``,
        each piece's cells together. ``packed``: the pieces packed (the compiled route
        reads their vertices from it), when the caller has them so."""
        cand_cells: list[np.ndarray] = []
        cand_piece: list[np.ndarray] = []
        cand_mask: list[np.ndarray] = []
        inside_parts = []
        todo = range(len(pieces))
        if fastpath.compiled() and self.compiled and pieces:
            # In C from the packed vertices, piece by piece (_fast.entries: the padded route's
            # doubles); it leaves pieces of more than _BLOCK_EDGES edges or 2^20 cells to the
            # routes below.
            if packed is None:
                packed = PieceSet(pieces, (self._lo, self._hi))
            pid, cells_k, inside, masks, todo = fastpath.entries(
                packed.start, packed.offsets, self._lo, self._hi, self.ox, self.oy, self.x0, self.y0, self.inv_w, self.inv_h,
                self.cw, self.ch, self.margin, self.nx, self.ny, MASK_EDGES, _BLOCK_EDGES, 1 << 20,
                self.cw + self.ch, 0.25 * min(self.cw, self.ch), WIDE_MASK)
            if not todo:
                return cells_k, pid, masks, inside
            cand_cells.append(cells_k)
            cand_piece.append(pid)
            inside_parts.append(inside)
            cand_mask.append(masks)
        sizes = [len(p) for p in pieces]
        # Pieces are classified together, in blocks of (piece, cell) pairs (one numpy
        # pass instead of one per piece), those with masks apart from the wider ones so
        # that a 4-gon is not padded to a margin's 70 edges; huge pieces one by one.
        for group in ([k for k in todo if sizes[k] <= MASK_EDGES],
                      [k for k in todo if MASK_EDGES < sizes[k] <= _BLOCK_EDGES]):
            if group:
                pid, cells_k, inside, masks = self._classify_many(pieces, group)
                cand_cells.append(cells_k)
                cand_piece.append(pid)
                inside_parts.append(inside)
                cand_mask.append(masks)
        for k in todo:
            p = pieces[k]
            if sizes[k] <= _BLOCK_EDGES:
                continue
            cells_k, inside, masks = self._classify(p, with_masks=False)
            cand_cells.append(cells_k)
            cand_piece.append(np.full(cells_k.size, k, dtype=np.int64))
            inside_parts.append(inside)
            cand_mask.append(masks)
        if not cand_cells:
            z = np.zeros(0, dtype=np.int64)
            return z, z, z, np.zeros(0, dtype=bool)
        if len(cand_cells) == 1:  # one group: its arrays as they are (a copy costs fresh pages)
            return cand_cells[0], cand_piece[0], cand_mask[0], inside_parts[0]
        return (np.concatenate(cand_cells), np.concatenate(cand_piece), np.concatenate(cand_mask),
                np.concatenate(inside_parts))

    def edge_mask(self, p: np.ndarray, cell: int) -> int:
        """The edge mask of convex piece ``p`` in ``cell``, as the build computes it for
        pieces of at most MASK_EDGES edges (bit e: the edge from vertex e-1 to e, set
        when the edge's line may pass within the margin of the cell). Wider pieces
        store WIDE_MASK at build; the point test asks this once per cell it visits.
        Below, the cell meets the edges on x = 2 (bit 2) and y = 2 (bit 3).

        >>> from cspace.translation.broadphase import GridIndex
        >>> g = GridIndex([np.array([[-1., -1], [2, -1], [2, 2], [-1, 2]])], (0, 4, 0, 4), cells=16)
        >>> bin(g.edge_mask(np.array([[-1., -1], [2, -1], [2, 2], [-1, 2]]), 6))  # cell [2, 3] x [1, 2]
        '0b1100'
        """
        nrm, c, hi, _ = self._half_planes(p)
        i, j = cell % self.nx, cell // self.nx
        d = ((self.x0 - self.ox) + i * self.cw) * nrm[:, 0]
        d += ((self.y0 - self.oy) + j * self.ch) * nrm[:, 1]
        d -= c
        near = np.flatnonzero(~(d <= -self.margin - hi))
        return sum(1 << ((int(e) + 1) % len(p)) for e in near)

    def _half_planes(self, p: np.ndarray):
        """Edge half-planes of ``p`` in the grid's local frame, n . x <= c with n the
        outward unit normal of edge q[i] -> q[i+1]; and per edge the largest (``hi``)
        and smallest (``lo``) of n . (corner - lower-left corner) over a cell."""
        q = p - (self.ox, self.oy)
        e = np.roll(q, -1, axis=0) - q
        nrm = np.column_stack([e[:, 1], -e[:, 0]])
        # A piece that rounded to a point (a disk of radius 1e-200 at (5, 5)) has zero-length
        # edges: their NaN normals make every comparison False, so no cell is called
        # inside or separated by them and the exact narrow phase decides (quietly).
        with np.errstate(invalid="ignore", divide="ignore"):
            nrm /= np.hypot(nrm[:, 0], nrm[:, 1])[:, None]
        c = nrm[:, 0] * q[:, 0] + nrm[:, 1] * q[:, 1]  # the build's c, the same doubles
        hi = np.maximum(nrm[:, 0], 0.0) * self.cw + np.maximum(nrm[:, 1], 0.0) * self.ch
        lo = np.minimum(nrm[:, 0], 0.0) * self.cw + np.minimum(nrm[:, 1], 0.0) * self.ch
        return nrm, c, hi, lo

    def _classify_many(self, pieces: list[np.ndarray], ks: list[int]):
        """:meth:`_classify` for the pieces ``ks`` at once: ``(piece, cell, inside, mask)``
        per (piece, cell) pair that may meet, piece-major, each piece's cells in
        :meth:`_classify`'s order, with the same arithmetic.

        Edges are padded to the widest piece with a dummy edge (zero normal, offset
        +inf) that every cell lies strictly inside and no cell is separated by.
        Pieces wider than MASK_EDGES are classified through their chord polygons
        (:func:`cspace.kernel.polygons.chords.chord_polygons`): conservatively, and with WIDE_MASK as their
        masks.
        """
        m = self.margin
        sizes = np.array([len(pieces[k]) for k in ks], dtype=np.int64)
        E = int(sizes.max())
        K = len(ks)
        Q = np.zeros((K, E, 2))
        # A row at a time costs ~0.3-0.5 us a piece, one scatter of all the vertices ~10 ns a
        # vertex and more per piece (measured): rows below 64 pieces or above 8 vertices a piece.
        if K < 64 or int(sizes.sum()) > 8 * K:
            for r, (k, size) in enumerate(zip(ks, sizes.tolist())):
                Q[r, :size] = pieces[k]
        else:  # one scatter: row r, slots 0 .. sizes[r] - 1
            row = np.repeat(np.arange(K), sizes)
            col = np.arange(len(row)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
            Q[row, col] = np.concatenate([pieces[k] for k in ks])
        Q[:, :, 0] -= self.ox  # per coordinate: 4x faster than broadcasting a pair
        Q[:, :, 1] -= self.oy
        # Pieces wider than MASK_EDGES get WIDE_MASK (their cells' masks on demand).
        wide = sizes > MASK_EDGES
        sag = None
        if wide.all():
            chords = fastpath.chord_polygons if fastpath.compiled() and self.compiled else chord_polygons
            Q, sizes, sag = chords(Q, sizes, self.cw + self.ch, 0.25 * min(self.cw, self.ch))
            E = Q.shape[1]
        # Each piece's box of cells (widened by the margin), clipped to the grid.
        lo_xy, hi_xy = self._lo[ks], self._hi[ks]
        i0 = np.maximum(np.floor((lo_xy[:, 0] - m - self.x0) * self.inv_w), 0).astype(np.int64)
        i1 = np.minimum(np.floor((hi_xy[:, 0] + m - self.x0) * self.inv_w), self.nx - 1).astype(np.int64)
        j0 = np.maximum(np.floor((lo_xy[:, 1] - m - self.y0) * self.inv_h), 0).astype(np.int64)
        j1 = np.minimum(np.floor((hi_xy[:, 1] + m - self.y0) * self.inv_h), self.ny - 1).astype(np.int64)
        W = np.maximum(i1 - i0 + 1, 0)
        H = np.maximum(j1 - j0 + 1, 0)
        x_off, y_off, cw, ch = self.x0 - self.ox, self.y0 - self.oy, self.cw, self.ch
        parts = []
        narrow_box = W <= SCAN_COLUMNS
        if not (narrow_box & (W * H > 0)).any() and not (~narrow_box & (H > 0)).any():
            return self._joined([])
        slot = np.arange(E)
        valid = slot[None, :] < sizes[:, None]
        nxt = np.where(slot[None, :] + 1 < sizes[:, None], slot[None, :] + 1, 0)
        e = np.take_along_axis(Q, nxt[:, :, None], axis=1) - Q
        nrm = np.stack([e[:, :, 1], -e[:, :, 0]], axis=2)
        with np.errstate(invalid="ignore", divide="ignore"):
            nrm /= np.hypot(nrm[:, :, 0], nrm[:, :, 1])[:, :, None]
        nrm[~valid] = 0.0
        c = nrm[:, :, 0] * Q[:, :, 0] + nrm[:, :, 1] * Q[:, :, 1]
        c[~valid] = np.inf
        hi = np.maximum(nrm[:, :, 0], 0.0) * self.cw + np.maximum(nrm[:, :, 1], 0.0) * self.ch
        lo = np.minimum(nrm[:, :, 0], 0.0) * self.cw + np.minimum(nrm[:, :, 1], 0.0) * self.ch
        if sag is not None:  # separation from a chord's line pushed out past every vertex
            lo -= sag
        # Bit e stands for the edge ending at vertex e: slot i (edge i -> i+1) is bit (i + 1) % n.
        with_masks = not wide.all()
        shift = np.where(wide[:, None], 0, (slot[None, :] + 1) % sizes[:, None])
        weights = np.where(valid & ~wide[:, None], np.left_shift(np.int64(1), shift), 0)

        def evaluate(row, ii, jj):
            """inside, separated, mask of the cells (piece row[k], cell ii[k], jj[k])."""
            n = len(row)
            inside = np.empty(n, dtype=bool)
            separated = np.empty(n, dtype=bool)
            masks = np.empty(n, dtype=np.int64)
            step = max(1, (1 << 21) // E)
            for s in range(0, n, step):
                r = row[s : s + step]
                cx0 = x_off + ii[s : s + step] * cw
                cy0 = y_off + jj[s : s + step] * ch
                d = cx0[:, None] * nrm[r, :, 0]
                d += cy0[:, None] * nrm[r, :, 1]
                d -= c[r]
                strictly_in = d <= -m - hi[r]
                inside[s : s + step] = strictly_in.all(axis=1)
                masks[s : s + step] = ((~strictly_in) * weights[r]).sum(axis=1) if with_masks else 0
                separated[s : s + step] = (d >= m - lo[r]).any(axis=1)
            return inside, separated, masks

        # Pieces at most SCAN_COLUMNS cells wide: every cell of their box is evaluated.
        # Wider ones row by row (_scan_rows): per row and edge the column where the edge's
        # test flips is found exactly, so only the cells near the boundary are evaluated.
        dense = np.flatnonzero(narrow_box & (W * H > 0))
        if len(dense):
            counts = (W * H)[dense]
            total = int(counts.sum())
            row = np.repeat(dense, counts)
            t = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
            ii = i0[row] + t % W[row]
            jj = j0[row] + t // W[row]
            inside, separated, masks = evaluate(row, ii, jj)
            keep = ~separated
            parts.append((row[keep], ii[keep], jj[keep], inside[keep], masks[keep]))
        scan = np.flatnonzero(~narrow_box & (H > 0))
        if len(scan):
            parts += self._scan_rows(scan, i0, i1, j0, H, nrm, c, hi, lo, evaluate)
        return self._joined([self._gathered(parts, ks, wide)] if parts else [])

    def _gathered(self, parts: list, ks: list[int], wide: np.ndarray) -> tuple:
        """Entries ``(piece, cell, inside, mask)`` from the numpy route's parts ``(row, i, j,
        inside, mask)``."""
        row, ii, jj, inside, masks = parts[0] if len(parts) == 1 else (np.concatenate(x) for x in zip(*parts))
        pid = np.asarray(ks, dtype=np.int64)[row]
        if wide.any():
            masks = np.where(wide[row], np.int64(WIDE_MASK), masks)
        return pid, jj * self.nx + ii, inside, masks

    @staticmethod
    def _joined(parts: list) -> tuple:
        """:meth:`_classify_many`'s answer ``(piece, cell, inside, mask)`` from its parts."""
        if not parts:
            z = np.zeros(0, dtype=np.int64)
            return z, z, np.zeros(0, dtype=bool), z
        return parts[0] if len(parts) == 1 else tuple(np.concatenate(x) for x in zip(*parts))

    def _scan_rows(self, pieces, i0, i1, j0, H, nrm, c, hi, lo, evaluate) -> list:
        """:meth:`_classify_many`'s cells of wide boxes, row by row, the same answers.

        Along a row the classification value d = ((x0 - ox) + i cw) n_x + (cy n_y) - c of
        an edge is evaluated in floats, each operation rounded monotonically, so as a
        function of the column i it is monotone (with the sign of n_x; constant when
        n_x is 0 or NaN). Each edge's "strictly inside" and "separating" tests therefore
        flip at most once along the row, at a column found exactly by bisection on the
        same float expression. Cells inside for every edge are inside (no edge near
        them: mask 0), cells separated by an edge are dropped, and only the cells in
        between are evaluated in full, as the dense route does.
        """
        m, x_off, y_off, cw, ch = self.margin, self.x0 - self.ox, self.y0 - self.oy, self.cw, self.ch
        out = []
        E = nrm.shape[1]
        per = max(1, (1 << 20) // E)  # rows per block
        rows_all = np.repeat(pieces, H[pieces])
        local = np.arange(len(rows_all)) - np.repeat(np.cumsum(H[pieces]) - H[pieces], H[pieces])
        for s in range(0, len(rows_all), per):
            rr = rows_all[s : s + per]
            jj = j0[rr] + local[s : s + per]
            n0 = nrm[rr, :, 0]
            yterm = (y_off + jj * ch)[:, None] * nrm[rr, :, 1]
            cc = c[rr]
            t_in, t_sep = -m - hi[rr], m - lo[rr]
            a, b = i0[rr][:, None], i1[rr][:, None]
            pos, neg = n0 > 0, n0 < 0

            def d_at(i):
                d = (x_off + i * cw) * n0
                d += yterm
                d -= cc
                return d

            def flip(test, t):
                """First column where test(d) turns True (monotone False..True), b + 1 if none.

                The column where d crosses t, solved in reals, is a guess: the float test at
                it and at the column before narrow [L, U] to it when it is right (almost
                always), and the bisection on the float test finishes what it leaves, so
                the answer is the bisection's whatever the guess."""
                L = np.broadcast_to(a, n0.shape).copy()
                U = np.broadcast_to(b + 1, n0.shape).copy()
                with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                    g = ((t - yterm + cc) / n0 - x_off) / cw
                g = np.clip(np.nan_to_num(np.floor(g), nan=-1.0, posinf=-1.0, neginf=-1.0) + 1, L, U).astype(np.int64)
                for probe in (g, g - 1):  # test(probe) True: the flip is at or before it
                    at = (probe >= L) & (probe < U)
                    f = test(d_at(np.clip(probe, a, b))) & at
                    U = np.where(f, probe, U)
                    L = np.where(at & ~f, probe + 1, L)
                while True:
                    act = L < U
                    if not act.any():
                        return L
                    mid = (L + U) // 2
                    f = test(d_at(np.minimum(mid, b))) & act
                    U = np.where(f, mid, U)
                    L = np.where(act & ~f, mid + 1, L)

            d0 = d_at(a)
            # strictly inside edge e: a prefix of the row (n_x > 0), a suffix (n_x < 0), all or none
            f_in = flip(lambda d: np.where(pos, ~(d <= t_in), d <= t_in), t_in)
            lo_in = np.where(pos, a, np.where(neg, f_in, np.where(d0 <= t_in, a, b + 1)))
            hi_in = np.where(pos, f_in - 1, np.where(neg, b, np.where(d0 <= t_in, b, a - 1)))
            # not separated by edge e: likewise
            f_ns = flip(lambda d: np.where(pos, d >= t_sep, ~(d >= t_sep)), t_sep)
            lo_ns = np.where(pos, a, np.where(neg, f_ns, np.where(~(d0 >= t_sep), a, b + 1)))
            hi_ns = np.where(pos, f_ns - 1, np.where(neg, b, np.where(~(d0 >= t_sep), b, a - 1)))
            in_lo, in_hi = lo_in.max(axis=1), hi_in.min(axis=1)
            ns_lo, ns_hi = lo_ns.max(axis=1), hi_ns.min(axis=1)
            in_lo, in_hi = np.maximum(in_lo, ns_lo), np.minimum(in_hi, ns_hi)
            has_in = in_lo <= in_hi
            # runs of cells: inside [in_lo, in_hi]; to evaluate: the rest of [ns_lo, ns_hi]
            left_hi = np.where(has_in, in_lo - 1, ns_hi)
            right_lo = np.where(has_in, in_hi + 1, ns_hi + 1)
            cells = [_runs(rr, jj, ns_lo, left_hi), _runs(rr, jj, right_lo, ns_hi)]
            er, ei, ej = (np.concatenate(x) for x in zip(*cells))
            inside, separated, masks = evaluate(er, ei, ej)
            keep = ~separated
            out.append((er[keep], ei[keep], ej[keep], inside[keep], masks[keep]))
            ir, ic, ij = _runs(rr, jj, in_lo, in_hi)
            out.append((ir, ic, ij, np.ones(len(ir), dtype=bool), np.zeros(len(ir), dtype=np.int64)))
        return out

    def _classify(self, p: np.ndarray, with_masks: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cells that closed convex ``p`` may meet, which of them lie inside ``p``, and for
        each the bit mask of the edges whose line passes within the margin of it (Python
        ints beyond MASK_EDGES edges; WIDE_MASK for every cell without ``with_masks``)."""
        m = self.margin
        i0 = math.floor((p[:, 0].min() - m - self.x0) * self.inv_w)
        i1 = math.floor((p[:, 0].max() + m - self.x0) * self.inv_w)
        j0 = math.floor((p[:, 1].min() - m - self.y0) * self.inv_h)
        j1 = math.floor((p[:, 1].max() + m - self.y0) * self.inv_h)
        i0, j0 = max(i0, 0), max(j0, 0)
        i1, j1 = min(i1, self.nx - 1), min(j1, self.ny - 1)
        if i0 > i1 or j0 > j1:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool), np.zeros(0, dtype=np.int64)
        ii, jj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
        ii, jj = ii.ravel(), jj.ravel()
        nrm, c, hi, lo = self._half_planes(p)
        inside = np.empty(ii.size, dtype=bool)
        separated = np.empty(ii.size, dtype=bool)
        # Bit e stands for the edge ending at vertex e (q[e-1] -> q[e]); the half-planes
        # are for q[e] -> q[e+1], i.e. bit e+1. Up to MASK_EDGES edges the masks are int64,
        # beyond that Python ints (an object array).
        wide = len(p) > MASK_EDGES
        masks = (np.full(ii.size, WIDE_MASK, dtype=np.int64) if not with_masks
                 else np.empty(ii.size, dtype=object if wide else np.int64))
        weights = None if wide else np.left_shift(np.int64(1), (np.arange(len(p)) + 1) % len(p))
        # Over a cell [x, x + cw] x [y, y + ch] the signed distance n . corner - c is
        # largest at the corner picked by the signs of n and smallest at the opposite one:
        # d = n . (x, y) - c, plus hi (resp. lo) per edge. One (cells, edges) block.
        step = max(1, (1 << 21) // len(p))  # bound the (cells, edges) block
        for s in range(0, ii.size, step):
            cx0 = (self.x0 - self.ox) + ii[s : s + step] * self.cw
            cy0 = (self.y0 - self.oy) + jj[s : s + step] * self.ch
            d = np.multiply.outer(cx0, nrm[:, 0])
            d += np.multiply.outer(cy0, nrm[:, 1])
            d -= c
            strictly_in = d <= -m - hi  # (cells, edges): every corner well inside the edge's half-plane
            inside[s : s + step] = strictly_in.all(axis=1)
            if not with_masks:
                pass
            elif wide:
                bits = np.packbits(np.roll(~strictly_in, 1, axis=1), axis=1, bitorder="little")
                masks[s : s + step] = [int.from_bytes(b.tobytes(), "little") for b in bits]
            else:
                masks[s : s + step] = (~strictly_in) @ weights
            # Separated when every corner lies beyond one edge; the cell's own axes are
            # covered by the bounding-box range above.
            separated[s : s + step] = (d >= m - lo).any(axis=1)
        keep = ~separated
        return (jj * self.nx + ii)[keep], inside[keep], masks[keep]
