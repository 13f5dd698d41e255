"""The scaling benchmark's machinery: the exponent fit and the smallest sweeps.

Timings themselves are not asserted (speed lives in scripts/bench_*.py); only that
the rows hold the fields the docs are generated from, with sane values.
"""
import math

import numpy as np
import pytest
from conftest import load_script


@pytest.fixture(scope="module")
def bench():
    return load_script("bench_scaling")


def test_fit_exponent_recovers_power_laws(bench):
    x = np.array([10, 30, 100, 300, 1000], dtype=float)
    assert abs(bench.fit_exponent(x, 3 * x**2) - 2) < 1e-9
    assert abs(bench.fit_exponent(x, 0.5 * x**-1.5) + 1.5) < 1e-9
    assert abs(bench.fit_exponent(x, np.full(5, 7.0))) < 1e-9


def test_obstacle_sweep_rows(bench):
    rows = bench.sweep_obstacles([10, 30], queries=50, batches=2)
    assert [r["x"] for r in rows] == [10, 30]
    for r in rows:
        assert r["sweep"] == "obstacles" and r["vertices"] == 8
        assert set(r) >= {"build_s", "sum_s", "index_s", "peak_mib", "pieces", "is_free_us", "segment_free_us"}
        # 8-gon sums never decompose; pruning may only drop pieces inside another one
        assert 0 < r["pieces"] <= r["obstacles"]
        assert all(math.isfinite(r[k]) and r[k] > 0 for k in ("build_s", "peak_mib", "is_free_us", "segment_free_us"))
    table = bench.fits(rows)
    assert {f["field"] for f in table} == {"build_s", "sum_s", "index_s", "peak_mib", "is_free_us", "segment_free_us"}


def test_scenes_are_what_they_claim(bench):
    from cspace import is_convex, scenario_from_dict

    sc = scenario_from_dict(bench.scattered_scene(12, 32, seed=3))
    assert len(sc.obstacles) == 12
    assert all(len(o.polygon) == 32 and is_convex(o.polygon, strict=True) for o in sc.obstacles)
    assert len(sc.robot[0].polygon) == 8
    c = bench.comb(5)
    assert len(c) == 20 and not is_convex(c)


def test_comb_sweep_counts_pairs(bench):
    rows = bench.sweep_combs([2, 3])
    for r in rows:
        n = r["x"]
        # a comb with n teeth decomposes into at least n + 1 convex pieces
        assert r["pairs"] >= (n + 1) ** 2
        assert 0 < r["pieces"] <= r["pairs"]
        # nm teeth sums on distinct vertical strips, 4 corners each, plus the 4 outer corners:
        # the Θ(nm) boundary the script's comment block claims for this layout
        assert r["union_vertices"] == 4 * (n * n + 1)
        assert r["union_holes"] == 0
