"""Regenerate every figure of the user guide (docs/guide.md) from the bundled scenarios.

One command, no hand-edited pictures:

    python scripts/make_figures.py [--out docs/figures] [--only basic,families,circles,...] [--list]

Each figure is a plan with a fixed seed (``cspace plan --plot``), a C-space picture
(``cspace show --plot``), the exact shortest path, the circles multi-query run, a small
``cspace bench`` sweep's error-against-run-time figure (drawn by
:mod:`planners.pictures.bench_figure` from the sweep's results.json), or the stability chart. PNGs
are written atomically (temporary file, then rename; :mod:`planners.pictures.plot` does it for
the pictures it draws), so an interrupted run never leaves a half-written picture.
``--only`` takes figure names or group names (see ``--list``); positional names do the same
(``python scripts/make_figures.py basic_plan maze_cspace``).

Deterministic output: the pictures of :mod:`planners.pictures.plot` are saved here at their own
figure size and a fixed dpi, without ``bbox_inches="tight"`` (which sized each PNG by its title's
and legend's text, so a changed label changed the PNG's pixel size); every plan has a fixed seed.
Each such PNG records its legend entries in its metadata (the PNG text key ``Legend``, one
label a line: :func:`legend_labels` reads it back), so tests/project/test_docs_drift.py can compare a fresh
drawing with the committed one. The whole set takes
well under two minutes on a laptop core; the acceptance sweep behind
``error_vs_time.png`` takes about ten and runs only when named (``--only acceptance``).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass
from typing import Callable

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIOS = os.path.join(ROOT, "scenarios")

# One picture per scenario family (plan and C-space), with the seed each plan uses.
FAMILIES = ("maze", "bug_trap", "narrow_passage", "random_polygons", "disks", "office", "combs", "parts", "theta")
SEED = 1
DPI = 130  # the pictures of planners.pictures.plot (the bench, slab and stability charts keep their own 110)
LEGEND_KEY = "Legend"  # PNG text key holding the legend entries, one a line
LIBRARIES_KEY = "Libraries"  # numpy, shapely and matplotlib versions: the same ones draw the same pixels


@dataclass
class Figure:
    """One PNG of the guide: its file name, its group and how to draw it."""

    name: str
    group: str
    what: str
    draw: Callable[[str], str]  # output path -> one-line summary


def figure_legend(fig) -> list[str]:
    """The legend entries of a matplotlib Figure (figure legends, then each axis's), in order."""
    labels = []
    for leg in list(fig.legends) + [ax.get_legend() for ax in fig.axes]:
        if leg is not None:
            labels += [t.get_text() for t in leg.get_texts()]
    return labels


def save_fixed(fig, out: str, fmt: str | None = None) -> None:
    """Write ``fig`` atomically at its own size and :data:`DPI` (no tight bounding box, so the
    pixel size never depends on the text drawn), its legend entries in the PNG metadata; close it."""
    from planners.output import atomic_path
    from planners.pictures.plot import mpl

    plt = mpl()[0]
    fmt = fmt or os.path.splitext(out)[1].lstrip(".").lower() or "png"
    fig.tight_layout()
    _fit_inside(fig)
    meta = {LEGEND_KEY: "\n".join(figure_legend(fig)), LIBRARIES_KEY: libraries()} if fmt == "png" else None
    with atomic_path(out) as tmp:
        fig.savefig(tmp, format=fmt, dpi=DPI, metadata=meta)
    plt.close(fig)


def _fit_inside(fig, margin: float = 0.04) -> None:
    """Shrink the subplot area until everything drawn (labels, legend, a zoom inset beside the
    axis) lies inside the fixed canvas: tight_layout alone may leave an inset's overhang out."""
    W, H = fig.get_size_inches()
    for _ in range(4):
        bb = fig.get_tightbbox(fig.canvas.get_renderer())
        over = (max(0.0, margin - bb.x0) / W, max(0.0, bb.x1 - W + margin) / W,
                max(0.0, margin - bb.y0) / H, max(0.0, bb.y1 - H + margin) / H)
        if not any(over):
            return
        sp = fig.subplotpars
        left, bottom = min(sp.left + over[0], 0.4), min(sp.bottom + over[2], 0.4)
        right, top = max(sp.right - over[1], left + 0.2), max(sp.top - over[3], bottom + 0.2)
        if (left, right, bottom, top) == (sp.left, sp.right, sp.bottom, sp.top):
            return  # cannot fit (a title wider than the page): leave it as it is
        fig.subplots_adjust(left=left, right=right, bottom=bottom, top=top)


class fixed_size_saves:
    """While active, :mod:`planners.pictures.plot` saves through :func:`save_fixed` (its
    ``plot_result``/``plot_scene`` and the CLI's ``--plot`` look ``save`` up at call time)."""

    def __enter__(self):
        import planners.pictures.plot as plot

        self._plot, self._saved = plot, plot.save
        plot.save = save_fixed
        return self

    def __exit__(self, *exc):
        self._plot.save = self._saved
        return False


def libraries() -> str:
    """The versions of the libraries a drawing's pixels depend on (its geometry's and its renderer's).

    >>> libraries().startswith("numpy ")
    True
    """
    import matplotlib
    import numpy
    import shapely

    return f"numpy {numpy.__version__}, shapely {shapely.__version__}, matplotlib {matplotlib.__version__}"


def drawn_with(png: str) -> str | None:
    """The libraries recorded in a PNG by :func:`save_fixed` (None when it has none recorded)."""
    from PIL import Image

    with Image.open(png) as im:
        return im.info.get(LIBRARIES_KEY)


def legend_labels(png: str) -> list[str] | None:
    """The legend entries recorded in a PNG by :func:`save_fixed` (None when it has none recorded)."""
    from PIL import Image

    with Image.open(png) as im:
        text = im.info.get(LEGEND_KEY)
    return None if text is None else (text.split("\n") if text else [])


def png_size(png: str) -> tuple[int, int]:
    """(width, height) in pixels of a PNG, read from its header."""
    import struct

    with open(png, "rb") as fh:
        head = fh.read(24)
    return struct.unpack(">II", head[16:24])


def _scenario(name: str) -> str:
    return os.path.join(SCENARIOS, f"{name}.toml")


def plan_figure(scenario: str, planner: str | None = None, seed: int = SEED) -> Callable[[str], str]:
    """A plan of the scenario with its own [planner] defaults (or ``planner``), as ``cspace plan --plot``."""

    def draw(out: str) -> str:
        from planners import plan
        from planners.pictures.plot import plot_result

        res = plan(_scenario(scenario), planner=planner, seed=seed)
        plot_result(res, out)
        state = f"length {res.length:.6g}" if res.solved else "not solved"
        return f"{res.planner} seed {res.seed}: {state}"

    return draw


def se2_plan_figure(scenario: str, seed: int = 0, animate: bool = False, folder: str = "se2",
                    planner: str | None = None) -> Callable[[str], str]:
    """A rotating robot's plan (scenarios/se2/, or a car's in scenarios/car/ with
    ``folder="car"``), its footprint along the path; with ``animate`` also the GIF of
    ``cspace plan --animate`` beside the PNG (same name, .gif). ``planner``: as the guide's
    command names it (None: the scene's own, or the default)."""

    def draw(out: str) -> str:
        from planners.pictures.animate import animate_path
        from planners import plan
        from planners.pictures.plot import plot_result

        res = plan(os.path.join(SCENARIOS, folder, f"{scenario}.toml"), seed=seed, planner=planner)
        plot_result(res, out)
        if animate and res.solved:
            animate_path(res, os.path.splitext(out)[0] + ".gif")
        state = f"length {res.length:.6g}" if res.solved else "not solved"
        return f"{res.planner} seed {res.seed}: {state}" + (" (+ GIF)" if animate and res.solved else "")

    return draw


def se2_slab_figure(scenario: str, theta: float) -> Callable[[str], str]:
    """One angle slab's C-space of a rotating robot, as ``cspace show --space se2 --theta``."""

    def draw(out: str) -> str:
        from planners.cli import main

        code = main(["show", os.path.join(SCENARIOS, "se2", f"{scenario}.toml"), "--theta", repr(theta),
                     "--plot", out])
        return f"slab of theta {theta:g} (exit {code})"

    return draw


def slab_pair_figure(scenario: str, a: float, b: float, c: float) -> Callable[[str], str]:
    """The exact SE(2) planner's slab graph for the two slabs [a, b] and [b, c]."""

    def draw(out: str) -> str:
        from cspace.io.load import load_scenario
        from planners.pictures.slab_pair import plot_slab_pair

        plot_slab_pair(load_scenario(os.path.join(SCENARIOS, "se2", f"{scenario}.toml")), a, b, c, out)
        return f"slabs [{a:.4g}, {b:.4g}] and [{b:.4g}, {c:.4g}]"

    return draw


def cspace_figure(scenario: str) -> Callable[[str], str]:
    """Workspace, C-obstacles and their convex pieces, as ``cspace show --plot``."""

    def draw(out: str) -> str:
        from cspace.translation.cspace import CSpace
        from cspace.io.load import load_scenario
        from planners.pictures.plot import plot_scene

        sc = load_scenario(_scenario(scenario))
        cs = CSpace.from_scenario(sc)
        plot_scene(sc, cs, out)
        return f"{len(cs.pieces)} C-obstacle pieces"

    return draw


def circles_figure(time_limit: float = 1.0, seed: int = 0) -> Callable[[str], str]:
    """OMPL's circles problem: all 100 queries at ``time_limit`` each, on one C-space."""

    def draw(out: str) -> str:
        from planners import plan
        from planners.pictures.plot import plot_result

        res = plan(os.path.join(SCENARIOS, "ompl", "circles.toml"), time=time_limit, seed=seed, all_queries=True)
        plot_result(res, out)
        solved = [q for q in res.queries if q.solved]
        mean = sum(q.length for q in solved) / max(len(solved), 1)
        return f"{len(solved)}/{len(res.queries)} solved, mean length {mean:.4g}"

    return draw


# The guide's ROS map: the robot, start and goal its commands use.
MAP = os.path.join(SCENARIOS, "maps", "office.yaml")
MAP_ROBOT = os.path.join(SCENARIOS, "maps", "robot.toml")
MAP_START, MAP_GOAL = (0.5, 0.5), (9.5, 6.5)


def map_figure(seed: int = SEED) -> Callable[[str], str]:
    """The ROS map imported and planned, as ``cspace plan office.yaml --robot robot.toml --plot``."""

    def draw(out: str) -> str:
        from cspace.io.importers.imported import ImportOptions, load_imported
        from planners.cli.imports import read_robot
        from planners import plan
        from planners.pictures.plot import plot_result

        opts = ImportOptions(robot=read_robot(MAP_ROBOT), start=MAP_START, goal=MAP_GOAL)
        res = plan(load_imported(MAP, options=opts), seed=seed)
        plot_result(res, out)
        return f"{res.planner} seed {res.seed}: " + (f"length {res.length:.6g}" if res.solved else "not solved")

    return draw


def stability_figure(out: str) -> str:
    """The stability catalogue's chart, as ``cspace stability --plot``."""
    from planners.pictures.stability_chart import plot_stability
    from planners.stability import catalogue as stability

    rows = stability.run_all()
    plot_stability(rows, out)
    passed = sum(1 for r in rows if r["passed"])
    return f"{passed}/{len(rows)} cases pass"


BENCH_ARGS = ["scenarios/bug_trap.toml", "--planners", "RRTConnect,RRTstar", "--times", "0.03,0.1,0.3",
              "--runs", "5", "--workers", "2", "--quiet", "--no-plot"]


def bench_figure(args: list[str] = BENCH_ARGS) -> Callable[[str], str]:
    """``cspace bench ARGS``'s error-against-run-time figure, drawn from its results.json."""

    def draw(out: str) -> str:
        import json
        import shutil
        import subprocess
        import tempfile

        from planners.pictures.bench_figure import plot_error_vs_time

        work = tempfile.mkdtemp(prefix="cspace-bench-")
        try:
            cmd = [sys.executable, "-c", "from planners.cli import console; console()", "bench", *args, "--out", work]
            proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=3600)
            results = os.path.join(work, "results.json")
            if proc.returncode != 0 or not os.path.exists(results):
                raise RuntimeError(f"cspace bench failed (exit {proc.returncode}): {proc.stderr.strip()[-500:]}")
            with open(results) as fh:
                rows = json.load(fh)["rows"]
            plot_error_vs_time(rows, out)  # written atomically
            return f"{len(rows)} runs, {sum(bool(r['solved']) for r in rows)} solved"
        finally:
            shutil.rmtree(work, ignore_errors=True)

    return draw


# The acceptance sweep of the guide's error_vs_time.png: 4 scenarios x 4 planners x 5 budgets x 10
# runs, 800 runs (about ten minutes on two workers). Drawn only when named: --only acceptance.
ACCEPTANCE_ARGS = ["scenarios/basic.toml", "scenarios/maze.toml", "scenarios/narrow_passage.toml",
                   "scenarios/bug_trap.toml", "--runs", "10", "--workers", "2", "--quiet", "--no-plot"]


LONG_GROUPS = ("acceptance", "view", "arena")  # view: needs chromium and plotly; arena: chromium and plannerarena


def figures() -> list[Figure]:
    """Every figure the guide uses, in the guide's order."""
    out = [
        Figure("basic_plan", "basic", "first plan: basic.toml, RRTConnect", plan_figure("basic")),
        Figure("basic_cspace", "basic", "C-space of basic.toml", cspace_figure("basic")),
        Figure("basic_exact", "basic", "exact shortest path of basic.toml", plan_figure("basic", planner="exact")),
        Figure("clearance_plan", "clearance", "clearance.toml: the exact path keeping a 0.3 margin",
               plan_figure("clearance")),
        Figure("u_robot_cspace", "basic", "C-space of u_robot.toml (a non-convex robot)", cspace_figure("u_robot")),
    ]
    for fam in FAMILIES:
        out.append(Figure(f"{fam}_cspace", "families", f"C-space of {fam}.toml", cspace_figure(fam)))
        out.append(Figure(f"{fam}_plan", "families", f"plan of {fam}.toml", plan_figure(fam)))
    out.append(Figure("se2_piano_corridor", "se2", "SE(2): a bar round a corner (GIF beside it)",
                      se2_plan_figure("piano_corridor", animate=True)))
    out.append(Figure("se2_tee_slot", "se2", "SE(2): a T through a slot", se2_plan_figure("tee_slot")))
    out.append(Figure("se2_car_maze", "se2", "SE(2): a car-shaped body through a maze", se2_plan_figure("car_maze")))
    out.append(Figure("se2_tee_slot_slab", "se2", "SE(2): the slab C-space of theta = pi/2",
                      se2_slab_figure("tee_slot", 1.5707963267948966)))
    out.append(Figure("plank_corner_tight", "se2exact", "SE(2) exact: a plank round a corner, 1 % of room",
                      se2_plan_figure("plank_corner_tight", planner="exact")))
    out.append(Figure("door_tight", "se2exact", "SE(2) exact: a box through a door 1 % wider than it",
                      se2_plan_figure("door_tight", planner="exact")))
    out.append(Figure("bug_trap_l_slabs", "se2exact", "SE(2) exact: the slab graph of the L in the trap",
                      slab_pair_figure("bug_trap_l", -0.25 * math.pi, 0.0, 0.25 * math.pi)))
    out.append(Figure("car_parking", "car", "car: parallel parking, Reeds-Shepp (GIF beside it)",
                      se2_plan_figure("parking", animate=True, folder="car")))
    out.append(Figure("car_u_turn", "car", "car: a three-point turn in a narrow street", se2_plan_figure("u_turn", folder="car")))
    out.append(Figure("car_loading_dock", "car", "car: backing into a loading bay", se2_plan_figure("loading_dock", folder="car")))
    out.append(Figure("car_maze", "car", "car: Dubins through a maze", se2_plan_figure("maze", folder="car")))
    out.append(Figure("car_parallel_tight", "car", "car: parallel parking with 10 % slack (auto: Laumond's curves)",
                      se2_plan_figure("parallel_tight", folder="car")))
    out.append(Figure("car_dead_end_alley", "car", "car: turning round at the end of a dead-end alley",
                      se2_plan_figure("dead_end_alley", folder="car")))
    out.append(Figure("car_garage_reverse", "car", "car: a garage entered in reverse",
                      se2_plan_figure("garage_reverse", folder="car")))
    out.append(Figure("car_u_turn_cusps", "car", "car: a U-turn with two cusps",
                      se2_plan_figure("u_turn_cusps", folder="car")))
    out.append(Figure("map_office", "maps", "a ROS occupancy map imported and planned", map_figure()))
    out.append(Figure("circles_queries", "circles", "OMPL circles: 100 queries, 1 s each", circles_figure()))
    out.append(Figure("bench_bug_trap", "bench", "cspace bench: bug_trap, RRTConnect vs RRTstar", bench_figure()))
    out.append(Figure("error_vs_time", "acceptance", "cspace bench: the acceptance sweep (4 scenarios, 4 planners)",
                      bench_figure(ACCEPTANCE_ARGS)))
    out.append(Figure("stability", "stability", "stability catalogue", stability_figure))
    out.append(Figure("view_bar_door", "view", "cspace view: bar_door's offline page in headless Chromium", view_figure))
    out.append(Figure("planner_arena", "arena", "Planner Arena on a cspace bench --db database, in headless Chromium",
                      arena_figure))
    return out


def view_figure(out: str) -> str:
    """scripts/make_view_screenshots.py's screenshot of bar_door's ``cspace view`` page."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_view_screenshots",
                                                  os.path.join(ROOT, "scripts", "make_view_screenshots.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.bar_door_screenshot(out)
    return "the page drawn by headless Chromium, the bar half way through the door"


def arena_figure(out: str) -> str:
    """scripts/make_arena_screenshot.py's screenshot of Planner Arena showing a small sweep's database."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_arena_screenshot",
                                                  os.path.join(ROOT, "scripts", "make_arena_screenshot.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.arena_screenshot(out)


def select(all_figs: list[Figure], only: str | None) -> list[Figure]:
    """The figures named by ``--only`` (names or groups, comma-separated); when None, all but
    the long ones (group ``acceptance``)."""
    if not only:
        return [f for f in all_figs if f.group not in LONG_GROUPS]
    keys = {k.strip() for k in only.split(",") if k.strip()}
    known = {f.name for f in all_figs} | {f.group for f in all_figs}
    unknown = keys - known
    if unknown:
        raise SystemExit(f"error: --only: unknown figure or group: {', '.join(sorted(unknown))} "
                         f"(see --list)")
    return [f for f in all_figs if f.name in keys or f.group in keys]


def draw_figure(fig: Figure, path: str) -> str:
    """Draw one figure to ``path`` at its fixed size; returns its one-line summary. A PNG drawn by
    a routine of its own (not :func:`save_fixed`) gets the libraries recorded afterwards."""
    with fixed_size_saves():
        summary = fig.draw(path)
    if path.endswith(".png") and os.path.exists(path) and drawn_with(path) is None:
        from PIL import Image, PngImagePlugin

        with Image.open(path) as im:
            im.load()
            info = PngImagePlugin.PngInfo()
            for k, v in im.info.items():
                if isinstance(v, str):
                    info.add_text(k, v)
            info.add_text(LIBRARIES_KEY, libraries())
            from planners.output import atomic_path

            with atomic_path(path) as tmp:
                im.save(tmp, format="png", pnginfo=info)
    return summary


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "figures"), help="folder for the PNGs")
    ap.add_argument("--only", help="comma-separated figure names or groups (basic, families, se2, maps, circles, bench, "
                                   "stability; acceptance, the long sweep, only when named)")
    ap.add_argument("--list", action="store_true", help="list the figures and exit")
    ap.add_argument("names", nargs="*", help="figure names or groups (as --only)")
    args = ap.parse_args(argv)
    if args.names:
        args.only = ",".join(filter(None, [args.only, *args.names]))
    figs = select(figures(), args.only)
    if args.list:
        for f in figs if args.only else figures():
            print(f"{f.name:<24} {f.group:<10} {f.what}" + (" (only when named)" if f.group in LONG_GROUPS else ""))
        return 0
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from benchutil import check_out

    check_out(args.out, (), "--out", folder=True)  # before any work: created if missing, and writable
    t_all = time.perf_counter()
    for f in figs:
        path = os.path.join(args.out, f"{f.name}.png")
        t = time.perf_counter()
        note = draw_figure(f, path)
        w, h = png_size(path)
        print(f"{path}: {f.what}; {note} ({w}x{h} px, {time.perf_counter() - t:.1f} s)", flush=True)
    print(f"{len(figs)} figures in {time.perf_counter() - t_all:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
