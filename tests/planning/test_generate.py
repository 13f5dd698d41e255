"""Generated scenes are valid by construction: they load, start and goal are free, and they
are solvable (checked with the exact planner) unless asked otherwise; same seed, same file."""
import subprocess
import sys

import pytest

import planners
from cspace.io.load import load_scenario
from planners.cli.generate import generate


@pytest.mark.parametrize("kind,size", [("random", 30), ("maze", 5), ("disks", 15), ("office", 2), ("narrow", None)])
@pytest.mark.parametrize("seed", [0, 7])
def test_generated_scene_is_valid_and_solvable(tmp_path, kind, size, seed):
    path = tmp_path / f"{kind}.toml"
    path.write_text(generate(kind, seed=seed, size=size))
    sc = load_scenario(str(path))  # raises if start or goal collides or any field is wrong
    res = planners.shortest_path(sc)
    assert res.solved, res.message


def test_same_seed_same_file_and_seeds_differ():
    assert generate("random", seed=3, size=20) == generate("random", seed=3, size=20)
    assert generate("random", seed=3, size=20) != generate("random", seed=4, size=20)


def test_narrow_below_one_is_unsolvable_and_says_so(tmp_path):
    path = tmp_path / "n.toml"
    path.write_text(generate("narrow", seed=0, ratio=0.999))
    sc = load_scenario(str(path))
    assert sc.expect == "unsolvable"
    assert planners.shortest_path(sc).message.startswith("proven unsolvable")


def test_cli_writes_the_file(tmp_path):
    out = tmp_path / "m.toml"
    r = subprocess.run([sys.executable, "-m", "planners.cli", "generate", "maze", "--size", "3", "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert load_scenario(str(out)).name == "maze-3x3"
    bad = subprocess.run([sys.executable, "-m", "planners.cli", "generate", "maze", "--out", str(tmp_path / "x.txt")],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--out" in bad.stderr
    for args in (["--size", "0"], ["--size", "-5"], ["--ratio", "-1"]):  # were IndexError, ValueError, ...
        bad = subprocess.run([sys.executable, "-m", "planners.cli", "generate", "narrow" if "--ratio" in args else "maze",
                              *args, "--out", str(out)], capture_output=True, text=True, timeout=120)
        assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and f": {args[0]}: " in bad.stderr, bad.stderr
