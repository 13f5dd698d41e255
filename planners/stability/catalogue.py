"""``cspace stability``: stiff and extreme cases through every layer, against exact references.

This module owns the stability catalogue: a list of :class:`Case` (name, layer, a
function) run through every layer of the toolkit (predicate, hull, sum, erosion,
decomposition, GJK, EPA, C-space query, planning). Each case computes its answer,
measures the error against an exact reference (``fractions.Fraction`` or exact
integers, brute force: all-pairs hulls, vertex-edge distances, separating axes),
and checks it against the guarantee its layer documents (:data:`GUARANTEES`).

A case function returns ``(result, error, passed, seconds)``: a short text of the
answer, the error against the reference (0 for exact layers), whether the layer's
guarantee holds, and the run time of the layer call alone (references not timed).

The parts: the exact references in :mod:`planners.stability.exact`, the stiff inputs in
:mod:`planners.stability.inputs`, the per-layer checks in :mod:`planners.stability.checks`;
here the catalogue itself, running it, and its table (the chart: :mod:`planners.pictures.stability_chart`;
the command: :mod:`planners.cli.stability`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .checks import (EPS, cspace_case, decomp_case, epa_case, erode_case, gjk_case, hull_case,
                               plan_case, pred_case, sum_case)
from .exact import (c_obstacles, exact_clearance, exact_depth, exact_distance, exact_erosion, exact_free,
                              exact_hull, exact_relation, exact_segment_free, exact_sum, sums_representable,
                              vertex_error)
from .inputs import (box_polygon, circle_points, comb_points, contact_pairs, ulps_down, int_points, l_shape, near_parallel_triples,
                               pred_near_line, random_convex, seeded_rng, sliver_points, square_with_extras, ulps_up, passage)

# The public names, as before the split (the references and the passage scene live in their modules).
__all__ = ["EPS", "GUARANTEES", "Case", "SCALES", "WIDTH", "catalogue", "run_case", "run_all", "format_table", "passage", "c_obstacles", "exact_clearance", "exact_depth", "exact_distance",
           "exact_erosion", "exact_free", "exact_hull", "exact_relation", "exact_segment_free", "exact_sum",
           "sums_representable", "vertex_error"]

# What each layer promises; the bound each case checks.
GUARANTEES = {
    "predicate": "exact sign for all finite doubles (error = wrong signs = 0)",
    "hull": "exact: the vertex set equals the exact strict hull of the input (error 0)",
    "sum": "integer input: exact (error 0); floats: vertices within 2 eps*scale of the exact sum, strictly convex",
    "erosion": "exact in rationals (error 0); float vertices are that rounded once (<= eps*scale)",
    "decomposition": "exact cover: convex pieces of input vertices, areas sum exactly to the polygon's (error 0)",
    "gjk": "relation (separated/touching/overlapping) exact; touching distance exactly 0; "
           "separated distance within 1e-9*scale (relative to the local extent)",
    "epa": "touching depth exactly 0; depth within EPA_TOL*scale + 64 eps*scale of the exact depth",
    "cspace": "closed obstacles (touching = collision), repeatable; is_free/segment_free exact on the C-obstacle "
              "pieces (vertices rounded once), so exact on the true geometry when obstacle-robot differences are "
              "representable, else only within 2 eps*|coordinates| of contact; clearance within 1e-9*extent + that",
    "planning": "exact planner: solvable <=> found, unsolvable proven; OMPL paths re-verified exactly",
}


@dataclass(frozen=True)
class Case:
    """One catalogue entry. ``run() -> (result, error, passed, seconds)``."""

    name: str
    layer: str
    run: Callable[[], tuple]
    about: str = ""
    needs_ompl: bool = False  # a sampling planner's case: skipped, with a note, where OMPL is missing


# ---------------------------------------------------------------- the catalogue


# 2^±700 (about 1e±211): products of four coordinates leave the double range there.
SCALES = (2.0**-700, 1e-9, 1e-3, 1.0, 1e3, 1e9, 2.0**700)


def _scale_name(s: float) -> str:
    """'1e-09' as :g would print it, or '2^700' for the powers of two at the range's ends."""
    m, e = math.frexp(s)
    return f"2^{e - 1}" if m == 0.5 and abs(e - 1) > 64 else f"{s:g}"


def catalogue() -> list[Case]:
    """Every case, in layer order. Deterministic (fixed seeds)."""
    from cspace import convex_hull as hull

    cases: list[Case] = []
    add = lambda name, layer, fn, about="": cases.append(Case(name, layer, fn, about))
    rng = seeded_rng(7)
    sq = lambda s, o=0.0: box_polygon(o, o, o + s, o + s)

    # predicate
    for s in SCALES:
        add(f"pred_scale_{_scale_name(s)}", "predicate", pred_case(pred_near_line(s, 0.0, seed=1)), "near-collinear triples")
    add("pred_offset_1e8", "predicate", pred_case(pred_near_line(1.0, 1e8, seed=2)))
    add("pred_near_parallel", "predicate", pred_case(near_parallel_triples()), "u=(1e6,1), v=(2e6,2+d), d ~ ulps")
    add("pred_int_2^52", "predicate", pred_case(pred_near_line(2.0 ** 51, 0.0, seed=3)
                                                 + [((0.0, 0.0), (2.0 ** 52, 2.0 ** 52 - 1), (2.0 ** 52 - 1, 2.0 ** 52 - 2))]))

    # hull
    for s in SCALES:
        add(f"hull_scale_{_scale_name(s)}", "hull", hull_case(square_with_extras(s, 0.0)), "collinear, repeated, 1-ulp bumps")
    add("hull_offset_1e8", "hull", hull_case(square_with_extras(1.0, 1e8)))
    add("hull_sliver_1e9", "hull", hull_case(sliver_points(1e9)))
    add("hull_circle_100k", "hull", hull_case(circle_points(100_000), limit_s=3.0), "100 000 vertices, < 3 s")
    add("hull_circle_100k_offset_1e8", "hull", hull_case(circle_points(100_000, 1.0, 1e8), limit_s=3.0))
    add("hull_int_2^52", "hull", hull_case(np.r_[int_points(rng, 300), [[0, 2.0 ** 52], [2.0 ** 51, 2.0 ** 52]]]))

    # sum
    for s in SCALES:
        add(f"sum_scale_{_scale_name(s)}", "sum", sum_case(random_convex(rng, 40, s), random_convex(rng, 40, s / 3), False))
    add("sum_offset_1e8", "sum", sum_case(random_convex(rng, 40, 1.0, 1e8), random_convex(rng, 40, 1.0, 1e8), False))
    for name, y in (("sum_near_parallel_1e-9", 2 + 1e-9), ("sum_near_parallel_ulp", ulps_up(2.0)),
                    ("sum_near_parallel_-ulp", ulps_down(2.0))):
        add(name, "sum", sum_case([[0, 0], [1e6, 1], [0, 1e6]], [[0, 0], [2e6, y], [0, 1e6]], False),
            "edges u=(1e6,1), v=(2e6,y): cross within ulps of 0")
    add("sum_collinear_repeated", "sum", sum_case(
        [[0, 0], [0, 0], [0.5, 0], [1, 0], [1, 0.25], [1, 1], [1, 1], [0, 1]],
        [[0.1, 0.1], [0.3, 0.1], [0.3, 0.1], [0.2, 0.3], [0.15, 0.2]], False))
    add("sum_sliver_1e9", "sum", sum_case(hull(sliver_points(1e9)), hull(sliver_points(1e9)[:, ::-1] * [1, -1]), False))
    add("sum_circle_100k_square", "sum", sum_case(circle_points(100_000), sq(0.5), False, limit_s=3.0),
        "100 000 + 4 vertices, < 3 s")
    add("sum_int_2^52", "sum", sum_case(hull(int_points(rng, 60, 2 ** 51)), hull(int_points(rng, 60, 2 ** 51)), True),
        "integer input: exact")
    add("sum_int_circle_100k", "sum", sum_case(hull(np.round(circle_points(100_000, 2.0 ** 40))), sq(2.0 ** 40), True,
                                                limit_s=3.0), "integer circle of radius 2^40 (hull) + square: exact")

    # erosion
    for s in SCALES:
        add(f"erode_scale_{_scale_name(s)}", "erosion", erode_case(random_convex(rng, 30, s), random_convex(rng, 8, s / 5)))
    add("erode_offset_1e8", "erosion", erode_case(random_convex(rng, 30, 1.0, 1e8), random_convex(rng, 8, 0.2, 1e8)))
    add("erode_exact_fit", "erosion", erode_case(sq(1.0, 0.3), sq(1.0, 0.7)), "B exactly as big as A: a point")
    add("erode_exact_fit_offset_1e8", "erosion", erode_case(box_polygon(1e8, 1e8, 1e8 + 1, 1e8 + 3), sq(1.0)),
        "fits in one direction only: a segment")
    add("erode_sliver_1e9", "erosion", erode_case(hull(sliver_points(1e9)), [[0, 0], [1e-3, 0], [0, 1e-12]]))
    add("erode_int_2^52", "erosion", erode_case(hull(int_points(rng, 60)), hull(int_points(rng, 8, 2 ** 48))))

    # decomposition
    for s in SCALES:
        add(f"decomp_L_scale_{_scale_name(s)}", "decomposition", decomp_case(l_shape(s, 0.0)))
    add("decomp_L_offset_1e8", "decomposition", decomp_case(l_shape(1.0, 1e8)))
    add("decomp_collinear_repeated", "decomposition", decomp_case(
        [[0, 0], [1, 0], [2, 0], [2, 0], [2, 1], [1.5, 1], [1, 1], [1, 2], [0, 2], [0, 1]]))
    add("decomp_comb_sliver_1e9", "decomposition", decomp_case(comb_points(6, 1e9)), "teeth of aspect 1e9")
    add("decomp_hole_offset_1e8", "decomposition", decomp_case(box_polygon(1e8, 1e8, 1e8 + 4, 1e8 + 4),
                                                                [box_polygon(1e8 + 1, 1e8 + 1, 1e8 + 3, 1e8 + 3)[::-1]]))
    add("decomp_int_2^52", "decomposition", decomp_case(l_shape(2.0 ** 50, 0.0) + [[2.0 ** 50 - 1, 3.0]]))

    # GJK and EPA
    for s in SCALES:
        a = random_convex(rng, 20, s)
        add(f"gjk_separated_scale_{_scale_name(s)}", "gjk", gjk_case(a, a + [3 * s, s / 7], "separated"))
        add(f"epa_overlap_scale_{_scale_name(s)}", "epa", epa_case(a, a + [s / 3, s / 5], "overlapping"))
    a, b = random_convex(rng, 20, 1.0, 1e8), random_convex(rng, 20, 1.0, 1e8)
    add("gjk_offset_1e8", "gjk", gjk_case(a, b + [2.5, 0.0], "separated"))
    add("epa_offset_1e8", "epa", epa_case(a, b + [0.3, 0.1], "overlapping"))
    for s, o in ((1.0, 0.0), (1.0, 1e8), (1e-9, 0.0), (2.0 ** 30, 2.0 ** 51)):
        tag = f"s{s:g}_o{o:g}"
        for kind, A, B in contact_pairs(s, o):
            add(f"gjk_touch_{kind}_{tag}", "gjk", gjk_case(A, B, "touching"))
            add(f"epa_touch_{kind}_{tag}", "epa", epa_case(A, B, "touching"))
    sl = hull(sliver_points(1e9))
    add("gjk_sliver_gap_1ulp", "gjk", gjk_case(sl, box_polygon(0.0, ulps_up(1e-9), 1.0, 1.0) + [0, 0], "separated"),
        "sliver apex one ulp below a box")
    add("gjk_near_parallel_gap", "gjk", gjk_case([[0, 0], [1e6, 1], [0, 1]],
                                                  [[0, ulps_up(1.0)], [2e6, ulps_up(3.0)], [0, 5]], None))
    add("epa_sliver_overlap", "epa", epa_case(sl, sl + [0.25, 0.0], "overlapping"))
    add("gjk_int_2^52", "gjk", gjk_case(hull(int_points(rng, 30, 2 ** 50)), hull(int_points(rng, 30, 2 ** 50)) + 2.0 ** 51))

    # C-space queries: zero clearance, 1e-6 wider, 1e-6 narrower, at several scales and offsets
    for w, o in ((1.0, 0.0), (1.0, 1e8), (1e-9, 0.0), (1e9, 0.0), (0.1, 0.3)):
        for label, slack in (("exact", 0.0), ("wider", 1e-6 * w), ("narrower", -1e-6 * w)):
            add(f"cspace_{label}_w{w:g}_o{o:g}", "cspace", cspace_case(w, slack, o),
                "closed obstacles: touching is collision")
    # non-dyadic widths far from the origin: the rounded C-obstacle closes a passage the true
    # geometry leaves open by less than one ulp (decided consistently, within the rounding band)
    for w, o in ((0.3, 1e8 + 0.1), (1 / 3, 1e8 / 3)):
        add(f"cspace_exact_w{w:.3g}_o{o:.10g}", "cspace", cspace_case(w, 0.0, o), "sums not representable")
    # scenes far smaller than their coordinates (extent ~1e-13 |coordinate|): the broad phase's
    # margin spans many grid cells, and its segment walk must still terminate
    for w, o in ((1e-5, 1e8 + 0.1), (1e-3, 1e9)):
        for label, slack in (("exact", 0.0), ("wider", 1e-6 * w)):
            add(f"cspace_tiny_{label}_w{w:g}_o{o:.10g}", "cspace", cspace_case(w, slack, o),
                "extent near the float resolution of the coordinates")

    # planning (each <= 1 s)
    add("plan_exact_wider", "planning", plan_case(1.0, 1e-6, 0.0, "exact", True))
    add("plan_exact_wider_o1e8", "planning", plan_case(1.0, 1e-6, 1e8, "exact", True))
    add("plan_exact_zero_clearance", "planning", plan_case(1.0, 0.0, 0.0, "exact", False))
    add("plan_exact_narrower", "planning", plan_case(1.0, -1e-6, 0.0, "exact", False))
    add("plan_exact_narrower_o1e8", "planning", plan_case(1.0, -1e-6, 1e8, "exact", False))
    cases.append(Case("plan_rrtconnect_o1e8", "planning", plan_case(1.0, 0.5, 1e8, "RRTConnect", True),
                      needs_ompl=True))
    return cases


def run_case(case: Case) -> dict:
    """Run one case; a crash or a NaN is a failure, reported, never raised."""
    t = time.perf_counter()
    try:
        result, error, passed, seconds = case.run()
    except Exception as exc:  # a crash is a failed guarantee, not a crashed report
        result, error, passed, seconds = f"CRASH {type(exc).__name__}: {exc}", math.inf, False, time.perf_counter() - t
    if not isinstance(error, (int, float)) or math.isnan(error):
        passed = False
    return {"case": case.name, "layer": case.layer, "result": result,
            "error": float(error) if math.isfinite(error) else None,
            "time_ms": 1000.0 * seconds, "passed": bool(passed), "guarantee": GUARANTEES[case.layer]}


def runnable(cases: list[Case]) -> tuple[list[Case], list[Case]]:
    """The cases this installation can run, and those it skips (they need OMPL, which is missing).

    >>> runnable([])
    ([], [])
    """
    from ..adapters.glue import ompl_available

    if any(c.needs_ompl for c in cases) and not ompl_available():
        return [c for c in cases if not c.needs_ompl], [c for c in cases if c.needs_ompl]
    return list(cases), []


def run_all(cases: list[Case] | None = None, progress: bool | None = False) -> list[dict]:
    """Rows of the report, one per case (a bar on a terminal with ``progress=None``).

    Cases that need OMPL are left out where it is not installed (see :func:`runnable`)."""
    from ..progress import track

    cases, _ = runnable(catalogue() if cases is None else cases)
    return [run_case(c) for c in track(cases, "stability", enabled=progress, unit="case")]


WIDTH = 80  # the table fits a classic terminal: results go on their own indented line


def format_table(rows: list[dict], width: int = WIDTH) -> str:
    """The report as a text table, one case per two lines: name and numbers, then its result.

    The layer is the case name's prefix (``pred_``, ``hull_``, ``gjk_`` ...), so it
    takes no column; the result is wrapped to ``width`` under its case.

    >>> print(format_table([{"case": "c", "layer": "hull", "result": "ok", "error": 0.0,
    ...                      "time_ms": 1.5, "passed": True}]))
    case     error  time ms  pass
    ----  --------  -------  ----
    c     0.00e+00      1.5  pass
        ok
    """
    import textwrap

    head = ("case", "error", "time ms", "pass")
    body = [(r["case"], "-" if r["error"] is None else f"{r['error']:.2e}", f"{r['time_ms']:.1f}",
             "pass" if r["passed"] else "FAIL") for r in rows]
    w = [max(len(x[i]) for x in [head] + body) for i in range(4)]
    line = lambda x: "  ".join([x[0].ljust(w[0]), x[1].rjust(w[1]), x[2].rjust(w[2]), x[3]]).rstrip()
    out = [line(head), "  ".join("-" * k for k in w)]
    for x, r in zip(body, rows):
        out.append(line(x))
        out += textwrap.wrap(str(r["result"]), width, initial_indent="    ", subsequent_indent="      ",
                             break_on_hyphens=False) or ["    -"]
    return "\n".join(out)


