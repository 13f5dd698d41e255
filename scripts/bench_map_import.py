"""Importing noisy ROS maps (issue 36): seconds per million cells, and peak memory.

A map of N x N cells, each occupied with probability --noise (seeded, the worst case
for the tracing: about 0.55 traced vertices per cell at 50 %), is written as PNG +
YAML and imported as ``cspace import`` does it: the import (read, classify, trace,
simplify at the default tolerance) and the validation of the scenario it makes, timed
apart. Each size runs in a child process (its peak RSS is the size's own), median of
--reps runs. Time linear in the map's size shows as a flat "s / M cells" column.

Usage: python scripts/bench_map_import.py [--sizes 128,256,512,1024] [--noise 0.5] [--reps 3]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def child(yaml_path: str, size: int, reps: int) -> dict:
    """Import ``yaml_path`` ``reps`` times in this process: median seconds, peak RSS."""
    sys.path.insert(0, HERE)
    from noisy_map import start_goal

    from cspace.io.importers.imported import ImportOptions, import_file
    from cspace.io.scenario.validate import scenario_from_dict

    start, goal = start_goal(size)
    opts = ImportOptions(robot={"radius": 0.2}, start=start, goal=goal)
    t_imp, t_val = [], []
    for _ in range(reps):
        t = time.perf_counter()
        imp = import_file(yaml_path, opts)
        t_imp.append(time.perf_counter() - t)
        t = time.perf_counter()
        scenario_from_dict(imp.data, yaml_path)
        t_val.append(time.perf_counter() - t)
    traced = next(line for line in imp.report if line.startswith("obstacles:"))
    return {"import": statistics.median(t_imp), "validate": statistics.median(t_val),
            "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, "traced": traced}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="128,256,512,1024")
    ap.add_argument("--noise", type=float, default=0.5)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--child", nargs=3, metavar=("YAML", "SIZE", "REPS"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child[0], int(args.child[1]), int(args.child[2]))))
        return 0
    sys.path.insert(0, HERE)
    from noisy_map import noisy_image, write_map

    print(f"noisy maps ({args.noise:.0%} occupied), median of {args.reps}; import = read + trace + simplify, "
          "validate = the scenario check `cspace import` runs after it")
    print(f"{'cells':>11} {'import s':>9} {'s / M cells':>12} {'validate s':>11} {'s / M cells':>12} "
          f"{'peak MB':>8}  traced")
    with tempfile.TemporaryDirectory() as tmp:
        for size in (int(s) for s in args.sizes.split(",")):
            y = write_map(tmp, noisy_image(size, args.noise, seed=size), f"noisy{size}", png=True)
            out = subprocess.run([sys.executable, __file__, "--child", y, str(size), str(args.reps)],
                                 capture_output=True, text=True)
            if out.returncode:
                print(f"{size:>5} x {size:<5} failed: {out.stderr.strip().splitlines()[-1]}")
                continue
            r = json.loads(out.stdout)
            m = size * size / 1e6
            print(f"{size:>5} x {size:<5} {r['import']:9.2f} {r['import'] / m:12.2f} {r['validate']:11.2f} "
                  f"{r['validate'] / m:12.2f} {r['rss_mb']:8.0f}  {r['traced'][len('obstacles: '):]}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
