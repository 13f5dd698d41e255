"""The large fuzz campaign of issue 36: scenario files (tests/cli/test_fuzz_cli.py) and imported
maps and meshes (tests/io/test_fuzz_maps.py, tests/io/test_fuzz_meshes.py) under the exit-code
contract of tests/helpers/fuzzing.py (0/1/2, never 3; exit 2 one line; inputs never written over;
no temporaries; valid JSON); and, since issue 48, the campaign surfaces (tests/bench/
test_fuzz_campaigns.py: hostile ``--db`` files and the names they hold, ``--log`` folders,
``--scheduler`` addresses and servers, sweep sizes, page names; a refused database unchanged,
nothing written outside the outputs).

Runs the scenario fuzz and the import fuzz (its two files in one process: the last test of
test_fuzz_meshes.py reports both) as two pytest processes (in parallel with ``--jobs 2``), each with
``CSPACE_FUZZ_EXAMPLES`` examples per test, and prints one JSON summary: cases and files per
input kind, the exit-code histogram, exit 3 and modified-input counts, the slowest case. A case
that breaks the contract is kept (its files and the reason) under ``OUT/kept`` and counted; the
run goes on.

Usage: python scripts/fuzz_inputs.py [--scenario N] [--imports N] [--campaigns N] [--out DIR] [--jobs 1|2]
(--out is checked before any work: created if missing, and writable; OUT/summary.json is written atomically.)

The defaults (1000 and 2000 examples per test: 4 tests each) give about 12 000 cases and
about 22 000 generated files; expect a few minutes per 1000 cases a core.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The test files of each campaign, run in one pytest process (relative to ROOT): the imports'
# report is the last test of test_fuzz_meshes.py, after test_fuzz_maps.py's cases.
FILES = {"scenario": (os.path.join("tests", "cli", "test_fuzz_cli.py"),),
         "imports": (os.path.join("tests", "io", "test_fuzz_maps.py"), os.path.join("tests", "io", "test_fuzz_meshes.py")),
         "campaigns": (os.path.join("tests", "bench", "test_fuzz_campaigns.py"),)}


def run_files(test_files: tuple, examples: int, out: str, tag: str) -> tuple[subprocess.Popen, str]:
    report = os.path.join(out, f"report-{tag}.json")
    env = dict(os.environ, CSPACE_FUZZ_EXAMPLES=str(examples), CSPACE_FUZZ_REPORT=report,
               CSPACE_FUZZ_KEEP=os.path.join(out, "kept", tag))
    log = open(os.path.join(out, f"pytest-{tag}.log"), "w")
    proc = subprocess.Popen([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *test_files],
                            cwd=ROOT, env=env, stdout=log, stderr=subprocess.STDOUT)
    return proc, report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", type=int, default=1000, help="examples per test of test_fuzz_cli.py (4 tests)")
    ap.add_argument("--imports", type=int, default=2000,
                    help="examples per test of test_fuzz_maps.py and test_fuzz_meshes.py (4 tests)")
    ap.add_argument("--campaigns", type=int, default=200,
                    help="examples per test of test_fuzz_campaigns.py (3 tests; a bench sweep or a page each)")
    ap.add_argument("--out", default="fuzz_out", help="folder for the reports, logs and kept cases")
    ap.add_argument("--jobs", type=int, choices=(1, 2), default=2)
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_out, write_json

    check_out(args.out, (), "--out", folder=True)  # before any work: created, and writable
    out = os.path.abspath(args.out)
    t0 = time.time()
    plan = [(FILES[tag], n, tag) for n, tag in ((args.scenario, "scenario"), (args.imports, "imports"),
                                                (args.campaigns, "campaigns")) if n > 0]
    reports, codes = {}, {}
    running = []
    for f, n, tag in plan:
        proc, rep = run_files(f, n, out, tag)
        running.append((tag, proc))
        reports[tag] = rep
        if args.jobs == 1:
            codes[tag] = proc.wait()
    for tag, proc in running:
        codes[tag] = proc.wait()
    summary = {"seconds": round(time.time() - t0, 1), "pytest_exit": codes, "cases": 0, "cases_by_kind": {},
               "files_by_kind": {}, "exit": {}, "exit_3": 0, "inputs_modified": 0, "contract_broken": 0,
               "slowest_s": 0.0, "slowest": ""}
    for tag, path in reports.items():
        if not os.path.exists(path):
            summary.setdefault("missing_reports", []).append(tag)
            continue
        with open(path) as fh:
            r = json.load(fh)
        summary["cases"] += r["cases"]
        for k, v in r["exit"].items():
            summary["exit"][k] = summary["exit"].get(k, 0) + v
        for label, v in r["by_test"].items():
            name = label.split(":")[0]
            kind = "map" if name.startswith("map") else "mesh" if name.startswith("mesh") else \
                "fixed cases" if name in ("templates", "found") else \
                name if name in ("db files", "db seed", "scheduler", "page") else "scenario"
            summary["cases_by_kind"][kind] = summary["cases_by_kind"].get(kind, 0) + v
        for k, v in r.get("files", {}).items():
            summary["files_by_kind"][k] = summary["files_by_kind"].get(k, 0) + v
        summary["exit_3"] += r["exit"].get("3", 0)
        summary["inputs_modified"] += r.get("inputs_modified", 0)
        summary["contract_broken"] += r.get("contract_broken", 0)
        if r["slowest_s"] > summary["slowest_s"]:
            summary["slowest_s"], summary["slowest"] = r["slowest_s"], r["slowest"]
        # A generated scenario is one file (the option and generate cases reuse a bundled scenario).
        scen = sum(v for label, v in r["by_test"].items() if label.startswith("scenario files"))
        if scen:
            summary["files_by_kind"]["scenario"] = summary["files_by_kind"].get("scenario", 0) + scen
    summary["files"] = sum(summary["files_by_kind"].values())
    print(json.dumps(summary, indent=1))
    write_json(os.path.join(out, "summary.json"), summary, "--out")
    ok = summary["exit_3"] == 0 and summary["contract_broken"] == 0 and not any(codes.values())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
