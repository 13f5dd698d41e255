"""The optional compiled fast path: which C routines are available, and their handles.

This module owns the choice between the compiled routines of ``cspace/_fast.c`` and the
pure-Python path. The extension is built by ``setup.py`` when a C compiler is present
(``optional=True``: without one, cspace installs and runs pure). ``CSPACE_PURE=1`` in
the environment, read at import, forces the pure path.

The C routines decide only what Shewchuk's stage-A float filter certifies and answer
"undecided" (-1) otherwise; the caller then runs the pure path, which is exact
(rationals). So both paths give the same answers, the pure one being the oracle
(tests/test_fastpath.py checks that on random and degenerate queries).
"""
from __future__ import annotations

import os

import numpy as np

_fast = None
if os.environ.get("CSPACE_PURE", "") in ("", "0"):
    try:
        from . import _fast  # type: ignore[attr-defined,no-redef]
    except ImportError:  # not built (no compiler): the pure path
        _fast = None

ENABLED: bool = _fast is not None


def grid_handle(index, packed, bounds):
    """A handle on a copy of ``index`` (a :class:`cspace.broadphase.GridIndex`) and
    ``packed`` (its :class:`cspace.pieces.PieceSet`) for the compiled queries, or None
    on the pure path.

    >>> import numpy as np
    >>> from cspace.broadphase import GridIndex
    >>> from cspace.pieces import PieceSet
    >>> sq = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])]
    >>> h = grid_handle(GridIndex(sq, (0, 10, 0, 10)), PieceSet(sq), (0, 10, 0, 10))
    >>> h is None or (_fast.point(h, 5.0, 5.0), _fast.segment(h, 1.0, 5.0, 9.0, 5.0)) == (0, 0)
    True
    """
    if _fast is None:
        return None
    xy = packed.start if len(packed) else np.zeros((0, 2))
    return _fast.grid(
        np.ascontiguousarray(index.state, dtype=np.uint8),
        np.ascontiguousarray(index.blocker, dtype=np.int64),
        np.ascontiguousarray(index._starts, dtype=np.int64),
        np.ascontiguousarray(index._cand, dtype=np.int64),
        np.ascontiguousarray(packed.offsets, dtype=np.int64),
        np.ascontiguousarray(xy, dtype=np.float64),
        index.nx, index.ny, index.x0, index.y0, index.inv_w, index.inv_h, index.cw, index.ch, index.margin,
        *map(float, bounds))
