"""Minkowski sums of non-convex polygons (holes included) as unions of convex sums.

A ⊕ B = ∪_{i,j} (A_i ⊕ B_j) for convex decompositions {A_i} of A and {B_j} of B
(the sum distributes over union). Each pairwise sum is an exact angular merge, all
pairs in one batch (:func:`cspace.pairsums.pairwise_sums`, equal to
:func:`cspace.minkowski.minkowski_sum` pair for pair); the union is shapely's (GEOS
OverlayNG), first per piece of A, then of those rows.
The boundary of the union can have Θ(n²m²) complexity in the worst case (comb ⊕
comb), which is why the C-space keeps the pieces and never needs the union.

Holes of the sum survive the union: a hole is a region no pairwise sum covers, so
it is kept however small it is next to the operands (the case CGAL's
reduced-convolution method must handle with care).
"""
from __future__ import annotations

import numpy as np

from .decompose import convex_decompose
from .pairsums import pairwise_sums


def minkowski_pieces(A, B, holes_a=None, holes_b=None) -> list[np.ndarray]:
    """The convex pieces A_i ⊕ B_j whose union is A ⊕ B.

    >>> L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    >>> len(minkowski_pieces(L, [[0, 0], [1, 0], [0, 1]]))
    2
    """
    return pairwise_sums(convex_decompose(A, holes_a), convex_decompose(B, holes_b))


def minkowski_sum_nonconvex(A, B, holes_a=None, holes_b=None):
    """A ⊕ B for simple polygons with holes, as a shapely Polygon or MultiPolygon.

    ``A`` and ``B`` are vertex arrays (either orientation) or shapely Polygons
    (whose interiors are their holes).

    >>> L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    >>> minkowski_sum_nonconvex(L, [[0, 0], [1, 0], [1, 1], [0, 1]]).area
    8.0
    """
    import shapely

    pa, pb = convex_decompose(A, holes_a), convex_decompose(B, holes_b)
    pieces = pairwise_sums(pa, pb)
    sizes = np.array([len(p) for p in pieces])
    if (sizes < 3).any():  # a degenerate pairwise sum (never from a proper decomposition)
        polys = np.array([shapely.Polygon(p) if len(p) >= 3 else shapely.Polygon() for p in pieces])
    else:
        rings = shapely.linearrings(np.concatenate(pieces), indices=np.repeat(np.arange(len(pieces)), sizes))
        polys = shapely.polygons(rings)
    # Union row by row (row i is A_i ⊕ B: pieces that overlap a lot), then the rows:
    # GEOS's cascaded union is about twice as fast this way as on the flat list.
    rows = shapely.union_all(polys.reshape(len(pa), len(pb)), axis=1)
    return shapely.union_all(rows)
