"""The C-space benchmark's pieces: the shapely peer, the OMPL timing loop, the combs,
pyclipper's full sum and the stage table. Timings are not asserted (speed lives in
scripts/bench_cspace.py), only that the pieces compute the right things."""
import math

import numpy as np
import pytest
import shapely

from conftest import load_script
from cspace import CSpace, minkowski_sum_nonconvex



@pytest.fixture(scope="module")
def bench():
    return load_script("bench_cspace")


@pytest.fixture(scope="module")
def scene(bench):
    sc = bench.random_scene(seed=3, size=30)
    return sc, CSpace.from_scenario(sc)


def test_comb_shape(bench):
    A = bench.comb(20, 1.0, 1.0, 4.0, 1.0)
    poly = shapely.Polygon(A)
    assert len(A) == 80 and poly.is_valid
    assert math.isclose(poly.area, 39 * 1 + 20 * 4, rel_tol=1e-12)  # base bar + teeth
    _, B = bench.combs()
    pb = shapely.Polygon(B)
    assert len(B) == 40 and pb.is_valid and pb.exterior.is_ccw
    assert math.isclose(pb.area, 14 * 0.5 + 10 * 0.5 * 3, rel_tol=1e-12)  # rotation keeps the area
    assert np.allclose((B.min(axis=0) + B.max(axis=0)) / 2, 0.0, atol=2.0)  # roughly centred


def test_shapely_peer_agrees_with_cspace(bench, scene):
    sc, cs = scene
    peer = bench.shapely_checker(sc)
    pred = bench.shapely_checker(sc, predicate=True)
    from planners.adapters.translation import validity_function

    ours = validity_function(cs)
    rng = np.random.default_rng(7)
    xmin, xmax, ymin, ymax = sc.bounds
    pts = rng.uniform((xmin, ymin), (xmax, ymax), (400, 2)).tolist()
    for q in pts:
        assert peer(q) == pred(q)
    row = bench.agreement(sc, ours, peer, 400, seed=7)
    assert row["disagree_away"] == 0
    assert 0 < row["valid"] < 400  # the scene has both free and blocked states
    # a state on an obstacle vertex collides; outside the bounds is never valid
    v = np.asarray(sc.obstacles[0].polygon)[0] - np.asarray(sc.robot[0].polygon)[0]
    assert not peer(v) and not ours(v)
    assert not peer((xmax + 1.0, ymax)) and not ours((xmax + 1.0, ymax))


def test_ompl_timing_loop(bench, scene):
    sc, cs = scene
    from planners.adapters.translation import validity_function

    si, keep = bench.ompl_space_information(cs, 0)
    res = bench.states_per_second(si, {"noop": (lambda s: True, 2000), "ours": (validity_function(cs), 2000),
                                       "never": (lambda s: False, 500)}, reps=2)
    assert res["noop"][1] == 1.0 and res["never"][1] == 0.0
    assert 0.0 < res["ours"][1] < 1.0
    assert all(v[0] > 0 and len(v[2]) == 2 for v in res.values())
    del keep


def test_clipper_full_sum_matches_references(bench):
    # small combs: pyclipper's full sum, ours and the triangle-pair reference agree
    A = bench.comb(3, 1.0, 1.0, 2.0, 0.5)
    B = bench.rotate(bench.comb(2, 0.5, 1.0, 1.5, 0.5) - (1.0, 1.0), 30.0)
    ref = bench.triangle_pair_area(A, B)
    ours = minkowski_sum_nonconvex(A, B).area
    s = bench.CLIP_SCALE
    paths = bench.clipper_sum(np.rint(A * s).astype(np.int64).tolist(), np.rint(B * s).astype(np.int64).tolist())
    clip = bench.clipper_area(paths, s)
    assert abs(ours - ref) <= 1e-12 * ref
    assert abs(clip - ref) <= 1e-5 * ref  # rounding to a 2^-20 grid
    # the swept boundary alone misses the interior when a teeth gap is filled: union matters
    import pyclipper

    swept = pyclipper.MinkowskiSum(np.rint(B * s).astype(np.int64).tolist(),
                                   np.rint(A * s).astype(np.int64).tolist(), True)
    assert bench.clipper_area(paths, s) >= bench.clipper_area(swept, s) - 1e-9


def test_clipper_sum_of_squares_is_exact(bench):
    # a square with a square: the sum is a 3 x 3 square, no hole
    sq = [[0, 0], [2, 0], [2, 2], [0, 2]]
    one = [[0, 0], [1, 0], [1, 1], [0, 1]]
    assert bench.clipper_area(bench.clipper_sum(sq, one), 1.0) == 9.0


def test_stage_rows(bench):
    files = bench.scenario_files()
    assert any(f.parent.name == "ompl" for f in files) and any(f.parent.name == "scenarios" for f in files)
    row = bench.stage_row(bench.ROOT / "scenarios" / "combs.toml")
    assert "index" in row["ran"] and "load" in row["ran"]
    assert row["after"] == row["before"] - row["outside"] - row["inside"] == row["pieces"]
    point = bench.stage_row(bench.ROOT / "scenarios" / "ompl" / "empty.toml")
    assert "minkowski" in point["skipped"] and point["pieces"] == 0
    # medians over builds, and the index's share of the stages (load excluded)
    three = bench.stage_row(bench.ROOT / "scenarios" / "basic.toml", reps=3)
    st = {s["stage"]: s["seconds"] for s in three["stages"] if s["ran"]}
    share = bench.index_share(three)
    assert share == st["index"] / sum(v for k, v in st.items() if k != "load") and 0 < share < 1
    assert bench.index_share({"stages": [{"stage": "load", "ran": True, "seconds": 1.0}]}) is None


@pytest.mark.parametrize("name", ["combs.toml", "random_polygons.toml", "u_robot.toml"])
def test_point_test_matches_brute_force(bench, name):
    # The validity checker's hot path (grid + inlined narrow phase in MIXED cells)
    # against an exact brute force over every piece, on uniform states, piece
    # vertices and edge midpoints (on the boundary: not free) and points just off them.
    from cspace.kernel.polygons.predicates import orient2d_many

    cs = CSpace.from_scenario(bench.ROOT / "scenarios" / name)
    xmin, xmax, ymin, ymax = cs.bounds
    rng = np.random.default_rng(11)
    pts = [rng.uniform((xmin, ymin), (xmax, ymax), (1500, 2))]
    for p in cs.pieces[:40]:
        mid = (p + np.roll(p, -1, axis=0)) / 2
        pts += [p, mid, np.nextafter(mid, mid + 1.0), np.nextafter(mid, mid - 1.0)]
    pts = np.concatenate(pts)
    blocked = np.zeros(len(pts), dtype=bool)
    for p in cs.pieces:
        s, e = p, np.roll(p, -1, axis=0)
        blocked |= (orient2d_many(s[None], e[None], pts[:, None, :]) >= 0).all(axis=1)
    inside = (pts[:, 0] >= xmin) & (pts[:, 0] <= xmax) & (pts[:, 1] >= ymin) & (pts[:, 1] <= ymax)
    want = (inside & ~blocked).tolist()
    q_test, xy_test = cs.point_test(state=True), cs.point_test()
    got_q = [q_test(q) for q in pts.tolist()]
    got_xy = [xy_test(x, y) for x, y in pts.tolist()]
    assert got_q == want and got_xy == want
    assert cs.checks["exact_points"] > 0  # MIXED cells were exercised
