"""Control characters in names (issue 48, point 10): a scenario's ``name`` with one is refused in
one line; a name taken from a file's name is shown with them escaped; no message, summary or
log line carries a raw one (an escape sequence recolours a terminal, a newline breaks a log)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import ROOT, SCENARIOS
from cspace.io.scenario.messages import CONTROL, clip, printable

BASIC = os.path.join(SCENARIOS, "basic.toml")
HOSTILE = ["\x1b[31mred", "two\nlines", "cr\rhere", "del\x7f", "csi\x9b31m", "bidi\u202eevil", "nul\x00",
           "tab\there", "iso\u2066x\u2069"]


def cspace(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "planners.cli", *args], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=300)


@given(st.text())
def test_printable_leaves_no_control_character_and_keeps_plain_text(text):
    out = printable(text)
    assert CONTROL.search(out) is None and CONTROL.search(clip(text)) is None
    if CONTROL.search(text) is None:
        assert out == text


def toml_string(s: str) -> str:
    return '"' + "".join(c if c.isprintable() and c not in '"\\' else f"\\u{ord(c):04x}" for c in s) + '"'


@pytest.mark.parametrize("name", HOSTILE, ids=range(len(HOSTILE)))
def test_a_name_with_a_control_character_is_refused_in_one_line(tmp_path, name):
    text = open(BASIC, encoding="utf-8").read().replace('name = "basic"', f"name = {toml_string(name)}", 1)
    assert text != open(BASIC, encoding="utf-8").read()
    f = tmp_path / "s.toml"
    f.write_text(text, encoding="utf-8")
    r = cspace("plan", str(f), "--planner", "exact")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "name" in r.stderr and "control character" in r.stderr and CONTROL.search(r.stderr.strip()) is None


@pytest.mark.skipif(sys.platform == "win32", reason="control characters in file names")
def test_a_name_from_a_file_name_is_shown_escaped(tmp_path):
    text = open(BASIC, encoding="utf-8").read().replace('name = "basic"', "", 1)
    f = tmp_path / "evil\x1b[31m\n|>>>.toml"
    f.write_text(text, encoding="utf-8")
    r = cspace("plan", str(f), "--planner", "exact", "-v")
    assert r.returncode == 0, r.stderr
    assert CONTROL.search((r.stdout + r.stderr).replace("\n", "")) is None
    assert "evil\\x1b[31m\\n|>>>" in r.stdout


MATH = ["a $\\frac{1 x$ b", "$$", "$x^$", "back\\slash $\\undefined$", "50$ and 60$"]


# One name in the quick pass, every one in the slow pass (each draws every picture: ~2.5 s).
@pytest.mark.parametrize("name", [pytest.param(m, marks=() if i == 0 else pytest.mark.slow) for i, m in enumerate(MATH)],
                         ids=range(len(MATH)))
def test_a_name_is_text_in_every_picture_never_mathtext(tmp_path, name):
    # matplotlib reads $...$ as mathtext: a scene's name with dollars raised a ParseException
    # (exit 3) in plot titles; names are text in the plot, the animation and the bench figure
    from planners.cli import main

    text = open(BASIC, encoding="utf-8").read().replace('name = "basic"', f"name = {toml_string(name)}", 1)
    f = tmp_path / "s.toml"
    f.write_text(text, encoding="utf-8")
    assert main(["plan", str(f), "--planner", "exact", "--plot", str(tmp_path / "p.png"),
                 "--animate", str(tmp_path / "a.gif")]) == 0
    assert main(["bench", str(f), "--planners", "RRTConnect", "--times", "0.01", "--runs", "1", "-q",
                 "--out", str(tmp_path / "b")]) == 0
    assert (tmp_path / "p.png").stat().st_size and (tmp_path / "b" / "error_vs_time.png").stat().st_size
