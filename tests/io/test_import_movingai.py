"""MovingAI maps and scenario files (issue 50, point 2): the cells as closed unit squares in
MovingAI's frame and in Bench-MR's, the border, the .scen rows as queries with their octile
optimum, and hostile files (one line, exit 2, bounded work).

Oracles: shapely's union of the blocked cells' squares placed by the format's definition
(written here independently of the importer), and the files written here in the format.
"""
from __future__ import annotations

import json

import pytest
import shapely
from hypothesis import given, settings, strategies as st

from cspace.io.importers.imported import ImportOptions, import_file
from cspace.io.importers.movingai import read_scen, row_slice, scen_point
from planners.cli import main


def write_map(tmp_path, rows: list[str], name: str = "m.map") -> str:
    f = tmp_path / name
    f.write_text(f"type octile\nheight {len(rows)}\nwidth {len(rows[0])}\nmap\n" + "\n".join(rows) + "\n")
    return str(f)


def squares(rows: list[str], reading: str, blocked: str = "@OTW"):
    """The oracle: each blocked cell's square, placed as the format's reading says."""
    h = len(rows)
    boxes = []
    for y, row in enumerate(rows):
        for x, ch in enumerate(row):
            if (ch != ".") if reading == "bench-mr" else (ch in blocked):
                boxes.append(shapely.box(x - 0.5, y - 0.5, x + 0.5, y + 0.5) if reading == "bench-mr"
                             else shapely.box(x, h - 1 - y, x + 1, h - y))
    return shapely.union_all(boxes)


def union_of(imp) -> shapely.Geometry:
    return shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", [])) for o in imp.data["obstacles"]])


ROWS = ["..........",
        ".@@@......",
        ".@.@..T...",
        ".@@@......",
        "......WW..",
        ".....OO..."]


@pytest.mark.parametrize("reading", ["movingai", "bench-mr"])
def test_blocked_cells_are_their_squares_in_either_frame(tmp_path, reading):
    f = write_map(tmp_path, ROWS)
    s, g = scen_point(0, 0, len(ROWS), reading), scen_point(9, 5, len(ROWS), reading)
    imp = import_file(f, ImportOptions(start=s, goal=g, grid_reading=reading))
    assert shapely.symmetric_difference(union_of(imp), squares(ROWS, reading)).area == 0
    holes = sum(len(o.get("holes", [])) for o in imp.data["obstacles"])
    assert holes == 1  # the ring of @ around the free cell (2, 2)


def test_the_border_blocks_the_outermost_cells(tmp_path):
    f = write_map(tmp_path, ROWS)
    imp = import_file(f, ImportOptions(start=(1.5, 1.5), goal=(8.5, 4.5), border=True))
    rows = ["@" * 10] + ["@" + r[1:-1] + "@" for r in ROWS[1:-1]] + ["@" * 10]
    assert shapely.symmetric_difference(union_of(imp), squares(rows, "movingai")).area == 0


@settings(max_examples=30, deadline=None)
@given(st.lists(st.text(alphabet=".@T", min_size=6, max_size=6), min_size=2, max_size=7))
def test_random_grids_import_exactly_or_grow(rows):
    """Property: the obstacles contain every blocked square, and any extra area is whole free
    cells filled where blocked cells met only at a corner (reported)."""
    import os
    import tempfile

    d = tempfile.mkdtemp()
    f = os.path.join(d, "r.map")
    open(f, "w").write(f"type octile\nheight {len(rows)}\nwidth 6\nmap\n" + "\n".join(rows) + "\n")
    imp = import_file(f, ImportOptions(start=(-5, -5), goal=(-5, -4)))
    got, want = union_of(imp) if imp.data["obstacles"] else shapely.Polygon(), squares(rows, "movingai")
    assert got.buffer(1e-9).contains(want) if not want.is_empty else True
    extra = got.area - want.area
    filled = [w for w in imp.warnings if "corner" in w]
    assert extra == (int(filled[0].split(": ")[1].split()[0]) if filled else 0)


def test_scen_rows_and_python_slices(tmp_path):
    f = tmp_path / "m.scen"
    f.write_text("version 1\n" + "".join(f"0\tm.map\t10\t6\t0\t{i % 6}\t9\t0\t{9 + i}.5\n" for i in range(12)))
    assert [r.index for r in read_scen(str(f), "-3:")] == [9, 10, 11]
    assert read_scen(str(f), "2")[0].optimum == 11.5
    assert list(row_slice(":2", 12)) == [0, 1] and list(row_slice("10:100", 12)) == [10, 11]


def octile(rows: list[str], s: tuple, g: tuple) -> float:
    """The oracle: MovingAI's octile optimum (8-connected Dijkstra, no corner cutting)."""
    import heapq

    free = lambda x, y: 0 <= y < len(rows) and 0 <= x < len(rows[0]) and rows[y][x] in ".GS"  # noqa: E731
    dist, heap = {s: 0.0}, [(0.0, s)]
    while heap:
        d, (x, y) = heapq.heappop(heap)
        if (x, y) == g:
            return d
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                n = (x + dx, y + dy)
                if (dx or dy) and free(*n) and (not (dx and dy) or (free(x + dx, y) and free(x, y + dy))):
                    nd = d + (2 ** 0.5 if dx and dy else 1.0)
                    if nd < dist.get(n, float("inf")):
                        dist[n] = nd
                        heapq.heappush(heap, (nd, n))
    return float("inf")


def test_plan_scen_rows_as_queries_with_their_octile_optimum(tmp_path, capsys):
    pytest.importorskip("ompl")
    f = write_map(tmp_path, ROWS)
    scen = tmp_path / "m.map.scen"
    pairs = [((0, 0), (9, 5)), ((4, 1), (0, 5)), ((9, 0), (0, 4))]
    opt = [round(octile(ROWS, s, g), 8) for s, g in pairs]
    scen.write_text("version 1\n" + "".join(f"0\tm.map\t10\t6\t{s[0]}\t{s[1]}\t{g[0]}\t{g[1]}\t{o:.8f}\n"
                                            for (s, g), o in zip(pairs, opt)))
    out = tmp_path / "r.json"
    code = main(["plan", f, "--scen", str(scen), "--scen-rows", "0:2", "--planner", "exact", "--json", str(out)])
    text = capsys.readouterr().out
    doc = json.loads(out.read_text())
    assert code == 0 and "2/2 queries solved" in text
    assert [m["octile_optimum"] for m in doc["movingai"]] == opt[:2]
    # the exact any-angle optimum never exceeds the octile (8-connected grid) optimum
    assert all(m["length"] <= m["octile_optimum"] + 1e-9 for m in doc["movingai"])
    assert all(q["bench_mr"]["exact_goal_path"] for q in doc["queries"])  # Bench-MR's metrics per query
    starts = [q["path"][0][:2] for q in doc["queries"]]
    assert starts == [[0.5, 5.5], [4.5, 4.5]]  # cell centres, row 0 at the top


def test_a_row_whose_robot_touches_an_obstacle_is_left_out_and_counted(tmp_path, capsys):
    pytest.importorskip("ompl")
    f = write_map(tmp_path, ["......", "......", "..@...", "......"])
    scen = tmp_path / "m.scen"
    scen.write_text("version 1\n0\tm.map\t6\t4\t0\t0\t5\t0\t5\n0\tm.map\t6\t4\t1\t2\t5\t3\t5\n")
    code = main(["plan", f, "--scen", str(scen), "--radius", "0.6", "--planner", "exact"])
    cap = capsys.readouterr()
    assert code == 1 and "row 1: the robot at its start or goal touches an obstacle: left out" in cap.err
    assert "1/1 queries solved" in cap.out and "1 of 2 .scen rows left out" in cap.out


HOSTILE = {
    "huge header": ("type octile\nheight 100000\nwidth 100000\nmap\n....\n", "over the limit"),
    "short row": ("type octile\nheight 2\nwidth 3\nmap\n...\n..\n", "row 1"),
    "missing rows": ("type octile\nheight 3\nwidth 3\nmap\n...\n", "rows of cells"),
    "extra rows": ("type octile\nheight 1\nwidth 3\nmap\n...\n...\n", "more rows"),
    "unknown terrain": ("type octile\nheight 1\nwidth 3\nmap\n.x.\n", "terrain 'x'"),
    "bad height": ("type octile\nheight -3\nwidth 3\nmap\n...\n", "height"),
    "nan height": ("type octile\nheight nan\nwidth 3\nmap\n...\n", "height"),
    "no header": ("....\n....\n", "type"),
    "empty": ("", "header"),
}


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_maps_get_one_line_and_exit_2(tmp_path, capsys, name):
    text, words = HOSTILE[name]
    f = tmp_path / "h.map"
    f.write_text(text)
    code = main(["plan", str(f), "--start", "0.5,0.5", "--goal", "1.5,0.5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and str(f) in err[0] and words in err[0], err


SCEN_HOSTILE = {
    "no version": ("0\tm.map\t3\t1\t0\t0\t2\t0\t2\n", "version"),
    "eight fields": ("version 1\n0\tm.map\t3\t1\t0\t0\t2\t0\n", "9 fields"),
    "nan optimum": ("version 1\n0\tm.map\t3\t1\t0\t0\t2\t0\tnan\n", "optimal length"),
    "outside": ("version 1\n0\tm.map\t3\t1\t0\t0\t5\t0\t5\n", "outside"),
    "negative cell": ("version 1\n0\tm.map\t3\t1\t-1\t0\t2\t0\t2\n", "integers"),
    "other map": ("version 1\n0\tm.map\t4\t1\t0\t0\t2\t0\t2\n", "made for a 4 x 1 map"),
}


@pytest.mark.parametrize("name", sorted(SCEN_HOSTILE))
def test_hostile_scen_files_get_one_line_and_exit_2(tmp_path, capsys, name):
    text, words = SCEN_HOSTILE[name]
    f = write_map(tmp_path, ["..."])
    scen = tmp_path / "h.scen"
    scen.write_text(text)
    code = main(["plan", f, "--scen", str(scen)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and words in err[0], err


@pytest.mark.parametrize("rows", ["x:y", "1:2:3", "50"])
def test_bad_row_selections_get_one_line(tmp_path, capsys, rows):
    f = write_map(tmp_path, ["..."])
    scen = tmp_path / "h.scen"
    scen.write_text("version 1\n0\tm.map\t3\t1\t0\t0\t2\t0\t2\n")
    code = main(["plan", f, "--scen", str(scen), "--scen-rows", rows])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--scen-rows" in err[0], err
