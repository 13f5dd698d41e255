"""Minkowski sums of convex polygons by the angular merge, and reflection.

The sum of convex polygons P_1 ⊕ ... ⊕ P_k is the convex polygon whose edge
sequence is the merge of the operands' edge sequences by polar angle (foundations
note, section on the merge). Start at the sum of the operands' lowest-then-leftmost
vertices, which is the sum's lowest-then-leftmost vertex; then walk the edges in
angle order. Each vertex of the sum is the sum of one vertex per operand.

Angles are compared exactly: first by half-plane (the upper half [0, pi) versus the
lower half [pi, 2 pi), decided by the signs of the edge's coordinates, which float
subtraction preserves), then by the exact sign of the cross product of the two
edge vectors (:func:`cspace.kernel.polygons.predicates.cross_diff_sign`). Parallel edges of equal
direction are fused, so the sum has no collinear vertex and at most sum(n_i)
vertices. Integer input (|x| < 2^52) gives the exact integer sum. Float input gives
each vertex as a sum of input vertices rounded once per addition; if that rounding
makes a turn non-convex, the exact hull of the rounded vertices is returned, so the
output is always strictly convex by the exact test.

Two code paths, one semantics: a scalar merge for the small polygons of C-space
pieces (:mod:`cspace.kernel.minkowski.scalar`), and a vectorised one for large inputs
(:mod:`cspace.kernel.minkowski.sorted_keys`: a stable sort of pseudo-angle keys, whose order
is then certified pair by pair with the exact comparison, :mod:`cspace.kernel.minkowski.certify`;
any doubt falls back to the scalar merge). This module owns the API and the choice of route.

The compiled pair sum. The C merge of two convex polygons (``_fast.pair_sums``, in
cspace/compiled/_build.c) is ~20x the scalar merge on small pairs, but the extension belongs to
:mod:`cspace.spaces` and the kernel imports nothing above it (kernel <- io <- spaces). So the
route is a hook: :func:`use_pair_sum` takes a callable ``f([P], [Q]) -> [sum or None]``, and
:mod:`cspace.compiled.fastpath` registers its ``pair_sums`` there when the extension is loaded
(``import cspace.compiled.fastpath``, which every C-space build and ``cspace.minkowski_sum`` do).
Two-operand sums of at most :data:`_SCALAR_MAX` vertices go through it; the C merge writes
only what it certifies (canonical operands, certified angle comparisons and turns), the very
arrays the scalar merge returns, and answers None otherwise: the pure route then runs. Under
``fastpath.disabled()`` or ``CSPACE_PURE=1`` the hook answers None (or is not registered).
"""
from __future__ import annotations

import numpy as np

from .scalar import certify_small, clean_edges_small, clean_small, merge2_small, merge_small
from .sorted_keys import clean_convex, merge_vectorised, prep_fast
from ..polygons.polygon import as_array, lowest_first
from ..polygons.predicates import NonFiniteError

# Up to this many vertices in total the scalar merge is faster than numpy's overhead.
_SCALAR_MAX = 96

_pair_sum = None  # the compiled pair sum registered by use_pair_sum (None: the pure route)


def use_pair_sum(fn):
    """Route two-operand sums of small convex polygons through ``fn`` (``fn([P], [Q])`` returns
    ``[P ⊕ Q]``, or ``[None]``/None when it cannot certify it); None restores the pure route.
    Returns the previous hook. :mod:`cspace.compiled.fastpath` registers the compiled one."""
    global _pair_sum
    previous, _pair_sum = _pair_sum, fn
    return previous


def reflect(polygon) -> np.ndarray:
    """The reflection −P = {−p : p ∈ P}, CCW and lowest-first like its input.

    Reflection through the origin is a rotation by pi, so orientation is kept.

    >>> reflect([[0, 0], [2, 0], [0, 1]]).tolist()
    [[0.0, -1.0], [0.0, 0.0], [-2.0, 0.0]]
    """
    p = as_array(polygon, nonempty=True)
    return lowest_first(-p + 0.0)  # + 0.0 turns -0.0 into 0.0


def minkowski_sum(P, Q, *more) -> np.ndarray:
    """P ⊕ Q (⊕ more...) of convex polygons, by one angular merge of all their edges.

    Operands may be in either orientation and may be degenerate (a point, a segment);
    they may carry repeated or collinear vertices. A non-convex operand raises
    ``ValueError``. The result is CCW from its lowest-then-leftmost vertex, with no
    collinear vertices.

    >>> minkowski_sum([[0, 0], [2, 0], [0, 2]], [[0, 0], [1, 0], [1, 1], [0, 1]]).tolist()
    [[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [1.0, 3.0], [0.0, 3.0]]
    """
    ops = [as_array(x, copy=False, nonempty=True) for x in (P, Q) + more]  # only read
    try:
        return _minkowski_sum(ops)
    except (OverflowError, NonFiniteError):  # an exact step met a NaN or an infinity
        if not all(np.isfinite(o).all() for o in ops):
            raise ValueError("minkowski_sum: coordinates must be finite") from None
        raise ValueError("minkowski_sum: the sum's coordinates overflow the double range") from None


def _roll_lowest(p: np.ndarray) -> np.ndarray:
    """``p`` from its lowest vertex (then the leftmost of a CCW bottom edge), cheaply: the start
    the C merge needs. A wrong guess (CW, not convex) is only refused by its certified check."""
    y = p[:, 1]
    i = int(y.argmin())
    if y[i - 1] == y[i]:  # a horizontal bottom edge: CCW, its left end comes first
        i -= 1
    return p if i == 0 else np.concatenate((p[i:], p[:i]))


def _minkowski_sum(ops: list) -> np.ndarray:
    """:func:`minkowski_sum` of operands already converted to arrays."""
    if sum(len(o) for o in ops) <= _SCALAR_MAX:
        if len(ops) == 2:
            if _pair_sum is not None and len(ops[0]) >= 3 and len(ops[1]) >= 3:
                got = _pair_sum([_roll_lowest(ops[0])], [_roll_lowest(ops[1])])
                if got is not None and got[0] is not None:
                    return got[0].copy()  # a view of the call's buffer: the caller owns its array
            (P, EP), (Q, EQ) = clean_edges_small(ops[0].tolist()), clean_edges_small(ops[1].tolist())
            flat, exact = merge2_small(P, Q, EP, EQ)
            if exact:  # the exact sum, strictly convex by the exact merge
                return np.array(flat, dtype=np.float64).reshape(-1, 2)
            out = list(zip(flat[::2], flat[1::2]))
        else:
            out = merge_small([clean_small(o.tolist()) for o in ops])
        return np.array(certify_small(out), dtype=np.float64)
    out = None
    if all(len(o) >= 3 for o in ops):  # the common case: certify while merging
        fast = [prep_fast(o) for o in ops]
        if all(f is not None for f in fast):
            out = merge_vectorised([f[0] for f in fast], [f[1] for f in fast])
    if out is None:  # repeats, collinear or degenerate operands: clean them first
        polys = [clean_convex(o) for o in ops]
        out = merge_vectorised(polys)
    if out is None:  # the float pre-sort could not be certified: exact scalar merge
        out = np.array(certify_small(merge_small([clean_small(p.tolist()) for p in polys])))
    return out

