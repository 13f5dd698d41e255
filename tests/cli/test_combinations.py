"""Features meet here (issue 39.12): every bundled scene, in its own space and a few in the others,
planned with the output and planning options in a pairwise covering set. Every pair of options
(each on or off) occurs together in every space, and every scene runs with each option on and
off; each run checks its exit code and every file it asked for (a PNG, a GIF, JSON whose path
matches the CSV, per-query rows with --all-queries, the clearance kept, -v's summary).

The defects this would have caught: --plot with a clearance and a non-convex robot (exit 3),
-v on every rotating plan (exit 1), --csv with --all-queries writing query 0 only.
"""
from __future__ import annotations

import contextlib
import csv
import glob
import io
import itertools
import json
import os

import pytest

from conftest import SCENARIOS
from cspace.io.load import load_scenario
from planners.cli import main

OPTIONS = ("plot", "json", "csv", "animate", "verbose", "clearance", "all_queries")
D = 0.01  # the clearance asked for: small, so that every solvable scene stays solvable
# scenes built with almost no room (a door 1.001 times the robot, a plank that barely turns)
TIGHT = {"narrow_passage.toml": 1e-5, "door_tight.toml": 1e-6, "hole_turn.toml": 1e-6,
         "plank_corner_tight.toml": 1e-6, "parking.toml": 1e-3}
SLOW = {"env2.toml", "big.toml"}  # ~10 s of PRM each: planned in test_scenarios with their defaults


def _scenes() -> list[tuple[str, tuple[str, ...]]]:
    """(scenario, extra arguments): each bundled file in its own space, and translation files as
    rotating robots and cars."""
    files = sorted(f for pattern in ("*.toml", "se2/*.toml", "car/*.toml", "ompl/*.toml")
                   for f in glob.glob(os.path.join(SCENARIOS, pattern)) if os.path.basename(f) not in SLOW)
    scenes = [(f, ()) for f in files]
    scenes += [(os.path.join(SCENARIOS, "basic.toml"), ("--space", "se2")),
               (os.path.join(SCENARIOS, "u_robot.toml"), ("--space", "se2")),
               (os.path.join(SCENARIOS, "basic.toml"), ("--space", "reeds-shepp", "--turning-radius", "0.5")),
               (os.path.join(SCENARIOS, "maps", "office.yaml"),
                ("--radius", "0.2", "--start", "0.5,0.5", "--goal", "9.5,6.5"))]
    return scenes


def _pairwise(n_scenes: int) -> list[tuple[int, tuple[bool, ...]]]:
    """Greedy covering rows (scene, options): every scene with every option on and off, and every
    pair of options in each of its four settings. Deterministic: ties go to the first candidate."""
    k = len(OPTIONS)
    need = {("s", s, i, v) for s in range(n_scenes) for i in range(k) for v in (False, True)}
    need |= {("o", i, j, a, b) for i, j in itertools.combinations(range(k), 2) for a in (False, True)
             for b in (False, True)}
    rows = []
    candidates = [(s, o) for s in range(n_scenes) for o in itertools.product((False, True), repeat=k)]

    def covers(row):
        s, o = row
        return {("s", s, i, o[i]) for i in range(k)} | {("o", i, j, o[i], o[j])
                                                        for i, j in itertools.combinations(range(k), 2)}

    while need:
        best = max(candidates, key=lambda row: len(covers(row) & need))
        rows.append(best)
        need -= covers(best)
    return rows


SCENES = _scenes()
ROWS = _pairwise(len(SCENES))


def test_the_rows_cover_every_pair():
    # the covering property itself, checked independently of how the rows were chosen
    for i, j in itertools.combinations(range(len(OPTIONS)), 2):
        assert {(o[i], o[j]) for _, o in ROWS} == {(a, b) for a in (False, True) for b in (False, True)}
    for s in range(len(SCENES)):
        for i in range(len(OPTIONS)):
            assert {o[i] for t, o in ROWS if t == s} == {False, True}, (SCENES[s], OPTIONS[i])
    assert len(ROWS) <= 3 * len(SCENES)


def _queries_file(sc, path) -> str:
    """The scene's query and its reverse, as a --queries file."""
    def pose(p):
        return "[" + ", ".join(repr(float(x)) for x in p) + "]"
    if sc.space == "dubins":  # forward only: the reverse may not exist, so the query twice
        second = f"start = {pose(sc.start)}\ngoal = {pose(sc.goal)}\n"
    else:  # a rigid body and a car with reverse gear drive a path backwards
        second = f"start = {pose(sc.goal)}\ngoal = {pose(sc.start)}\n"
    path.write_text(f"[[queries]]\nstart = {pose(sc.start)}\ngoal = {pose(sc.goal)}\n[[queries]]\n{second}",
                    encoding="utf-8")
    return str(path)


def _label(row) -> str:
    s, o = row
    f, extra = SCENES[s]
    return os.path.relpath(f, SCENARIOS) + ("[" + " ".join(extra[:2]) + "]" if extra else "") + ":" + (
        "+".join(n for n, on in zip(OPTIONS, o) if on) or "bare")


@pytest.mark.slow
@pytest.mark.parametrize("row", ROWS, ids=[_label(r) for r in ROWS])
def test_options_together(row, tmp_path):
    s, o = row
    on = dict(zip(OPTIONS, o))
    f, extra = SCENES[s]
    if f.endswith(".yaml"):  # an imported map: its queries come from the options
        sc = None
    else:
        sc = load_scenario(f, **({"space": extra[1]} if extra[:1] == ("--space",) else {}),
                           **({"turning_radius": float(extra[3])} if "--turning-radius" in extra else {}))
    # A solvable scene planned by a planner that stops at its first path gets a generous budget: its
    # time is what the machine needs (the pure path, a loaded machine), never part of the answer.
    first = (sc.planner.get("name", "RRTConnect") if sc is not None else "RRTConnect") in ("RRTConnect", "exact")
    budget = "60" if first and (sc is None or sc.expect != "unsolvable") else "5"
    args = ["plan", f, *extra, "--seed", "1", "--time", budget]
    out = {k: tmp_path / n for k, n in (("plot", "p.png"), ("json", "p.json"), ("csv", "p.csv"),
                                        ("animate", "p.gif"))}
    for k in ("plot", "json", "csv", "animate"):
        if on[k]:
            args += [f"--{k}", str(out[k])]
    if on["verbose"]:
        args.append("-v")
    margin = TIGHT.get(os.path.basename(f), D)
    if on["clearance"]:
        args += ["--clearance", str(margin)]
    if on["all_queries"] and sc is not None:
        args += ["--queries", _queries_file(sc, tmp_path / "q.toml")]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main(args)
    text, err = stdout.getvalue(), stderr.getvalue()
    unsolvable = sc is not None and sc.expect == "unsolvable"
    assert code == (1 if unsolvable else 0), (args, code, text[-1500:], err[-1500:])
    assert "Traceback" not in err and "internal error" not in err
    if on["verbose"]:
        assert "stages:" in text
    if unsolvable:
        return
    if on["plot"]:
        assert out["plot"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    if on["animate"]:
        assert out["animate"].read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    nq = 2 if on["all_queries"] and sc is not None and sc.space != "dubins" else 1  # (a query twice plans once)
    if on["json"]:
        data = json.loads(out["json"].read_text())
        results = data["queries"] if "queries" in data else [data]
        assert len(results) == nq and all(r["solved"] for r in results)
        if on["clearance"]:  # kept along every motion: the certified (or exact) minimum is at least D
            assert all(r["min_clearance"] is not None and float(r["min_clearance"]) >= margin * (1 - 1e-9)
                       for r in results)  # JSON has no infinity: an empty scene's is "inf"
        paths = [r["path"] for r in results]
    if on["csv"]:
        with open(out["csv"], newline="") as fh:
            rows = list(csv.DictReader(fh))
        if nq > 1:
            assert {r["query"] for r in rows} == {str(i) for i in range(nq)}
        if on["json"]:  # the two files hold the same waypoints
            assert len(rows) == sum(len(p) for p in paths)
            flat = [w for p in paths for w in p]
            assert all(float(r["x"]) == pytest.approx(w[0], abs=1e-9) and float(r["y"]) == pytest.approx(w[1], abs=1e-9)
                       for r, w in zip(rows, flat))
