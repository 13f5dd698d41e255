"""GJK and EPA against shapely and the materialised Minkowski difference, plus the degenerate corpus."""
import math

import numpy as np
import pytest
import shapely

from cspace.kernel.distance.epa import epa_penetration
from cspace.kernel.distance.gjk import exact_relation, gjk_distance, gjk_intersects
from cspace.kernel.polygons.hull import convex_hull

SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def rand_convex(rng, n, center, radius):
    a = np.sort(rng.uniform(0, 2 * np.pi, n))
    return convex_hull(np.asarray(center) + radius * np.c_[np.cos(a), np.sin(a)])


def geom(p):
    return shapely.Polygon(p) if len(p) >= 3 else shapely.LineString(p) if len(p) == 2 else shapely.Point(p[0])


@pytest.mark.parametrize("scale,shift", [(1.0, 0.0), (1e-6, 0.0), (1e6, 0.0), (1.0, 1e8)])
def test_distance_matches_shapely(scale, shift):
    rng = np.random.default_rng(1)
    for _ in range(300):
        A = rand_convex(rng, int(rng.integers(1, 10)), rng.uniform(-3, 3, 2), rng.uniform(0.2, 2))
        B = rand_convex(rng, int(rng.integers(1, 10)), rng.uniform(-3, 3, 2), rng.uniform(0.2, 2))
        A, B = A * scale + shift, B * scale + shift
        d = gjk_distance(A, B)
        ref = geom(A).distance(geom(B))
        assert abs(d.distance - ref) <= 1e-9 * 6 * scale
        assert not math.isnan(d.distance)
        if ref > 1e-6 * scale:  # away from contact the answers must agree exactly
            assert d.status == "separated" and not gjk_intersects(A, B)
            # The witness points are shifted back to the input's frame: one rounding of |shift|.
            assert math.dist(d.point_a, d.point_b) == pytest.approx(d.distance, rel=1e-12, abs=8e-16 * shift)
            assert geom(A).distance(shapely.Point(d.point_a)) <= 1e-9 * scale + 4e-16 * shift
            assert geom(B).distance(shapely.Point(d.point_b)) <= 1e-9 * scale + 4e-16 * shift
        elif geom(A).intersection(geom(B)).area > 1e-6 * scale * scale:
            assert d.status == "overlapping" and gjk_intersects(A, B)


@pytest.mark.parametrize("shift", [0.0, 1e8])
def test_touching_squares(shift):
    edge = gjk_distance(SQ + shift, SQ + [1.0, 0.0] + shift)
    vertex = gjk_distance(SQ + shift, SQ + [1.0, 1.0] + shift)
    half = gjk_distance(SQ + shift, SQ + [1.0, 0.5] + shift)
    for d in (edge, vertex, half):
        assert d.status == "touching" and d.distance == 0.0
    assert epa_penetration(SQ + shift, SQ + [1.0, 0.0] + shift).depth == 0.0
    assert gjk_distance(SQ + shift, SQ + [1.0 + 2**-40, 0.0] + shift).status == ("separated" if shift == 0 else "touching")


def test_identical_and_tiny_shift():
    assert gjk_distance(SQ, SQ).status == "overlapping"
    assert epa_penetration(SQ, SQ).depth == pytest.approx(1.0)
    moved = SQ + [1e-12, 0.0]
    assert gjk_distance(SQ, moved).status == "overlapping"
    assert epa_penetration(SQ, moved).depth == pytest.approx(1.0 - 1e-12, abs=1e-15)


def test_points_and_segments():
    seg = np.array([[0.0, 0.0], [2.0, 0.0]])
    assert gjk_distance(seg, [[1.0, 1.0]]).distance == 1.0
    assert gjk_distance(seg, [[1.0, 0.0]]).status == "touching"
    assert gjk_distance([[0.0, 0.0]], [[3.0, 4.0]]).distance == 5.0
    assert gjk_distance([[1.0, 1.0]], [[1.0, 1.0]]).status == "touching"
    assert gjk_distance(seg, [[3.0, 0.0], [4.0, 0.0]]).distance == 1.0
    # Crossing segments: no line separates them even weakly, so they penetrate (depth 1).
    assert exact_relation(seg, [[1.0, -1.0], [1.0, 1.0]]) == "overlapping"
    assert epa_penetration(seg, [[1.0, -1.0], [1.0, 1.0]]).depth == pytest.approx(1.0)
    assert exact_relation(SQ, [[0.5, -1.0], [0.5, 2.0]]) == "overlapping"


def test_epa_matches_materialised_difference():
    rng = np.random.default_rng(2)
    checked = 0
    for n in (8, 64):
        for _ in range(100):
            A = rand_convex(rng, n, (0, 0), 1.0)
            B = rand_convex(rng, n, rng.uniform(-1.2, 1.2, 2), rng.uniform(0.3, 1.2))
            p = epa_penetration(A, B)
            if p.status != "overlapping":
                continue
            D = shapely.MultiPoint((A[:, None, :] - B[None, :, :]).reshape(-1, 2)).convex_hull
            assert p.depth == pytest.approx(D.exterior.distance(shapely.Point(0, 0)), abs=1e-12)
            assert np.hypot(*p.normal) == pytest.approx(1.0)
            assert gjk_distance(A, B + p.depth * p.normal).distance <= 1e-9
            assert p.iterations <= len(A) + len(B) + 8
            checked += 1
    assert checked > 100


def test_epa_on_separated_input_is_a_status_not_an_error():
    p = epa_penetration(SQ, SQ + [3.0, 0.0])
    assert p.status == "separated" and p.depth == 0.0 and p.normal.tolist() == [1.0, 0.0]


def test_degenerate_corpus_never_nan():
    corpus = [SQ, SQ[:1], SQ[:2], np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), np.array([[0.0, 0.0], [1e-300, 0.0], [0.0, 1e-300]]),
              SQ * 1e9, SQ * 1e-9, SQ + 1e8, np.array([[0.0, 0.0], [1.0, 1e-17], [2.0, 0.0], [1.0, 1.0]])]
    for A in corpus:
        for B in corpus:
            d = gjk_distance(A, B)
            p = epa_penetration(A, B)
            assert all(math.isfinite(x) for x in (d.distance, p.depth, *p.normal, *d.point_a, *d.point_b))
            assert d.iterations <= 64


def test_relation_skips_hull_only_for_strictly_convex_ccw_input():
    from cspace.kernel.distance.gjk_exact import _as_hull

    t = np.arange(5) * 2 * np.pi / 5
    pent = np.round(np.c_[np.cos(t), np.sin(t)] * 1000)
    star = pent[[0, 2, 4, 1, 3]]  # every turn left, but winds twice
    assert _as_hull(pent, convex_hull) is pent
    assert _as_hull(star, convex_hull) is not star
    assert sorted(map(tuple, _as_hull(star, convex_hull).tolist())) == sorted(map(tuple, pent.tolist()))
    assert _as_hull(pent[::-1], convex_hull) is not pent  # clockwise
    square_with_repeat = np.array([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1.0]])
    assert len(_as_hull(square_with_repeat, convex_hull)) == 4
    # a touching pair given as a pentagram still reports touching, not a false overlap
    assert exact_relation(star, 2 * pent[np.argmax(pent[:, 0])] - pent) == "touching"


def test_contact_shortcut_agrees_with_the_full_separating_axis_test():
    # gjk_distance proves near-contact relations from one line at GJK's contact when it can;
    # on exact integer contacts (vertex-vertex, edge-edge, vertex-edge, one unit off) it must
    # give the relation of the full exact test, which it otherwise falls back to.
    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(120):
        A = convex_hull(rng.integers(0, 20, (int(rng.integers(3, 12)), 2)).astype(float))
        if len(A) < 3:
            continue
        v = A[np.argmax(A[:, 0])]
        w, h = np.ptp(A[:, 0]), np.ptp(A[:, 1])
        others = [2 * v - A + s for s in ((0, 0), (1, 0), (-1, 0), (0, 1), (1, 1))]
        others += [A + [w, int(rng.integers(-5, 6))], A + [0, h], A + [w + 1, 0]]
        for B in others:
            for P, Q in ((A, B), (B, A)):
                status = gjk_distance(P, Q).status
                assert status == exact_relation(P, Q)
                seen.add(status)
    assert seen == {"separated", "touching", "overlapping"}
