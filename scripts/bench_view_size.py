"""The offline page of a finely approximated disk robot: size and time of ``view_html`` with the
moving footprint decimated (:data:`planners.pictures.view.figure.MOVING_VERTICES`, issue 48)
against the peer, the same page with every frame repeating the whole footprint (the page before
issue 48), interleaved round by round; medians, and the ratio.

The scene: a disk robot of radius 0.5 at ``disk_tolerance = 1e-8`` (about 22 000 vertices) in a
10 x 10 square with one wall, planned once with RRTConnect (seed 0).

Usage: python scripts/bench_view_size.py [--rounds N] [--poses N]
"""
from __future__ import annotations

import argparse
import statistics
import time

SCENE = {"name": "fine disk", "disk_tolerance": 1e-8, "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
         "robot": {"radius": 0.5}, "obstacles": [{"polygon": [[4, 0], [5, 0], [5, 6], [4, 6]]}],
         "start": {"x": 1, "y": 1}, "goal": {"x": 9, "y": 9}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--poses", type=int, default=120)
    args = ap.parse_args(argv)
    import planners
    from cspace.io.load import scenario_from_dict
    from planners.pictures.view import figure as fg
    from planners.pictures.view import view_html

    res = planners.plan(scenario_from_dict(SCENE, "fine_disk.toml"), seed=0)
    if not res.solved:
        print("not solved: nothing to draw")
        return 1
    keep = fg.MOVING_VERTICES, fg.MAX_POINTS
    times: dict[str, list[float]] = {"decimated": [], "whole footprint (peer)": []}
    sizes = {}
    try:
        for _ in range(args.rounds):
            for name, limit in (("whole footprint (peer)", 10**9), ("decimated", keep[0])):
                fg.MOVING_VERTICES, fg.MAX_POINTS = limit, 10**12
                t0 = time.perf_counter()
                sizes[name] = len(view_html(res, poses=args.poses))
                times[name].append(time.perf_counter() - t0)
    finally:
        fg.MOVING_VERTICES, fg.MAX_POINTS = keep
    peer = statistics.median(times["whole footprint (peer)"])
    print(f"{'page':<24} {'median s':>9} {'MB':>7} {'time ratio':>11}")
    for name in ("whole footprint (peer)", "decimated"):
        m = statistics.median(times[name])
        print(f"{name:<24} {m:>9.2f} {sizes[name] / 1e6:>7.1f} {m / peer:>11.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
