"""The ``cspace`` command through a subprocess: exit codes, one-line errors, quiet output, outputs."""
from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys

import numpy as np
import pytest
import shapely

from conftest import OMPL_SCENES, ROOT

BASIC = """
name = "cli"
[bounds]
xmin = 0
xmax = 10
ymin = 0
ymax = 10
[robot]
polygon = [[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]]
[[obstacles]]
polygon = [[4, 0], [6, 0], [6, 7], [4, 7]]
[start]
x = 1
y = 1
[goal]
x = 9
y = 1
"""

TRAPPED = BASIC.replace("polygon = [[4, 0], [6, 0], [6, 7], [4, 7]]", "polygon = [[4, 0], [6, 0], [6, 10], [4, 10]]")


def cspace(*args, timeout=60):
    """Run the installed command as a user would."""
    exe = os.path.join(os.path.dirname(sys.executable), "cspace")
    return subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=timeout)


def test_plan_solves_and_writes_json_and_plot(write_toml, tmp_path):
    path = write_toml(BASIC)
    out, png = tmp_path / "r.json", tmp_path / "r.png"
    r = cspace("plan", path, "--json", out, "--plot", png, "--seed", 4)
    assert r.returncode == 0, r.stderr
    assert "solved" in r.stdout and r.stderr == ""
    d = json.loads(out.read_text())
    for key in ("scenario", "solved", "exact", "planner", "seed", "path", "length", "timings", "checks", "stages"):
        assert key in d
    assert d["solved"] and d["exact"] and d["seed"] == 4
    path_xy = np.array(d["path"])
    assert tuple(path_xy[0]) == (1.0, 1.0) and tuple(path_xy[-1]) == (9.0, 1.0)
    # the robot swept along each segment overlaps no obstacle's interior (independent check)
    wall = shapely.Polygon([[4, 0], [6, 0], [6, 7], [4, 7]])
    robot = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    for a, b in zip(path_xy[:-1], path_xy[1:]):
        swept = shapely.MultiPoint(np.vstack([robot + a, robot + b])).convex_hull
        assert not swept.intersects(wall.buffer(-1e-12)) or swept.intersection(wall).area == 0
        assert (swept.bounds[0] >= -0.3 - 1e-12) and swept.bounds[2] <= 10.3 + 1e-12
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("ext, magic", [(".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_plot_formats_by_extension(write_toml, tmp_path, ext, magic):
    out = tmp_path / f"p{ext}"
    r = cspace("plan", write_toml(BASIC), "--plot", out)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes().startswith(magic)


def test_unsolvable_exits_1_within_the_time_limit(write_toml, tmp_path):
    import time

    out = tmp_path / "r.json"
    t = time.perf_counter()
    r = cspace("plan", write_toml(TRAPPED), "--time", "0.5", "--json", out)
    elapsed = time.perf_counter() - t
    assert r.returncode == 1, r.stdout + r.stderr
    assert json.loads(out.read_text())["solved"] is False
    assert elapsed < 0.5 + 1.0 + 2.0  # limit + a second + interpreter start-up on a loaded machine
    assert "leaked" not in r.stderr


def test_same_seed_same_path(write_toml, tmp_path):
    path = write_toml(BASIC.replace("[[obstacles]]", "[[obstacles]]\npolygon = [[2, 3], [3, 3], [3, 9], [2, 9]]\n[[obstacles]]"))
    outs = []
    for i in range(2):
        out = tmp_path / f"r{i}.json"
        assert cspace("plan", path, "--seed", 11, "--json", out).returncode == 0
        outs.append(json.loads(out.read_text())["path"])
    assert outs[0] == outs[1]


def test_quiet_by_default_and_verbose_reports_stages(write_toml):
    r = cspace("plan", write_toml(BASIC))
    assert "leaked" not in r.stderr and "Info:" not in r.stdout + r.stderr
    v = cspace("plan", write_toml(BASIC), "--verbose")
    assert v.returncode == 0 and "minkowski" in v.stdout and "index" in v.stdout


BAD = [
    ("missing.toml", None, "file"),
    ("bad.toml", "[bounds\n", "toml"),
    ("bad.toml", BASIC.replace("xmax = 10", 'xmax = "ten"'), "bounds.xmax"),
    ("bad.toml", BASIC.replace("xmax = 10", "xmax = nan"), "bounds.xmax"),
    ("bad.toml", BASIC.replace("[start]\nx = 1\ny = 1\n", ""), "start"),
    ("bad.toml", BASIC.replace("[[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]]", "[[0, 0], [1, 1], [0, 0]]"), "robot.polygon"),
    ("bad.toml", BASIC.replace("[[4, 0], [6, 0], [6, 7], [4, 7]]", "[[4, 0], [6, 7], [6, 0], [4, 7]]"), "obstacles[0].polygon"),
    ("bad.toml", BASIC.replace("[[4, 0], [6, 0], [6, 7], [4, 7]]", "[[4, 0], [5, 0], [6, 0]]"), "obstacles[0].polygon"),
    ("bad.toml", BASIC.replace("ymin = 0", "ymin = 10"), "bounds"),
    ("bad.toml", BASIC.replace("x = 9\n", "x = 12\n"), "goal"),
    ("bad.toml", BASIC.replace("x = 1\n", "x = 4.5\n", 1), "start"),
]


@pytest.mark.parametrize("name, text, field", BAD)
def test_bad_input_exits_2_with_one_line(write_toml, tmp_path, name, text, field):
    path = write_toml(text, name) if text is not None else str(tmp_path / name)
    out = tmp_path / "keep.json"
    out.write_text("previous result\n")
    before = hashlib.sha256(open(path, "rb").read()).hexdigest() if os.path.exists(path) else None
    r = cspace("plan", path, "--json", out)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {path}: {field}: "), r.stderr
    assert "Traceback" not in r.stderr and r.stdout == ""
    assert out.read_text() == "previous result\n"  # nothing already written is lost
    if before is not None:
        assert hashlib.sha256(open(path, "rb").read()).hexdigest() == before


@pytest.mark.parametrize("args, field", [
    (["--planner", "NoSuchPlanner"], "--planner"),
    (["--time", "0"], "--time"),
    (["--time", "-2"], "--time"),
    (["--plot", "x.gif"], "--plot"),
    (["--json", "/no/such/dir/r.json"], "--json"),
    (["--iterations", "-3"], "--iterations"),  # was a silent 'not solved' (exit 1)
    (["--iterations", "0"], "--iterations"),
])
def test_bad_options_exit_2_with_one_line(write_toml, args, field):
    r = cspace("plan", write_toml(BASIC), *args)
    assert r.returncode == 2, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and f": {field}: " in lines[0] and "Traceback" not in r.stderr


def test_non_numeric_option_is_one_line():
    r = cspace("plan", os.path.join(OMPL_SCENES, "env1.toml"), "--time", "abc")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1


def test_show_prints_the_stages(tmp_path):
    out = tmp_path / "scene.png"
    r = cspace("show", os.path.join(OMPL_SCENES, "circles.toml"), "--plot", out)
    assert r.returncode == 0, r.stderr
    assert "minkowski" in r.stdout and "skipped" in r.stdout
    assert out.exists()


def test_closed_pipe_is_quiet():
    # `cspace show ... | head -c 1`: the reader goes away; no traceback, no "internal error"
    code = (
        "import sys, planners.cli as c\n"
        "class Gone:\n"
        "    def write(self, s): raise BrokenPipeError(32, 'Broken pipe')\n"
        "    def flush(self): pass\n"
        "sys.stdout = Gone()\n"
        "sys.exit(c.main(['show', 'scenarios/basic.toml']))\n"
    )
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 141, r.stderr
    assert r.stderr == ""


@pytest.mark.parametrize("args, names", [
    (["plan", "scenarios/basic.toml", "--json", "{}", "--csv", "{}", "--plot", "{}"], ["a.json", "a.csv", "a.png"]),
    *(pytest.param(*c, marks=pytest.mark.slow) for c in [  # (a second each: the other commands in the slow pass)
        (["plan", "scenarios/car/u_turn.toml", "--json", "{}", "--plot", "{}"], ["a.json", "a.png"]),
        (["show", "scenarios/basic.toml", "--json", "{}", "--plot", "{}"], ["a.json", "a.png"]),
        (["show", "scenarios/basic.toml", "--space", "se2", "--plot", "{}"], ["a.png"]),
        (["view", "scenarios/basic.toml", "--out", "{}", "-v"], ["a.html"]),
        (["stability", "--json", "{}"], ["a.json"])]),
])
def test_a_closed_pipe_still_gets_the_files_asked_for(tmp_path, args, names):
    # `cspace plan ... --json out.json | head -1`: the reader goes away before the report is read;
    # the files asked for are written all the same (found by hand: they were lost), then 141, quietly
    r, w = os.pipe()
    os.close(r)  # a reader gone before the first line: every write to stdout fails at once
    outs = iter(tmp_path / n for n in names)
    args = [str(next(outs)) if a == "{}" else a for a in args]
    try:
        p = subprocess.run([sys.executable, "-m", "planners.cli", *args], cwd=ROOT, stdout=w, stderr=subprocess.PIPE,
                           text=True, timeout=300)
    finally:
        os.close(w)
    assert p.returncode == 141, p.stderr
    assert p.stderr == ""
    assert all((tmp_path / n).exists() and (tmp_path / n).stat().st_size > 0 for n in names)
    if names[0] == "a.json" and args[0] == "plan":
        assert json.loads((tmp_path / "a.json").read_text())["solved"] is True


def test_version_is_one_line_naming_the_dependencies():
    import cspace as pkg
    from importlib import metadata

    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    r = cspace("--version")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    line = r.stdout.strip()
    assert "\n" not in line and line.startswith(f"cspace {pkg.__version__} (Python ")
    for dep in ("numpy", "shapely", "ompl"):
        assert f"{dep} " in line
    # One version, three places: pyproject.toml, the package, the installed metadata.
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        assert tomllib.load(fh)["project"]["version"] == pkg.__version__ == metadata.version("cspace")


def test_the_listing_shows_the_help_each_command_registers():
    # `cspace --help` lists the commands from planners.cli.HELP without importing them.
    import argparse
    import importlib

    from planners.cli import COMMANDS, HELP

    assert set(HELP) == set(COMMANDS)
    for name, module in COMMANDS.items():
        sub = argparse.ArgumentParser().add_subparsers()
        importlib.import_module(module).register(sub)
        assert sub._choices_actions[0].help == HELP[name], name


def test_bare_command_lists_the_commands_and_exits_0():
    from planners.cli import COMMANDS

    r = cspace()
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert r.stdout.startswith("usage: cspace")
    for name in COMMANDS:
        assert f"\n    {name} " in r.stdout or f"\n    {name}\n" in r.stdout, name
    assert "--version" in r.stdout


def test_a_disk_below_the_ulp_of_its_centre_is_refused_in_one_line(write_toml):
    # Radius 1e-200 at (5, 5): the disk rounds to the point (5, 5). Its C-obstacle used to
    # be placed at the origin (a point operand dropped by the vectorised sum, a false
    # "free" at (5, 5)) and the broad phase printed a RuntimeWarning about the piece's
    # zero-length edges. Such a disk cannot be represented: bad input, exit 2.
    text = BASIC.replace("[[obstacles]]\npolygon = [[4, 0], [6, 0], [6, 7], [4, 7]]",
                         "[[obstacles]]\ncenter = [5, 5]\nradius = 1e-200")
    r = cspace("plan", write_toml(text), "--planner", "exact")
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "obstacles[0].radius: 1e-200 is too small for a disk centred at (5.0, 5.0)" in r.stderr
    # Small but representable, and a tiny disk robot (centred on the origin): planned, quietly.
    r = cspace("plan", write_toml(text.replace("radius = 1e-200", "radius = 1e-12")
                                  .replace("[robot]\npolygon = [[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]]",
                                           "[robot]\nradius = 1e-200")), "--planner", "exact")
    assert r.returncode == 0 and r.stderr == "", r.stderr


@pytest.mark.parametrize("name", sorted(__import__("planners.cli", fromlist=["COMMANDS"]).COMMANDS))
def test_every_option_says_what_it_does_and_its_default(name):
    # `cspace COMMAND --help` explains each option, and shows each default that is a value
    # (a switch's False and a "not given" None are not shown)
    import argparse

    from planners.cli.command import build_parser

    sub = next(a for a in build_parser(name)._actions if isinstance(a, argparse._SubParsersAction)).choices[name]
    for action in sub._actions:
        if not action.option_strings or action.help == argparse.SUPPRESS:
            continue
        assert action.help, f"cspace {name} {action.option_strings[0]}: no help text"
        if action.default not in (None, False, argparse.SUPPRESS):
            assert "default" in action.help, f"cspace {name} {action.option_strings[0]}: default {action.default!r} unsaid"
