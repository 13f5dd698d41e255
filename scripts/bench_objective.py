"""The clearance objective's cost per iteration against the length objective's (issue 39, item 7).

RRTstar plans each scene (default: the bundled bug_trap and office) for a fixed number of
iterations (``--iterations``, evaluations of the termination condition: one per iteration
of RRTstar's loop) under ``--objective length`` and ``--objective clearance``, on one
C-space per scene, the two runs of a repetition interleaved and seeded alike (seed = the
repetition). Figures: the solve time per iteration of each (medians over ``--reps``), the
median over repetitions of the ratio clearance / length (target: <= 5x), and the median
min_clearance of each objective's paths (the clearance objective's should be larger).
A third peer, interleaved too, is the floor of any Python objective: the same objective
class with a motion cost that measures nothing (a random number): RRTstar calls the
objective's motionCost about 100-250 times per new state (its neighbours, and their rewiring),
and each call from OMPL into Python costs about 0.5 us; the clearance objective's costs add in
C++ (no combineCosts in Python), and its motion cost is compiled where the fast path is built
(CSPACE_PURE=1 measures the pure one).

Usage: python scripts/bench_objective.py [--iterations N] [--reps R] [scenario.toml ...]
"""
from __future__ import annotations

import argparse
import math
import os
import random
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

from cspace import CSpace, load_scenario  # noqa: E402

DEFAULT = ("bug_trap.toml", "office.toml")
TARGET = 5.0  # clearance / length, per iteration


def run(sc, cs, objective: str, iterations: int, seed: int) -> tuple[float, float]:
    """(solve seconds per iteration, min_clearance or nan) of one RRTstar plan; ``floor``:
    the clearance objective whose motion cost is a random number."""
    from planners import plan
    from planners.adapters import objectives

    real = objectives.make_objective
    if objective == "floor":
        def noop(name, si, adapter):
            from planners.adapters.glue import ompl

            obj, cost, rnd = real(name, si, adapter), ompl()[0].Cost, random.Random(seed).random
            obj.motionCost = lambda s1, s2: cost(rnd())  # as the translation objective sets its own
            return obj

        objectives.make_objective = noop
    try:
        r = plan(sc, planner="RRTstar", time=600.0, seed=seed, iterations=iterations, cspace=cs,
                 objective="clearance" if objective == "floor" else objective)
    finally:
        objectives.make_objective = real
    return r.timings["solve"] / iterations, (r.min_clearance if r.solved else float("nan"))


def solved_median(values: list) -> str:
    """The median over the solved runs (an unsolved run's clearance is nan), with how many those
    were when not all; "unsolved" when none was (never a bare nan).

    >>> solved_median([0.5, 0.7, 0.6]), solved_median([0.5, float("nan"), 0.7]), solved_median([float("nan")] * 2)
    ('0.6', '0.6 (2/3)', 'unsolved')
    """
    done = [v for v in values if math.isfinite(v)]
    if not done:
        return "unsolved"
    text = f"{statistics.median(done):.4g}"
    return text if len(done) == len(values) else f"{text} ({len(done)}/{len(values)})"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenarios", nargs="*")
    ap.add_argument("--iterations", type=int, default=3000)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    paths = [p if os.path.exists(p) else os.path.join(ROOT, "scenarios", p) for p in (args.scenarios or DEFAULT)]
    print(f"RRTstar, {args.iterations} iterations, {args.reps} interleaved repetitions (medians)")
    print(f"{'scene':<14} {'length us/it':>12} {'clearance us/it':>15} {'ratio':>6} {'<= 5x':>5}  "
          f"{'floor ratio':>11}  {'min clearance: length':>21} {'clearance':>9}")
    worst = 0.0
    for path in paths:
        sc = load_scenario(path)
        cs = CSpace.from_scenario(sc)
        run(sc, cs, "clearance", 50, 0)  # warm both paths (imports, the objective's classes)
        run(sc, cs, "length", 50, 0)
        t = {"length": [], "clearance": [], "floor": []}
        c = {"length": [], "clearance": [], "floor": []}
        ratios, floors = [], []
        for rep in range(args.reps):
            order = ("length", "clearance", "floor")[rep % 3:] + ("length", "clearance", "floor")[:rep % 3]
            got = {}
            for objective in order:
                got[objective] = run(sc, cs, objective, args.iterations, rep)
                t[objective].append(got[objective][0])
                c[objective].append(got[objective][1])
            ratios.append(got["clearance"][0] / got["length"][0])
            floors.append(got["floor"][0] / got["length"][0])
        ratio = statistics.median(ratios)
        worst = max(worst, ratio)
        print(f"{sc.name:<14} {1e6 * statistics.median(t['length']):12.1f} {1e6 * statistics.median(t['clearance']):15.1f} "
              f"{ratio:6.2f} {'yes' if ratio <= TARGET else 'NO':>5}  {statistics.median(floors):11.2f}  "
              f"{solved_median(c['length']):>21} "
              f"{solved_median(c['clearance']):>9}")
    print(f"worst ratio clearance / length per iteration: {worst:.2f}x (target <= {TARGET:g}x: "
          f"{'met' if worst <= TARGET else 'NOT met'})")


if __name__ == "__main__":
    main()
