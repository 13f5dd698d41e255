"""``cspace plan --queries FILE``: many start/goal pairs on one prepared C-space, for scenarios and
for imported maps (which have no start of their own), with one-line faults naming the file."""
from __future__ import annotations

import json
import os

import pytest

from conftest import SCENARIOS, load_script
from planners.cli import main

BASIC = os.path.join(SCENARIOS, "basic.toml")
OFFICE = os.path.join(SCENARIOS, "maps", "office.yaml")


def write(tmp_path, text: str, name: str = "q.toml") -> str:
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def test_a_queries_file_replaces_the_scenarios_queries(tmp_path, capsys):
    q = write(tmp_path, "[[queries]]\nstart = [1, 9]\ngoal = [9, 1]\n[[queries]]\nstart = [9, 9]\ngoal = [1, 1]\n")
    js = tmp_path / "r.json"
    assert main(["plan", BASIC, "--queries", q, "--json", str(js)]) == 0
    r = json.loads(js.read_text())
    assert [(tuple(x["start"]), tuple(x["goal"])) for x in r["queries"]] == [((1, 9), (9, 1)), ((9, 9), (1, 1))]
    assert all(x["solved"] for x in r["queries"])
    assert "2/2 queries solved" in capsys.readouterr().out


def test_a_map_takes_its_start_and_goal_from_the_queries(tmp_path):
    q = write(tmp_path, "[[queries]]\nstart = [0.5, 0.5]\ngoal = [9.5, 6.5]\n[[queries]]\nstart = [9.5, 6.5]\n"
                        "goal = [1.0, 3.0]\n")
    js = tmp_path / "r.json"
    assert main(["plan", OFFICE, "--radius", "0.2", "--queries", q, "--json", str(js)]) == 0
    r = json.loads(js.read_text())
    assert len(r["queries"]) == 2 and all(x["solved"] for x in r["queries"])


def test_rotating_queries_on_a_map(tmp_path):
    q = write(tmp_path, "[[queries]]\nstart = [0.8, 0.8, 0.0]\ngoal = [9.5, 6.5, 1.5]\n")
    js = tmp_path / "r.json"
    assert main(["plan", OFFICE, "--polygon=-0.2,-0.1;0.2,-0.1;0.2,0.1;-0.2,0.1", "--space", "se2",
                 "--queries", q, "--json", str(js), "--time", "20"]) == 0
    r = json.loads(js.read_text())
    assert r["solved"] and r["path"][-1] == [9.5, 6.5, 1.5]


@pytest.mark.parametrize("text, fault", [
    ("[[queries]]\nstart = [1, 9]\n", "queries[0].goal: missing"),
    ("[[queries]]\nstart = [1, 9]\ngoal = [99, 1]\n", "queries[0].goal: (99.0, 1.0) is outside the bounds"),
    ("[[queries]]\nstart = [3.5, 3]\ngoal = [1, 1]\n", "queries[0].start: (3.5, 3.0) puts the robot in collision"),
    ("name = 'x'\n", "name: unknown field"),
    ("", "queries: none given"),
    ("[[queries]\n", "toml: invalid TOML"),
])
def test_a_bad_queries_file_is_one_line_naming_it(tmp_path, capsys, text, fault):
    q = write(tmp_path, text)
    assert main(["plan", BASIC, "--queries", q]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"error: {q}: ") and fault in err, err


def test_an_output_over_the_queries_file_is_refused(tmp_path, capsys):
    q = write(tmp_path, "[[queries]]\nstart = [1, 9]\ngoal = [9, 1]\n", "q.json")
    before = open(q).read()
    assert main(["plan", BASIC, "--queries", q, "--json", q]) == 2
    assert open(q).read() == before and "error:" in capsys.readouterr().err


def test_the_warehouse_generator_makes_free_pairs(tmp_path):
    wh = load_script("make_warehouse_map")
    img = wh.warehouse(size=600, seed=3)  # a 30 m warehouse: the same layout rules, smaller
    pairs = wh.pairs(img, 5, seed=3)
    assert len(pairs) == 5
    for s, g in pairs:
        assert wh.footprint_free(img, *s) and wh.footprint_free(img, *g)
    # the check is not blind: a pose on a rack is refused
    rows, cols = (img == 0).nonzero()
    r, c = rows[len(rows) // 2], cols[len(cols) // 2]
    assert not wh.footprint_free(img, (c + 0.5) * wh.RES, (img.shape[0] - 1 - r + 0.5) * wh.RES, 0.0)


def test_a_maps_first_query_in_collision_names_the_queries_file(tmp_path, capsys):
    q = write(tmp_path, "[[queries]]\nstart = [0.5, 0.5]\ngoal = [8.0, 2.0]\n")
    assert main(["plan", OFFICE, "--radius", "0.2", "--queries", q]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {q}: queries[0].goal: (8.0, 2.0) puts the robot in collision"), err


def test_the_queries_file_counts_in_the_load_time(tmp_path):
    q = write(tmp_path, "[[queries]]\nstart = [1, 9]\ngoal = [9, 1]\n")
    js = tmp_path / "r.json"
    assert main(["plan", BASIC, "--queries", q, "--json", str(js)]) == 0
    assert json.loads(js.read_text())["timings"]["load"] > 0  # read, validated and checked here, not in plan()
