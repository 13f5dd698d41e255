"""The checked union (cspace.kernel.minkowski.union): GEOS's float overlay, checked against its inputs.

Oracles: GEOS's snap-rounded overlay (``grid_size``: robust by construction), areas
by the shoelace formula, and a union deliberately made wrong.
"""
import numpy as np
import pytest
import shapely
from hypothesis import given, settings, strategies as st

from cspace import minkowski_sum_nonconvex
from cspace.kernel.minkowski import union as union_mod
from cspace.kernel.polygons.decompose import convex_decompose
from cspace.kernel.minkowski.nonconvex import _convolution_roles, _operand
from cspace.kernel.minkowski.convolution import convex_sums_with
from cspace.kernel.polygons.decompose import decompose_normalized
from cspace.kernel.minkowski.pairsums import pairwise_sums
from cspace.kernel.minkowski.union import UnionError, faithful, union

# A rotated 3-tooth comb (found by tests/kernel/test_convolution.py in CI): A ⊕ A by the
# convolution route gives five valid regions whose GEOS 3.14 union_all has area 106
# instead of 124; the checked union must not return that.
ROTATED_COMB = np.array([
    [4.589422449855687, -5.285565398021353], [8.364826305585225, -2.0074065052672907],
    [7.709194527034413, -1.2523257341213831], [4.6888714424507825, -3.874852848324633],
    [3.3776078853491573, -2.364691306032818], [6.397930969932787, 0.25783580817043206],
    [5.742299191381975, 1.0129165793163395], [2.721976106798345, -1.6096105348869103],
    [1.4107125496967199, -0.0994489925950951], [4.4310356342803505, 2.5230781216081546],
    [3.7754038557295377, 3.278158892754062], [0.0, 0.0]])


def snapped_union(polys):
    """The oracle: GEOS's fixed-precision (snap-rounding) union on a 2^-40 grid."""
    return shapely.union_all(polys, grid_size=2.0**-40)


def comb_regions():
    (X, hx), (Q, _) = _operand(ROTATED_COMB, None, "A"), _operand(ROTATED_COMB.copy(), None, "B")
    X, hx, _, Q = _convolution_roles(X, hx, Q, [])
    return convex_sums_with(decompose_normalized(X, hx), Q)


def test_the_rotated_comb_sum_keeps_all_its_area():
    ref = snapped_union([shapely.Polygon(p) for p in pairwise_sums(convex_decompose(ROTATED_COMB),
                                                                   convex_decompose(ROTATED_COMB))])
    got = minkowski_sum_nonconvex(ROTATED_COMB, ROTATED_COMB)
    assert ref.area == pytest.approx(124.0, rel=1e-9)
    assert shapely.symmetric_difference(got, ref).area <= 1e-9 * ref.area


def test_the_check_passes_a_right_union_and_fails_a_wrong_one():
    regions = comb_regions()
    right = snapped_union(regions)
    assert faithful(right, regions, slack=2.0**-40)
    assert union(regions).area == pytest.approx(right.area, rel=1e-9)
    raw = shapely.union_all(regions)
    if raw.area < 0.99 * right.area:  # this GEOS has the bug: the check must see it
        assert not faithful(raw, regions)
    assert not faithful(shapely.union_all(regions[1:]), regions)  # a piece left out
    assert not faithful(shapely.box(*right.bounds), regions)  # grown: more than the pieces' areas
    holed = right.difference(shapely.Point(6.0, 0.0).buffer(0.3))  # a bite inside the sum
    assert right.covers(shapely.Point(6.0, 0.0)) and not faithful(holed, regions)


def test_a_failing_float_union_is_taken_again_with_snap_rounding(monkeypatch):
    a, b = shapely.box(0, 0, 2, 2), shapely.box(1, 1, 3, 3)
    real = shapely.union_all
    calls = []

    def wrong_unless_snapped(polys, grid_size=None, **kw):
        calls.append(grid_size)
        return polys[0] if grid_size is None else real(polys, grid_size=grid_size, **kw)

    monkeypatch.setattr(shapely, "union_all", wrong_unless_snapped)
    assert union([a, b]).area == 7.0
    assert calls[0] is None and calls[1] == 2.0**-40  # scale 3: grid 2^(2 - 42)


def test_a_union_wrong_both_ways_raises(monkeypatch):
    import cspace

    a, b = shapely.box(0, 0, 2, 2), shapely.box(1, 1, 3, 3)
    monkeypatch.setattr(shapely, "union_all", lambda polys, **kw: polys[0])
    with pytest.raises(cspace.UnionError, match="failed its check"):
        union([a, b])
    with pytest.raises(UnionError):  # and through the public sum: never the wrong region
        minkowski_sum_nonconvex(ROTATED_COMB, ROTATED_COMB)


boxes = st.tuples(st.integers(-20, 20), st.integers(-20, 20), st.integers(1, 15), st.integers(1, 15))


@settings(max_examples=60, deadline=None)
@given(st.lists(boxes, min_size=2, max_size=12), st.floats(0, 3.1))
def test_right_unions_pass(spec, angle):
    # Random rectangles, turned (float coordinates): GEOS's union passes the check and
    # agrees with the snap-rounded oracle.
    c, s = np.cos(angle), np.sin(angle)
    polys = [shapely.Polygon(np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]], float) @ [[c, s], [-s, c]])
             for x, y, w, h in spec]
    got = union(polys)
    ref = snapped_union(polys)
    assert shapely.symmetric_difference(got, ref).area <= 1e-9 * ref.area
    raw = shapely.union_all(polys)
    if raw.area == pytest.approx(ref.area, rel=1e-12):  # a right union: the check raises no false alarm
        assert union_mod.faithful(raw, polys)


def test_a_big_soup_checks_through_the_tree():
    # Enough off-vertex points and edges that the union's boundary is matched through an
    # STRtree of the inputs' edges: a right union passes, one with a bite taken does not.
    rng = np.random.default_rng(1)
    tri = rng.uniform(0, 60, (800, 1, 2)) + rng.uniform(-2, 2, (800, 3, 2))
    polys = shapely.polygons(np.concatenate((tri, tri[:, :1]), axis=1))
    polys = np.array([shapely.orient_polygons(p) for p in polys[shapely.area(polys) > 1e-3]])
    right = shapely.union_all(polys)
    own, _ = union_mod._samples(np.array([right], dtype=object))
    pts, edges = union_mod._samples(polys)
    rest = ~np.isin(own[:, 0] + 1j * own[:, 1], pts[:, 0] + 1j * pts[:, 1])
    assert rest.sum() * len(edges) > 1 << 22  # the tree's branch
    assert faithful(right, polys)
    x, y = shapely.get_coordinates(polys[0]).mean(axis=0)
    assert not faithful(right.difference(shapely.Point(x, y).buffer(0.05)), polys)
