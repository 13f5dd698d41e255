"""The shortest-path benchmark's machinery on its smallest scenes (no timing asserted:
speed lives in scripts/bench_shortest.py); the two searches must agree there."""
import numpy as np
import pytest
from conftest import load_script


@pytest.fixture(scope="module")
def bench():
    return load_script("bench_shortest")


@pytest.mark.parametrize("family", ["scattered", "grid"])
def test_rows_agree_and_hold_the_plotted_fields(bench, family):
    row = bench.measure(family, 200, reps=1, old_limit=30.0, seed=3)
    assert row["family"] == family and row["vertices"] > 50 and row["solved"]
    assert row["agree"] is True and row["method"] == "mesh"
    assert row["new_s"] > 0 and row["old_s"] > 0 and row["ratio"] == pytest.approx(row["old_s"] / row["new_s"])


def test_fits_recover_a_power_law(bench):
    rows = [{"family": "grid", "vertices": v, "new_s": 1e-3 * v**1.5} for v in (100, 400, 1600)]
    (fit,) = bench.fits(rows)
    assert fit["search"] == "mesh" and fit["k"] == pytest.approx(1.5)
    assert bench.fit_exponent(np.array([1, 10]), np.array([5, 5])) == pytest.approx(0.0, abs=1e-12)
