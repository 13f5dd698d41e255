"""The convex kernel: hull, angular-merge sums, half-planes, erosion, against exact references."""
import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cspace.kernel.polygons.halfplane import erode, erode_exact, halfplanes, support
from cspace.kernel.polygons.hull import convex_hull
from cspace.kernel.minkowski.merge import minkowski_sum, reflect
from cspace.kernel.polygons.polygon import is_convex, lowest_first
from cspace.kernel.polygons.predicates import orient2d


def exact_sum(*polys):
    """Reference P ⊕ Q ⊕ ...: the hull of all vertex sums, all in Fractions (no float step)."""
    acc = [(Fraction(0), Fraction(0))]
    for p in polys:
        acc = [(a + Fraction(x), b + Fraction(y)) for a, b in acc for x, y in np.asarray(p, float).tolist()]
    return hull_fractions(acc)


def hull_fractions(acc):
    """Andrew's monotone chain in exact rationals, lowest-then-leftmost vertex first."""
    pts = sorted(set(acc))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def chain(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    h = pts if len(pts) <= 2 else chain(pts)[:-1] + chain(pts[::-1])[:-1]
    k = min(range(len(h)), key=lambda i: (h[i][1], h[i][0]))
    return h[k:] + h[:k]


def strictly_convex(p):
    n = len(p)
    return n < 3 or all(orient2d(p[i - 1], p[i], p[(i + 1) % n]) > 0 for i in range(n))


def as_fr(p):
    return [(Fraction(x), Fraction(y)) for x, y in np.asarray(p).tolist()]


int_points = st.lists(st.tuples(st.integers(-1000, 1000), st.integers(-1000, 1000)), min_size=1, max_size=30)


def test_worked_example():
    out = minkowski_sum([[0, 0], [2, 0], [0, 2]], [[0, 0], [1, 0], [1, 1], [0, 1]])
    assert out.tolist() == [[0, 0], [3, 0], [3, 1], [1, 3], [0, 3]]


@settings(max_examples=200, deadline=None)
@given(int_points, int_points)
def test_integer_sums_are_exact(a, b):
    P, Q = convex_hull(a), convex_hull(b)
    assert as_fr(minkowski_sum(P, Q)) == exact_sum(P, Q)
    assert as_fr(minkowski_sum(P[::-1], Q)) == exact_sum(P, Q)  # either orientation


@settings(max_examples=100, deadline=None)
@given(int_points, int_points, int_points)
def test_k_way_equals_pairwise_folding_and_associativity(a, b, c):
    P, Q, R = convex_hull(a), convex_hull(b), convex_hull(c)
    k = minkowski_sum(P, Q, R)
    assert k.tolist() == minkowski_sum(minkowski_sum(P, Q), R).tolist()
    assert k.tolist() == minkowski_sum(P, minkowski_sum(Q, R)).tolist()
    assert minkowski_sum(P, Q).tolist() == minkowski_sum(Q, P).tolist()
    assert len(k) <= len(P) + len(Q) + len(R)


@settings(max_examples=100, deadline=None)
@given(int_points, int_points)
def test_area_is_mixed_area_formula_and_support_is_additive(a, b):
    P, Q = convex_hull(a), convex_hull(b)
    S = minkowski_sum(P, Q)

    def area(p):
        p = as_fr(p)
        n = len(p)
        return sum(p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1] for i in range(n)) / 2 if n > 2 else 0

    def mixed(p, q):
        # 2 V(P, Q) = sum over Q's edges e of h_P(n_e), n_e the outward normal with |n_e| = |e|
        # (translation-invariant because the n_e sum to zero).
        q = as_fr(q)
        if len(q) < 2:
            return 0
        total = Fraction(0)
        for i in range(len(q)):
            (x0, y0), (x1, y1) = q[i], q[(i + 1) % len(q)]
            nx, ny = y1 - y0, x0 - x1
            total += max(nx * x + ny * y for x, y in as_fr(p))
        return total

    # area(P ⊕ Q) = area(P) + area(Q) + 2 V(P, Q)
    assert area(S) == area(P) + area(Q) + mixed(P, Q)
    for d in [(1, 0), (0, 1), (-3, 7), (2, -5)]:
        assert support(S, d) == support(P, d) + support(Q, d)


@pytest.mark.parametrize("delta", [2.0**-30, 2.0**-40, 2.0**-52, -(2.0**-40)])
def test_near_parallel_edges_exact(delta):
    # The note's example: u = (1e6, 1), v = (2e6, 2 + delta), nearly parallel.
    P = np.array([[0.0, 0.0], [1e6, 1.0], [0.0, 5.0]])
    Q = np.array([[0.0, 0.0], [2e6, 2.0 + delta], [0.0, 3.0]])
    S = minkowski_sum(P, Q)
    assert strictly_convex(S) and is_convex(S, strict=True)
    assert as_fr(S) == exact_sum(P, Q)


@pytest.mark.parametrize("scale,shift", [(1e9, 0.0), (1e-9, 0.0), (1.0, 1e8), (1.0, 0.0)])
def test_float_inputs_strictly_convex_and_close_to_exact(scale, shift):
    rng = np.random.default_rng(5)
    for _ in range(200):
        P = convex_hull(rng.normal(size=(int(rng.integers(1, 12)), 2)) * scale + shift)
        Q = convex_hull(rng.normal(size=(int(rng.integers(1, 12)), 2)) * scale + shift)
        S = minkowski_sum(P, Q)
        assert strictly_convex(S)
        ref = exact_sum(P, Q)
        # Each vertex is a once-rounded sum of two input vertices (or the exact hull repaired it).
        tol = 4 * np.finfo(float).eps * (2 * abs(shift) + 8 * scale)
        for (x, y) in S.tolist():
            assert min(abs(float(rx) - x) + abs(float(ry) - y) for rx, ry in ref) <= tol


def test_large_vectorised_path_matches_exact():
    rng = np.random.default_rng(0)
    a = np.sort(rng.uniform(0, 2 * np.pi, 3000))
    P = convex_hull(np.round(np.c_[np.cos(a), np.sin(a)] * 2**30))
    b = np.sort(rng.uniform(0, 2 * np.pi, 2000))
    Q = convex_hull(np.round(np.c_[np.cos(b), np.sin(b)] * 2**29) + 7)
    S = minkowski_sum(P, Q)
    assert strictly_convex(S)
    # The exact reference without the quadratic blow-up: the scalar exact merge on the same input.
    from cspace.kernel.minkowski.scalar import clean_small, merge2_small
    ref, exact = merge2_small(clean_small(P.tolist()), clean_small(Q.tolist()))
    assert exact and S.ravel().tolist() == ref


def test_degenerate_operands():
    sq = [[0, 0], [1, 0], [1, 1], [0, 1]]
    assert minkowski_sum(sq, [[5, 5]]).tolist() == [[5, 5], [6, 5], [6, 6], [5, 6]]
    assert minkowski_sum(sq, [[0, 0], [2, 0]]).tolist() == [[0, 0], [3, 0], [3, 1], [0, 1]]
    assert minkowski_sum([[0, 0], [1, 1]], [[0, 0], [2, 2]]).tolist() == [[0, 0], [3, 3]]
    assert minkowski_sum([[1, 2]], [[3, 4]]).tolist() == [[4, 6]]
    with pytest.raises(ValueError):
        minkowski_sum([[0, 0], [2, 0], [1, 1], [2, 2], [0, 2]], sq)


def test_hull_and_reflect():
    assert convex_hull([[0, 0], [1, 1e-300], [2, 0], [1, 1]]).tolist() == [[0, 0], [2, 0], [1, 1]]
    assert convex_hull([[0, 0], [1, 0], [2, 0]]).tolist() == [[0, 0], [2, 0]]
    P = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 3.0]])
    assert reflect(P).tolist() == lowest_first(-P).tolist()


@settings(max_examples=100, deadline=None)
@given(int_points, int_points)
def test_erosion_contains_and_is_maximal(a, b):
    A, B = convex_hull(a), convex_hull(b)
    if len(A) < 3:
        return
    E = erode_exact(A, B)
    fa = as_fr(A)
    n, c = halfplanes(A)

    def inside_A(x, y):
        return all(Fraction(nx) * x + Fraction(ny) * y <= Fraction(cc) for (nx, ny), cc in zip(n.tolist(), c.tolist()))

    # (A ⊖ B) ⊕ B ⊆ A, exactly: every vertex sum lies in A.
    for ex, ey in E:
        for bx, by in as_fr(B):
            assert inside_A(ex + bx, ey + by)
    # Maximal: when B fits, at least one of A's half-planes is tight for (A ⊖ B) ⊕ B.
    if E:
        assert any(any(Fraction(nx) * (ex + bx) + Fraction(ny) * (ey + by) == Fraction(cc)
                       for ex, ey in E for bx, by in as_fr(B)) for (nx, ny), cc in zip(n.tolist(), c.tolist()))
    else:  # B does not fit: then its width exceeds A's in some edge normal of A
        assert len(erode(A, B)) == 0
        assert any(support(B, nn) + support(B, -np.asarray(nn)) > support(A, nn) + support(A, -np.asarray(nn))
                   for nn in n.tolist()) or len(B) >= 3


def test_erosion_is_not_the_sum_with_the_reflection():
    A = [[0, 0], [4, 0], [4, 3], [0, 3]]
    B = [[0, 0], [1, 0], [1, 1], [0, 1]]
    assert erode(A, B).tolist() == [[0, 0], [3, 0], [3, 2], [0, 2]]
    assert minkowski_sum(A, reflect(B)).tolist() != erode(A, B).tolist()
    assert erode([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 0], [1, 0], [1, 1], [0, 1]]).tolist() == [[0, 0]]


# ---------------------------------------------------------------- the vectorised route (> 96 vertices)


def _scalar_reference(*polys):
    """The scalar exact merge on the same operands: same rounding semantics, other code path."""
    from cspace.kernel.minkowski.scalar import certify_small, clean_small, merge_small

    return certify_small(merge_small([clean_small(np.asarray(p, float).tolist()) for p in polys]))


def random_convex(rng, n, scale=1.0, offset=0.0, integer=False):
    """n random points on an ellipse-ish curve, hulled exactly: a convex polygon of about n vertices."""
    a = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = rng.uniform(0.5, 2.0)
    p = np.c_[r * np.cos(a), np.sin(a)] * scale + offset
    return convex_hull(np.round(p) if integer else p)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([1e-9, 1.0, 1e9]), st.sampled_from([0.0, 1e8]),
       st.integers(2, 3))
def test_vectorised_route_equals_scalar_route_on_floats(seed, scale, offset, k):
    rng = np.random.default_rng(seed)
    polys = [random_convex(rng, int(rng.integers(60, 300)), scale, offset * scale) for _ in range(k)]
    S = minkowski_sum(*polys)
    assert strictly_convex(S)
    assert S.tolist() == [list(v) for v in _scalar_reference(*polys)]


@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_vectorised_route_exact_on_integers(seed):
    rng = np.random.default_rng(seed)
    P = random_convex(rng, 70, 2.0**20, integer=True)
    Q = random_convex(rng, 60, 2.0**18, 5.0, integer=True)
    assert len(P) + len(Q) > 96
    S = minkowski_sum(P, Q)
    assert as_fr(S) == exact_sum(P, Q)


def test_vectorised_route_cleans_cw_collinear_and_repeated_operands():
    rng = np.random.default_rng(7)
    P = random_convex(rng, 150, 2.0**20, integer=True)
    Q = random_convex(rng, 150, 2.0**20, integer=True)
    # Clockwise, with exact midpoints of edges inserted (collinear) and repeated vertices.
    mid = (P + np.roll(P, -1, axis=0)) / 2
    messy = np.empty((2 * len(P), 2))
    messy[0::2], messy[1::2] = P, mid
    messy = np.repeat(messy, 2, axis=0)[::-1]
    S = minkowski_sum(messy, Q)
    assert S.tolist() == minkowski_sum(P, Q).tolist()
    assert strictly_convex(S) and len(S) <= len(P) + len(Q)


def test_vectorised_route_repeated_vertex_is_silent():
    # A repeated vertex away from the lowest one passes the fast path's orientation
    # test and reaches the pseudo-angle as a zero edge (0 / 0): the merge must fall
    # back to the clean route without a RuntimeWarning reaching the caller.
    rng = np.random.default_rng(11)
    P = random_convex(rng, 150, 2.0**20, integer=True)
    Q = random_convex(rng, 150, 2.0**20, integer=True)
    lo = int(np.lexsort((P[:, 0], P[:, 1]))[0])
    j = (lo + len(P) // 2) % len(P)
    doubled = np.insert(P, j, P[j], axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        S = minkowski_sum(doubled, Q)
    assert S.tolist() == minkowski_sum(P, Q).tolist()


def test_vectorised_route_rejects_non_convex_operands():
    rng = np.random.default_rng(3)
    P = random_convex(rng, 200)
    Q = random_convex(rng, 200)
    dented = P.copy()
    dented[50] = 0.9 * dented[50] + 0.1 * P.mean(axis=0)  # a reflex vertex
    with pytest.raises(ValueError):
        minkowski_sum(dented, Q)
    # All turns left but winding twice around (a {101/2} star polygon).
    a = 4 * np.pi * np.arange(101) / 101
    with pytest.raises(ValueError):
        minkowski_sum(np.c_[np.cos(a), np.sin(a)], Q)


def test_vectorised_route_at_underflowing_scale():
    # Edge-vector products of operands scaled by 2^-700 underflow to zero; they must not
    # be taken as exactly parallel (which fused 390 of 400 vertices away). Scaling by a
    # power of two is exact, so the sum is the unit-scale sum scaled.
    t = np.linspace(0, 2 * np.pi, 201)[:-1]
    P = np.round(np.c_[np.cos(t), np.sin(t)] * 2**20)
    Q = P.copy()
    Q[:, 1] += Q[:, 0] * 2.0**-30  # edges a hair off P's
    s = 2.0**-700
    ref = minkowski_sum(P, Q)
    assert len(ref) == 400
    assert np.array_equal(minkowski_sum(P * s, Q * s), ref * s)


@pytest.mark.slow
@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.integers(2, 3), st.sampled_from(["int", "float", "parallel"]))
def test_vectorised_route_is_independent_of_start_vertex_and_orientation(seed, reverse, k, kind):
    # The large path reads each operand from its lowest vertex in place (no rotated
    # copy) and, for two operands, rebuilds every vertex from the two counts of edges
    # taken: any start vertex and either orientation must give the same sum, equal to
    # the scalar merge. 'parallel': scaled copies, so every edge fuses with another.
    rng = np.random.default_rng(seed)
    integer = kind != "float"
    base = random_convex(rng, int(rng.integers(60, 400)), 2.0**20, integer=integer)
    polys = [base * 2.0**i if kind == "parallel" else random_convex(rng, int(rng.integers(60, 400)), 2.0**20,
                                                                     integer=integer) for i in range(k)]
    want = minkowski_sum(*polys)
    moved = []
    for p in polys:
        q = np.roll(p, int(rng.integers(1, len(p))), axis=0)
        moved.append(q[::-1] if reverse else q)
    S = minkowski_sum(*moved)
    assert strictly_convex(S)
    assert S.tolist() == want.tolist() == [list(v) for v in _scalar_reference(*polys)]
    if integer and k == 2 and len(polys[0]) * len(polys[1]) <= 20000:  # the Fraction hull is O(nm)
        assert as_fr(S) == exact_sum(*polys)


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize("shift", [0, 1, 2, -1])
@pytest.mark.slow
def test_vectorised_route_finds_the_leftmost_of_a_flat_bottom(reverse, shift):
    # A horizontal bottom edge gives two lowest vertices; the fast path must start from
    # the left one wherever the pair sits in the array, including split across its end.
    t = np.linspace(0, np.pi, 151)
    top = np.c_[np.cos(t), np.sin(t)] * 2**20  # the upper half disc: (2^20, 0) ... (-2^20, 0)
    P = np.round(top)  # CCW from the bottom-right vertex; the bottom edge closes the ring
    Q = np.round(np.c_[np.cos(t * 2 + 0.1), np.sin(t * 2 + 0.1)] * 2**19)
    Q = convex_hull(Q)
    ccw = np.roll(P, shift, axis=0)
    S = minkowski_sum(ccw[::-1] if reverse else ccw, Q)
    assert strictly_convex(S)
    assert S.tolist() == [list(v) for v in _scalar_reference(P, Q)]
    assert as_fr(S) == exact_sum(P, Q)
    assert S[0].tolist() == (P[np.lexsort((P[:, 0], P[:, 1]))[0]] + Q[0]).tolist()


@pytest.mark.parametrize("n", [3, 40, 200])
@pytest.mark.parametrize("scale", [1.0, 1e-5, 1e-200])
def test_a_point_given_as_many_equal_vertices_translates_a_large_operand(n, scale):
    # A disk of radius 1e-200 at (5, 5) rounds to n copies of (5, 5). The vectorised float
    # route used to drop a point operand from every vertex but the first: the sum of
    # (5, 5) and a 71-gon came out at the origin. Oracle: Q + (5, 5), vertex for vertex
    # (each a single rounded addition, which the sum's certification keeps).
    t = np.linspace(0.0, 2 * np.pi, 72)[:-1]
    Q = np.column_stack([np.cos(t), np.sin(t)]) * scale
    for P in (np.full((n, 2), 5.0), np.array([[5.0, 5.0]])):
        got = minkowski_sum(P, Q)
        want = lowest_first(Q + 5.0)
        if scale < 1e-100:  # 5 + 1e-200 rounds to 5: the sum is the point itself
            want = np.array([[5.0, 5.0]])
        assert got.shape == want.shape and np.array_equal(got, want), (n, scale)
    # Several operands, two of them points.
    got = minkowski_sum(np.full((n, 2), 5.0), Q, np.full((30, 2), 1.0), [[0.5, 0.25]])
    assert np.allclose(got.mean(axis=0), (6.5, 6.25), rtol=0, atol=1e-12)
