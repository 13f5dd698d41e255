"""Convex decomposition and non-convex sums against shapely and an independent reference."""
import numpy as np
import pytest
import shapely

from cspace.kernel.polygons.decompose import convex_decompose
from cspace.kernel.minkowski.merge import minkowski_sum
from cspace.kernel.minkowski.nonconvex import minkowski_pieces, minkowski_sum_nonconvex
from cspace.kernel.polygons.polygon import is_convex
from cspace.kernel.polygons.predicates import orient2d


def comb(teeth, w=1.0, gap=1.0, h=4.0, spine=1.0):
    pts = [[0.0, 0.0], [teeth * w + (teeth - 1) * gap, 0.0]]
    x = teeth * w + (teeth - 1) * gap
    for t in range(teeth):
        xr = x - t * (w + gap)
        pts += [[xr, spine + h], [xr - w, spine + h]]
        if t < teeth - 1:
            pts += [[xr - w, spine], [xr - w - gap, spine]]
    return np.array(pts)


def reflex_count(p):
    n = len(p)
    return sum(orient2d(p[i - 1], p[i], p[(i + 1) % n]) < 0 for i in range(n))


def star(k, seed):
    rng = np.random.default_rng(seed)
    a = np.sort(rng.uniform(0, 2 * np.pi, k))
    r = rng.uniform(0.3, 1.0, k)
    return np.c_[r * np.cos(a), r * np.sin(a)]


SHAPES = [comb(5), comb(12), np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2.0]])] + [star(k, s) for k, s in
                                                                                             [(8, 1), (20, 2), (40, 3)]]


@pytest.mark.parametrize("poly", SHAPES, ids=lambda p: f"{len(p)}v")
def test_pieces_convex_cover_exactly_and_respect_the_bound(poly):
    pieces = convex_decompose(poly)
    assert all(is_convex(p, strict=True) for p in pieces)
    ref = shapely.Polygon(poly)
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    assert abs(sum(shapely.Polygon(p).area for p in pieces) - ref.area) <= 1e-12 * ref.area  # disjoint interiors
    assert union.symmetric_difference(ref).area <= 1e-12 * ref.area
    assert len(pieces) <= 2 * reflex_count(poly) + 1


def test_convex_input_is_returned_untouched():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    (only,) = convex_decompose(sq)
    assert only.tolist() == sq.tolist()


def test_comb_is_optimal_and_holes_are_covered():
    assert len(convex_decompose(comb(6))) == 7  # spine + 6 teeth: the optimum
    shell = np.array([[0.0, 0], [10, 0], [10, 10], [0, 10]])
    hole = np.array([[3.0, 3], [7, 3], [5, 7]])
    pieces = convex_decompose(shell, [hole])
    ref = shapely.Polygon(shell, [hole])
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    assert union.symmetric_difference(ref).area <= 1e-12 * ref.area
    assert sum(shapely.Polygon(p).area for p in pieces) == pytest.approx(ref.area, rel=1e-12)


@pytest.mark.parametrize("k", range(8))
def test_an_l_shape_is_two_pieces_in_every_rotation_and_mirror(k):
    L = np.array([[96.0, 51], [100, 51], [100, 53], [97, 53], [97, 52], [96, 52]])  # one reflex vertex
    P = L @ np.linalg.matrix_power(np.array([[0.0, -1.0], [1.0, 0.0]]), k % 4)  # k quarter turns
    if k >= 4:
        P = P * [-1.0, 1.0]
    assert len(convex_decompose(P)) == 2


def reference_sum(A, B):
    """Independent: the union of all triangle-pair sums (GEOS triangulation, hull of the 9 vertex sums)."""
    def tris(P):
        return [np.asarray(t.exterior.coords)[:3] for t in shapely.get_parts(shapely.constrained_delaunay_triangles(P))]
    A = A if hasattr(A, "geom_type") else shapely.Polygon(A)
    B = B if hasattr(B, "geom_type") else shapely.Polygon(B)
    return shapely.union_all([shapely.MultiPoint((ta[:, None] + tb[None]).reshape(-1, 2)).convex_hull
                              for ta in tris(A) for tb in tris(B)])


@pytest.mark.parametrize("A,B", [(comb(5), comb(3)), (comb(20), comb(10)), (star(20, 5), comb(4)), (star(12, 6), star(9, 7))])
def test_nonconvex_sum_matches_reference(A, B):
    got = minkowski_sum_nonconvex(A, B)
    ref = reference_sum(A, B)
    assert got.symmetric_difference(ref).area <= 1e-9 * ref.area


def test_small_hole_of_the_sum_survives():
    # A square ring with a hole 4 wide, plus a 3.9-wide square: the sum keeps a 0.1-wide hole.
    ring = shapely.Polygon([[0, 0], [10, 0], [10, 10], [0, 10]], [[[3, 3], [3, 7], [7, 7], [7, 3]]])
    sq = np.array([[0.0, 0.0], [3.9, 0.0], [3.9, 3.9], [0.0, 3.9]]) - 1.95
    got = minkowski_sum_nonconvex(ring, sq)
    assert got.geom_type == "MultiPolygon" and len(got.geoms) == 1 and len(got.geoms[0].interiors) == 1
    assert shapely.Polygon(got.geoms[0].interiors[0]).area == pytest.approx(0.01, rel=1e-9)


def test_pieces_are_pairwise_sums():
    L = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2.0]])
    tri = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    pieces = minkowski_pieces(L, tri)
    assert len(pieces) == 2
    assert sorted(map(len, pieces)) == sorted(len(minkowski_sum(p, tri)) for p in convex_decompose(L))


# One return type, MultiPolygon operands, and bad operands refused before GEOS.
SQ1 = [[0, 0], [1, 0], [1, 1], [0, 1]]


@pytest.mark.parametrize("A, B, parts", [
    (SQ1, SQ1, 1),                                                   # convex: pairwise route
    ([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], SQ1, 1),      # convolution route
    (shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(5, 0, 6, 1)]), SQ1, 2),
    (shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(1.5, 0, 2.5, 1)]), SQ1, 1),  # parts merge
    ([[0, 0], [1, 0]], [[0, 0], [2, 0]], 0),                         # two parallel segments: no area
    ([[0, 0], [1, 0]], [[0, 0], [0, 2]], 1),                         # two segments: a parallelogram
])
def test_nonconvex_sum_is_always_a_multipolygon(A, B, parts):
    got = minkowski_sum_nonconvex(A, B)
    assert got.geom_type == "MultiPolygon" and len(got.geoms) == parts
    # Oracle: the union of the sums of shapely's parts, by brute force (convex hull of the
    # vertex sums of each triangle pair would do; here the operands are convex or an L).
    ga = A if hasattr(A, "geom_type") else shapely.Polygon(A) if len(A) > 2 else shapely.LineString(A)
    gb = B if hasattr(B, "geom_type") else shapely.Polygon(B) if len(B) > 2 else shapely.LineString(B)
    if parts:
        ref = reference_sum(ga, gb) if ga.geom_type != "LineString" else shapely.MultiPoint(
            [(p[0] + q[0], p[1] + q[1]) for p in ga.coords for q in gb.coords]).convex_hull
        assert got.symmetric_difference(ref).area <= 1e-12 * ref.area


def test_multipolygon_operand_equals_the_union_of_its_parts_sums():
    a1, a2 = shapely.Polygon([[0, 0], [3, 0], [3, 1], [1, 1], [1, 3], [0, 3]]), shapely.box(6, 6, 7, 9)
    B = [[0, 0], [1, 0], [1, 2], [0.5, 0.5], [0, 2]]
    got = minkowski_sum_nonconvex(shapely.MultiPolygon([a1, a2]), B)
    want = shapely.union_all([minkowski_sum_nonconvex(a1, B), minkowski_sum_nonconvex(a2, B)])
    assert got.symmetric_difference(want).area <= 1e-12 * want.area and len(got.geoms) == 2


@pytest.mark.parametrize("A, match", [
    ([[0, 0], [2, 2], [2, 0], [0, 2]], r"A is not a simple polygon \(Self-intersection"),
    ([[0, 0], [np.nan, 0], [1, 1]], "finite"),
    (shapely.LineString([(0, 0), (1, 1)]), "not a \\(Multi\\)Polygon"),
])
def test_bad_nonconvex_operands_raise_value_error_without_geos_noise(A, match, capfd):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=match):
            minkowski_sum_nonconvex(A, SQ1)
    assert capfd.readouterr() == ("", "")
