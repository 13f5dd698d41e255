"""FREE and POSSIBLE regions of angle slabs (cspace.se2.slab_graph), checked against shapely.

The references here are independent of the project's geometry: robots are turned with
numpy's cos / sin and placed as shapely polygons, collisions are shapely's ``intersects``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings, strategies as st

from cspace.se2.link_points import deep_point
from cspace.se2.slab_graph import SlabRegions, point_free


def turned(poly, th, x=0.0, y=0.0):
    c, s = math.cos(th), math.sin(th)
    p = np.asarray(poly, dtype=float)
    return np.column_stack([p[:, 0] * c - p[:, 1] * s + x, p[:, 0] * s + p[:, 1] * c + y])


TRI = np.array([[-0.5, -0.3], [1.2, -0.1], [0.1, 0.6]])  # no symmetry: a wrong reflection shows
BOXES = [np.array([[3., 2], [4, 2], [4, 6], [3, 6]]), np.array([[6., 5], [8, 5], [8, 6], [6, 6]])]
BOUNDS = (0.0, 10.0, 0.0, 8.0)


def union_of(region):
    return shapely.union_all(region.components) if region.components else shapely.Polygon()


def test_reflection_convention_matches_shapely():
    sr = SlabRegions(BOXES, [TRI], BOUNDS)
    obs = shapely.union_all([shapely.Polygon(b) for b in BOXES])
    rng = np.random.default_rng(1)
    for _ in range(300):
        x, y, th = rng.uniform(0, 10), rng.uniform(0, 8), rng.uniform(-math.pi, math.pi)
        truth = not shapely.Polygon(turned(TRI, th, x, y)).intersects(obs)
        d = obs.distance(shapely.Polygon(turned(TRI, th, x, y)))
        if d > 1e-9 or not truth:
            assert sr.pose_free(x, y, th) == truth, (x, y, th)


def test_zero_width_free_is_the_translation_cspace():
    sr = SlabRegions(BOXES, [TRI], BOUNDS)
    obs = shapely.union_all([shapely.Polygon(b) for b in BOXES])
    th = 0.7
    F = union_of(sr.free_at(th))
    rng = np.random.default_rng(2)
    for _ in range(300):
        x, y = rng.uniform(0, 10), rng.uniform(0, 8)
        d = obs.distance(shapely.Polygon(turned(TRI, th, x, y)))
        if d > 1e-6:
            assert F.intersects(shapely.Point(x, y))
        elif d == 0.0:
            assert not F.contains(shapely.Point(x, y))


@settings(max_examples=25, deadline=None)
@given(a=st.floats(-math.pi, math.pi - 0.01), w=st.floats(0.001, math.pi / 4))
def test_free_inside_possible_and_both_sound(a, w):
    b = min(a + w, math.pi)
    sr = SlabRegions(BOXES, [TRI, np.array([[-1., -0.2], [-0.4, -0.2], [-0.4, 0.2], [-1., 0.2]])], BOUNDS)
    F, P = sr.free(a, b), sr.possible(a, b)
    assert union_of(F).difference(union_of(P)).area <= 1e-9
    obs = shapely.union_all([shapely.Polygon(o) for o in BOXES])
    rng = np.random.default_rng(3)
    pu = union_of(P)
    for _ in range(40):
        x, y = rng.uniform(0, 10), rng.uniform(0, 8)
        angles = np.linspace(a, b, 9)
        free_all = all(not shapely.Polygon(turned(p, t, x, y)).intersects(obs) for p in sr.robot for t in angles)
        if sr.containing(F, x, y) is not None:
            assert free_all  # FREE: free at every angle of the slab
        t = rng.uniform(a, b)
        if not any(shapely.Polygon(turned(p, t, x, y)).intersects(obs) for p in sr.robot):
            assert pu.distance(shapely.Point(x, y)) <= sr.tol  # a free pose lies in POSSIBLE


@settings(max_examples=30, deadline=None)
@given(a=st.floats(-math.pi, math.pi), w=st.floats(0.0, math.pi / 4), n=st.integers(3, 7), seed=st.integers(0, 99))
def test_core_inside_the_turned_piece(a, w, n, seed):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-2, 2, size=(n, 2)) + rng.uniform(-1, 1, size=2)
    hull = shapely.MultiPoint(pts).convex_hull
    if hull.geom_type != "Polygon" or hull.area < 1e-3:
        return
    piece = np.asarray(shapely.orient_polygons(hull).exterior.coords[:-1])
    sr = SlabRegions(BOXES, [piece], BOUNDS)
    core = sr.possible(a, a + w).cores[0]
    if not len(core):
        return
    C = shapely.Polygon(core)
    for t in np.linspace(a, a + w, 200):
        assert shapely.Polygon(turned(piece, t)).contains(C)


def test_regions_are_cached_and_components_ordered():
    sr = SlabRegions(BOXES, [TRI], BOUNDS)
    r1 = sr.possible(0.0, 0.5)
    assert sr.possible(0.0, 0.5) is r1 and sr.counts["possible_built"] == 1
    boxes = [c.bounds for c in r1.components]
    assert boxes == sorted(boxes)


def test_links_between_slabs():
    wall = [np.array([[4., 0], [5, 0], [5, 4], [4, 4]]), np.array([[4., 5], [5, 5], [5, 10], [4, 10]])]
    bar = [np.array([[-1., -0.2], [1, -0.2], [1, 0.2], [-1, 0.2]])]
    sr = SlabRegions(wall, bar, (0, 10, 0, 10))
    f1, f2 = sr.free(0.0, 0.2), sr.free(0.2, 0.4)
    links = sr.free_links(f1, f2)
    assert links and all(point_free(f1.pieces, sr.bounds, *pt) and point_free(f2.pieces, sr.bounds, *pt)
                         for _, _, pt in links)
    p1, p2 = sr.possible(0.0, 0.2), sr.possible(0.2, 0.4)
    assert set(sr.possible_links(p1, p2)) >= {(0, 0)}
    assert sr.near(p1, 1.0, 1.0) == [0] and sr.near(p1, 4.5, 2.0) == []


def test_deep_point_and_point_free():
    assert deep_point(shapely.box(0, 0, 1, 1e-12), 1e-9) is None
    x, y = deep_point(shapely.box(0, 0, 4, 1), 0.1)
    assert 0.1 < y < 0.9
    sq = np.array([[1., 1], [2, 1], [2, 2], [1, 2]])
    assert not point_free([sq], (0, 3, 0, 3), 2.0, 2.0)  # touching is collision
    assert not point_free([sq], (0, 3, 0, 3), 3.5, 0.5)  # out of bounds


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10**6))
def test_point_free_with_a_regions_boxes_is_shapelys_answer(seed):
    # the region's kept piece boxes (the exact planner's turn points) and the boxes made per call
    # give the same answers, and both are shapely's (closed pieces: touching is collision)
    rng = np.random.default_rng(seed)
    sr = SlabRegions(BOXES, [TRI], BOUNDS)
    a = float(rng.uniform(-math.pi, math.pi - 0.3))
    reg = sr.free(a, a + 0.3)
    obs = shapely.union_all([shapely.Polygon(p) for p in reg.pieces])
    corners = np.concatenate(reg.pieces)
    pts = np.concatenate([rng.uniform(0, 10, (40, 2)) * [1, 0.8], corners[rng.integers(0, len(corners), 10)]])
    for x, y in pts.tolist():
        truth = BOUNDS[0] <= x <= BOUNDS[1] and BOUNDS[2] <= y <= BOUNDS[3] and not obs.intersects(shapely.Point(x, y))
        assert point_free(reg.pieces, sr.bounds, x, y, reg.piece_boxes) == point_free(reg.pieces, sr.bounds, x, y)
        if obs.distance(shapely.Point(x, y)) > 1e-9 or not truth:  # (shapely's float test is the oracle off the edges)
            assert point_free(reg.pieces, sr.bounds, x, y) == truth, (x, y)


def test_possible_links_and_near_agree_with_measured_distances():
    # overlapping components are linked by the prepared intersects test without a distance: the
    # same pairs as measuring every one
    sr = SlabRegions(BOXES, [TRI], BOUNDS)
    for a in np.linspace(-math.pi, math.pi - 0.4, 9):
        p1, p2 = sr.possible(a, a + 0.2), sr.possible(a + 0.2, a + 0.4)
        measured = [(i, j) for i in range(len(p1.components)) for j in range(len(p2.components))
                    if shapely.distance(p1.components[i], p2.components[j]) <= sr.tol]
        assert sr.possible_links(p1, p2) == measured
        for x, y in ((1.0, 1.0), (3.0, 4.0), (5.0, 5.5), (9.5, 7.5)):
            assert sr.near(p1, x, y) == [i for i, c in enumerate(p1.components)
                                         if shapely.distance(c, shapely.Point(x, y)) <= sr.tol]


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10_000))
def test_quick_links_join_the_same_components_at_points_deep_in_both(seed):
    """Links found without the overlay (``quick_links``: a component's own deep point, where the
    next slab's component holds it that deep) join the same component pairs as the overlay's, at
    points farther than the link depth from both components' boundaries (shapely's distances)."""
    rng = np.random.default_rng(seed)
    boxes = []
    for _ in range(int(rng.integers(4, 14))):  # (many: pockets, components apart whose boxes overlap)
        x, y, w, h = rng.uniform(0, 9), rng.uniform(0, 7), rng.uniform(0.2, 2.5), rng.uniform(0.2, 2.5)
        boxes.append(np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]]))
    slow, quick = SlabRegions(boxes, [TRI], BOUNDS), SlabRegions(boxes, [TRI], BOUNDS)
    quick.quick_links = True
    for k in range(8):
        a, b = -math.pi + k * math.pi / 4, -math.pi + (k + 1) * math.pi / 4
        c, d = b, b + math.pi / 4
        r1, r2 = quick.free(a, b), quick.free(c, d)
        want = {(i, j) for i, j, _ in slow.free_links(slow.free(a, b), slow.free(c, d))}
        got = quick.free_links(r1, r2)
        assert {(i, j) for i, j, _ in got} == want
        for i, j, (x, y) in got:
            p = shapely.Point(x, y)
            both = r1.components[i].intersection(r2.components[j])
            assert both.covers(p)
            if r1.components[i].boundary.distance(p) > quick.tol and r2.components[j].boundary.distance(p) > quick.tol:
                continue  # a deep link (the quick one's, or the overlay's where it was deep)
            assert deep_point(both, quick.tol) is None  # else only where the overlap has no deep point
