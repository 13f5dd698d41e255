"""docs/guide.md stays true: its pictures exist and are regenerated, its Python runs, its options exist."""
from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT

GUIDE = os.path.join(ROOT, "docs", "guide.md")


def guide() -> str:
    with open(GUIDE, encoding="utf-8") as fh:
        return fh.read()


def make_figures_module():
    spec = importlib.util.spec_from_file_location("make_figures", os.path.join(ROOT, "scripts", "make_figures.py"))
    mod = importlib.util.module_from_spec(spec)
    sys.modules["make_figures"] = mod  # dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


def test_every_picture_exists_and_is_regenerated():
    refs = set(re.findall(r"!\[[^\]]*\]\(figures/([\w.-]+)\.png\)", guide()))
    assert len(refs) >= 20
    made = {f.name for f in make_figures_module().figures()}
    assert refs <= made, f"pictures no script makes: {sorted(refs - made)}"
    for name in refs:
        assert os.path.getsize(os.path.join(ROOT, "docs", "figures", f"{name}.png")) > 10_000, name


def test_python_blocks_run_and_print_what_the_comments_say(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    src = "\n".join(re.findall(r"```python\n(.*?)```", guide(), re.S))
    # Pictures go to tmp_path, not into the repository.
    src = src.replace('"basic_plan.png"', repr(str(tmp_path / "p.png"))).replace(
        '"basic_cspace.png"', repr(str(tmp_path / "c.png")))
    env: dict = {}
    exec(compile(src, "guide.md", "exec"), env)
    assert env["res"].solved and env["opt"].solved
    assert env["opt"].length <= env["res"].length
    assert (tmp_path / "p.png").stat().st_size > 10_000
    assert env["cs"].is_free((1, 1)) and not env["cs"].is_free((2.7, 3))
    assert len(env["solved"]) >= 95  # the circles line of the guide (OMPL's bar)


@pytest.mark.parametrize("command", ["plan", "show", "generate", "stability", "bench"])
def test_documented_options_exist(command):
    from planners.cli import COMMANDS

    if command == "bench" and importlib.util.find_spec(COMMANDS["bench"]) is None:
        pytest.skip("planners.bench not present")
    proc = subprocess.run([sys.executable, "-c", "from planners.cli import main; import sys; sys.exit(main())",
                           command, "--help"], capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    section = guide().split(f"### `cspace {command}`", 1)[1].split("\n### ", 1)[0].split("\n## ", 1)[0]
    # Options on lines that run another subcommand belong to that one.
    own = "\n".join(line for line in section.splitlines()
                    if not re.search(r"cspace (?!%s\b)[a-z]+ " % command, line))
    documented = set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", own))
    offered = set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", proc.stdout))
    assert documented, command
    assert documented <= offered, f"documented but not offered: {sorted(documented - offered)}"
    assert offered - {"--help"} <= documented, f"offered but not documented: {sorted(offered - documented)}"


def quoted_runs() -> list:
    """(shell block, quoted output, its line) for every ```sh block the guide follows with
    "prints `...`" (or "It prints"): what that block's commands must print."""
    out = []
    for m in re.finditer(r"```sh\n((?:(?!```).)*)```\n\n(?:It )?prints `([^`]*)`", guide(), re.S):
        out.append(pytest.param(m.group(1), m.group(2), id=f"line{guide()[:m.start()].count(chr(10)) + 1}"))
    return out


@pytest.mark.parametrize("block, quoted", quoted_runs())
def test_shell_blocks_print_what_the_guide_quotes(block, quoted, tmp_path):
    # Each command of the block runs as written (from the repository, its files written into
    # tmp_path); the quote, its line breaks as spaces and "(...)" / "..." standing for any text,
    # is found in what the block printed.
    printed = ""
    for line in block.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        args = line.split()
        assert args[0] == "cspace", line
        args = [os.path.join(ROOT, a) if a.startswith("scenarios/") else a for a in args[1:]]
        proc = subprocess.run([sys.executable, "-c", "from planners.cli import main; import sys; sys.exit(main())",
                               *args], capture_output=True, text=True, timeout=300, cwd=tmp_path)
        assert proc.returncode in (0, 1), (line, proc.stderr)
        printed += proc.stdout
    pattern = ".*?".join(re.escape(part) for part in re.split(r"\(\.\.\.\)|\.\.\.", " ".join(quoted.split())))
    assert re.search(pattern, " ".join(printed.split())), (quoted, printed)
    assert len(quoted_runs()) >= 3
