"""The stability catalogue's chart: run time per case, coloured by whether its guarantee held."""
from __future__ import annotations

from ..output import atomic_path


def plot_stability(rows: list[dict], path: str) -> None:
    """Bar chart of run times per case, coloured by pass/fail (matplotlib imported here only)."""
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["text.parse_math"] = False  # a scene's name is text, never mathtext ($...$)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(max(8, 0.18 * len(rows)), 5))
    times = [max(r["time_ms"], 1e-3) for r in rows]
    ax.bar(range(len(rows)), times, color=["tab:green" if r["passed"] else "tab:red" for r in rows])
    ax.set_yscale("log")
    ax.set_xticks(range(len(rows)), [r["case"] for r in rows], rotation=90, fontsize=6)
    ax.set_ylabel("time of the layer call (ms)")
    ax.set_xlabel("case (its name begins with its layer)")
    from matplotlib.patches import Patch

    ax.legend(handles=[Patch(color="tab:green", label="guarantee holds"), Patch(color="tab:red", label="FAILED")],
              loc="upper left", fontsize=8)
    ax.set_title(f"cspace stability: {sum(r['passed'] for r in rows)}/{len(rows)} cases pass")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
