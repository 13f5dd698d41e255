"""Every script's output files (the benches', and those of the scripts that make figures, maps,
screenshots and the benchmarks page) are checked before any work and written atomically
(scripts/benchutil.py: ``check_out``, ``check_json``, ``write_json``), as the CLI's are: an output
option pointed at a folder (an output folder at a file), or at one of the run's inputs (a bundled
scenario), is one line naming the option, exit 2, the input unchanged; a run stopped half-way
through writing leaves the old file. (Here, beside the other checks across scripts/.)

Found by reading the scripts: they wrote with a plain ``open(path, "w")`` after the whole run, so
``--json scenarios/se2/bar_door.toml`` replaced a bundled scene and a folder was a traceback after
minutes of work. No bench runs here: its work is replaced by a function that raises (a missing check
then fails the test at once), and every way the script could write is closed while a refusal is
tested, so a faulty script cannot write into the repository.
"""
from __future__ import annotations

import builtins
import json
import os
import sys

import pytest

from conftest import SCENARIOS, load_script

_LOADED: dict = {}


def script(name: str):
    """The script's module, loaded once per test session."""
    if name not in _LOADED:
        _LOADED[name] = load_script(name)
    return _LOADED[name]


class Ran(Exception):
    """The bench's work, or a write, was reached: its output was not checked first."""


def raiser(*_a, **_k):
    raise Ran("reached the bench's work (or a write) before checking the output")


# (script, output option, extra arguments, its work (poisoned), a bundled input it reads: None if none)
CASES = [
    ("bench_auto", "--json", [], ["scene_rows"], "se2/bar_door.toml"),
    ("bench_auto", "--json", ["--parts", "C"], ["scene_rows"], "car/parking.toml"),
    ("bench_car", "--json", [], ["part_m", "part_t"], "car/parking.toml"),
    ("bench_cspace", "--out-json", [], ["part_a", "part_b", "part_c"], "ompl/env1.toml"),
    ("bench_cspace", "--out-json", ["--parts", "C"], ["part_a", "part_b", "part_c"], "basic.toml"),
    ("bench_planning", "--out-json", [], ["prepare"], "basic.toml"),
    ("bench_scaling", "--out-json", ["--plot", "", "--no-big"], ["run"], None),
    ("bench_scaling", "--plot", ["--no-big"], ["run"], None),
    ("bench_se2", "--json", [], ["part_v", "part_m", "part_t", "part_p"], "se2/tee_slot.toml"),
    ("bench_se2", "--json", ["--parts", "P"], ["part_v", "part_m", "part_t", "part_p"], "car/u_turn.toml"),
    ("bench_se2_exact", "--json", [], ["run_scene", "families"], "se2/bug_trap.toml"),
    ("bench_se2_exact", "--json", ["--families", "1"], ["run_scene", "families"], "se2/bug_trap.toml"),
    ("bench_shortest", "--out-json", [], ["measure"], None),
    ("bench_shortest", "--plot", [], ["measure"], None),
    ("bench_startup", "--out-json", [], ["run"], "basic.toml"),
    ("bench_warehouse", "--json", ["--no-peer"], ["wh.write", "se2_run"], None),
    ("bench_gjk", "--plot", [], ["make_pairs"], None),
    ("make_example_map", "--out", [], ["office"], None),
    ("make_benchmarks_page", "--out", ["--only", "bench_gjk"], ["run_script", "run_planner_sweep", "machine_note"],
     "basic.toml"),
    ("make_benchmarks_page", "--out", ["--only", "bench_gjk"], ["run_script", "run_planner_sweep", "machine_note"],
     "maps/office.yaml"),
]
IDS = [f"{c[0]}{c[1]}{''.join(c[2])}" for c in CASES]


def closed(monkeypatch, mod, work) -> None:
    """``mod``'s work raises, and so does every write it could make (its ``open`` for writing, the
    atomic writers): a script that does not check its output fails here, writing nothing."""
    import planners.output

    benchutil = sys.modules.get("benchutil") or load_script("benchutil")  # the one the scripts import
    for name in work:
        owner, _, attr = name.rpartition(".")
        monkeypatch.setattr(getattr(mod, owner) if owner else mod, attr, raiser)

    def guarded_open(path, mode="r", *a, **k):
        if any(c in mode for c in "wax+"):
            raiser()
        return builtins.open(path, mode, *a, **k)

    monkeypatch.setattr(mod, "open", guarded_open, raising=False)
    monkeypatch.setattr(benchutil, "write_json", raiser)
    monkeypatch.setattr(planners.output, "atomic_path", raiser)


@pytest.mark.parametrize("name, option, extra, work, _input", CASES, ids=IDS)
def test_an_output_that_is_a_folder_is_refused_before_any_work(tmp_path, capsys, monkeypatch, name, option, extra,
                                                                work, _input):
    mod = script(name)
    closed(monkeypatch, mod, work)
    folder = tmp_path / "figures.png"  # (a plot's extension: the folder is what is refused)
    folder.mkdir()
    with pytest.raises(SystemExit) as exc:
        mod.main(extra + [option, str(folder)])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1, err
    assert option in err[0] and str(folder) in err[0] and "is a directory" in err[0]
    assert os.listdir(tmp_path) == ["figures.png"] and os.listdir(folder) == []


@pytest.mark.parametrize("name, option, extra, work, input_", [c for c in CASES if c[4]],
                         ids=[i for i, c in zip(IDS, CASES) if c[4]])
def test_an_output_over_a_bundled_input_is_refused_and_the_input_unchanged(capsys, monkeypatch, name, option, extra,
                                                                           work, input_):
    mod = script(name)
    closed(monkeypatch, mod, work)
    target = os.path.join(SCENARIOS, input_)
    before = open(target, "rb").read()
    with pytest.raises(SystemExit) as exc:
        mod.main(extra + [option, target])
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1, err
    assert option in err[0] and "writing it would destroy it" in err[0]
    assert open(target, "rb").read() == before


@pytest.mark.parametrize("name", ["bench_scaling", "bench_shortest"])
def test_a_plot_of_an_unknown_format_or_two_options_on_one_file_are_refused(tmp_path, capsys, monkeypatch, name):
    mod = script(name)
    closed(monkeypatch, mod, ["run"] if name == "bench_scaling" else ["measure"])
    same = str(tmp_path / "o.png")
    for args, says in ((["--plot", str(tmp_path / "o.txt")], "unsupported extension '.txt'"),
                       (["--plot", same, "--out-json", same], "is also the --plot output")):
        with pytest.raises(SystemExit) as exc:
            mod.main(args + (["--no-big"] if name == "bench_scaling" else []))
        err = capsys.readouterr().err.strip().splitlines()
        assert exc.value.code == 2 and len(err) == 1 and says in err[0], err
    assert os.listdir(tmp_path) == []


def fake_startup(monkeypatch, mod):
    rows = [{"command": "python -c pass (peer)", "median_s": 0.02, "over_peer_s": 0.0, "target_s": None, "met": None}]
    monkeypatch.setattr(mod, "run", lambda *a: [dict(r) for r in rows])
    return rows


def fake_planning(monkeypatch, mod):
    monkeypatch.setattr(mod, "prepare", lambda names: [])
    monkeypatch.setattr(mod, "run_all", lambda *a: {})
    return []


def fake_families(monkeypatch, mod):
    monkeypatch.setattr(mod, "families", lambda *a: [{"family": "doors 0.3 %", "solved": 1}])
    return [{"family": "doors 0.3 %", "solved": 1}]


# (script, output option, arguments that make the run tiny, what fakes its work -> the figures expected)
TINY = [
    ("bench_auto", "--json", ["--parts", "-"], lambda mp, mod: {}),
    ("bench_car", "--json", ["--parts", "-"], lambda mp, mod: {}),
    ("bench_cspace", "--out-json", ["--parts", "-"], lambda mp, mod: {}),
    ("bench_se2", "--json", ["--parts", "-"], lambda mp, mod: {}),
    ("bench_se2_exact", "--json", ["--families", "1"], fake_families),
    ("bench_planning", "--out-json", [], fake_planning),
    ("bench_startup", "--out-json", [], fake_startup),
]


@pytest.mark.parametrize("name, option, args, fake", TINY, ids=[t[0] for t in TINY])
def test_the_figures_are_written_atomically(tmp_path, capsys, monkeypatch, name, option, args, fake):
    mod = script(name)
    expected = fake(monkeypatch, mod)
    out = tmp_path / "figures.json"
    out.write_bytes(b"old figures")
    real_dump = json.dump

    def dies_half_way(obj, fh, **kw):  # a run stopped while writing: half a file was written
        fh.write("{")
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(json, "dump", dies_half_way)
        with pytest.raises(KeyboardInterrupt):
            mod.main(args + [option, str(out)])
    assert out.read_bytes() == b"old figures" and os.listdir(tmp_path) == ["figures.json"]
    assert json.dump is real_dump
    assert mod.main(args + [option, str(out)]) == 0
    assert json.loads(out.read_text()) == expected and os.listdir(tmp_path) == ["figures.json"]


@pytest.mark.parametrize("name, option, work", [("fuzz_inputs", "--out", ["run_files"]),
                                                 ("make_warehouse_map", "--out", ["warehouse", "write"]),
                                                 ("noisy_map", "OUT_DIR", ["noisy_image", "write_map"]),
                                                 ("make_figures", "--out", ["draw_figure"]),
                                                 ("make_benchmarks_page", "--work", ["run_script", "run_planner_sweep",
                                                                                     "machine_note"]),
                                                 ("bench_benchmr", "--figures", ["polygon_problems", "figures"])])
def test_an_output_folder_that_is_a_file_is_refused_before_any_work(tmp_path, capsys, monkeypatch, name, option, work):
    mod = script(name)
    closed(monkeypatch, mod, work)
    f = tmp_path / "summary.json"
    f.write_bytes(b"kept")
    args = [str(f)] if option == "OUT_DIR" else [option, str(f)]
    if name == "bench_benchmr":  # an (empty) checkout, or it runs nothing
        (tmp_path / "bm" / "bin" / "polygon_mazes").mkdir(parents=True)
        args += ["--bench-mr", str(tmp_path / "bm")]
    with pytest.raises(SystemExit) as exc:
        mod.main(args)
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1 and option in err[0] and "not a folder" in err[0], err
    assert f.read_bytes() == b"kept"
    assert set(os.listdir(tmp_path)) == ({"summary.json", "bm"} if name == "bench_benchmr" else {"summary.json"})


@pytest.mark.parametrize("name, shoot, work", [
    ("make_view_screenshots", "bar_door_screenshot", ["Browser"]),
    ("make_arena_screenshot", "arena_screenshot", ["_browser_module", "make_database", "start_arena"])])
def test_a_screenshot_is_checked_before_any_work(tmp_path, capsys, monkeypatch, name, shoot, work):
    import planners

    mod = script(name)
    closed(monkeypatch, mod, work)
    monkeypatch.setattr(planners, "plan", raiser)
    scene = os.path.join(SCENARIOS, "se2", "bar_door.toml")
    before = open(scene, "rb").read()
    folder = tmp_path / "shot.png"
    folder.mkdir()
    for out, says in ((str(folder), "is a directory"), (scene, "unsupported extension"),
                      (str(tmp_path / "shot.jpg"), "unsupported extension")):
        with pytest.raises(SystemExit) as exc:
            getattr(mod, shoot)(out)
        err = capsys.readouterr().err.strip().splitlines()
        assert exc.value.code == 2 and len(err) == 1 and says in err[0], err
    assert open(scene, "rb").read() == before and os.listdir(tmp_path) == ["shot.png"] and os.listdir(folder) == []
