"""The convolution route: the cycle itself, the winding theorem, and the sums it gives.

Oracles: the convex merge (for convex Q the cycle is the sum's boundary), shapely
(the number of components of (x - P) ∩ Q, which the winding number must equal),
the pieces route (union of all pairwise convex sums) and the triangle-pair union.
"""
import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings, strategies as st

from cspace.kernel.minkowski.convolution import convex_sums_with, convolution_cycles
from cspace.kernel.polygons.decompose import convex_decompose
from cspace.kernel.polygons.hull import convex_hull
from cspace.kernel.minkowski.merge import minkowski_sum
from cspace.kernel.minkowski.nonconvex import _convolution_roles, _operand, _union_of_pairwise_sums, minkowski_sum_nonconvex
from cspace.kernel.polygons.polygon import drop_collinear, is_simple, lowest_first, normalize

from test_decompose import comb, reference_sum


def star(k, rng, integer):
    a = np.sort(rng.uniform(0, 2 * np.pi, k))
    r = rng.uniform(0.3, 1.0, k)
    p = np.c_[r * np.cos(a), r * np.sin(a)] * 10 + rng.uniform(-20, 20, 2)
    return np.rint(p) if integer else p


def convex(k, rng, integer):
    p = rng.uniform(-6, 6, (k, 2))
    return convex_hull(np.rint(p) if integer else p)


@st.composite
def simple_polygons(draw, convex_only=False):
    seed = draw(st.integers(0, 2**31))
    integer = draw(st.booleans())
    rng = np.random.default_rng(seed)
    k = draw(st.integers(3, 10 if convex_only else 24))
    if convex_only:
        p = convex(k, rng, integer)
        assume(len(p) >= 3)
        return p
    kind = draw(st.sampled_from(["star", "comb", "rotated comb"]))
    if kind == "star":
        p = star(k, rng, integer)
    else:
        p = comb(draw(st.integers(2, 6)), w=1.0, gap=draw(st.sampled_from([0.5, 1.0, 2.0])))
        if kind == "rotated comb":
            t = rng.uniform(0, 2 * np.pi)
            p = p @ np.array([[np.cos(t), np.sin(t)], [-np.sin(t), np.cos(t)]])
    p = normalize(p)
    assume(len(p) >= 3 and is_simple(p))
    return p


def winding(ring: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Winding numbers of the closed polyline ``ring`` around points ``x`` (none on it)."""
    a, b = ring, np.roll(ring, -1, axis=0)
    ax, ay = a[:, 0][None] - x[:, 0, None], a[:, 1][None] - x[:, 1, None]
    bx, by = b[:, 0][None] - x[:, 0, None], b[:, 1][None] - x[:, 1, None]
    cross = ax * by - ay * bx
    up = (ay <= 0) & (by > 0) & (cross > 0)
    down = (ay > 0) & (by <= 0) & (cross < 0)
    return up.sum(axis=1) - down.sum(axis=1)


@settings(max_examples=150, deadline=None)
@given(simple_polygons(convex_only=True), simple_polygons(convex_only=True))
def test_for_convex_q_the_cycle_is_the_convex_sum(P, Q):
    pts, sizes = convolution_cycles([P], Q)
    assert sizes.tolist() == [len(pts)]
    assert lowest_first(drop_collinear(pts)).tolist() == minkowski_sum(P, Q).tolist()


@settings(max_examples=60, deadline=None)
@given(simple_polygons(convex_only=True), simple_polygons(), st.integers(0, 2**31))
def test_winding_number_counts_the_components_of_the_intersection(P, Q, seed):
    (ring,) = [convolution_cycles([P], Q)[0]]
    line = shapely.LinearRing(ring)
    lo, hi = ring.min(axis=0) - 1, ring.max(axis=0) + 1
    x = np.random.default_rng(seed).uniform(lo, hi, (60, 2))
    x = x[shapely.distance(line, shapely.points(x)) > 1e-6]  # off the cycle
    w = winding(ring, x)
    Qs = shapely.Polygon(Q)
    for xi, wi in zip(x, w):
        inter = shapely.intersection(shapely.Polygon(xi - P), Qs)
        parts = [g for g in shapely.get_parts(inter) if g.geom_type == "Polygon" and g.area > 0]
        assert wi == len(parts)


@settings(max_examples=60, deadline=None)
@given(simple_polygons(), simple_polygons())
def test_convolution_route_equals_the_pieces_route(A, B):
    route = _convolution_roles(A, [], B, [])
    assume(route is not None)  # a star can come out convex
    got = minkowski_sum_nonconvex(A, B)
    ref = _union_of_pairwise_sums(A, [], B, [])
    assert shapely.symmetric_difference(got, ref).area <= 1e-9 * ref.area


def test_a_piece_out_of_angular_order_is_refused():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    L = normalize(np.array([[0.0, 0.0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]))
    for bad in (np.roll(sq, 1, axis=0), sq[::-1], np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0]])):
        with pytest.raises(ValueError, match="piece 1"):
            convolution_cycles([sq, bad], L)
    for bad_q in (L[::-1], np.insert(L, 2, L[2], axis=0)):  # clockwise; a repeated vertex
        with pytest.raises(ValueError, match="Q must be"):
            convolution_cycles([sq], bad_q)


def test_one_region_per_piece_is_the_piece_sum_union():
    A, Q = normalize(comb(6)), normalize(comb(3, w=0.5, gap=1.0))
    pieces = convex_decompose(A)
    regions = convex_sums_with(pieces, Q)
    assert len(regions) == len(pieces)
    for piece, region in zip(pieces, regions):
        ref = _union_of_pairwise_sums(piece, [], Q, [])
        assert shapely.symmetric_difference(region, ref).area <= 1e-12 * ref.area


@pytest.mark.parametrize("threads", ["2", "3", "8"])
def test_threads_give_the_very_same_regions(monkeypatch, threads):
    # The cycles are buffered in chunks on several threads (GEOS releases the GIL):
    # every region must be identical, vertex for vertex, to the one-thread result.
    A, Q = normalize(comb(20)), normalize(comb(10, w=0.5, gap=1.0))
    pieces = convex_decompose(A)
    monkeypatch.setenv("CSPACE_THREADS", "1")
    one = convex_sums_with(pieces, Q)
    monkeypatch.setenv("CSPACE_THREADS", threads)
    many = convex_sums_with(pieces, Q)
    assert len(one) == len(many) == len(pieces)
    assert all(a.equals_exact(b, 0.0) for a, b in zip(one, many))


def test_a_failure_on_a_worker_thread_reaches_the_caller(monkeypatch):
    import cspace.kernel.minkowski.convolution as cv

    calls = []

    def failing(polys, distance):
        calls.append(len(polys))
        if len(calls) > 1:
            raise RuntimeError("worker failed")
        return shapely.buffer(polys, distance)

    monkeypatch.setenv("CSPACE_THREADS", "2")
    monkeypatch.setattr(shapely, "buffer", failing)
    with pytest.raises(RuntimeError, match="worker failed"):
        cv._buffer_zero(np.array([shapely.box(0, 0, 1, 1)] * 300), np.full(300, 5))


@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0])
def test_comb_sum_through_the_convolution_matches_the_triangle_pairs(angle):
    t = np.radians(angle)
    B = comb(4, w=0.5, gap=1.0, h=3.0, spine=0.5) @ np.array([[np.cos(t), np.sin(t)], [-np.sin(t), np.cos(t)]])
    A = comb(8)
    got = minkowski_sum_nonconvex(A, B)
    ref = reference_sum(A, B)
    assert shapely.symmetric_difference(got, ref).area <= 1e-9 * ref.area


def test_holes_go_to_the_decomposed_operand():
    ring = shapely.Polygon([[0, 0], [10, 0], [10, 10], [0, 10]], [[[3, 3], [3, 7], [7, 7], [7, 3]]])
    L = np.array([[0, 0], [2, 0], [2, 0.5], [0.5, 0.5], [0.5, 2], [0, 2.0]]) - 1.0
    (a, ha), (b, hb) = _operand(ring, None), _operand(L, None)
    X, holes_x, x_convex, Q = _convolution_roles(a, ha, b, hb)
    assert len(holes_x) == 1 and Q.tolist() == b.tolist()  # the ring is decomposed, the L convolved
    got = minkowski_sum_nonconvex(ring, L)
    ref = reference_sum(ring, L)
    assert shapely.symmetric_difference(got, ref).area <= 1e-9 * ref.area
    assert len(got.geoms) == 1 and len(got.geoms[0].interiors) == 1  # the hole shrinks but survives


def test_both_holed_or_degenerate_operands_take_the_pieces_route():
    ring = shapely.Polygon([[0, 0], [10, 0], [10, 10], [0, 10]], [[[3, 3], [3, 7], [7, 7], [7, 3]]])
    (a, ha) = _operand(ring, None)
    assert _convolution_roles(a, ha, a, ha) is None
    seg = np.array([[0.0, 0.0], [3.0, 0.0]])
    (s, hs) = _operand(seg, None)
    assert _convolution_roles(normalize(comb(3)), [], s, hs) is None
    A = comb(3)
    got = minkowski_sum_nonconvex(A, seg)
    # A ⊕ S = (∂A ⊕ S) ∪ (A + s0) for a segment S: every edge swept along S, and A.
    e0, e1 = A, np.roll(A, -1, axis=0)
    quads = [shapely.Polygon([p, q, q + seg[1], p + seg[1]]) for p, q in zip(e0, e1)]
    ref = shapely.union_all([q for q in quads if q.area > 0] + [shapely.Polygon(A)])
    assert shapely.symmetric_difference(got, ref).area <= 1e-12 * ref.area
