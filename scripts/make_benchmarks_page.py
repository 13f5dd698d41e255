"""Write docs/benchmarks.md from the bench scripts' own output: no number is typed by hand.

    python scripts/make_benchmarks_page.py [--out docs/benchmarks.md] [--work DIR] [--from DIR]

Each ``scripts/bench_*.py`` is run in its quick mode (``--quick`` where the script has
it, else the small arguments in ``QUICK_ARGS``), with ``--out-json`` where it offers
one. Its printed table (medians and the ratios against peers measured in the same
run) is copied verbatim into the page, and its JSON rows, when there are any, are
rendered as Markdown tables. ``cspace bench`` (planners: error against run time) is
run on a small sweep too. Outputs of every run are kept in ``--work`` (default: a
temporary folder); ``--from DIR`` re-renders the page from such a folder without
running anything. A script missing from ``scripts/`` is listed as "not yet run".

Bench-MR's suite (``scripts/bench_benchmr.py``) reads a Bench-MR checkout, which lives outside
the repository: it runs only when ``--bench-mr DIR`` (or ``$BENCH_MR``) names one, with
``BENCH_MR_ARGS`` and ``--figures docs/figures/benchmr`` (a picture of each polygon world and
car model with cspace's paths, committed with the page); its section then shows the table, the
per-world ratios, the peer's recheck counts and those pictures. Without a checkout the section
says how to run it, and nothing outside the repository is read. OMPL.app's planar problems
(``scripts/bench_omplapp.py``) are read the same way from an OMPL.app checkout, ``--omplapp DIR``
(or ``$OMPLAPP``), with ``OMPLAPP_ARGS``.
"""
from __future__ import annotations

import argparse
import datetime as dt
import glob
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Scripts the page expects; others found in scripts/ are run too.
EXPECTED = ("bench_minkowski", "bench_gjk", "bench_scaling", "bench_cspace", "bench_direct", "bench_shortest")
# Small arguments for scripts without a --quick mode (their defaults take minutes).
QUICK_ARGS = {
    "bench_minkowski": ["--sizes", "8,64,1024"],
    "bench_gjk": ["--pairs", "3"],
    "bench_scaling": ["--plot", ""],
    "bench_clearance": ["--reps", "15"],  # its ratios are of 0.2-1 ms builds: 5 medians swing by 0.1x
    # issue 47's targets are over 100 pairs. Nav2's map is another project's: the script reads it
    # from NAV2_DIR (set it in the environment; without it the section says nothing was run).
    "bench_nav2": ["--pairs", "100"],
}
# The planner sweep of ``cspace bench``: small, so that the page builds in minutes.
PLANNER_SWEEP = ["scenarios/bug_trap.toml", "scenarios/maze.toml", "--planners", "RRTConnect,RRTstar",
                 "--times", "0.1,0.3,1", "--runs", "5", "--workers", "2", "--no-plot", "--quiet"]
TIMEOUT = 600  # seconds per script
# Bench-MR's suite: every polygon problem and the last 10 rows of each city map, one seed, 10 s a
# run (its --quick mode is 3 s and 3 rows); longer than the others, hence its own timeout.
BENCH_MR_ARGS = ["--seeds", "1", "--time", "10"]
BENCH_MR_FIGURES = os.path.join("docs", "figures", "benchmr")
# OMPL.app's planar problems: its defaults (10 seeds, 10 s a run), the figures issue 47's target is over.
OMPLAPP_ARGS: list[str] = []
# The longer scripts' own timeouts (seconds): 100 pairs x 3 spaces on a 2000 x 2000 map; Bench-MR's suite.
TIMEOUTS = {"bench_nav2": 1800, "bench_warehouse": 1800, "bench_benchmr": 1800, "bench_omplapp": 1800}
# Benches of another project's data: the option that names its checkout (without one: "Not run").
CHECKOUTS = {"bench_benchmr": "--bench-mr", "bench_omplapp": "--omplapp"}
# What each of them needs, for its section's "Not run" (the option, then the environment variable)
NOT_RUN = {"bench_benchmr": ("a Bench-MR checkout (github.com/robot-motion/bench-mr)", "BENCH_MR"),
           "bench_omplapp": ("an OMPL.app checkout (github.com/ompl/omplapp)", "OMPLAPP")}


def checkout_data(rec: dict, name: str) -> tuple[dict | None, list[str]]:
    """A checkout bench's JSON from its run's record, or (None, its section's "Not run" lines) where
    nothing ran (no checkout named).

    >>> checkout_data({"json": None}, "bench_omplapp")[1][0]
    'Not run: it needs an OMPL.app checkout (github.com/ompl/omplapp), which lives outside the repository:'
    """
    if not rec.get("json"):
        what, env = NOT_RUN[name]
        return None, [f"Not run: it needs {what}, which lives outside the repository:",
                      f"`python scripts/make_benchmarks_page.py {CHECKOUTS[name]} DIR` (or `${env}`).", ""]
    with open(rec["json"]) as fh:
        return json.load(fh), []


def help_text(script: str) -> str:
    """The script's ``--help`` (to find which options it offers)."""
    proc = subprocess.run([sys.executable, script, "--help"], capture_output=True, text=True, timeout=60, cwd=ROOT)
    return proc.stdout


def quick_command(name: str, script: str, json_path: str, checkout: str | None = None) -> tuple[list[str], bool]:
    """The command line of a quick run, and whether it writes JSON to ``json_path``
    (``bench_benchmr``, ``bench_omplapp``: their own arguments, with the other project's ``checkout``)."""
    h = help_text(script)
    args = list(QUICK_ARGS.get(name, []))
    if name == "bench_benchmr":
        args = ["--bench-mr", checkout or "", *BENCH_MR_ARGS, "--figures", BENCH_MR_FIGURES]
    elif name == "bench_omplapp":
        args = ["--omplapp", checkout or "", *OMPLAPP_ARGS]
    elif "--quick" in h:
        args.append("--quick")
    wants_json = "--out-json" in h
    if wants_json:
        args += ["--out-json", json_path]
    return ["python", os.path.relpath(script, ROOT), *args], wants_json


def run_script(name: str, script: str, work: str, checkout: str | None = None) -> dict:
    """Run one bench script, keep its stdout, JSON and timing in ``work``; returns the record."""
    json_path = os.path.join(work, f"{name}.json")
    cmd, wants_json = quick_command(name, script, json_path, checkout)
    started = {"date": dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "load": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}  # the machine may be shared
    limit = TIMEOUTS.get(name, TIMEOUT)
    t = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, *cmd[1:]], capture_output=True, text=True, timeout=limit, cwd=ROOT)
        rc, out, err = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired as exc:
        rc, out, err = "timeout", exc.stdout or "", f"timed out after {limit} s"
        out = out.decode() if isinstance(out, bytes) else out
    shown = _shown(cmd, json_path)
    if checkout:  # the checkout's place on this machine is no part of the command a reader types
        shown = shown.replace(shlex.quote(checkout), "DIR")
    rec = {"name": name, "command": shown, "seconds": time.perf_counter() - t, "rc": rc, **started,
           "stdout": out, "stderr": err[-2000:], "json": json_path if wants_json and os.path.exists(json_path) else None}
    _write_json(os.path.join(work, f"{name}.run.json"), rec)
    return rec


def _write_json(path: str, rec: dict) -> None:
    """A run's record in the work folder, written atomically (scripts/benchutil.py)."""
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from benchutil import write_json

    write_json(path, rec, "--work")


def run_planner_sweep(work: str) -> dict:
    """``cspace bench`` on a small sweep; the record points at its results.json."""
    out_dir = os.path.join(work, "planners")
    cmd = ["cspace", "bench", *PLANNER_SWEEP, "--out", out_dir]
    t = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, "-c", "from planners.cli import console; console()", *cmd[1:]],
                              capture_output=True, text=True, timeout=TIMEOUT, cwd=ROOT)
        rc, out, err = proc.returncode, proc.stdout, proc.stderr
    except subprocess.TimeoutExpired:
        rc, out, err = "timeout", "", f"timed out after {TIMEOUT} s"
    res = os.path.join(out_dir, "results.json")
    rec = {"name": "cspace_bench", "command": " ".join(cmd[:-2] + ["--out", "OUT"]),
           "seconds": time.perf_counter() - t, "rc": rc, "stdout": out, "stderr": err[-2000:],
           "json": res if os.path.exists(res) else None}
    _write_json(os.path.join(work, "cspace_bench.run.json"), rec)
    return rec


def _shown(cmd: list[str], json_path: str) -> str:
    """The command as a reader would type it (JSON into a local file name)."""
    return " ".join(shlex.quote(c if c != json_path else os.path.basename(json_path)) for c in cmd)


# ---------------------------------------------------------------- rendering

def fmt(v) -> str:
    """A cell: 4 significant digits for floats, as-is otherwise.

    >>> fmt(0.000123456), fmt(12345.678), fmt(3), fmt(None), fmt(True), fmt([1, 2.5]), fmt([{"a": 1}])
    ('0.0001235', '1.235e+04', '3', '-', 'True', '[1, 2.5]', '(1 items)')
    """
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, (list, tuple)) and not any(isinstance(x, (list, tuple, dict)) for x in v):
        return "[" + ", ".join(fmt(x) for x in v) + "]"
    if isinstance(v, (list, tuple, dict)):
        return f"({len(v)} items)"  # nested records: the printed table above shows them
    return str(v).replace("|", "\\|").replace("\n", " ")


def md_cell(text) -> str:
    r"""A name read from another project's file, safe in a Markdown table cell: its pipes,
    backslashes, backticks, angle brackets and line breaks escaped.

    >>> print(md_cell("a|b <x>`"))
    a\|b &lt;x&gt;\`
    """
    out = str(text).replace("\\", "\\\\").replace("|", "\\|").replace("`", "\\`")
    return out.replace("<", "&lt;").replace(">", "&gt;").replace("\r", " ").replace("\n", " ")


def md_table(rows: list[dict]) -> str:
    """A Markdown table of dict rows (columns in first-seen order).

    >>> print(md_table([{"a": 1, "b": 0.5}, {"a": 2, "c": "x"}]))
    | a | b | c |
    |---|---|---|
    | 1 | 0.5 | - |
    | 2 | - | x |
    """
    cols = list(dict.fromkeys(k for r in rows for k in r))
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    lines += ["| " + " | ".join(fmt(r.get(c)) for c in cols) + " |" for r in rows]
    return "\n".join(lines)


def json_tables(data, title: str = "") -> list[str]:
    """Markdown for a JSON result: each list of rows becomes tables (rows grouped by their fields)."""
    out = []
    if isinstance(data, list) and data and all(isinstance(r, dict) for r in data):
        groups: dict = {}
        for r in data:
            groups.setdefault(tuple(r), []).append(r)
        for rows in groups.values():
            out.append((f"*{title}*\n\n" if title else "") + md_table(rows))
    elif isinstance(data, dict):
        scalars = {k: v for k, v in data.items() if not isinstance(v, (list, dict))}
        if scalars:
            out.append((f"*{title}*: " if title else "") + ", ".join(f"{k} = {fmt(v)}" for k, v in scalars.items()))
        for k, v in data.items():
            if isinstance(v, (list, dict)):
                out += json_tables(v, f"{title}.{k}" if title else k)
    return out


def planner_tables(path: str) -> list[str]:
    """The error-against-run-time summary of a ``cspace bench`` results.json."""
    sys.path.insert(0, ROOT)
    from planners.pictures.bench_figure import curves

    with open(path) as fh:
        data = json.load(fh)
    rows = data["rows"] if isinstance(data, dict) and "rows" in data else data
    table = []
    for (scen, planner), c in curves(rows).items():
        for i, t in enumerate(c["time"]):
            table.append({"scenario": scen, "planner": planner, "budget s": t, "runs": c["runs"][i],
                          "success": f"{c['success'][i]:.0%}", "median error": c["median"][i],
                          "25%": c["q25"][i], "75%": c["q75"][i]})
    return [md_table(table)] if table else ["(no rows)"]


def benchmr_lines(rec: dict) -> list[str]:
    """The Bench-MR section's body from its run's JSON: the table, the ratios per world, the
    peer's recheck counts and the pictures of the polygon worlds (``--figures``).

    >>> rec = {"json": None, "stdout": "no Bench-MR checkout at '' (...): nothing run\\n"}
    >>> benchmr_lines(rec)[0].startswith("Not run: it needs a Bench-MR checkout")
    True
    """
    data, not_run = checkout_data(rec, "bench_benchmr")
    if data is None:
        return not_run
    ms = lambda v: "-" if v is None else f"{v * 1e3:.0f} ms"  # noqa: E731
    x = lambda v: "-" if v is None else f"{v:.2f}x"  # noqa: E731
    load = data.get("load_start")
    lines = ["Time: CPU seconds to the first path of each query and seed, ours certified (the default planner's "
             "order: a slice of sampling, the proof before sampling only where it found nothing, then RRTConnect, RRT "
             "for Dubins), the peer's OMPL's same planner with a shapely state check and the discrete motion check at "
             "Bench-MR's step (0.005 of its box's extent); each world's C-space is built once, before its queries "
             "(its own column), as the peer's checker is. A polygon world's bounds are its obstacles' box and two "
             "turning radii around it: Bench-MR bounds only the states its planners sample, its motion check walks "
             "curves out of the drawing and back (`--box-bounds`: the box alone). Every path of either side is "
             "judged by an independent swept check (colliding).", "",
             f"Load average at the run's start: {', '.join(f'{v:.2f}' for v in load)} (a 2-core machine shared with "
             "other work: absolute times are inflated, the ratios were measured in the same run)." if load else "", "",
             "| world | car | runs | C-space (once) | ours solved (proven unsolvable) | undecided | ours colliding | "
             "ours median | ours mean | peer solved | peer colliding | peer median | peer mean | "
             "ours / peer, medians | means |", "|" + "---|" * 15]
    for r in data["rows"]:
        lines.append("| " + " | ".join([
            md_cell(r["world"]), r["space"], str(r["runs"]) + (f" ({r['left_out']} rows left out)" if r.get("left_out") else ""),
            ms(r.get("prep_s")), f"{r['ours_solved']} ({r['proven_unsolvable']})", str(len(r.get("undecided_queries", []))),
            str(r["ours_colliding"]), ms(r["ours_median_s"]), ms(r["ours_mean_s"]), str(r.get("peer_solved", "-")),
            str(r.get("peer_colliding", "-")), ms(r.get("peer_median_s")), ms(r.get("peer_mean_s")),
            x(r.get("ratio")), x(r.get("ratio_mean"))]) + " |")
    proven = [r for r in data["rows"] if r.get("proven_unsolvable")]
    if proven:
        lines += ["", "Proven unsolvable (runs; every proof re-checked by `cspace check-proof`'s independent checker; "
                  "a Dubins car's is the reach proof of one end, closed under its forward steps):", ""]
        lines += [f"- {md_cell(r['world'])} {r['space']}: {r['proven_unsolvable']} runs, {r.get('proofs_accepted', '-')} proofs "
                  f"accepted, median {ms(r.get('proven_proof_median_s'))} CPU for the proofs" for r in proven]
    undecided = [(md_cell(r["world"]), r["space"], q, r.get("boxed_in", {}).get(str(q))) for r in data["rows"]
                 for q in r.get("undecided_queries", [])]
    if undecided:
        lines += ["", "Undecided: neither a path nor a proof within the time limit (for a Dubins car, neither the SE(2) "
                  "proof nor the reach proof of either end, within its cap); where a lattice of certified steps shows "
                  "the start's reach, or the goal's, ending away from the other end, it is named "
                  "(evidence, not a proof):", ""]
        lines += [f"- {w} {sp} query {q}: {why or 'no lattice evidence either'}" for w, sp, q, why in undecided]
    lines += ["", "Ours / the peer per world (both car models; the runs both solve with the peer's path sound), "
              "target <= 0.5x:", "", "| world | runs | medians | means |", "|---|---|---|---|"]
    lines += [f"| {md_cell(w['world'])} | {w['sound_runs']} | {x(w['ratio_median'])} | {x(w['ratio_mean'])} |"
              for w in data.get("worlds", [])]
    checked = [r for r in data["rows"] if r.get("peer_recheck")]
    if checked:
        lines += ["", "The peer's paths (each called collision-free by its discrete check at Bench-MR's 0.005), "
                  "written in Bench-MR's results format and re-checked by `cspace recheck`'s routine:", "",
                  "| world | car | peer's paths | colliding |", "|---|---|---|---|"]
        lines += [f"| {md_cell(r['world'])} | {r['space']} | {r['peer_recheck']['paths']} | {r['peer_recheck']['colliding']} |"
                  for r in checked]
    figures = sorted(glob.glob(os.path.join(ROOT, BENCH_MR_FIGURES, "*.png")))
    if figures:
        lines += ["", "cspace's paths (seed 0, one C-space per world and car model; `--figures`):", ""]
        lines += [f"![{os.path.splitext(os.path.basename(f))[0]}](figures/benchmr/{os.path.basename(f)})" for f in figures]
    return lines + [""]


def omplapp_lines(rec: dict) -> list[str]:
    """The OMPL.app section's body from its run's JSON: what was timed and judged, the load, the
    table per problem with the target's check.

    >>> omplapp_lines({"json": None, "stdout": ""})[0].startswith("Not run: it needs an OMPL.app checkout")
    True
    """
    data, not_run = checkout_data(rec, "bench_omplapp")
    if data is None:
        return not_run
    ms = lambda v: "-" if v is None else f"{v * 1e3:.1f} ms"  # noqa: E731
    x = lambda v: "-" if v is None else f"{v:.2f}x"  # noqa: E731
    load, end = data.get("load_start"), data.get("load_end")
    n = data.get("seeds")
    lines = [f"OMPL.app's five geometric planar problems (`resources/2D` of the checkout DIR, read as they are), {n} "
             f"seeds, {data.get('time', 10):g} s a run. Time: CPU seconds to the first path, ours the default planner "
             "`auto` (certified; the C-space built once before the seeds, its own column), the peer OMPL's RRTConnect "
             "on the same state space with coal and OMPL's discrete motion check at its default step; interleaved per "
             "seed. Every path of both is judged afterwards by the independent sweep (`scripts/sweep_oracle.py`): "
             "rejected = colliding, undecided = closer than the sweep resolves (neither counts as sound). ours / coal "
             "is the median of the per-seed ratios over the seeds whose coal path is sound (all seeds beside); target "
             "<= 0.5x (issue 47).", ""]
    if load:
        lines += [f"Load average at the run's start: {', '.join(f'{v:.2f}' for v in load)}"
                  + (f"; at its end: {', '.join(f'{v:.2f}' for v in end)}" if end else "")
                  + " (a 2-core machine shared with other work: absolute times are inflated, the ratios were measured "
                    "in the same run).", ""]
    lines += ["| problem | obstacle vertices | C-space (once) | ours solved | ours median | ours not sound | coal solved "
              "| coal median | coal rejected | coal undecided | ours / coal (sound) | (all) | target <= 0.5x |",
              "|" + "---|" * 13]
    for r in data["rows"]:
        lines.append("| " + " | ".join([
            md_cell(r["problem"]), str(r["vertices"]), ms(r["prep_s"]), f"{r['ours_solved']}/{r['seeds']}", ms(r["ours_median_s"]),
            str(r["ours_not_sound"]), f"{r['coal_solved']}/{r['seeds']}", ms(r["coal_median_s"]),
            str(r["coal_colliding"]), str(r["coal_undecided"]), x(r["ratio_sound"]) + f" ({r['sound_seeds']} seeds)",
            x(r["ratio_all"]), "met" if r["target_met"] else "**MISSED**"]) + " |")
    if data.get("skipped"):
        lines += ["", "Skipped: " + ", ".join(f"`{f}`" for f in data["skipped"]) + " (kinodynamic control problems: "
                  "cspace plans no control space)."]
    return lines + [""]


def machine_note(work: str) -> str:
    """Where the numbers were measured (saved with the run, so --from keeps it)."""
    path = os.path.join(work, "machine.json")
    if os.path.exists(path):
        with open(path) as fh:
            m = json.load(fh)
    else:
        import numpy

        m = {"date": dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
             "platform": platform.platform(), "processor": platform.processor() or platform.machine(),
             "cpus": os.cpu_count(), "python": platform.python_version(), "numpy": numpy.__version__,
             "load": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}
        sys.path.insert(0, ROOT)
        from planners.output import write_text

        write_text(path, json.dumps(m), "--work")
    load = f"; load average at start {', '.join(f'{x:.2f}' for x in m['load'])}" if m.get("load") else ""
    return (f"Measured {m['date']} on {m['platform']} ({m['processor']}, {m['cpus']} logical CPUs{load}), "
            f"Python {m['python']}, numpy {m['numpy']}.")


def render(records: list[dict], missing: list[str], work: str) -> str:
    lines = [
        "# Benchmarks",
        "",
        "<!-- generated by scripts/make_benchmarks_page.py: do not edit by hand -->",
        "",
        "Generated by `python scripts/make_benchmarks_page.py` from the quick modes of the bench",
        "scripts: every table below is the scripts' own output (medians over repetitions; ratios",
        "against peers measured in the same run). Absolute times depend on the machine and its",
        "load; the ratios are the meaningful part. The full (slower) runs are the same commands",
        "without the quick arguments.",
        "",
        machine_note(work),
        "",
        "## Reproduce",
        "",
        "```sh",
        "python scripts/make_benchmarks_page.py            # runs everything below, rewrites this page",
    ]
    lines += [r["command"] for r in records]
    lines += ["```", ""]
    for r in records:
        when = _when(r, work)
        lines += [f"## {r['name']}", "", f"`{r['command']}` ({r['seconds']:.0f} s wall, exit {r['rc']}{when})", ""]
        if r["name"] == "cspace_bench":
            lines += ["Error = path length / exact optimum − 1 over the solved runs (median and the 25–75 %",
                      "band), and the share of runs solved, per time budget. See the guide,",
                      "[reading the error-against-run-time report](guide.md#reading-the-error-against-run-time-report).",
                      ""]
            if r.get("json"):
                for t in planner_tables(r["json"]):
                    lines += [t, ""]
            if r["stdout"].strip():
                lines += ["```", r["stdout"].rstrip(), "```", ""]
        elif r["name"] in CHECKOUTS:
            lines += benchmr_lines(r) if r["name"] == "bench_benchmr" else omplapp_lines(r)
            if r["stdout"].strip() and r.get("json"):
                lines += ["<details><summary>The script's output</summary>", "", "```", r["stdout"].rstrip(), "```", "",
                          "</details>", ""]
        else:
            if r["stdout"].strip():
                lines += ["```", r["stdout"].rstrip(), "```", ""]
            if r.get("json"):
                with open(r["json"]) as fh:
                    data = json.load(fh)
                tables = json_tables(data)
                if tables:
                    lines += ["<details><summary>JSON rows</summary>", ""]
                    for t in tables:
                        lines += [t, ""]
                    lines += ["</details>", ""]
        if r["rc"] != 0:
            lines += ["**This run did not finish cleanly:**", "", "```", (r["stderr"] or "").rstrip(), "```", ""]
    if missing:
        lines += ["## Not yet run", ""]
        lines += [f"- `scripts/{m}.py`: not in the repository when this page was generated" for m in missing]
        lines += [""]
    return "\n".join(lines)


def _when(rec: dict, work: str) -> str:
    """When a run started and the machine's load then (the machine may be shared); a record
    without them: the page run's start, from the folder's machine.json."""
    if rec.get("load"):
        return f"; started {rec['date']}, load average {', '.join(f'{x:.2f}' for x in rec['load'])}"
    path = os.path.join(work, "machine.json")
    if not os.path.exists(path):
        return ""
    with open(path) as fh:
        m = json.load(fh)
    load = m.get("load")
    return f"; the page run started {m['date']}, load average then {', '.join(f'{x:.2f}' for x in load)}" if load else ""


def _sections(text: str) -> list[tuple[str, str]]:
    """The page cut at its ``## `` headings: (name, text) pairs, the preamble named ''."""
    out, name, buf = [], "", []
    for line in text.splitlines(keepends=True):
        if line.startswith("## "):
            out.append((name, "".join(buf)))
            name, buf = line[3:].strip(), []
        buf.append(line)
    out.append((name, "".join(buf)))
    return out


def splice(old: str, new: str, names: set) -> str:
    r"""``old`` with the sections ``names`` taken from ``new`` (added before "Not yet run"
    when the old page lacks them), and ``new``'s commands added to the Reproduce block:
    what ``--only`` writes, so that the other sections keep their measurements.

    >>> old = "# B\n\n## Reproduce\n\n```sh\nmake\n```\n\n## a\n\nold a\n\n## b\n\nold b\n"
    >>> new = "# B\n\n## Reproduce\n\n```sh\nmake\npython b\npython c\n```\n\n## b\n\nnew b\n\n## c\n\nnew c\n"
    >>> print(splice(old, new, {"b", "c"}), end="")
    # B
    <BLANKLINE>
    ## Reproduce
    <BLANKLINE>
    ```sh
    make
    python b
    python c
    ```
    <BLANKLINE>
    ## a
    <BLANKLINE>
    old a
    <BLANKLINE>
    ## b
    <BLANKLINE>
    new b
    <BLANKLINE>
    ## c
    <BLANKLINE>
    new c
    <BLANKLINE>
    """
    fresh = dict(_sections(new))
    parts = _sections(old)
    have = {n for n, _ in parts}
    out = []
    for name, text in parts:
        if name == "Reproduce" and "Reproduce" in fresh:
            lines = text.rstrip("\n").split("\n")
            end = max(i for i, ln in enumerate(lines) if ln.strip() == "```")
            known = set(lines)
            extra = [ln for ln in fresh["Reproduce"].split("\n") if ln.startswith("python ") and ln not in known]
            text = "\n".join(lines[:end] + extra + lines[end:]) + "\n\n"
        elif name == "Not yet run":
            out += [fresh[n] for n in names if n in fresh and n not in have]
            have |= names
        out.append(fresh[name] if name in names and name in fresh else text)
    out += [fresh[n] for n in sorted(names) if n in fresh and n not in have]
    return "".join(t.rstrip("\n") + "\n\n" for t in out if t.strip())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "benchmarks.md"))
    ap.add_argument("--work", help="folder for the runs' outputs (default: a temporary folder)")
    ap.add_argument("--from", dest="source", help="render from the outputs in this folder, without running")
    ap.add_argument("--only", help="comma-separated bench names to run (e.g. bench_minkowski,cspace_bench); "
                                   "the page's other sections are kept as they are")
    ap.add_argument("--no-planners", action="store_true", help="skip the cspace bench sweep")
    ap.add_argument("--bench-mr", default=os.environ.get("BENCH_MR") or None, metavar="DIR",
                    help="a Bench-MR checkout for scripts/bench_benchmr.py (default: $BENCH_MR; without one its "
                         "section says how to run it)")
    ap.add_argument("--omplapp", default=os.environ.get("OMPLAPP") or None, metavar="DIR",
                    help="an OMPL.app checkout (or its resources/2D) for scripts/bench_omplapp.py (default: $OMPLAPP; "
                         "without one its section says how to run it)")
    args = ap.parse_args(argv)
    sys.path.insert(0, ROOT)
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from benchutil import check_out

    # Before any work: the page never over a file the benches read (the bundled scenarios, a given
    # checkout's top folder) nor one of the --from records; --work a folder that can be written.
    scenes = [os.path.join(ROOT, "scenarios")] + [os.path.join(ROOT, "scenarios", d) for d in ("ompl", "se2", "car", "maps")]
    check_out(args.out, [p for p in (*scenes, args.source, args.bench_mr, args.omplapp) if p and os.path.isdir(p)],
              "--out")
    if args.work and not args.source:
        check_out(args.work, (), "--work", folder=True)
    found = {os.path.splitext(os.path.basename(p))[0]: p for p in sorted(glob.glob(os.path.join(ROOT, "scripts", "bench_*.py")))}
    order = [n for n in EXPECTED if n in found] + [n for n in found if n not in EXPECTED]
    missing = [n for n in EXPECTED if n not in found]
    only = set(args.only.split(",")) if args.only else None
    if args.source:
        work = args.source
        records = []
        for n in order + ["cspace_bench"]:
            if only and n not in only:
                continue
            p = os.path.join(work, f"{n}.run.json")
            if os.path.exists(p):
                with open(p) as fh:
                    records.append(json.load(fh))
            elif n != "cspace_bench":
                missing.append(n)
    else:
        work = args.work or tempfile.mkdtemp(prefix="cspace-bench-")
        os.makedirs(work, exist_ok=True)
        machine_note(work)
        records = []
        for n in order:
            if only and n not in only:
                continue
            print(f"running {n} ...", flush=True)
            checkout = {"bench_benchmr": args.bench_mr, "bench_omplapp": args.omplapp}.get(n)
            if n in CHECKOUTS and not checkout:  # its data lives outside the repository
                records.append({"name": n, "command": f"python scripts/{n}.py {CHECKOUTS[n]} DIR", "seconds": 0.0,
                                "rc": 0, "stdout": "", "stderr": "", "json": None})
                continue
            records.append(run_script(n, found[n], work, checkout))
            print(f"  {records[-1]['seconds']:.0f} s, exit {records[-1]['rc']}", flush=True)
        if not args.no_planners and (not only or "cspace_bench" in only):
            print("running cspace bench ...", flush=True)
            records.append(run_planner_sweep(work))
            print(f"  {records[-1]['seconds']:.0f} s, exit {records[-1]['rc']}", flush=True)
    text = render(records, missing, work)
    if only and os.path.exists(args.out):  # (with --from: those sections re-rendered from its records)
        # Only some sections were run: the others keep what the page already shows.
        with open(args.out) as fh:
            text = splice(fh.read(), text + "\n", {r["name"] for r in records}).rstrip("\n")
    sys.path.insert(0, ROOT)
    from planners.output import write_text

    write_text(args.out, text + "\n")
    print(f"wrote {args.out} (run outputs in {work})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
