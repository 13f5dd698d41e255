"""The committed figures and the guide's quoted outputs are what the scripts make now (issue 39,
item 11: docs drift).

* Figures: every figure scripts/make_figures.py draws by default (a few cheap ones in the quick
  pass, the rest in the slow one) is drawn into a temporary folder and compared with the
  committed PNG of docs/figures: the same pixel size (the script saves at a fixed figure size and
  dpi, never a tight bounding box), the same legend entries (the script records them in each
  PNG's metadata, key ``Legend``) and, but for the figures of measured times, the same pixels (at
  most 0.1 % differing) when drawn with the libraries the PNG records (key ``Libraries``). A committed picture that is stale fails here: rerun
  ``python scripts/make_figures.py --only NAME``.
* Quoted outputs: every ```text block of docs/guide.md that shows what a command prints is marked
  ``<!-- output: COMMAND -->``; scripts/make_guide_outputs.py runs the command and each quoted line
  must match a fresh one: lengths, counts and bytes to the printed digits, times within an order
  of magnitude (``loose`` blocks: the shape only). The numbers the prose quotes (PROSE there) are
  checked against the same runs. The slow blocks (stability, bench) run with CSPACE_DOCS_SLOW=1.
  On drift: ``python scripts/make_guide_outputs.py --write`` and edit the prose it names.
"""
from __future__ import annotations

import importlib.util
import os
import re
import sys

import pytest

from conftest import ROOT

FIGURES = os.path.join(ROOT, "docs", "figures")

# Cheap (well under a second each) and deterministic (fixed seeds, no time-limited search that
# could end elsewhere): the first plan, its C-space, and the clearance plan (its zoom inset).
CHEAP = ("basic_plan", "basic_cspace", "clearance_plan")


def load(name: str):
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, os.path.join(ROOT, "scripts", f"{name}.py"))
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod  # dataclasses look their module up
        spec.loader.exec_module(mod)
    return sys.modules[name]


def make_figures():
    if "make_figures" not in sys.modules:
        spec = importlib.util.spec_from_file_location("make_figures", os.path.join(ROOT, "scripts", "make_figures.py"))
        mod = importlib.util.module_from_spec(spec)
        sys.modules["make_figures"] = mod  # dataclasses look their module up
        spec.loader.exec_module(mod)
    return sys.modules["make_figures"]


# Figures whose content depends on measured times (a bench's run times, the catalogue's call
# times): their size is checked, not their pixels.
TIMED = {"bench_bug_trap": "run times of a bench sweep", "stability": "each case's measured time"}


def drawn_figures() -> list[str]:
    """Every figure ``python scripts/make_figures.py`` draws by default (the long groups aside)."""
    mf = make_figures()
    return [f.name for f in mf.figures() if f.group not in mf.LONG_GROUPS]


def differing_pixels(a: str, b: str) -> float:
    """The share of pixels of two same-sized PNGs whose colour differs by more than 40 of 255 in
    some channel (a changed path, label, number or shape; not antialiasing noise)."""
    import matplotlib.image as mpimg
    import numpy as np

    x, y = mpimg.imread(a)[..., :3], mpimg.imread(b)[..., :3]
    return float((np.abs(x.astype(float) - y.astype(float)).max(axis=2) > 40 / 255).mean())


@pytest.mark.parametrize("name", [n if n in CHEAP else pytest.param(n, marks=pytest.mark.slow) for n in drawn_figures()])
def test_committed_figure_matches_a_fresh_drawing(name, tmp_path):
    mf = make_figures()
    fig = {f.name: f for f in mf.figures()}[name]
    fresh = str(tmp_path / f"{name}.png")
    mf.draw_figure(fig, fresh)
    committed = os.path.join(FIGURES, f"{name}.png")
    rerun = f"rerun python scripts/make_figures.py --only {name}"
    assert mf.png_size(fresh) == mf.png_size(committed), (
        f"{name}.png: committed at {mf.png_size(committed)} px, drawn now at {mf.png_size(fresh)}: {rerun}")
    now, then = mf.legend_labels(fresh), mf.legend_labels(committed)
    assert then == now, f"{name}.png: committed legend {then}, drawn now {now}: {rerun}"
    # The same scene, seed, code and libraries draw the same picture (other numpy or shapely
    # versions, as the CI's lowest pins, may round a path a little differently: size and legend then).
    assert mf.drawn_with(committed) or name in TIMED, f"{name}.png records no libraries: {rerun}"
    if name not in TIMED and mf.drawn_with(committed) == mf.libraries():
        share = differing_pixels(fresh, committed)
        assert share <= 1e-3, f"{name}.png: {100 * share:.2f} % of its pixels differ from a fresh drawing: {rerun}"


def test_first_plan_shows_the_closest_approach():
    # The guide describes the star at the closest approach on the plan pictures.
    labels = make_figures().legend_labels(os.path.join(FIGURES, "basic_plan.png"))
    assert labels and any(s.startswith("closest approach") for s in labels), labels


def test_size_does_not_follow_the_text(tmp_path):
    # The same scene with a longer title and legend label: the same pixel size (no tight bbox).
    mf = make_figures()
    from cspace.io.load import load_scenario
    from cspace.translation.cspace import CSpace
    from planners.pictures.plot import figure_scene

    sc = load_scenario(os.path.join(ROOT, "scenarios", "basic.toml"))
    cs = CSpace.from_scenario(sc)
    sizes = []
    for k, title in enumerate(("short", "a longer title " * 3)):
        fig = figure_scene(sc, cs, title=title)
        fig.axes[0].get_legend().get_texts()[0].set_text("x" * (5 + 40 * k))
        out = str(tmp_path / f"{k}.png")
        mf.save_fixed(fig, out)
        sizes.append(mf.png_size(out))
    assert sizes[0] == sizes[1]


# ---------------------------------------------------------------- quoted outputs

GUIDE_OUT = load("make_guide_outputs")
BLOCKS = GUIDE_OUT.blocks()
RUN_SLOW = os.environ.get("CSPACE_DOCS_SLOW") == "1"
# ```text blocks that are not a command's output, or whose command is not one to run.
UNMARKED = {
    "s.toml: colour: unknown field": "messages of faulty scenario files (tests/io/test_messages.py checks them)",
    'pip install -e ".[io]"': "commands, shown as text: they need an OMPL.app checkout",
    "cspace plan ../bench-mr/": "commands, shown as text: they need a Bench-MR checkout (tests/io/test_import_svg.py "
                                "runs the format on files of its own)",
    "dask scheduler": "commands, shown as text: servers on several machines (tests/bench/test_bench_cluster.py "
                      "runs `--scheduler` on a LocalCluster)",
}


def test_every_quoted_output_is_marked():
    with open(GUIDE_OUT.GUIDE, encoding="utf-8") as fh:
        text = fh.read()
    assert len(BLOCKS) >= 10
    for m in re.finditer(r"^```text\n(.*?)^```", text, re.S | re.M):
        body = m.group(1)
        marked = text[:m.start()].endswith("-->\n") and "<!-- output: " in text[:m.start()].rsplit("\n", 2)[-2]
        synopsis = re.match(r"cspace [a-z-]+ \[-h\]", body)
        listed = any(body.startswith(k) for k in UNMARKED)
        line = text.count("\n", 0, m.start()) + 1
        assert marked or synopsis or listed, f"guide.md:{line}: a quoted output with no <!-- output: ... --> marker"


@pytest.mark.parametrize("block", BLOCKS, ids=[f"guide.md:{b.line_no}" for b in BLOCKS])
def test_quoted_output_matches_a_fresh_run(block):
    if block.slow and not RUN_SLOW:
        pytest.skip("slow (CSPACE_DOCS_SLOW=1 runs it)")
    from cspace.compiled import fastpath

    if not fastpath.compiled():  # the pure path's grids are coarser: other counters, the same answers
        pytest.skip("the guide quotes the compiled fast path's counters (grid cells, exact checks)")
    GUIDE_OUT.run(block, timeout=300)
    with open(GUIDE_OUT.GUIDE, encoding="utf-8") as fh:
        text = fh.read()
    problems = GUIDE_OUT.drift(block) + GUIDE_OUT.prose_drift(text, [block])
    assert problems == [], "\n".join(problems) + "\n(python scripts/make_guide_outputs.py --write)"


def test_the_checks_see_drift():
    # Without running anything: a stale length, a stale time and a stale prose time are caught.
    b = GUIDE_OUT.Block(commands=["cspace plan scenarios/ompl/circles.toml"], loose=False, slow=False,
                        lines=["x: length 18.3215, 8 waypoints, solve 6.6 ms", "...", "total time: total 5012.3 ms"],
                        start=0, end=0, line_no=1,
                        fresh=["x: length 18.3216, 8 waypoints, solve 0.4 ms", "total time: total 410.0 ms",
                               "100/100 queries solved, mean length 63.1677"])
    problems = GUIDE_OUT.drift(b)
    assert any("18.3215 now 18.3216" in p for p in problems), problems
    assert any("time 5012.3 now 410.0" in p for p in problems), problems
    assert not any("time 6.6" in p for p in problems)  # both under the floor: instant either way
    prose = GUIDE_OUT.prose_drift("mean length 63.35, in about 5 s for the whole\nrun. "
                                  "verified exactly), mean length 63.35", [b])
    assert any("prose time 5 s" in p for p in prose) and any("prose 63.35, now 63.17" in p for p in prose), prose


def test_a_whole_quote_missing_a_line_is_drift():
    # A quote with no "..." elision is the whole output: a line the run prints and the quote
    # leaves out (the "min clearance" line once) is drift; with an elision it is not.
    fresh = ["basic: solved by exact: length 17.4205, 7 waypoints, solve 13.8 ms", "min clearance 0 at (2.6, 6.3)",
             "stages: minkowski -> prune -> index -> visibility"]
    whole = GUIDE_OUT.Block(commands=["cspace plan scenarios/basic.toml"], loose=False, slow=False,
                            lines=[fresh[0], fresh[2]], start=0, end=0, line_no=1, fresh=fresh)
    assert [p for p in GUIDE_OUT.drift(whole) if "min clearance" in p and "leaves out" in p]
    elided = GUIDE_OUT.Block(commands=whole.commands, loose=False, slow=False, lines=[fresh[0], "...", fresh[2]],
                             start=0, end=0, line_no=1, fresh=fresh)
    assert GUIDE_OUT.drift(elided) == []
