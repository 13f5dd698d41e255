"""The ``cspace bench`` figure: error against run time, readable without the guide.

One column per scenario: on top the median error (length / exact optimum - 1; for SE(2)
and cars length / inscribed-disk lower bound - 1, an upper bound on the error) of the
solved runs with its 25-75 % band, below the success rate, both against the time
budget on log axes. When the runs measured their paths' clearance (every space but a
car's), a middle row shows the median ``min_clearance`` of the solved runs (25-75 %
band, linear axis: a clearance may be 0) against the same budgets. Tick labels are chosen here, not by matplotlib's log locator,
whose minor labels (``6x10^-2 4x10^-2 3x10^-2``) crowd a panel spanning less than a
decade: budgets get one tick each (thinned if many), errors get 1-2-5 ticks in plain
numbers. The legend sits under the figure and names every planner of the sweep,
saying which never solved a run (a planner without a single point on top would
otherwise vanish from the picture).

Rows are the bench's result rows (``scenario``, ``planner``, ``time_budget``,
``solved``, ``error``, optionally ``min_clearance``; others ignored), as ``results.json``
stores them.
"""
from __future__ import annotations

import math

ERROR_FLOOR = 1e-6  # errors below this are drawn at it (log axis); an exact 0 is essentially impossible
MAX_TICKS = 6  # labels per axis at most: more overlap on a 3.6-inch panel


def curves(rows: list[dict], field: str = "error") -> dict:
    """Per (scenario, planner): budgets, median / 25% / 75% of ``field`` over solved runs
    (those where it is a finite number), success rate.

    >>> r = [{"scenario": "s", "planner": "P", "time_budget": 1.0, "status": "ok", "solved": True, "error": e,
    ...       "min_clearance": 2 * e} for e in (0.1, 0.2, 0.3)]
    >>> curves(r)[("s", "P")]["median"], curves(r, "min_clearance")[("s", "P")]["median"]
    ([0.2], [0.4])
    """
    import numpy as np

    groups: dict = {}
    for r in rows:
        groups.setdefault((r["scenario"], r["planner"]), {}).setdefault(r["time_budget"], []).append(r)
    out = {}
    for key, by_t in groups.items():
        c = {"time": [], "median": [], "q25": [], "q75": [], "success": [], "proven": [], "runs": []}
        for t in sorted(by_t):
            rs = by_t[t]
            errs = [r[field] for r in rs if r["solved"] and _finite(r.get(field))]
            c["time"].append(t)
            c["runs"].append(len(rs))
            c["success"].append(sum(bool(r["solved"]) for r in rs) / len(rs))
            c["proven"].append(sum(proven_unsolvable(r) for r in rs) / len(rs))
            q = np.percentile(errs, [50, 25, 75]).tolist() if errs else [None] * 3
            c["median"].append(q[0])
            c["q25"].append(q[1])
            c["q75"].append(q[2])
        out[key] = c
    return out


def proven_unsolvable(row: dict) -> bool:
    """Did this run end with a proof that no path exists: its own ("proven unsolvable" in its
    message: a proof before sampling, the exact planners') or the exact reference's (a scene
    whose exact optimum is None)? Such a run is not a failure of its planner.

    >>> proven_unsolvable({"status": "ok", "solved": False, "message": "proven unsolvable before sampling: ..."})
    True
    >>> proven_unsolvable({"status": "ok", "solved": False, "reference": "optimum", "optimum": 2.0})
    False
    """
    if row.get("solved") or row.get("status") in ("crashed", "timeout"):
        return False
    return "proven unsolvable" in (row.get("message") or "") or (
        row.get("reference", "optimum") == "optimum" and "optimum" in row and row.get("optimum") is None)


def _finite(v) -> bool:
    """A number to take a median of (a clearance not measured is None, one without obstacles inf)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def has_clearance(rows: list[dict]) -> bool:
    """Whether any solved run measured its clearance (a car's runs do not): the figure's middle row.

    >>> has_clearance([{"solved": True, "min_clearance": None}]), has_clearance([{"solved": True, "min_clearance": 0.0}])
    (False, True)
    """
    return any(r.get("solved") and _finite(r.get("min_clearance")) for r in rows)


def thin(values: list[float], most: int = MAX_TICKS) -> list[float]:
    """At most ``most`` of the sorted ``values``, evenly spread, the first and last kept.

    >>> thin([0.01, 0.02, 0.03, 0.1, 0.2, 0.3, 1, 2, 3], 4)
    [0.01, 0.1, 0.3, 3]
    """
    vals = sorted(set(values))
    if len(vals) <= most:
        return vals
    step = (len(vals) - 1) / (most - 1)
    return [vals[round(i * step)] for i in range(most)]


def log_ticks(lo: float, hi: float, most: int = MAX_TICKS) -> list[float]:
    """Readable ticks for a log axis over [lo, hi]: the densest of 1-9, 1-2-5, 1-3 or decade
    steps that gives between two and ``most`` ticks (every k-th decade if even they are too many).

    >>> log_ticks(0.025, 0.07)
    [0.03, 0.04, 0.05, 0.06, 0.07]
    >>> log_ticks(0.004, 0.4)
    [0.005, 0.01, 0.02, 0.05, 0.1, 0.2]
    >>> log_ticks(1e-6, 10)
    [1e-06, 0.0001, 0.01, 1.0]
    """
    if not (0 < lo <= hi) or not math.isfinite(hi):
        return []
    k0, k1 = math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1
    ticks: list[float] = []
    for mantissas in ((1, 2, 3, 4, 5, 6, 7, 8, 9), (1, 2, 5), (1, 3), (1,)):
        # Rounded to 12 significant digits, so that 3 x 10^-2 is 0.03 and prints so.
        ticks = [float(f"{m * 10.0 ** k:.12g}") for k in range(k0, k1 + 1) for m in mantissas]
        ticks = [t for t in ticks if lo * (1 - 1e-9) <= t <= hi * (1 + 1e-9)]
        if 2 <= len(ticks) <= most:
            return ticks
    if len(ticks) > most:  # decades, every second (third ...) one
        return ticks[::math.ceil(len(ticks) / most)]
    # Not two nice numbers in range (a sliver of a decade): the ends, two digits each.
    return sorted({float(f"{lo:.2g}"), float(f"{hi:.2g}")})


def error_label(rows: list[dict], scen: str) -> str:
    """The error axis's label for ``scen``: against the exact optimum (translation), or
    against the inscribed-disk lower bound (SE(2), a car: rows with ``reference`` =
    ``lower_bound``), where the error drawn is an upper bound on the true one.

    >>> error_label([{"scenario": "s", "reference": "lower_bound"}], "s").splitlines()[0]
    'length / lower bound - 1'
    >>> error_label([{"scenario": "s", "reference": "optimum"}], "s").splitlines()[0]
    'length / optimum - 1'
    """
    if any(r.get("reference") == "lower_bound" for r in rows if r["scenario"] == scen):
        return "length / lower bound - 1\n(upper bound on the error; median, 25-75 %)"
    return "length / optimum - 1\n(median and 25-75 % of solved runs)"


def _set_log_ticks(axis, ticks: list[float]) -> None:
    """Put exactly these labelled ticks on a log axis (plain numbers), minor ticks unlabelled."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    axis.set_major_locator(FixedLocator(ticks))
    axis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def figure_error_vs_time(rows: list[dict]):
    """The Figure: per scenario, error (top), min clearance (middle, when measured) and
    success rate (bottom) against the budget."""
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["text.parse_math"] = False  # a scene's name is text, never mathtext ($...$)
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    cs = curves(rows)
    scens = list(dict.fromkeys(r["scenario"] for r in rows))
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    colors = {p: f"C{i % 10}" for i, p in enumerate(planners)}
    markers = {p: "osD^vP*X"[i % 8] for i, p in enumerate(planners)}
    # Hollow markers, larger for earlier planners: where curves coincide (several planners
    # at 0 % success) the markers nest and every colour still shows.
    n = len(planners)
    size = {p: 4.5 + 2.5 * min(n - 1 - i, 4) for i, p in enumerate(planners)}

    def style(p: str) -> dict:
        return {"color": colors[p], "marker": markers[p], "ms": size[p], "mfc": "none", "mew": 1.3, "lw": 1.4}

    clear = curves(rows, "min_clearance") if has_clearance(rows) else None
    ratios = [2, 1.5, 1] if clear else [2, 1]
    fig, axes = plt.subplots(len(ratios), len(scens), figsize=(3.8 * len(scens) + 0.8, 6.6 + 2.4 * bool(clear)),
                             squeeze=False, sharex="col", gridspec_kw={"height_ratios": ratios})
    budgets = sorted({r["time_budget"] for r in rows})
    for j, scen in enumerate(scens):
        top, bot = axes[0][j], axes[-1][j]
        if clear:
            lower = any(r.get("min_clearance_bound") == "lower" for r in rows if r["scenario"] == scen)
            _clearance_panel(axes[1][j], clear, scen, planners, style, colors, lower, first=j == 0)
        shown: list[float] = []
        for p in planners:
            c = cs.get((scen, p))
            if c is None:
                continue
            pts = [(t, m, a, b) for t, m, a, b in zip(c["time"], c["median"], c["q25"], c["q75"]) if m is not None]
            if pts:
                t, m, a, b = (list(v) for v in zip(*pts))
                fl = [max(v, ERROR_FLOOR) for v in m]
                lo, hi = [max(v, ERROR_FLOOR) for v in a], [max(v, ERROR_FLOOR) for v in b]
                top.plot(t, fl, "-", **style(p))
                top.fill_between(t, lo, hi, color=colors[p], alpha=0.2, lw=0)
                shown += lo + hi + fl
            bot.plot(c["time"], c["success"], "-", **style(p))
        top.set_xscale("log")
        top.set_yscale("log")
        if shown:
            lo, hi = min(shown), max(shown)
            top.set_ylim(lo / 1.3, hi * 1.3)
            _set_log_ticks(top.yaxis, log_ticks(lo / 1.3, hi * 1.3))
        else:
            top.set_ylim(ERROR_FLOOR * 10, 1.0)
            _set_log_ticks(top.yaxis, log_ticks(ERROR_FLOOR * 10, 1.0))
            impossible = all(proven_unsolvable(r) for r in rows if r["scenario"] == scen)
            top.text(0.5, 0.5, "proven unsolvable:\nno path exists" if impossible else "no run solved",
                     transform=top.transAxes, ha="center", va="center", color="0.4")
        top.set_title(scen)
        top.grid(True, which="major", alpha=0.3)
        top.tick_params(labelbottom=False)
        bot.set_xscale("log")
        _set_log_ticks(bot.xaxis, thin(budgets))
        if len(budgets) == 1:  # one budget: a log axis of zero width would have no room
            bot.set_xlim(budgets[0] / 2, budgets[0] * 2)
        bot.set_ylim(-0.05, 1.05)
        bot.set_yticks([0, 0.5, 1], ["0", "50 %", "100 %"])
        bot.grid(True, which="major", alpha=0.3)
        bot.set_xlabel("time budget (s)")
        if j == 0 or error_label(rows, scen) != error_label(rows, scens[0]):  # said again where it changes
            top.set_ylabel(error_label(rows, scen))
        if j == 0:
            bot.set_ylabel("runs solved")
    never = {p for p in planners if not any(r["solved"] for r in rows if r["planner"] == p)}
    handles = [Line2D([], [], **{**style(p), "ms": 7},
                      label=p + (" (no run solved)" if p in never else "")) for p in planners]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(planners), 6), fontsize=9, frameon=False,
               bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    return fig


def _clearance_panel(ax, clear: dict, scen: str, planners: list, style, colors: dict, lower: bool,
                     first: bool) -> None:
    """Median min clearance of the solved runs (25-75 % band) per planner against the budget.

    Linear axis: a clearance may be 0 (a path that touches). Ticks are plain numbers, at
    most MAX_TICKS (matplotlib's scalar formatter would move a common factor into an
    offset label, which reads as part of the number).
    """
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    shown = False
    for p in planners:
        c = clear.get((scen, p))
        pts = [(t, m, a, b) for t, m, a, b in zip(c["time"], c["median"], c["q25"], c["q75"])
               if m is not None] if c else []
        if pts:
            t, m, a, b = (list(v) for v in zip(*pts))
            ax.plot(t, m, "-", **style(p))
            ax.fill_between(t, a, b, color=colors[p], alpha=0.2, lw=0)
            shown = True
    if not shown:  # a car's scene (or no solved run): say so, no scale to read
        ax.text(0.5, 0.5, "no clearance measured", transform=ax.transAxes, ha="center", va="center", color="0.4")
        ax.set_yticks([])
    else:
        ax.yaxis.set_major_locator(MaxNLocator(nbins=MAX_TICKS - 1, min_n_ticks=2))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
    if lower:  # SE(2): the measure is a certified lower bound, said where it is read
        ax.text(0.02, 0.97, "certified lower bound", transform=ax.transAxes, ha="left", va="top", fontsize=8,
                color="0.4")
    ax.grid(True, which="major", alpha=0.3)
    ax.tick_params(labelbottom=False)
    if first:
        ax.set_ylabel("min clearance\n(median and 25-75 %)")


def plot_error_vs_time(rows: list[dict], path: str) -> None:
    """Median error (25-75 % band), median min clearance (when measured) and success rate
    against the time budget, one column per scenario."""
    import matplotlib.pyplot as plt

    from ..output import atomic_path

    fig = figure_error_vs_time(rows)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
