"""Start-up: how long a fresh interpreter takes to import cspace or run ``cspace --help``.

Each command runs in a fresh process (``subprocess``), interleaved round by round with
the peer, ``python -c pass`` (the interpreter's own start); the median wall time of
each over the rounds is printed, with the excess over the peer. Targets (issue 23):
``import cspace`` <= 0.3 s, ``cspace --help`` <= 0.4 s. ``import cspace`` loads names
on first use, so the table also shows what using the C-space costs
(``from cspace import CSpace``: numpy and the geometry modules) and what a scenario
file needs (``load_scenario``).

Usage: python scripts/bench_startup.py [--quick] [--rounds N] [--out-json FILE]
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = sys.executable
BASIC = os.path.join(ROOT, "scenarios", "basic.toml")


def commands() -> dict[str, list[str]]:
    """The timed commands (the peer first); each is a fresh process."""
    cmds = {
        "python -c pass (peer)": [PY, "-c", "pass"],
        "import cspace": [PY, "-c", "import cspace"],
        "import planners": [PY, "-c", "import planners"],
        "from cspace import CSpace": [PY, "-c", "from cspace import CSpace"],
        "load_scenario(basic.toml)": [PY, "-c", f"from cspace import load_scenario; load_scenario({BASIC!r})"],
        "python -m planners --help": [PY, "-m", "planners", "--help"],
        "cspace plan --help": [PY, "-m", "planners", "plan", "--help"],
    }
    exe = shutil.which("cspace", path=os.path.dirname(PY)) or shutil.which("cspace")
    if exe:
        cmds["cspace --help"] = [exe, "--help"]
    return cmds


def run(rounds: int) -> list[dict]:
    """Median wall seconds per command over ``rounds`` interleaved rounds."""
    cmds = commands()
    times: dict[str, list[float]] = {k: [] for k in cmds}
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    for _ in range(rounds):
        for name, cmd in cmds.items():
            t = time.perf_counter()
            subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
            times[name].append(time.perf_counter() - t)
    peer = statistics.median(times["python -c pass (peer)"])
    target = {"import cspace": 0.3, "cspace --help": 0.4, "python -m planners --help": 0.4}
    rows = []
    for name, ts in times.items():
        med = statistics.median(ts)
        rows.append({"command": name, "median_s": med, "over_peer_s": med - peer,
                     "target_s": target.get(name), "met": None if name not in target else med <= target[name]})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="5 rounds")
    ap.add_argument("--rounds", type=int, default=None, help="rounds (default 15)")
    ap.add_argument("--out-json", default=None)
    args = ap.parse_args(argv)
    rows = run(args.rounds or (5 if args.quick else 15))
    print(f"{'command':30s} {'median s':>9s} {'over peer s':>12s}  target")
    for r in rows:
        tgt = "" if r["target_s"] is None else f"<= {r['target_s']:g} s: {'met' if r['met'] else 'MISSED'}"
        print(f"{r['command']:30s} {r['median_s']:9.3f} {r['over_peer_s']:12.3f}  {tgt}")
    if args.out_json:
        with open(args.out_json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
