"""Minkowski sums of non-convex polygons (holes included) as unions of convex sums.

A ⊕ B = ∪_{i,j} (A_i ⊕ B_j) for convex decompositions {A_i} of A and {B_j} of B
(the sum distributes over union). Each pairwise sum is an exact angular merge
(:func:`cspace.minkowski.minkowski_sum`); the union is shapely's (GEOS OverlayNG).
The boundary of the union can have Θ(n²m²) complexity in the worst case (comb ⊕
comb), which is why the C-space keeps the pieces and never needs the union.

Holes of the sum survive the union: a hole is a region no pairwise sum covers, so
it is kept however small it is next to the operands (the case CGAL's
reduced-convolution method must handle with care).
"""
from __future__ import annotations

import numpy as np

from .decompose import convex_decompose
from .minkowski import minkowski_sum


def minkowski_pieces(A, B, holes_a=None, holes_b=None) -> list[np.ndarray]:
    """The convex pieces A_i ⊕ B_j whose union is A ⊕ B.

    >>> L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    >>> len(minkowski_pieces(L, [[0, 0], [1, 0], [0, 1]]))
    2
    """
    pa = convex_decompose(A, holes_a)
    pb = convex_decompose(B, holes_b)
    return [minkowski_sum(a, b) for a in pa for b in pb]


def minkowski_sum_nonconvex(A, B, holes_a=None, holes_b=None):
    """A ⊕ B for simple polygons with holes, as a shapely Polygon or MultiPolygon.

    ``A`` and ``B`` are vertex arrays (either orientation) or shapely Polygons
    (whose interiors are their holes).

    >>> L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    >>> minkowski_sum_nonconvex(L, [[0, 0], [1, 0], [1, 1], [0, 1]]).area
    8.0
    """
    import shapely

    pieces = minkowski_pieces(A, B, holes_a, holes_b)
    return shapely.union_all(shapely.polygons(pieces) if _same_size(pieces) else
                             [shapely.Polygon(p) for p in pieces])


def _same_size(pieces: list) -> bool:
    return len({len(p) for p in pieces}) == 1 and len(pieces[0]) >= 3
