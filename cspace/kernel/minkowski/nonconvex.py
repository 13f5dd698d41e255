"""Minkowski sums of non-convex polygons (holes included).

A ⊕ B = ∪_{i,j} (A_i ⊕ B_j) for convex decompositions {A_i} of A and {B_j} of B
(the sum distributes over union). Each pairwise sum is an exact angular merge, all
pairs in one batch (:func:`cspace.kernel.minkowski.pairsums.pairwise_sums`, equal to
:func:`cspace.kernel.minkowski.merge.minkowski_sum` pair for pair). :func:`minkowski_pieces`
returns these pieces; the C-space keeps them and never needs their union, whose
boundary can have Θ(n²m²) complexity (comb ⊕ comb).

:func:`minkowski_sum_nonconvex` returns the region itself. When one operand is
simple (no holes) and not convex, it decomposes only the other one and sums each
piece A_i with the whole simple operand Q through the convolution cycle
(:mod:`cspace.kernel.minkowski.convolution`): A ⊕ Q = ∪_i (A_i ⊕ Q), one GEOS region per piece and
one union of those. Otherwise (a convex operand, or holes in both) it takes the
union of the pairwise convex sums, first per piece of A, then of those rows.

Holes of the sum survive either way: a hole is a region no partial sum covers, so
it is kept however small it is next to the operands (the case CGAL's
reduced-convolution method must handle with care).
"""
from __future__ import annotations

import numpy as np

from .convolution import convex_sums_with
from ..polygons.decompose import convex_decompose, decompose_normalized
from .pairsums import pairwise_sums
from ..polygons.polygon import as_array, collinear_extent, is_convex, normalize, prev_next
from ..polygons.scaling import scaled_copies
from .union import union


def minkowski_pieces(A, B, holes_a=None, holes_b=None) -> list[np.ndarray]:
    """The convex pieces A_i ⊕ B_j whose union is A ⊕ B.

    >>> L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    >>> len(minkowski_pieces(L, [[0, 0], [1, 0], [0, 1]]))
    2
    """
    return pairwise_sums(convex_decompose(A, holes_a), convex_decompose(B, holes_b))


def minkowski_sum_nonconvex(A, B, holes_a=None, holes_b=None):
    """A ⊕ B for polygons with holes, always as a shapely ``MultiPolygon``.

    ``A`` and ``B`` are vertex arrays (either orientation), shapely Polygons (whose
    interiors are their holes) or shapely MultiPolygons (the sum distributes over their
    parts). The result is one type whatever the input: a MultiPolygon with one part per
    connected component of the sum (``.geoms[0]`` when it is connected); it is empty only
    when the sum has no area (two parallel segments). An operand whose vertices are
    collinear is the point or segment they span (a segment sweeps the other operand).
    A polygon that is not simple, or a non-finite coordinate, is a ``ValueError``.

    >>> L = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
    >>> minkowski_sum_nonconvex(L, [[0, 0], [1, 0], [1, 1], [0, 1]]).area
    8.0
    >>> region = minkowski_sum_nonconvex(L, L)  # the convolution route
    >>> region.geom_type, len(region.geoms), region.area
    ('MultiPolygon', 1, 13.0)
    """
    import shapely

    parts_a, parts_b = _parts(A, holes_a, "A"), _parts(B, holes_b, "B")
    sums = [_sum(a, ha, b, hb) for a, ha in parts_a for b, hb in parts_b]
    return _multipolygon(sums[0] if len(sums) == 1 else union(sums))


def _parts(P, holes, name: str) -> list:
    """[(polygon, holes)] of one operand: a MultiPolygon gives one entry per part."""
    if hasattr(P, "geom_type") and P.geom_type != "Polygon":
        import shapely

        parts = list(shapely.get_parts(P))
        if P.is_empty or not all(p.geom_type == "Polygon" for p in parts):
            raise ValueError(f"minkowski_sum_nonconvex: {name} is a {P.geom_type}, not a (Multi)Polygon with area")
        if holes is not None:
            raise ValueError(f"minkowski_sum_nonconvex: holes_{name.lower()} given with a MultiPolygon "
                             f"(its parts bring their own holes)")
        return [(p, None) for p in parts]
    return [(P, holes)]


def _multipolygon(region):
    """The region as a MultiPolygon (its polygons; nothing of lower dimension)."""
    import shapely

    if region.geom_type == "MultiPolygon":
        return region
    polys = [g for g in shapely.get_parts(region) if g.geom_type == "Polygon" and not g.is_empty]
    return shapely.MultiPolygon(polys)


def _sum(A, holes_a, B, holes_b):
    """A ⊕ B of two simple polygons with holes (a Polygon or a MultiPolygon)."""
    import shapely

    (A, holes_a), (B, holes_b) = _operand(A, holes_a, "A"), _operand(B, holes_b, "B")
    # GEOS's overlay multiplies coordinates: far from 1 in magnitude, sum a power-of-two
    # copy of the operands (exact) and scale the region back.
    rings = [A, B] + holes_a + holes_b
    rescaled = scaled_copies(rings, max(float(np.abs(p).max()) for p in rings if len(p)))
    if rescaled:
        k, scaled = rescaled
        region = _sum(scaled[0], scaled[2:2 + len(holes_a)], scaled[1], scaled[2 + len(holes_a):])
        with np.errstate(over="ignore"):
            region = shapely.transform(region, lambda c: np.ldexp(c, -k))
        if not np.isfinite(shapely.get_coordinates(region)).all():
            raise ValueError("minkowski_sum_nonconvex: the sum's coordinates overflow the double range")
        return region
    _check_simple(A, holes_a, "A")
    _check_simple(B, holes_b, "B")
    route = _convolution_roles(A, holes_a, B, holes_b)
    if route is not None:
        X, holes_x, x_convex, Q = route
        pieces = [X] if x_convex else decompose_normalized(X, holes_x)
        if all(len(p) >= 3 for p in pieces):
            return union(convex_sums_with(pieces, Q))
    return _union_of_pairwise_sums(A, holes_a, B, holes_b)


def _operand(P, holes, name: str = "operand"):
    """(normalised CCW shell, list of holes) of an array or a shapely Polygon."""
    if hasattr(P, "geom_type") and P.geom_type == "Polygon" and holes is None:
        holes = [as_array(r) for r in P.interiors]
    holes = [normalize(h, ccw=False) for h in (holes or [])]
    if len(as_array(P, copy=False)) == 0:
        raise ValueError(f"minkowski_sum_nonconvex: {name} has no vertices")
    shell = normalize(P)  # non-finite coordinates raise here, before GEOS sees them
    if len(shell) < 3:  # no area: the point or segment it spans (swept along the other operand)
        return collinear_extent(as_array(P)), []
    return shell, [h for h in holes if len(h) >= 3]


def _check_simple(shell, holes, name: str) -> None:
    """ValueError unless a shell with area is a simple polygon with its holes inside it
    (GEOS's validity; run on coordinates near 1, where its arithmetic cannot underflow)."""
    if len(shell) < 3:
        return
    import shapely

    geom = shapely.Polygon(shell, holes)
    if not shapely.is_valid(geom):
        raise ValueError(f"minkowski_sum_nonconvex: {name} is not a simple polygon ({shapely.is_valid_reason(geom)})")


def _convolution_roles(A, holes_a, B, holes_b):
    """(X, holes of X, is X convex, Q): decompose X, convolve its pieces with the
    simple, non-convex Q; None when no operand can be Q (holes, convexity, degeneracy).

    With two candidates, Q is the one whose boundary turns less. Every piece of X
    walks all of Q and inserts its edges once per full turn of Q, and GEOS's cost
    grows faster than linearly with one cycle's self-crossings, so many short cycles
    beat a few long ones.
    """
    if len(A) < 3 or len(B) < 3:
        return None
    a_convex, b_convex = is_convex(A), is_convex(B)
    a_ok, b_ok = not holes_a and not a_convex, not holes_b and not b_convex
    if not (a_ok or b_ok):
        return None
    if a_ok and b_ok:
        a_ok = (_turning(A), len(A)) < (_turning(B), len(B))
    return (B, holes_b, b_convex and not holes_b, A) if a_ok else (A, holes_a, a_convex and not holes_a, B)


def _turning(P: np.ndarray) -> float:
    """Total absolute turning of a polygon's boundary, in full turns (a float
    estimate: it only ranks the operands)."""
    prev, nxt = prev_next(P)
    u, v = P - prev, nxt - P  # the edges into and out of each vertex
    angle = np.arctan2(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0], (u * v).sum(axis=1))
    return float(np.abs(angle).sum() / (2 * np.pi))


def _union_of_pairwise_sums(A, holes_a, B, holes_b):
    """∪ (A_i ⊕ B_j): every pairwise convex sum, unioned per piece of A, then."""
    import shapely

    pa, pb = convex_decompose(A, holes_a), convex_decompose(B, holes_b)
    pieces = pairwise_sums(pa, pb)
    sizes = np.array([len(p) for p in pieces])
    if (sizes < 3).any():  # a degenerate pairwise sum (a point or segment operand)
        polys = np.array([shapely.Polygon(p) if len(p) >= 3 else shapely.Polygon() for p in pieces])
    else:
        rings = shapely.linearrings(np.concatenate(pieces), indices=np.repeat(np.arange(len(pieces)), sizes))
        polys = shapely.polygons(rings)
    # Union row by row (row i is A_i ⊕ B: pieces that overlap a lot), then the rows:
    # GEOS's cascaded union is about twice as fast this way as on the flat list.
    rows = shapely.union_all(polys.reshape(len(pa), len(pb)), axis=1)
    return union(polys, first=shapely.union_all(rows))  # checked against every pairwise sum
