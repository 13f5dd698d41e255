"""Hostile occupancy maps (issue 36 item 3): bounds on cells and traced vertices, refused in
one line before the work; noisy maps traced exactly in time linear in their size.

Oracles: the grid itself (shapely's union of the blocked cells' squares), and the corner
filling as it was first written (a whole-grid pass per round, obviously right, quadratic
on a chain of fills). Timings are the bench's (scripts/bench_map_import.py), not asserted.
"""
from __future__ import annotations

import os
import struct
import sys
import zlib

import numpy as np
import pytest
import shapely

from conftest import ROOT
from cspace.io.importers.imported import ImportOptions, import_file
from cspace.io.importers.occupancy import MAX_PIXELS, MAX_VERTICES, fill_corner_touches, staircase
from cspace.io.importers.trace import REGION_VERTICES, largest_error, staircase_polygons
from planners.cli import main

sys.path.insert(0, os.path.join(ROOT, "scripts"))
from noisy_map import noisy_image, start_goal, write_map  # noqa: E402


def fill_oracle(blocked: np.ndarray) -> int:
    """Corner filling, one whole-grid round at a time (the first implementation)."""
    filled = 0
    while True:
        a, b, c, d = blocked[:-1, :-1], blocked[:-1, 1:], blocked[1:, :-1], blocked[1:, 1:]
        main_, anti = a & d & ~b & ~c, b & c & ~a & ~d
        if not (main_.any() or anti.any()):
            return filled
        before = int(blocked.sum())
        blocked[:-1, 1:] |= main_
        blocked[:-1, :-1] |= anti
        filled += int(blocked.sum()) - before


def squares(mask: np.ndarray, res: float = 1.0):
    """The union of the True cells' squares, image row 0 at the top (as map_server). The squares
    share whole edges (a valid coverage): GEOS's coverage union, much faster than union_all."""
    rows, cols = np.nonzero(mask)
    j = mask.shape[0] - 1 - rows
    return shapely.coverage_union_all(shapely.box(cols * res, j * res, (cols + 1) * res, (j + 1) * res))


def run_import(capsys, tmp_path, yaml_path, *extra):
    out = tmp_path / "out.toml"
    code = main(["import", str(yaml_path), "--out", str(out), "--radius", "0.2", "--start", "0.4,0.4",
                 "--goal", "1,1", *extra])
    return code, capsys.readouterr().err.strip().splitlines(), out


def png_header_only(path, w: int, h: int) -> None:
    """A PNG of a signature, an IHDR declaring w x h 8-bit grey, and IEND: no pixel data at all."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b""))


@pytest.mark.parametrize("kind, w, h", [("pgm", 4097, 4096), ("pgm", 8192, 8192), ("png", 4096, 4097),
                                        ("png", 100000, 100000)])
def test_a_too_large_declared_image_is_refused_before_decoding(tmp_path, capsys, kind, w, h):
    # The files hold a header only: had the pixels been decoded, Pillow would say "truncated"
    # (one line too, but another one); the refusal names the size and the limit.
    y = write_map(str(tmp_path), noisy_image(8), "m", png=(kind == "png"))
    img = os.path.join(tmp_path, f"m.{kind}")
    if kind == "pgm":
        open(img, "wb").write(f"P5\n{w} {h}\n255\n".encode())
    else:
        png_header_only(img, w, h)
    code, err, out = run_import(capsys, tmp_path, y)
    assert code == 2 and len(err) == 1 and not out.exists(), err
    assert err[0].startswith(f"error: {img}: image: "), err
    assert str(MAX_PIXELS) in err[0] and "truncated" not in err[0] and "cannot read" not in err[0], err
    if w * h < 10**9:  # below Pillow's own bomb limit: the message is ours, with the declared size
        assert f"{w} x {h} pixels" in err[0], err


def test_the_largest_accepted_size_is_4096_squared():
    assert MAX_PIXELS == 4096 * 4096


def test_too_many_traced_vertices_are_refused_in_one_line(tmp_path, capsys):
    # 1500 x 1500 cells of 50 % noise trace to about 1.2 M vertices, over the 1 Mi limit.
    size = 1500
    y = write_map(str(tmp_path), noisy_image(size, 0.5, seed=3), "noisy", png=True)
    code, err, out = run_import(capsys, tmp_path, y)
    assert code == 2 and len(err) == 1 and not out.exists(), err
    assert err[0].startswith(f"error: {os.path.join(tmp_path, 'noisy.png')}: image: "), err
    assert f"over the limit of {MAX_VERTICES}" in err[0] and "coarsen" in err[0], err
    n = int(err[0].split("trace to ")[1].split()[0])
    assert MAX_VERTICES < n < 1.4e6


@pytest.mark.slow
def test_a_noisy_map_within_the_limits_imports_exactly(tmp_path, capsys):
    # 256 x 256 cells, half occupied: tens of thousands of vertices and thousands of holes
    # (several regions). At tolerance 0 the obstacles are exactly the blocked cells: the
    # occupied ones and those the corner filling adds (the oracle's filling).
    size, res = 256, 1.0
    img = noisy_image(size, 0.5, seed=11)
    y = write_map(str(tmp_path), img, "noisy", res=res)
    start, goal = start_goal(size, res)
    imp = import_file(y, ImportOptions(robot={"radius": 0.2}, start=start, goal=goal, tolerance=0.0,
                                       unknown="free"))
    union = shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", [])) for o in imp.data["obstacles"]])
    occupied = img == 0
    blocked = occupied[::-1].copy()  # rows bottom-up, as the tracer sees them
    filled = fill_oracle(blocked)
    oracle = squares(blocked[::-1], res)
    assert filled > 1000 and shapely.get_num_interior_rings(shapely.get_parts(union)).sum() > 1000
    assert union.area == oracle.area == blocked.sum()
    assert shapely.symmetric_difference(union, oracle).area == 0.0
    # every occupied cell inside (by area: GEOS 3.13's covers, shapely 2.1's, misjudges these huge
    # multipolygons that share edges exactly; the set equality above is already exact)
    assert shapely.difference(squares(occupied, res), union).area == 0.0
    # The default tolerance: fewer vertices, every occupied cell still inside, within the tolerance.
    code, err, out = run_import(capsys, tmp_path, y, "--start", f"{start[0]},{start[1]}",
                                "--goal", f"{goal[0]},{goal[1]}")
    assert code == 0, err
    simple = import_file(y, ImportOptions(robot={"radius": 0.2}, start=start, goal=goal, unknown="free"))
    grown = shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", []))
                               for o in simple.data["obstacles"]])
    assert grown.covers(oracle)
    assert 0 < largest_error(grown, oracle) <= 2.0 * res + 1e-9


@pytest.mark.parametrize("seed", range(6))
def test_the_linear_tracer_is_the_union_of_the_cells(seed):
    rng = np.random.default_rng(seed)
    h, w = rng.integers(1, 70, 2)
    grid = rng.random((h, w)) < rng.uniform(0.1, 0.9)
    grid[h // 3: 2 * h // 3, w // 3: 2 * w // 3] = seed % 2 == 0  # a block: islands in holes, or a hole
    fill_corner_touches(grid)
    polys = staircase_polygons(grid)
    union = shapely.MultiPolygon(list(polys))
    assert shapely.is_valid(union) and union.area == grid.sum()
    assert shapely.symmetric_difference(union, squares(grid[::-1])).area == 0.0
    # Collinear points dropped: no vertex has its two neighbours on one line.
    for ring in shapely.get_rings(polys):
        xy = shapely.get_coordinates(ring)[:-1]
        d1, d2 = xy - np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0) - xy
        assert (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] != 0).all()
    # Split into regions (a small vertex budget), the pieces still make exactly the cells.
    pieces = staircase(grid, max_vertices=40)
    assert shapely.union_all(shapely.get_parts(pieces)).symmetric_difference(union).area == 0.0


def test_a_grid_touching_at_a_corner_is_refused_by_the_tracer():
    with pytest.raises(ValueError, match="corner"):
        staircase_polygons(np.array([[1, 0], [0, 1]], dtype=bool))


def test_a_chain_of_corner_fills_is_filled_as_the_oracle_does():
    # Each fill makes the next corner touch (a ladder): the oracle takes one whole-grid
    # round per fill; the work list only the blocks around the cells just filled.
    n = 301
    g = np.zeros((n, 12), dtype=bool)
    g[n - 2::-2, 4] = True
    g[n - 1, 5] = True
    g[n - 3::-2, 6] = True
    for grid in (g, noisy_image(97, 0.45, seed=5) == 0, noisy_image(64, 0.7, seed=6) == 0):
        a, b = grid.copy(), grid.copy()
        assert fill_corner_touches(a) == fill_oracle(b) > 0
        assert (a == b).all()
    assert fill_corner_touches(g.copy()) == n - 1


def test_the_region_budget_is_documented_in_vertices():
    assert 1000 <= REGION_VERTICES <= MAX_VERTICES


def test_the_bench_script_runs_small(capsys):
    import bench_map_import

    assert bench_map_import.main(["--sizes", "64", "--reps", "1"]) == 0
    out = capsys.readouterr().out
    assert "64 x 64" in out and "failed" not in out
