"""The optional compiled fast path: which C routines are available, and their handles.

This module owns the choice between the compiled routines of ``cspace/compiled/_fast.c`` and the
pure-Python path. The extension is built by ``setup.py`` when a C compiler is present
(``optional=True``: without one, cspace installs and runs pure). ``CSPACE_PURE=1`` in
the environment, read at import, forces the pure path.

The C routines decide only what Shewchuk's stage-A float filter certifies and answer
"undecided" (-1) otherwise; the caller then runs the pure path, which is exact
(rationals). So both paths give the same answers, the pure one being the oracle
(tests/compiled/test_fastpath.py checks that on random and degenerate queries). The handles of
the SE(2) and car motion checks are made by :mod:`cspace.compiled.motions`, which reaches the
extension through :func:`extension` only (this module owns it).
"""
from __future__ import annotations

import contextlib
import math
import os
import warnings

import numpy as np

from .fingerprint import stale

_fast = None
STALE: str | None = None  # why a built extension is not used (its sources changed since the build)
if os.environ.get("CSPACE_PURE", "") in ("", "0"):
    try:
        from . import _fast  # type: ignore[attr-defined,no-redef]
    except ImportError:  # not built (no compiler): the pure path
        _fast = None
    if _fast is not None:
        STALE = stale(_fast, os.path.dirname(os.path.abspath(__file__)))
        if STALE is not None:  # the pure path, with the same answers, rather than stale code
            _fast = None
            warnings.warn(f"cspace's compiled fast path is {STALE}; running the pure Python path", stacklevel=2)

ENABLED: bool = _fast is not None


def grid_handle(index, packed, bounds):
    """A handle on the arrays of ``index`` (a :class:`cspace.translation.broadphase.GridIndex`) and
    ``packed`` (its :class:`cspace.kernel.polygons.pieces.PieceSet`) for the compiled queries, or None
    on the pure path.

    >>> import numpy as np
    >>> from cspace.translation.broadphase import GridIndex
    >>> from cspace.kernel.polygons.pieces import PieceSet
    >>> sq = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])]
    >>> h = grid_handle(GridIndex(sq, (0, 10, 0, 10)), PieceSet(sq), (0, 10, 0, 10))
    >>> h is None or (_fast.point(h, 5.0, 5.0), _fast.segment(h, 1.0, 5.0, 9.0, 5.0)) == (0, 0)
    True
    """
    if _fast is None:
        return None
    # The handle holds these arrays (no copy): the grid's and the pieces' own, read-only, as
    # GridIndex and PieceSet make them (C-contiguous; int8 states, int64 indices, float64
    # vertices: _fast.grid checks each one's byte length and refuses a strided one).
    arrays = (index.state, index.blocker, index._starts, index._cand, packed.offsets, packed.start)
    for a in arrays:
        a.flags.writeable = False
    return _fast.grid(*arrays, index.nx, index.ny, index.x0, index.y0, index.inv_w, index.inv_h, index.cw, index.ch,
                      index.margin, *map(float, bounds))


def compiled() -> bool:
    """Are the compiled routines in use now (built, not forced off, not :func:`disabled`)?

    >>> compiled() == (_fast is not None)
    True
    """
    return _fast is not None


def gjk_loop():
    """The compiled GJK loop (``_fast.gjk``) for :func:`cspace.kernel.distance.gjk.gjk_distance`'s
    ``loop=``, or None on the pure path. It repeats the pure loop's float operations in
    order, so the answers are the same to the bit (tests/compiled/test_gjk_fast.py).

    >>> from cspace.kernel.distance.gjk import gjk_distance
    >>> sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    >>> gjk_distance(sq, sq + 3, loop=gjk_loop()).distance == gjk_distance(sq, sq + 3).distance
    True
    """
    return None if _fast is None else _fast.gjk


def clearance_scan():
    """``_fast.clearance_scan`` (cspace/compiled/_nearest.c): min_clearance's search passing
    over the pairs that cannot beat the best distance, in C, or None on the pure path
    (:func:`cspace.translation.clearance.path_clearance` then measures every pair itself)."""
    return None if _fast is None else _fast.clearance_scan


def se2_pose():
    """The compiled filter stage of the SE(2) pose test (``_fast.se2_pose(handle, x, y, cos, sin)``:
    0 blocked, 1 free, 2 undecided), for a handle from :func:`se2_handle`; None on the pure path."""
    return None if _fast is None else _fast.se2_pose


def pack_boxes(pieces: list):
    """``(xy, off, lo, hi, scale)``: convex pieces packed (piece k in rows off[k] to
    off[k + 1] of xy), their boxes as :func:`cspace.kernel.polygons.polygon.piece_boxes` gives them,
    and the largest |coordinate| of the boxes, in one compiled pass; None on the pure path
    or for pieces that are not finite float64 (n, 2) arrays.

    >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    >>> out = pack_boxes([sq, np.zeros((0, 2))])
    >>> out is None or (out[1].tolist(), out[2].tolist(), out[3].tolist(), out[4]) == (
    ...     [0, 4, 4], [[4.0, 4.0], [np.inf, np.inf]], [[6.0, 6.0], [-np.inf, -np.inf]], 6.0)
    True
    """
    if _fast is None:
        return None
    out = _fast.pack_boxes(pieces if type(pieces) is list else list(pieces))
    if out is None:
        return None
    xy, off, lo, hi, scale = out
    f64 = lambda b: np.frombuffer(b, dtype=np.float64).reshape(-1, 2)  # noqa: E731
    return f64(xy), np.frombuffer(off, dtype=np.int64), f64(lo), f64(hi), scale


def box_gaps(lo: np.ndarray, hi: np.ndarray, olo: np.ndarray, ohi: np.ndarray) -> np.ndarray | None:
    """The distances between boxes ``(lo[r], hi[r])`` and ``(olo[k], ohi[k])`` as an (n, m)
    array, 0 where they meet (``_fast.box_gaps``, the doubles of numpy's
    ``hypot(max(olo - hi, lo - ohi, 0))``), or None on the pure path.

    >>> g = box_gaps(np.array([[0., 0]]), np.array([[1., 1]]), np.array([[4., 5], [0, 0]]), np.array([[6., 6], [2, 2]]))
    >>> g is None or g.tolist() == [[5.0, 0.0]]
    True
    """
    if _fast is None:
        return None
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    out = np.empty((len(lo), len(olo)))
    _fast.box_gaps(f64(lo), f64(hi), f64(olo), f64(ohi), out)
    return out


def assemble(*args) -> tuple[int, int, int]:
    """``_fast.assemble`` (cspace/compiled/_cells.c): the grid's state, blockers, candidates,
    masks and starts from its classified entries, as GridIndex's numpy route assembles
    them (cspace/translation/broadphase.py calls it when :func:`compiled`); returns the counts of
    FREE, MIXED and BLOCKED cells."""
    cc, cp, cm, inside, n, *out = args
    i64 = lambda a: np.ascontiguousarray(a, dtype=np.int64)  # noqa: E731
    return _fast.assemble(i64(cc), i64(cp), i64(cm), np.ascontiguousarray(inside, dtype=bool).view(np.uint8), int(n), *out)


def entries(xy, offsets, lo, hi, *frame) -> tuple:
    """``_fast.entries`` (cspace/compiled/_cells.c): the grid build's classified entries
    ``(piece, cell, inside, mask)`` of packed pieces, and the pieces it left to the numpy
    routes (cspace/translation/cellclass.py calls it when :func:`compiled`)."""
    f64, i64 = (lambda a: np.ascontiguousarray(a, dtype=np.float64)), (lambda a: np.ascontiguousarray(a, dtype=np.int64))
    ox, oy, x0, y0, iw, ih, cw, ch, m, nx, ny, mask_edges, block_edges, max_box, long_edge, tol, wide_mask = frame
    pid, cell, inside, mask, todo = _fast.entries(
        f64(xy), i64(offsets), f64(lo), f64(hi), *map(float, (ox, oy, x0, y0, iw, ih, cw, ch, m)),
        *map(int, (nx, ny, mask_edges, block_edges, max_box)), float(long_edge), float(tol), int(wide_mask))
    as64 = lambda b: np.frombuffer(b, dtype=np.int64)  # noqa: E731
    return as64(pid), as64(cell), np.frombuffer(inside, dtype=bool), as64(mask), todo


def pair_sums(pa: list, pb: list) -> list | None:
    """``[minkowski_sum(a, b) for a in pa for b in pb]`` by ``_fast.pair_sums`` (cspace/compiled/_build.c:
    one certified angular merge per pair), None for each pair it cannot certify (the
    caller computes those on the pure path); None on the pure path.

    >>> import numpy as np
    >>> sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    >>> out = pair_sums([sq], [sq - 1])
    >>> out is None or out[0].tolist() == [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
    True
    """
    if _fast is None:
        return None
    if len(pa) == 1 and len(pb) == 1:  # one pair (min_clearance's single C-obstacles): the lean call
        a, b = np.ascontiguousarray(pa[0], dtype=np.float64), np.ascontiguousarray(pb[0], dtype=np.float64)
        out, count = np.empty((len(a) + len(b), 2)), np.empty(1, dtype=np.int64)
        _fast.pair_sums(a, np.array([0, len(a)], dtype=np.int64), b, np.array([0, len(b)], dtype=np.int64), out, count)
        c = int(count[0])
        return [out[:c] if c > 0 else None]
    a_off = np.zeros(len(pa) + 1, dtype=np.int64)
    b_off = np.zeros(len(pb) + 1, dtype=np.int64)
    np.cumsum([len(p) for p in pa], out=a_off[1:])
    np.cumsum([len(p) for p in pb], out=b_off[1:])
    a_xy = np.ascontiguousarray(np.concatenate(pa) if pa else np.zeros((0, 2)), dtype=np.float64)
    b_xy = np.ascontiguousarray(np.concatenate(pb) if pb else np.zeros((0, 2)), dtype=np.float64)
    out = np.empty((int(a_off[-1]) * len(pb) + int(b_off[-1]) * len(pa), 2))
    count = np.empty(len(pa) * len(pb), dtype=np.int64)
    _fast.pair_sums(a_xy, a_off, b_xy, b_off, out, count)
    ends = np.cumsum(np.maximum(count, 0)).tolist()
    return [out[e - c:e] if c > 0 else None for c, e in zip(count.tolist(), ends)]


if _fast is not None:  # cspace.kernel.minkowski.merge.minkowski_sum's small pairs go through the C merge
    from ..kernel.minkowski.merge import use_pair_sum

    use_pair_sum(pair_sums)


def contained(pieces: list, qs: np.ndarray, ps: np.ndarray, packed: tuple | None = None) -> np.ndarray | None:
    """Per candidate pair (q, p): is piece p inside convex piece q? ``_fast.contained``
    (cspace/compiled/_build.c): 1 yes, 0 no, -1 not certified (the caller decides); None on
    the pure path. ``packed``: the pieces' vertices end to end and their sizes, if the caller has them.

    >>> sq, small = np.array([[0., 0], [4, 0], [4, 4], [0, 4]]), np.array([[1., 1], [2, 1], [1, 2]])
    >>> r = contained([sq, small], np.array([0, 1]), np.array([1, 0]))
    >>> r is None or r.tolist() == [1, 0]
    True
    """
    if _fast is None:
        return None
    off = np.zeros(len(pieces) + 1, dtype=np.int64)
    np.cumsum(packed[1] if packed is not None else [len(p) for p in pieces], out=off[1:])
    xy = packed[0] if packed is not None else np.concatenate(pieces) if pieces else np.zeros((0, 2))
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    out = np.empty(len(qs), dtype=np.int8)
    _fast.contained(xy, off, np.ascontiguousarray(qs, dtype=np.int64), np.ascontiguousarray(ps, dtype=np.int64), out)
    return out


def chord_polygons(Q: np.ndarray, sizes: np.ndarray, long_edge: float, tolerance: float):
    """:func:`cspace.kernel.polygons.chords.chord_polygons` by ``_fast.chords`` (cspace/compiled/_chords.c: the
    same float operations, piece by piece), the same chord polygons, counts and sagittas;
    None on the pure path.

    >>> sq = np.array([[[0., 0], [1, 0], [1, 1], [0, 1]]])
    >>> out = chord_polygons(sq, np.array([4]), long_edge=0.5, tolerance=0.1)
    >>> out is None or (int(out[1][0]), out[2][0].tolist()) == (4, [0.0, 0.0, 0.0, 0.0])
    True
    """
    if _fast is None:
        return None
    Q = np.ascontiguousarray(Q, dtype=np.float64)
    R = Q.copy()  # rows shorter than the longest keep their own vertices as padding
    n = np.empty(len(Q), dtype=np.int64)
    sag = np.empty(Q.shape[:2])
    _fast.chords(Q, np.ascontiguousarray(sizes, dtype=np.int64), float(long_edge), float(tolerance), R, n, sag)
    C = int(n.max()) if len(n) else 0
    return R[:, :C], n, sag[:, :C]


def segment_test(handle, pure, checks: dict):
    """The C-space's ``(ax, ay, bx, by) -> bool`` segment test: the compiled routine's
    certified answer when it has one, else ``pure`` (exact); ``pure`` itself on the pure
    path (``handle`` None). Counted in ``checks`` as the pure test counts.

    >>> segment_test(None, max, {}) is max
    True
    """
    if handle is None:
        return pure
    seg = _fast.segment

    def segment(ax: float, ay: float, bx: float, by: float) -> bool:
        r = seg(handle, ax, ay, bx, by)  # 1 or 3 free, 0 not, -1 undecided or out of bounds
        if r < 0:
            return pure(ax, ay, bx, by)
        checks["segments"] += 1
        if r != 1:
            checks["exact_segments"] += 1  # the narrow phase ran
        return r != 0

    return segment


def mixed_cell_test(handle, pure, checks: dict):
    """``(cell, x, y) -> bool``, the point test of a MIXED cell: the compiled test's
    certified answer when it has one, else ``pure`` (the Python narrow phase).

    >>> mixed_cell_test(None, max, {}) is max
    True
    """
    if handle is None:
        return pure
    point = _fast.point

    def free_in_cell(cell: int, x: float, y: float) -> bool:
        r = point(handle, x, y)  # 1 free, 0 not, -1 undecided
        if r < 0:
            return pure(cell, x, y)
        checks["exact_points"] += 1
        return r == 1

    return free_in_cell


def se2_slow_test(slab_handle, handle, pure, checks: dict):
    """``(x, y, th) -> bool``, the slow path of an SE(2) slab's pose test (free in the
    slab's C-space, else the exact test) in one compiled call; ``pure`` when it cannot
    decide. ``math.cos``/``math.sin`` are taken here, so the C filter turns the robot by
    the same doubles as the Python one.

    >>> se2_slow_test(None, None, max, {}) is max
    True
    """
    if handle is None or slab_handle is None:
        return pure
    both, cos, sin = _fast.se2_slow, math.cos, math.sin

    def slow(x: float, y: float, th: float) -> bool:
        r = both(slab_handle, handle, x, y, cos(th), sin(th))  # 1 free in the slab, 2 free, 0 not, -1 undecided
        if r < 0:
            return pure(x, y, th)
        if r != 1:
            checks["exact_states"] += 1  # decided by the exact test's filter stage
        return r != 0

    return slow


def se2_handle(cs):
    """A handle on the pose filter's data of a :class:`cspace.se2.cspace.SE2CSpace` (its obstacle
    edges and vertices, body-frame robot pieces and normals, and pair grid) for the
    compiled filter stage of its exact pose test, or None on the pure path (or without
    robot pieces).

    >>> import numpy as np
    >>> from cspace.se2.cspace import SE2CSpace
    >>> cs = SE2CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])],
    ...                [np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])], slabs=8)
    >>> h = se2_handle(cs)
    >>> h is None or (_fast.se2_pose(h, 5.0, 5.0, 1.0, 0.0), _fast.se2_pose(h, 1.0, 1.0, 1.0, 0.0)) == (0, 1)
    True
    """
    if _fast is None or not cs.robot_pieces:
        return None
    o_off = np.concatenate([[0], np.cumsum([len(p) for p in cs.obstacle_lists])]).astype(np.int64)
    r_off = np.concatenate([[0], np.cumsum([len(p) for p in cs._robot_lists])]).astype(np.int64)
    o_edge = np.array([e for edges in cs._obstacle_edges for e in edges], dtype=np.float64).reshape(-1, 4)
    o_pt = np.array([v for pts in cs.obstacle_lists for v in pts], dtype=np.float64).reshape(-1, 2)
    r_pt = np.array([v for pts in cs._robot_lists for v in pts], dtype=np.float64).reshape(-1, 2)
    r_nrm = np.array([v for nrm in cs._robot_normals for v in nrm], dtype=np.float64).reshape(-1, 3)
    cells = cs._pg_cells
    starts = np.concatenate([[0], np.cumsum([len(c) for c in cells])]).astype(np.int64)
    entries = [e for c in cells for e in c]
    e_ij = np.array([(e[0], e[1]) for e in entries], dtype=np.int64).reshape(-1, 2)
    e_box = np.array([e[5:9] for e in entries], dtype=np.float64).reshape(-1, 4)
    xmin, xmax, ymin, ymax = cs.bounds
    return _fast.se2(o_off, np.ascontiguousarray(o_edge), np.ascontiguousarray(o_pt), r_off,
                     np.ascontiguousarray(r_pt), np.ascontiguousarray(r_nrm), starts, np.ascontiguousarray(e_ij),
                     np.ascontiguousarray(e_box), cs._pg_n, len(cs.obstacle_lists), len(cs._robot_lists),
                     len(entries), xmin, xmax, ymin, ymax, cs.pad, cs._pg_x0, cs._pg_y0, cs._pg_iw, cs._pg_ih)



def disc_cost(unit: float, sigma: float, cost_type, at, slots_log2: int = 18):
    """The clearance objective's motion cost in translation, compiled
    (cspace/compiled/_disccost.c), or None on the pure path: ``(s1, s2) -> cost_type(exp(-c /
    sigma))``, c the disc bound of the motion's ends' clearances (``at(x, y)`` on raw OMPL
    coordinates, called once per state, then remembered in a table of 2^``slots_log2`` slots
    that starts over when half full) and of its length × ``unit``: the same doubles as
    :func:`planners.adapters.objectives.clearance_functions`'s motion.

    >>> f = disc_cost(1.0, 1.0, float, lambda x, y: 1.0)
    >>> f is None or f((0.0, 0.0), (1.0, 0.0)) == math.exp(-math.sqrt(0.75))
    True
    """
    if _fast is None:
        return None
    import functools

    return functools.partial(_fast.disc_cost, _fast.disc_cost_handle(float(unit), float(sigma), cost_type, at,
                                                                     int(slots_log2)))

@contextlib.contextmanager
def disabled():
    """Within the block, C-spaces are built on the pure path (no compiled handle): the
    oracle of the tests and the pure column of the benches. Objects keep the path they
    were built with (an SE(2) C-space's slabs: build them inside the block).

    >>> from cspace.compiled import fastpath
    >>> with fastpath.disabled():
    ...     inside = fastpath._fast
    >>> inside is None
    True
    """
    global _fast
    saved = _fast
    _fast = None
    try:
        yield
    finally:
        _fast = saved


def contiguous(a) -> np.ndarray:
    """A C-contiguous float64 array (the compiled handles' buffers)."""
    return np.ascontiguousarray(a, dtype=np.float64)


def packed(pieces: list) -> tuple[np.ndarray, np.ndarray]:
    """The motion handles' piece arrays: each piece's first row (int64, K + 1 entries) and all
    the vertices one piece after another (:func:`cspace.kernel.polygons.polygon.pack`)."""
    from ..kernel.polygons.polygon import pack

    xy, sizes = pack(list(pieces))
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64), contiguous(xy)


def extension():
    """The compiled extension module in use now, or None on the pure path (not built, forced
    off by ``CSPACE_PURE=1``, or inside :func:`disabled`): the handle makers of
    :mod:`cspace.compiled.motions` ask here, so that :func:`disabled` holds for them too.

    >>> (extension() is None) == (not compiled())
    True
    """
    return _fast
