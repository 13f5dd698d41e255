"""The stability catalogue's chart keeps one readable size whatever the number of cases (issue 51:
133 cases once made a 2633 x 550 px strip of 6-point names), and names each failed case."""
from __future__ import annotations

import pytest

from planners.pictures import stability_chart
from planners.pictures.stability_chart import layer_rows, plot_stability

LAYERS = ["predicate", "hull", "sum", "erosion", "decomposition", "gjk", "epa", "cspace", "planning"]


def rows(n: int, failed=()) -> list[dict]:
    return [{"case": f"{LAYERS[i % len(LAYERS)]}_case_{i}", "layer": LAYERS[i % len(LAYERS)],
             "time_ms": 10.0 ** ((i % 13) - 4), "passed": i not in failed} for i in range(n)]


def size(path) -> tuple[int, int]:
    import matplotlib.image as mpimg

    h, w = mpimg.imread(str(path)).shape[:2]
    return w, h


@pytest.mark.parametrize("n", [9, 133, 2000])
def test_the_size_follows_the_layers_not_the_cases(tmp_path, n):
    plot_stability(rows(n), tmp_path / "s.png")
    w, h = size(tmp_path / "s.png")
    assert (w, h) == size_of_nine_layers(tmp_path)
    assert w <= 1000 and h <= 700


def size_of_nine_layers(tmp_path):
    plot_stability(rows(9), tmp_path / "nine.png")
    return size(tmp_path / "nine.png")


def test_a_failed_case_is_named_on_the_chart(monkeypatch, tmp_path):
    import matplotlib.axes

    said = []
    real = matplotlib.axes.Axes.annotate
    monkeypatch.setattr(matplotlib.axes.Axes, "annotate", lambda ax, text, *a, **k: said.append(text) or real(ax, text, *a, **k))
    plot_stability(rows(133, failed={5, 77}), tmp_path / "s.png")
    assert sorted(said) == ["gjk_case_5", "gjk_case_77"]


def test_layers_keep_the_catalogue_order():
    assert [k for k, _ in layer_rows(rows(20))] == LAYERS
    assert sum(len(v) for _, v in layer_rows(rows(20))) == 20
    assert stability_chart.DPI * stability_chart.WIDTH_IN <= 1000
