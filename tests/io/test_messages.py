"""Bad input is exit 2 with one short line, never exit 3 (issue 24 items 5, 8).

Huge integers and hex literals, deep nesting, out-of-range seeds, long names,
byte-order marks and UTF-16, giant echoed values, numpy warnings.
"""
from __future__ import annotations

import os
import re
import warnings

import pytest

from conftest import ROOT
from cspace.io.scenario.messages import clip, show
from cspace.io.load import ScenarioError, load_scenario
from planners.cli import main

BASIC = open(os.path.join(ROOT, "scenarios", "basic.toml"), encoding="utf-8").read()


def run(capsys, *argv):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse's errors end here (our one-line parser error)
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def bad(capsys, tmp_path, text: str | bytes, *extra, field=None, limit=400):
    """The scenario ``text`` through ``cspace show``: exit 2 and one short line naming ``field``."""
    f = tmp_path / "s.toml"
    f.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
    code, out, err = run(capsys, "show", f, *extra)
    lines = err.strip().splitlines()
    assert code == 2, (code, err[:300])
    assert len(lines) == 1 and lines[0].startswith(f"error: {f}: "), err[:300]
    assert len(lines[0]) < limit, len(lines[0])
    if field is not None:
        assert f": {field}: " in lines[0], lines[0]
    return lines[0]


def with_start_x(value: str) -> str:
    return BASIC.replace("[start]\nx = 1.0", f"[start]\nx = {value}", 1)


def test_the_fixture_edit_applies():
    assert with_start_x("7") != BASIC


# ------------------------------------------------------------------ item 5: internal errors for bad input


def test_an_integer_of_5000_digits_is_bad_toml_not_an_internal_error(capsys, tmp_path):
    bad(capsys, tmp_path, with_start_x("9" * 5000), field="toml")


def test_a_4000_digit_hex_literal_is_one_short_line(capsys, tmp_path):
    msg = bad(capsys, tmp_path, with_start_x("0x" + "f" * 4000), field="start.x")
    assert "digits" in msg


def test_a_deeply_nested_array_is_one_line(capsys, tmp_path):
    bad(capsys, tmp_path, with_start_x("[" * 5000 + "]" * 5000), field="toml")


@pytest.mark.parametrize("depth", [50, 200])
def test_a_nested_point_is_one_line(capsys, tmp_path, depth):
    text = BASIC.replace("[[3, 0], [4, 0], [4, 6], [3, 6]]", "[" * depth + "1" + "]" * depth + ", [4, 0], [4, 6]]", 1)
    assert text != BASIC
    bad(capsys, tmp_path, text)


@pytest.mark.parametrize("seed", [str(2**64), str(2**63), str(2**32 - 1), "-1"])
def test_seed_out_of_range_in_the_file_is_exit_2(capsys, tmp_path, seed):
    text = re.sub(r"(?m)^seed = .*$", f"seed = {seed}", BASIC)
    assert text != BASIC
    f = tmp_path / "s.toml"
    f.write_text(text)
    code, _, err = run(capsys, "plan", f)
    assert code == 2 and "planner.seed" in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("seed", [str(2**64), str(2**63), str(2**32 - 1)])
def test_seed_option_out_of_range_is_exit_2(capsys, tmp_path, seed):
    f = tmp_path / "s.toml"
    f.write_text(BASIC)
    code, _, err = run(capsys, "plan", f, "--seed", seed)
    assert code == 2 and "--seed" in err and len(err.strip().splitlines()) == 1, err


def test_the_largest_seed_plans(capsys, tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(BASIC)
    assert run(capsys, "plan", f, "--seed", str(2**32 - 2))[0] == 0


def test_a_300_character_name_in_the_bench(capsys, tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(BASIC.replace('name = "basic"', f'name = "{"n" * 300}"'))
    out = tmp_path / "out"
    code, _, err = run(capsys, "bench", f, "--out", out, "--runs", "1", "--times", "0.02",
                       "--planners", "RRTConnect", "--no-plot", "-q")
    assert code == 0, err
    logs = os.listdir(out / "ompl")
    assert len(logs) == 1 and len(logs[0].encode()) <= 255


def test_bench_log_names_stay_distinct_when_cut():
    from planners.bench.outputs import _token

    a, b = _token("x" * 300 + "a"), _token("x" * 300 + "b")
    assert a != b and len(a) < 100


# ------------------------------------------------------------------ item 8: encodings and messages


def test_a_utf8_byte_order_mark_loads(tmp_path):
    f = tmp_path / "bom.toml"
    f.write_bytes(b"\xef\xbb\xbf" + BASIC.encode("utf-8"))
    assert load_scenario(str(f)).bounds == load_scenario(os.path.join(ROOT, "scenarios", "basic.toml")).bounds


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be", "utf-32"])
def test_utf16_is_one_clear_line(capsys, tmp_path, encoding):
    msg = bad(capsys, tmp_path, BASIC.encode(encoding), field="file")
    assert "UTF-8" in msg


def test_latin1_names_the_offset(capsys, tmp_path):
    msg = bad(capsys, tmp_path, ('name = "caf\xe9"\n' + BASIC).encode("latin-1"), field="file")
    assert "offset" in msg


def test_a_point_with_200000_coordinates_gives_a_short_line(capsys, tmp_path):
    pt = "[" + ", ".join(["1.5"] * 200_000) + "]"
    bad(capsys, tmp_path, BASIC.replace("[[3, 0], [4, 0], [4, 6], [3, 6]]", f"[{pt}, [4, 0], [4, 6]]", 1),
        field="obstacles[0].polygon[0]", limit=300)


def test_a_huge_unknown_key_and_string_value_are_clipped(capsys, tmp_path):
    bad(capsys, tmp_path, "k" * 100_000 + " = 1\n" + BASIC, limit=500)
    bad(capsys, tmp_path, BASIC.replace("[start]\nx = 1.0", f'[start]\nx = "{"s" * 100_000}"', 1),
        field="start.x", limit=300)


def test_huge_option_values_are_clipped(capsys, tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(BASIC)
    for args in (["--time", "x" * 100_000], ["--planner", "p" * 100_000], ["--seed", "9" * 100_000]):
        code, _, err = run(capsys, "plan", f, *args)
        assert code == 2 and len(err) < 500 and len(err.strip().splitlines()) == 1, err[:200]


def test_clip_and_show_never_fail():
    assert len(clip("x" * 10**6)) < 200
    assert "digits" in show(10**100_000) and "digits" in show(-(16**4000))
    nested = []
    for _ in range(5000):
        nested = [nested]
    assert len(show(nested)) < 200
    assert str(ScenarioError("f" * 10**5, "g" * 10**5, "m" * 10**6)).count("more characters") == 3


def quiet_show(tmp_path, text: str):
    """``cspace show`` in a fresh interpreter, where warnings print as a user sees them
    (pytest would catch them in-process)."""
    import subprocess
    import sys

    f = tmp_path / "s.toml"
    f.write_text(text)
    return subprocess.run([sys.executable, "-m", "planners.cli", "show", str(f)], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)


def test_numpy_warnings_never_reach_the_terminal(tmp_path):
    """A degenerate C-obstacle piece (a disk below the ulp) made the broad phase divide 0 by 0."""
    r = quiet_show(tmp_path, "[bounds]\nxmin = 49999990.0\nxmax = 50000010.0\nymin = 49999990.0\n"
                             "ymax = 50000010.0\n[[obstacles]]\ncenter = [50000000.0, 50000000.0]\nradius = 1e-9\n"
                             "[start]\nx = 49999995.0\ny = 50000000.0\n[goal]\nx = 50000005.0\ny = 50000000.0\n")
    assert r.returncode in (0, 2) and "Warning" not in r.stderr and len(r.stderr.splitlines()) <= 1, r.stderr


def test_huge_bounds_plan_quietly(tmp_path):
    text = BASIC
    for key in ("xmax", "ymax"):
        text = "\n".join(f"{key} = 1e120" if line.startswith(f"{key} =") else line for line in text.splitlines())
    r = quiet_show(tmp_path, text)
    assert r.returncode == 0 and r.stderr == "", r.stderr


def test_a_robot_file_given_as_a_scenario_says_what_it_is(capsys):
    """A user who plans scenarios/maps/robot.toml (a robot for --robot) is told to pass it with
    --robot, not only that [bounds] is missing; a scene missing [bounds] still hears the old line."""
    code = main(["plan", os.path.join(ROOT, "scenarios", "maps", "robot.toml")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--robot FILE" in err[0], err


def test_a_scene_without_bounds_is_told_the_table_is_missing(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('[robot]\npolygon = [[0, 0], [1, 0], [0, 1]]\n[[obstacles]]\npolygon = [[2, 2], [3, 2], [2, 3]]\n')
    with pytest.raises(ScenarioError, match="bounds: missing \\(a table is required\\)"):
        load_scenario(str(f))


def test_a_pose_in_collision_names_the_obstacle_by_its_box(capsys):
    """An imported map's obstacles have no [[obstacles]] table a user could count: the message
    gives the box of the one the pose touches, and that box holds the pose."""
    code = main(["plan", os.path.join(ROOT, "scenarios", "maps", "office.yaml"), "--start", "1,1", "--goal", "5,5"])
    err = capsys.readouterr().err.strip().splitlines()
    m = re.search(r"goal: \(5.0, 5.0\) .* obstacles\[\d+\] \(the one within x (\S+) to (\S+), y (\S+) to (\S+)\)", err[0])
    assert code == 2 and len(err) == 1 and m, err
    x0, x1, y0, y1 = map(float, m.groups())
    assert x0 <= 5.0 + 0.2 and x1 >= 5.0 - 0.2 and y0 <= 5.0 + 0.2 and y1 >= 5.0 - 0.2  # the robot reaches it


_BASE = {"bounds": "[bounds]\nxmin = -1\nxmax = 5\nymin = -1\nymax = 5\n", "robot": "[robot]\nradius = 0.1\n",
         "start": "[start]\nx = 1.0\ny = 1.0\n", "goal": "[goal]\nx = 4.0\ny = 4.0\n",
         "obstacles": "[[obstacles]]\npolygon = [[0, 0], [2, 0], [2, 2], [0, 2]]\n"}
# the guide's "Some messages, as printed": each line's field, and the file that makes it
_GUIDE_CASES = {
    "colour": {"extra": 'colour = "red"\n'},
    "robot.polgon": {"robot": "[robot]\npolgon = [[0, 0], [1, 0], [0, 1]]\n"},
    "obstacles[1]": {"obstacles": "[[obstacles]]\npolygon = [[3, 0], [4, 0], [4, 1]]\n[[obstacles]]\n"
                                  "center = [3, 3]\nradius = 0.5\npolygon = [[0, 0], [1, 0], [0, 1]]\n"},
    "robot.center": {"robot": "[robot]\ncenter = [0, 0]\nradius = 0.1\n"},
    "goal.theta": {"start": "[start]\nx = 3.0\ny = 1.0\ntheta = 0.5\n", "goal": "[goal]\nx = 4.0\ny = 4.0\ntheta = 1.0\n"},
    "obstacles[0].polygon": {"obstacles": "[[obstacles]]\npolygon = [[0, 0], [2, 2], [2, 0], [0, 2]]\n"},
    "start": {},
    "planner.seed": {"extra": "[planner]\nseed = -1\n"},
}


def test_the_guides_quoted_messages_are_what_runs(tmp_path, capsys, monkeypatch):
    """Every line of the guide's "Some messages, as printed" block is what `cspace plan` prints
    for a file with that fault (the guide quoted a seed message the loader no longer printed)."""
    guide = open(os.path.join(ROOT, "docs", "guide.md"), encoding="utf-8").read()
    block = guide.split("Some messages, as printed:", 1)[1].split("```text\n", 1)[1].split("```", 1)[0]
    lines = block.strip().splitlines()
    assert len(lines) == len(_GUIDE_CASES)
    monkeypatch.chdir(tmp_path)
    for line in lines:
        field = line.split(": ", 2)[1]
        case = _GUIDE_CASES[field]
        (tmp_path / "s.toml").write_text(case.get("extra", "") + "".join(case.get(k, v) for k, v in _BASE.items()))
        assert main(["plan", "s.toml"]) == 2
        assert capsys.readouterr().err.strip() == "error: " + line
