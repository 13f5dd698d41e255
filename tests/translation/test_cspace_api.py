"""CSpace's Python API is consistent with the kernel's: shapely inputs, either orientation,
arrays of queries, refused NaN and (x, y, theta), no GEOS message or warning reaching the user."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import shapely

from cspace import CSpace

SQ = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
RING = shapely.Polygon([[1, 1], [7, 1], [7, 7], [1, 7]], [[[3, 3], [3, 5], [5, 5], [5, 3]]])
L_SHAPE = np.array([[6.0, 8.0], [9.0, 8.0], [9.0, 9.0], [7.0, 9.0], [7.0, 9.5], [6.0, 9.5]])
TRI = np.array([[-0.3, -0.2], [0.3, -0.2], [0.0, 0.3]])
BOUNDS = (0.0, 10.0, 0.0, 10.0)


def _probes(n=3000, seed=1):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-0.5, 10.5, size=(n, 2))
    # Points on the obstacles' and the bounds' edges and corners, where closedness matters.
    edge = [(x, y) for x in (0.0, 1.0, 3.0, 5.0, 7.0, 10.0) for y in (0.0, 1.0, 3.0, 4.0, 7.0, 10.0)]
    return np.vstack([pts, edge])


def _oracle(obstacle_geoms, robot_geom, q) -> bool:
    """Robot at q touches no obstacle (closed sets) and q is in the bounds: shapely."""
    x, y = q
    if not (0 <= x <= 10 and 0 <= y <= 10):
        return False
    body = shapely.affinity.translate(robot_geom, x, y) if robot_geom is not None else shapely.Point(x, y)
    return not any(g.intersects(body) for g in obstacle_geoms)


def test_shapely_obstacles_and_robot_give_the_array_answers_and_shapelys():
    import shapely.affinity  # noqa: F401  (used by _oracle)

    multi = shapely.MultiPolygon([shapely.Polygon(L_SHAPE), shapely.box(8.5, 1, 9.5, 2)])
    robot = shapely.Polygon(TRI)
    from_shapely = CSpace(BOUNDS, [RING, multi], robot)
    from_arrays = CSpace(BOUNDS, [np.array(RING.exterior.coords), L_SHAPE, np.array([[8.5, 1], [9.5, 1], [9.5, 2],
                                                                                     [8.5, 2]])],
                         [TRI], obstacle_holes=[[np.array(RING.interiors[0].coords)], [], []])
    pts = _probes()
    got = from_shapely.is_free(pts)
    assert got.tolist() == from_arrays.is_free(pts).tolist()
    want = [_oracle([RING, multi], robot, q) for q in pts.tolist()]
    assert got.tolist() == want
    assert got.any() and not got.all()
    # The pieces of the MultiPolygon report the input obstacle they came from.
    assert set(from_shapely.piece_obstacle.tolist()) == {0, 1}


def test_robot_as_a_multipolygon_is_its_parts():
    parts = shapely.MultiPolygon([shapely.box(-0.2, -0.2, 0.2, 0.2), shapely.box(0.6, -0.1, 0.8, 0.1)])
    cs = CSpace(BOUNDS, [SQ + 4.0], parts)
    ref = CSpace(BOUNDS, [SQ + 4.0], [np.array(p.exterior.coords) for p in parts.geoms])
    pts = _probes(1500, seed=2)
    assert cs.is_free(pts).tolist() == ref.is_free(pts).tolist()
    assert cs.is_free((3.3, 5.0)) is False  # the second part reaches into the square


@pytest.mark.parametrize("variant", ["cw", "closed", "repeated", "collinear"])
def test_any_orientation_and_closing_vertex_give_the_same_cspace(variant):
    # A clockwise square used to be read as an empty obstacle: (5, 5) inside it was "free".
    sq = SQ + 4.0
    poly = {"cw": sq[::-1], "closed": np.vstack([sq, sq[:1]]), "repeated": np.vstack([sq[:2], sq[1:]]),
            "collinear": np.insert(sq, 1, [5.0, 4.0], axis=0)}[variant]
    given = poly.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning from a zero-length edge
        cs = CSpace(BOUNDS, [poly], [TRI])
    assert np.array_equal(poly, given)  # inputs are never modified
    ref = CSpace(BOUNDS, [sq], [TRI])
    pts = _probes(1500, seed=3)
    assert cs.is_free(pts).tolist() == ref.is_free(pts).tolist()
    assert not cs.is_free((5, 5)) and cs.is_free((1, 1))


@pytest.mark.parametrize(
    "obstacles, robot, match",
    [
        ([[[0, 0], [2, 2], [2, 0], [0, 2]]], None, r"obstacles\[0\]: not a simple polygon \(Self-intersection"),
        ([SQ, [[0, 0], [1, 0], [2, 0]]], None, r"obstacles\[1\]: the polygon has zero area"),
        ([[[0, 0], [math.nan, 0], [1, 1]]], None, r"obstacles\[0\]: coordinates must be finite"),
        ([shapely.LineString([(0, 0), (1, 1)])], None, r"obstacles\[0\]: a LineString is not an area"),
        ([SQ], [[[0, 0], [1, 1], [1, 0], [0, 1]]], r"robot\[0\]: not a simple polygon"),
        ([SQ], shapely.Polygon(RING), r"robot\[0\]: a robot part has no holes"),
        ([RING], None, None),  # fine: a shapely polygon brings its holes
    ],
)
def test_bad_geometry_is_one_clear_value_error_and_nothing_from_geos(obstacles, robot, match, capfd):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if match is None:
            CSpace(BOUNDS, obstacles, robot)
        else:
            with pytest.raises(ValueError, match=match):
                CSpace(BOUNDS, obstacles, robot)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


@pytest.fixture(scope="module")
def cs():
    return CSpace(BOUNDS, [RING, L_SHAPE], [TRI])


def test_is_free_on_arrays_is_the_scalar_answer_point_by_point(cs):
    pts = _probes(4000, seed=4)
    # Points near grid lines and the bounds' edges too, where the cell index rounds.
    nx, ny = cs.index.nx, cs.index.ny
    gx = np.linspace(0, 10, nx + 1)[::7]
    pts = np.vstack([pts, np.column_stack([gx, np.full_like(gx, 4.0)]), np.column_stack([np.nextafter(gx, 11), gx])])
    n0 = cs.point_count()
    got = cs.is_free(pts)
    assert got.dtype == bool and got.shape == (len(pts),)
    assert cs.point_count() == n0 + len(pts)
    assert got.tolist() == [cs.is_free((x, y)) for x, y in pts.tolist()]
    assert cs.is_free(pts.tolist()).tolist() == got.tolist()  # nested lists too
    assert cs.is_free(np.zeros((0, 2))).shape == (0,)
    assert cs.is_free(np.array([0.5, 0.5])) is True  # a (2,) array is one point
    assert cs.is_free([0.5, 0.5]) is True and cs.is_free((np.float64(0.5), 0.5)) is True
    assert cs.is_free((1, 1)) is False and cs.is_free(np.array([1, 1])) is False  # integers


def test_clearance_and_segments_on_arrays_are_the_scalar_answers(cs):
    rng = np.random.default_rng(5)
    pts = rng.uniform(0, 10, size=(60, 2))
    c = cs.clearance(pts)
    assert c.dtype == np.float64 and c.tolist() == [cs.clearance(tuple(p)) for p in pts.tolist()]
    assert (c > 0).any() and (c == 0).any()
    segs = rng.uniform(0, 10, size=(200, 2, 2))
    segs[:, 1] = segs[:, 0] + 0.1 * (segs[:, 1] - segs[:, 0])  # short motions: some free, some not
    want = [cs.segment_free(tuple(a), tuple(b)) for a, b in segs.tolist()]
    assert cs.segment_free(segs).tolist() == want
    assert cs.segment_free(segs[:, 0], segs[:, 1]).tolist() == want
    assert any(want) and not all(want)


@pytest.mark.parametrize("bad", [(math.nan, 1.0), (1.0, math.inf), (-math.inf, 1.0), np.array([1.0, math.nan])])
def test_non_finite_queries_raise_like_the_kernel(cs, bad):
    with pytest.raises(ValueError, match="finite"):
        cs.is_free(bad)
    with pytest.raises(ValueError, match="finite"):
        cs.is_free(np.array([[1.0, 1.0], list(bad)]))
    with pytest.raises(ValueError, match="finite"):
        cs.clearance(bad)
    with pytest.raises(ValueError, match="finite"):
        cs.segment_free((1.0, 1.0), bad)
    with pytest.raises(ValueError, match="finite"):
        cs.segment_free(bad, (1.0, 1.0))


def test_a_pose_with_theta_is_refused_not_read_as_x_y(cs):
    assert cs.is_free((0.5, 0.5))
    for call in (lambda: cs.is_free((1.0, 1.0, 0.5)), lambda: cs.is_free([[1.0, 1.0, 0.5]]),
                 lambda: cs.clearance((1.0, 1.0, 0.5)), lambda: cs.segment_free((1, 1, 0), (2, 2, 0)),
                 lambda: cs.segment_free(np.zeros((3, 2, 3)))):
        with pytest.raises(ValueError, match=r"\(x, y, theta\) given to a translation C-space"):
            call()
    with pytest.raises(ValueError, match="expected a point"):
        cs.is_free((1.0,))
