"""OMPL.app's planar problems side by side (scripts/bench_omplapp.py) and its page section, on a
checkout written here (a .cfg and COLLADA boxes in OMPL.app's format, tests/helpers/import_files.py):
it finds the problems in the checkout or its resources/2D, skips the kinodynamic ones, judges
every path, reports a path of ours that the sweep does not pass as a fault (exit 1), and the
page says how to run it when no checkout is given."""
from __future__ import annotations

import json
import os

import pytest

from conftest import load_script
from import_files import ROBOT_BOXES, WORLD_BOXES, dae_text, has_collada

BENCH = load_script("bench_omplapp")
PAGE = load_script("make_benchmarks_page")


def checkout(root) -> str:
    """A checkout of one planar problem (named as OMPL.app's bug trap) and one kinodynamic car."""
    d = root / "resources" / "2D"
    d.mkdir(parents=True)
    keys = ("robot = robot.dae\nworld = world.dae\nstart.x = -5\nstart.y = 0\nstart.theta = 0\ngoal.x = 5\n"
            "goal.y = 0\ngoal.theta = 1.57\nvolume.min.x = -10\nvolume.min.y = -10\nvolume.max.x = 10\n"
            "volume.max.y = 10\n")
    (d / "BugTrap_planar.cfg").write_text("[problem]\nname = Tiny\n" + keys)
    (d / "Maze_kcar.cfg").write_text("[problem]\nname = TinyCar\ncontrol = kinematic_car\n" + keys)
    (d / "robot.dae").write_text(dae_text(ROBOT_BOXES))
    (d / "world.dae").write_text(dae_text(WORLD_BOXES))
    return str(d)


def test_the_problems_are_found_in_the_checkout_or_its_folder(tmp_path):
    d = checkout(tmp_path)
    assert BENCH.resources(str(tmp_path)) == d and BENCH.resources(d) == d
    assert BENCH.resources(str(tmp_path / "resources")) is None and BENCH.resources("") is None


def test_without_a_checkout_it_says_so_and_runs_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("OMPLAPP", raising=False)
    monkeypatch.setattr(BENCH, "run_problem", lambda *a: pytest.fail("ran"))
    assert BENCH.main(["--omplapp", str(tmp_path)]) == 0
    assert "no OMPL.app checkout" in capsys.readouterr().out


def runs(*rows):
    return {"problem": "p", "vertices": 4, "prep_s": 0.1,
            "runs": [{"seed": k, "rounds": 1, "ours_s": o, "coal_s": c, "ours": vo, "coal": vc}
                     for k, (o, c, vo, vc) in enumerate(rows)]}


@pytest.mark.parametrize("args, says", [
    (["--json", "{cfg}"], "writing it would destroy it"), (["--json", "{dir}"], "is a directory"),
    (["--seeds", "0"], "--seeds"), (["--time", "-1"], "--time"), (["--problems", "NoSuch"], "--problems")])
def test_bad_options_and_a_json_over_the_checkout_are_refused_before_any_work(tmp_path, capsys, args, says):
    # found by hand: --json over a problem's .cfg replaced it, and --seeds -1 ran nothing and said "met"
    # (every option is checked before the bench looks for coal: this runs where coal is not installed)
    d = checkout(tmp_path)
    cfg = os.path.join(d, "BugTrap_planar.cfg")
    before = {f: open(os.path.join(d, f), "rb").read() for f in os.listdir(d)}
    with pytest.raises(SystemExit) as exc:
        BENCH.main(["--omplapp", str(tmp_path)] + [a.format(cfg=cfg, dir=d) for a in args])
    assert exc.value.code == 2 and says in capsys.readouterr().err
    assert {f: open(os.path.join(d, f), "rb").read() for f in os.listdir(d)} == before


def test_the_ratio_counts_coal_s_sound_seeds_and_the_target_is_checked():
    r = BENCH.summary(runs((1.0, 4.0, "sound", "sound"), (1.0, 1.0, "sound", "colliding"),
                           (3.0, 4.0, "sound", "sound"), (1.0, 8.0, "sound", "undecided"), (None, 2.0, None, "sound")))
    assert r["ratio_sound"] == (0.25 + 0.75) / 2 and r["sound_seeds"] == 2  # seeds 0 and 2
    assert r["ratio_all"] == 0.5  # the median of 0.125, 0.25, 0.75 and 1
    assert r["coal_colliding"] == 1 and r["coal_undecided"] == 1 and r["ours_solved"] == 4 and r["target_met"]
    slow = BENCH.summary(runs((3.0, 4.0, "sound", "sound")))
    assert slow["ratio_sound"] == 0.75 and not slow["target_met"]
    assert BENCH.summary(runs((1.0, 4.0, "sound", "colliding")))["ratio_sound"] is None  # no sound seed: not met


def test_a_path_of_ours_the_sweep_rejects_is_a_fault(tmp_path, capsys, monkeypatch):
    pytest.importorskip("coal")
    checkout(tmp_path)
    monkeypatch.setattr(BENCH, "run_problem", lambda *a: runs((1.0, 4.0, "colliding", "sound")))
    assert BENCH.main(["--omplapp", str(tmp_path), "--seeds", "1"]) == 1
    out = capsys.readouterr().out
    assert "FAULT: ours on p, seed 0: the sweep says colliding" in out and "ours not sound 1" in out


@pytest.mark.skipif(not has_collada(), reason="pycollada")
def test_a_tiny_checkout_is_run_and_judged(tmp_path, capsys):
    pytest.importorskip("ompl")
    pytest.importorskip("coal")
    checkout(tmp_path)
    out = tmp_path / "o.json"
    assert BENCH.main(["--omplapp", str(tmp_path), "--seeds", "1", "--time", "2", "--repeats", "1",
                       "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Maze_kcar.cfg: skipped (a kinodynamic control problem" in text
    data = json.loads(out.read_text())
    assert data["skipped"] == ["Maze_kcar.cfg"] and len(data["rows"]) == 1
    row, run = data["rows"][0], data["results"][0]["runs"][0]
    assert row["problem"] == "Tiny" and row["ours_solved"] == 1 and row["ours_not_sound"] == 0
    assert run["ours"] == "sound" and run["coal"] in ("sound", "colliding", "undecided")  # both judged
    assert len(data["load_start"]) == 3


@pytest.mark.parametrize("name, env, needs, flags", [
    ("bench_omplapp", "OMPLAPP", "an OMPL.app checkout", ["--out-json"]),
    ("bench_benchmr", "BENCH_MR", "a Bench-MR checkout", ["--out-json", "--figures"])])
def test_the_page_runs_a_checkout_bench_only_with_its_checkout(tmp_path, monkeypatch, name, env, needs, flags):
    # (both benches whose data lives in another project's checkout: make_benchmarks_page.CHECKOUTS)
    monkeypatch.delenv(env, raising=False)
    ran = []
    monkeypatch.setattr(PAGE, "run_script", lambda *a, **k: ran.append(a) or {})
    page = tmp_path / "page.md"
    assert PAGE.main(["--only", name, "--out", str(page), "--work", str(tmp_path / "w")]) == 0
    assert ran == [] and f"Not run: it needs {needs}" in page.read_text()
    assert f"python scripts/{name}.py {PAGE.CHECKOUTS[name]} DIR" in page.read_text()
    cmd, wants = PAGE.quick_command(name, os.path.join(PAGE.ROOT, "scripts", f"{name}.py"), "x.json", "/some/checkout")
    assert cmd[cmd.index(PAGE.CHECKOUTS[name]) + 1] == "/some/checkout" and wants and all(f in cmd for f in flags)


def test_the_page_shows_the_table(tmp_path):
    row = BENCH.summary(runs((0.01, 0.04, "sound", "sound"), (0.02, 0.01, "sound", "colliding")))
    (tmp_path / "o.json").write_text(json.dumps({"rows": [row], "skipped": ["Maze_kcar.cfg"], "seeds": 2, "time": 10,
                                                 "load_start": [1.5, 1.25, 1.0], "load_end": [2.0, 1.5, 1.0]}))
    text = "\n".join(PAGE.omplapp_lines({"json": str(tmp_path / "o.json"), "stdout": ""}))
    assert "| p | 4 | 100.0 ms | 2/2 | 15.0 ms | 0 | 2/2 | 25.0 ms | 1 | 0 | 0.25x (1 seeds) | 1.12x | met |" in text
    assert "1.50, 1.25, 1.00" in text and "`Maze_kcar.cfg`" in text
    # a name read from the checkout's file is escaped in the table (a pipe would cut the row)
    (tmp_path / "o.json").write_text(json.dumps({"rows": [dict(row, problem="a|b<i>")], "seeds": 2}))
    text = "\n".join(PAGE.omplapp_lines({"json": str(tmp_path / "o.json"), "stdout": ""}))
    assert "| a\\|b&lt;i&gt; | 4 |" in text
