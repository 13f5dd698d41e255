"""C-space point and segment queries against shapely on the workspace (an independent route).

Oracle: the robot translated to q, as shapely polygons, intersects a closed obstacle.
Random float states never land exactly on a boundary, so closed/open conventions
do not matter for these samples.
"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import shapely

from cspace import load_scenario
from cspace.translation.cspace import CSpace
from cspace.io.scenario.probe import CollisionProbe

from conftest import OMPL_SCENES, SCENARIOS


def _robot_swept(sc, a, b):
    """Workspace region swept by the robot translating from a to b (convex hull per part)."""
    parts = []
    for part in sc.robot:
        pts = np.vstack([part.polygon + a, part.polygon + b])
        parts.append(shapely.MultiPoint(pts).convex_hull)
    return shapely.union_all(parts) if parts else shapely.LineString([a, b])


def _with_margin(sc):
    """The scenario whose robot is the robot inflated by its margin (issue 21), as the C-space
    sees it: each convex part summed with the margin polygons, the hull of all vertex sums
    (numpy + shapely), so the shapely oracle below checks the margin's C-space too."""
    import dataclasses

    from cspace.kernel.polygons.polygon import is_convex
    from cspace.io.load import Shape

    margins = sc.margins()
    if not margins:
        return sc
    parts = [s.polygon for s in sc.robot] or [np.zeros((1, 2))]
    assert all(len(p) < 3 or is_convex(p) for p in parts), "the oracle sums convex parts only"
    robot = []
    for p in parts:
        pts = p
        for m in margins:
            pts = (pts[:, None, :] + m[None, :, :]).reshape(-1, 2)
        hull = shapely.MultiPoint(pts).convex_hull
        robot.append(Shape(np.asarray(hull.exterior.coords)[:-1][::1]))
    return dataclasses.replace(sc, robot=robot)


def _scenes():
    names = [os.path.join(OMPL_SCENES, f) for f in ("circles.toml", "env1.toml", "normal.toml")]
    if os.path.isdir(SCENARIOS):
        names += sorted(os.path.join(SCENARIOS, f) for f in os.listdir(SCENARIOS) if f.endswith(".toml"))
    return names


@pytest.mark.parametrize("path", _scenes(), ids=os.path.basename)
def test_point_queries_agree_with_shapely(path):
    sc = load_scenario(path)
    if len(sc.obstacles) > 300:
        pytest.skip("large scene: covered by the dedicated test")
    cs = CSpace.from_scenario(sc)
    probe = CollisionProbe(_with_margin(sc))
    rng = np.random.default_rng(1)
    xmin, xmax, ymin, ymax = sc.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], size=(1500, 2))
    ours = [cs.is_free_xy(x, y) for x, y in pts.tolist()]
    ref = [probe.first_hit(x, y) is None for x, y in pts.tolist()]
    assert ours == ref


@pytest.mark.parametrize("path", _scenes(), ids=os.path.basename)
def test_segment_queries_agree_with_shapely(path):
    sc = load_scenario(path)
    if len(sc.obstacles) > 300:
        pytest.skip("large scene: covered by the dedicated test")
    cs = CSpace.from_scenario(sc)
    obstacles = shapely.union_all([o.to_shapely() for o in sc.obstacles])
    shapely.prepare(obstacles)
    rng = np.random.default_rng(2)
    xmin, xmax, ymin, ymax = sc.bounds
    a = rng.uniform([xmin, ymin], [xmax, ymax], size=(300, 2))
    b = a + (rng.uniform([xmin, ymin], [xmax, ymax], size=(300, 2)) - a) * rng.uniform(0, 0.4, size=(300, 1))
    inflated = _with_margin(sc)
    for p, q in zip(a, b):
        ref = not obstacles.intersects(_robot_swept(inflated, p, q))
        assert cs.segment_free(p, q) == ref, (p, q)


def test_thin_obstacle_is_not_tunnelled():
    # a wall 1e-9 thick: any sampling-based motion check at resolution 1e-3 would miss it
    wall = np.array([[5.0, 0.0], [5.0 + 1e-9, 0.0], [5.0 + 1e-9, 10.0], [5.0, 10.0]])
    cs = CSpace((0, 10, 0, 10), [wall])
    assert cs.is_free((1, 5)) and cs.is_free((9, 5))
    assert not cs.segment_free((1, 5), (9, 5))
    assert cs.segment_free((1, 5), (4.9, 9))


def test_touching_counts_as_collision_consistently():
    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    cs = CSpace((0, 10, 0, 10), [sq])
    assert not cs.is_free((6.0, 5.0))  # on the edge
    assert not cs.is_free((4.0, 4.0))  # on a vertex
    assert cs.is_free((6.0 + 2 ** -40, 5.0))
    assert not cs.segment_free((6.0, 0.0), (6.0, 10.0))  # grazing along an edge
    assert cs.segment_free((6.0 + 2 ** -40, 0.0), (6.0 + 2 ** -40, 10.0))


def test_offset_scene_keeps_exact_answers():
    # the same geometry shifted by 1e8: the answers must not change
    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    off = 1e8
    cs = CSpace((off, off + 10, off, off + 10), [sq + off])
    assert not cs.is_free((off + 6.0, off + 5.0))
    assert cs.is_free((off + 6.0 + 2e-8, off + 5.0))
    assert not cs.segment_free((off + 1, off + 5), (off + 9, off + 5))


def test_pruning_drops_outside_and_contained_pieces():
    inside = np.array([[4.5, 4.5], [5.5, 4.5], [5.5, 5.5], [4.5, 5.5]])
    big = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    far = np.array([[40.0, 40.0], [41.0, 40.0], [41.0, 41.0]])
    cs = CSpace((0, 10, 0, 10), [inside, big, far])
    rep = {s["stage"]: s for s in cs.report()["stages"]}
    assert rep["prune"]["outside_bounds"] == 1
    assert rep["prune"]["inside_another"] == 1
    assert len(cs.pieces) == 1
    assert rep["minkowski"]["ran"] is False  # a point robot is not summed


def test_index_boxes_are_the_kept_pieces_boxes():
    # The index takes the prune's boxes of the pieces it kept (outside ones dropped, contained
    # ones removed): each must be its piece's own box, as piece_boxes computes it afresh.
    from cspace.kernel.polygons.polygon import piece_boxes

    rng = np.random.default_rng(7)
    obstacles = [np.array([[4.5, 4.5], [5.5, 4.5], [5.5, 5.5], [4.5, 5.5]]),
                 np.array([[40.0, 40.0], [41.0, 40.0], [41.0, 41.0]])]
    for _ in range(30):
        c, r = rng.uniform(-1, 11, 2), rng.uniform(0.1, 2.0)
        k = int(rng.integers(3, 9))
        a = np.sort(rng.uniform(0, 2 * np.pi, k))
        obstacles.append(c + r * np.column_stack([np.cos(a), np.sin(a)]))
    obstacles.append(np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]]))
    cs = CSpace((0, 10, 0, 10), obstacles)
    rep = {s["stage"]: s for s in cs.report()["stages"]}
    assert rep["prune"]["outside_bounds"] >= 1 and rep["prune"]["inside_another"] >= 1
    lo, hi = piece_boxes(cs.pieces)
    assert np.array_equal(cs.packed.lo, lo) and np.array_equal(cs.packed.hi, hi)
    assert np.array_equal(cs.index._lo, lo) and np.array_equal(cs.index._hi, hi)


def test_clearance_matches_shapely_distance():
    pytest.importorskip("cspace.kernel.distance.gjk")
    sc = load_scenario(os.path.join(OMPL_SCENES, "circles.toml"))
    cs = CSpace.from_scenario(sc)
    union = shapely.union_all([shapely.Polygon(p) for p in cs.pieces])
    rng = np.random.default_rng(3)
    xmin, xmax, ymin, ymax = sc.bounds
    n = 0
    for x, y in rng.uniform([xmin, ymin], [xmax, ymax], size=(200, 2)):
        if cs.is_free((x, y)):
            assert cs.clearance((x, y)) == pytest.approx(union.distance(shapely.Point(x, y)), rel=1e-9, abs=1e-12)
            n += 1
    assert n > 50
    assert math.isinf(CSpace((0, 1, 0, 1), []).clearance((0.5, 0.5)))


@pytest.mark.parametrize("name", ["random_polygons.toml", "combs.toml", "disks.toml", "maze.toml"])
def test_mixed_cell_edge_masks_are_conservative(name):
    # The narrow phase of a MIXED cell skips a candidate's edges outside the cell's mask:
    # every point of the cell (and its margin) must lie strictly inside those edges' half-planes.
    from cspace.kernel.polygons.predicates import orient2d_many
    from cspace.translation.broadphase import WIDE_MASK

    cs = CSpace.from_scenario(load_scenario(os.path.join(SCENARIOS, name)))
    g = cs.index
    rng = np.random.default_rng(0)
    starts, cand, masks = g._starts_list, g._cand_list, g.cand_masks_list
    cells = np.flatnonzero(g.state == 1)
    skipped = 0
    for cell in rng.choice(cells, size=min(300, len(cells)), replace=False).tolist():
        i, j = cell % g.nx, cell // g.nx
        x0, y0 = g.x0 + i * g.cw - g.margin, g.y0 + j * g.ch - g.margin
        w, h = g.cw + 2 * g.margin, g.ch + 2 * g.margin
        pts = np.column_stack([x0 + w * rng.random(40), y0 + h * rng.random(40)])
        pts = np.vstack([pts, [[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]])
        for t in range(starts[cell], starts[cell + 1]):
            k, mask = cand[t], masks[t]
            p = cs.pieces[k]
            if mask == WIDE_MASK:  # a wide piece (disks): the mask the point test computes on demand
                mask = g.edge_mask(p, cell)
            for e in range(len(p)):
                if (mask >> e) & 1:
                    continue
                skipped += 1
                s = orient2d_many(np.broadcast_to(p[e - 1], pts.shape), np.broadcast_to(p[e], pts.shape), pts)
                assert (s > 0).all(), (name, cell, k, e)
    assert skipped > 0  # the masks really drop edges


@pytest.mark.parametrize("offset", [0.0, 1e8])
def test_point_test_off_the_grid_goes_to_the_exact_test(offset):
    # The hot path reads a border cell or raises IndexError past the grid's top and
    # right edges and compares only against the lower edges: every point around the
    # bounds, at 0, a fraction of a cell, one, two and many cells out, and the
    # non-finite ones, must get the exact answer. Obstacles straddle two corners, so
    # a point read from a wrong (neighbouring or wrapped) cell would be answered wrong.
    o = offset
    sq = lambda x0, y0, s: np.array([[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]) + o
    cs = CSpace((o, o + 10.0, o, o + 10.0), [sq(8.0, 8.0, 4.0), sq(-2.0, -2.0, 4.0), sq(4.0, 4.0, 1.0)])
    cw, ch = 10.0 / cs.index.nx, 10.0 / cs.index.ny
    xs = [o + d for d in (-1e6, -2.5 * cw, -1.5 * cw, -0.5 * cw, 0.0, 0.5 * cw, 3.0, 4.5, 9.0, 10.0 - 0.5 * cw,
                          10.0, 10.0 + 0.5 * cw, 10.0 + 1.5 * cw, 10.0 + 2.5 * cw, 1e6)]
    ys = [o + d for d in (-1e6, -1.5 * ch, -0.5 * ch, 0.0, 1.0, 4.5, 9.0, 10.0, 10.0 + 0.5 * ch, 10.0 + 1.5 * ch, 1e6)]
    odd = [math.nan, math.inf, -math.inf, 1e308, -1e308]
    q_test, xy_test = cs.point_test(state=True), cs.point_test()
    for x in xs + odd:
        for y in ys + odd:
            inside = o <= x <= o + 10.0 and o <= y <= o + 10.0
            blocked = any(shapely.Polygon(p).intersects(shapely.Point(x, y)) for p in cs.pieces) if inside else True
            want = inside and not blocked
            assert q_test((x, y)) == want and xy_test(x, y) == want == cs._is_free_exact(x, y), (x, y)
