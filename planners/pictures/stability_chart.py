"""The stability catalogue's chart: each layer's cases as a strip of run times, coloured by
whether the case's guarantee held, the failures named.

One row per layer (at most a dozen, whatever the number of cases), so the picture keeps one
size and its labels stay readable: the catalogue's 133 cases once made a 2633-pixel strip of
6-point names. Each case's name and time are in ``--json``; the chart shows where the time goes
and which guarantee failed.
"""
from __future__ import annotations

from ..output import atomic_path

WIDTH_IN, ROW_IN, BASE_IN = 8.0, 0.42, 1.5  # the figure's width, and its height per layer and beyond
DPI = 110


def layer_rows(rows: list[dict]) -> list[tuple[str, list[dict]]]:
    """The cases grouped by layer, in the catalogue's order of first appearance.

    >>> [(k, len(v)) for k, v in layer_rows([{"layer": "a"}, {"layer": "b"}, {"layer": "a"}])]
    [('a', 2), ('b', 1)]
    """
    groups: dict[str, list[dict]] = {}
    for r in rows:
        groups.setdefault(str(r.get("layer") or r["case"].split("_")[0]), []).append(r)
    return list(groups.items())


def plot_stability(rows: list[dict], path: str) -> None:
    """Per layer, a strip of its cases' times (log scale), green where the guarantee holds and red
    where it failed (each failure named beside its point); matplotlib imported here only."""
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["text.parse_math"] = False  # a scene's name is text, never mathtext ($...$)
    import matplotlib.pyplot as plt
    import numpy as np

    groups = layer_rows(rows)
    fig, ax = plt.subplots(figsize=(WIDTH_IN, BASE_IN + ROW_IN * max(len(groups), 1)))
    jitter = np.random.default_rng(0)  # fixed: the same catalogue draws the same picture
    for y, (layer, cases) in enumerate(groups):
        times = np.array([max(float(r["time_ms"]), 1e-3) for r in cases])
        ok = np.array([bool(r["passed"]) for r in cases])
        dy = jitter.uniform(-0.18, 0.18, len(cases))
        ax.scatter(times[ok], y + dy[ok], s=18, color="tab:green", alpha=0.75, linewidths=0)
        ax.scatter(times[~ok], y + dy[~ok], s=36, color="tab:red", marker="X")
        for r, t, d in zip(cases, times, dy):
            if not r["passed"]:
                ax.annotate(r["case"], (t, y + d), xytext=(4, 3), textcoords="offset points", fontsize=7, color="tab:red")
    ax.set_yticks(range(len(groups)), [f"{layer}  {sum(r['passed'] for r in c)}/{len(c)}" for layer, c in groups],
                  fontsize=9)
    ax.set_ylim(len(groups) - 0.5, -0.5)
    ax.set_xscale("log")
    from matplotlib.ticker import FuncFormatter

    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))  # (mathtext is off: no 10^k labels)
    ax.set_xlabel("time of the layer call (ms, log scale); a point per case")
    ax.grid(axis="x", which="major", alpha=0.3)
    from matplotlib.lines import Line2D

    ax.legend(handles=[Line2D([], [], marker="o", ls="", color="tab:green", label="guarantee holds"),
                       Line2D([], [], marker="X", ls="", color="tab:red", label="FAILED (named)")],
              loc="lower right", fontsize=8)
    ax.set_title(f"cspace stability: {sum(r['passed'] for r in rows)}/{len(rows)} cases pass "
                 f"(layer: cases that pass / cases)", fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    plt.close(fig)
