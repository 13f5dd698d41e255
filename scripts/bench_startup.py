"""Start-up: how long a fresh interpreter takes to import cspace or run ``cspace --help``.

Each command runs in a fresh process (``subprocess``), interleaved round by round with
the peer, ``python -c pass`` (the interpreter's own start); the median wall time of
each over the rounds is printed, with the excess over the peer. Targets (issue 23):
``import cspace`` <= 0.3 s, ``cspace --help`` <= 0.4 s. ``import cspace`` loads names
on first use, so the table also shows what using the C-space costs
(``from cspace import CSpace``: numpy and the geometry modules) and what a scenario
file needs (``load_scenario``).

``--against REV`` times the same commands, interleaved, in a checkout of REV as well (a git
worktree in a temporary folder, run from there; the compiled fast path is copied over when
its C sources are the same in both), so a change's start-up is compared side by side with
the commit before it, ``cspace plan scenarios/basic.toml`` included.

Usage: python scripts/bench_startup.py [--quick] [--rounds N] [--against REV] [--out-json FILE]
(--out-json is checked before any work, never over scenarios/basic.toml, and written atomically.)
"""
from __future__ import annotations

import argparse
import contextlib
import filecmp
import glob
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
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


def tree_commands() -> dict[str, list[str]]:
    """The commands that read the tree they run in (``against`` runs them in the other one too)."""
    return {
        "import cspace": [PY, "-c", "import cspace"],
        "import planners": [PY, "-c", "import planners"],
        "python -m planners --help": [PY, "-m", "planners", "--help"],
        "cspace plan basic.toml": [PY, "-m", "planners", "plan", os.path.join("scenarios", "basic.toml")],
    }


def fast_dir(tree: str) -> str:
    """The folder of a tree's compiled fast path (its C sources and the built extension):
    cspace/compiled, or cspace/spaces before the geometry was laid out by robot kind."""
    for sub in ("compiled", "spaces"):
        if os.path.exists(os.path.join(tree, "cspace", sub, "_fast.c")):
            return os.path.join(tree, "cspace", sub)
    return os.path.join(tree, "cspace", "compiled")


@contextlib.contextmanager
def checkout(rev: str):
    """A worktree of ``rev`` in a temporary folder (removed afterwards), with this tree's
    compiled fast path copied in when the C sources are identical."""
    tmp = tempfile.mkdtemp(prefix="cspace-startup-")
    path = os.path.join(tmp, "tree")
    subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", path, rev], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        here, there = fast_dir(ROOT), fast_dir(path)
        sources = sorted(os.path.basename(f) for f in glob.glob(os.path.join(here, "_*.[ch]")))
        if all(os.path.exists(os.path.join(there, f)) and filecmp.cmp(os.path.join(here, f), os.path.join(there, f),
                                                                      shallow=False) for f in sources):
            for so in glob.glob(os.path.join(here, "_fast*.so")) + glob.glob(os.path.join(here, "_fast*.pyd")):
                shutil.copy2(so, there)
        yield path
    finally:
        subprocess.run(["git", "-C", ROOT, "worktree", "remove", "--force", path], check=False,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        shutil.rmtree(tmp, ignore_errors=True)


def run(rounds: int, against: str | None = None) -> list[dict]:
    """Median wall seconds per command over ``rounds`` interleaved rounds (with ``against``,
    also each tree command in a checkout of that revision, interleaved with ours)."""
    cmds = {name: (cmd, ROOT) for name, cmd in commands().items()}
    with contextlib.ExitStack() as stack:
        if against:
            other = stack.enter_context(checkout(against))
            for name, cmd in tree_commands().items():
                cmds.setdefault(name, (cmd, ROOT))
                cmds[f"{name} [{against}]"] = (cmd, other)
        times: dict[str, list[float]] = {k: [] for k in cmds}
        for _ in range(rounds):
            for name, (cmd, cwd) in cmds.items():
                # PYTHONPATH puts the tree's own packages first (the installed ones are this tree's)
                env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPATH": cwd}
                t = time.perf_counter()
                subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               check=True)
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
    ap.add_argument("--against", metavar="REV", help="also time the tree commands in a checkout of REV")
    ap.add_argument("--out-json", default=None)
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_json, write_json

    check_json(args.out_json, [BASIC], "--out-json")  # (never over the scenario it plans)
    rows = run(args.rounds or (5 if args.quick else 15), args.against)
    print(f"{'command':30s} {'median s':>9s} {'over peer s':>12s}  target")
    for r in rows:
        tgt = "" if r["target_s"] is None else f"<= {r['target_s']:g} s: {'met' if r['met'] else 'MISSED'}"
        print(f"{r['command']:30s} {r['median_s']:9.3f} {r['over_peer_s']:12.3f}  {tgt}")
    if args.against:
        med = {r["command"]: r["median_s"] for r in rows}
        print(f"\nthis tree / {args.against}, median wall time:")
        for name in tree_commands():
            print(f"  {name:30s} {med[name] / med[f'{name} [{args.against}]']:.3f}x")
    if args.out_json:
        write_json(args.out_json, rows, "--out-json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
