"""ROS occupancy-grid maps (issue 22): thresholds as map_server, conservative polygons, plans
on imported maps checked against the grid itself, bad input as one line.

Every map is written here with Pillow; the oracle is the grid: each blocked cell's square
(built from resolution and origin, image row 0 at the top) must be covered by the polygons.
"""
from __future__ import annotations

import os

import numpy as np
import pytest
import shapely
from PIL import Image

from cspace.io.importers.imported import ImportOptions, import_file, load_imported
from cspace.io.importers.occupancy import MapInfo, classify, parse_flat_yaml
from cspace.io.load import load_scenario
from planners.cli import main

FREE, OCC, UNK = 254, 0, 205  # map_server's grey levels (trinary, not negated)


def blobs(h: int, w: int, seed: int, n: int = 12, unknown: bool = True) -> np.ndarray:
    """A grey image: free, with disks and boxes of occupied cells, and an unknown patch."""
    rng = np.random.default_rng(seed)
    img = np.full((h, w), FREE, np.uint8)
    yy, xx = np.mgrid[:h, :w]
    for _ in range(n):
        r, c, rad = rng.integers(0, h), rng.integers(0, w), rng.integers(1, 7)
        if rng.random() < 0.5:
            img[(yy - r) ** 2 + (xx - c) ** 2 < rad * rad] = OCC
        else:
            img[r:r + rad, c:c + 2 * rad] = OCC
    img[rng.random((h, w)) < 0.01] = OCC  # salt: single cells, some touching only at corners
    if unknown:
        img[: h // 6, : w // 6] = UNK
    return img


def write_map(folder, img, name="m", resolution=0.05, origin=(-1.0, -2.0, 0.0), ext="png", extra="", mode=None):
    folder = str(folder)
    im = img if isinstance(img, Image.Image) else Image.fromarray(img)
    im.save(os.path.join(folder, f"{name}.{ext}"))
    y = os.path.join(folder, f"{name}.yaml")
    with open(y, "w") as fh:
        fh.write(f"image: {name}.{ext}\nresolution: {resolution!r}\norigin: [{origin[0]!r}, {origin[1]!r}, "
                 f"{origin[2]!r}]\noccupied_thresh: 0.65\nfree_thresh: 0.196\n{extra}")
        if mode:
            fh.write(f"mode: {mode}\n")
    return y


def cell_squares(mask: np.ndarray, resolution: float, origin) -> np.ndarray:
    """The squares of the True cells, as map_server places them (image row 0 at the top)."""
    h = mask.shape[0]
    rows, cols = np.nonzero(mask)
    j = h - 1 - rows
    ox, oy = origin[0], origin[1]
    return shapely.box(ox + cols * resolution, oy + j * resolution, ox + (cols + 1) * resolution,
                       oy + (j + 1) * resolution)


def union_of(data) -> shapely.Geometry:
    return shapely.union_all([shapely.Polygon(o["polygon"], o.get("holes", [])) for o in data["obstacles"]])


def options(**kw):
    kw.setdefault("start", (0.0, 0.0))
    kw.setdefault("goal", (1.0, 1.0))
    return ImportOptions(**kw)


# ------------------------------------------------------------------ containment: every blocked cell inside


@pytest.mark.parametrize("resolution, origin", [(0.05, (-1.0, -2.0, 0.0)), (1.0, (0.0, 0.0, 0.0)),
                                                (0.1, (1e4 + 0.3, -7.7, 0.0)), (0.025, (-3.3, 2.1, 0.0)),
                                                (2.0**-7, (0.0, 0.0, 0.0)), (3.0, (-100.0, 50.0, 0.0)),
                                                (0.01, (1e9 + 0.37, -3e8, 0.0))])  # ulps near 1e-7
@pytest.mark.parametrize("tolerance", [0.0, None, 3.0])  # in cells (None: the default, two cells)
def test_every_blocked_cell_is_inside_the_polygons(tmp_path, resolution, origin, tolerance):
    img = blobs(70, 90, seed=int(resolution * 1000) % 97)
    y = write_map(tmp_path, img, resolution=resolution, origin=origin)
    tol = None if tolerance is None else tolerance * resolution
    imp = import_file(y, options(tolerance=tol))
    u = union_of(imp.data)
    blocked = img <= UNK  # occupied or unknown (unknown count as obstacles by default)
    assert shapely.covers(u, cell_squares(blocked, resolution, origin)).all()
    # ... and nothing far from a blocked cell: within the tolerance (the exact staircase: within 0)
    cells = shapely.union_all(cell_squares(blocked, resolution, origin))
    ring = shapely.box(origin[0] - resolution, origin[1] - resolution, origin[0] + 91 * resolution,
                       origin[1] + 71 * resolution).difference(
        shapely.box(origin[0], origin[1], origin[0] + 90 * resolution, origin[1] + 70 * resolution))
    cells = cells.union(ring)  # the ring of unknown cells around the map
    reach = 1e-9 * resolution * 100 if tolerance == 0 else (2 * resolution if tolerance is None else tol) * 1.0001
    reach += 1e3 * np.spacing(abs(origin[0]) + abs(origin[1]) + 100 * resolution)  # this oracle's own rounding
    # (free cells filled where blocked cells touched only at a corner are the one exception, counted)
    filled = sum(int(w.split(": ")[1].split()[0]) for w in imp.warnings if "touched only at a corner" in w)
    extra = u.difference(cells.buffer(reach, join_style="mitre")).area
    assert extra <= (filled + 1e-6) * resolution**2 * (1 + 1e-9)
    # the polygons are what the loader accepts: simple shells, holes fitting inside
    from cspace.kernel.polygons.polygon import invalid_reason

    for o in imp.data["obstacles"]:
        assert invalid_reason(np.array(o["polygon"])) is None
        assert invalid_reason(np.array(o["polygon"]), [np.array(h) for h in o.get("holes", [])]) is None


def test_the_exact_staircase_has_the_area_and_the_holes_of_the_cells(tmp_path):
    img = np.full((40, 40), FREE, np.uint8)
    img[5:25, 5:25] = OCC          # a square ...
    img[10:15, 10:20] = FREE       # ... with a 5 x 10 hole
    img[30:33, 30:38] = OCC        # and a bar
    y = write_map(tmp_path, img, resolution=0.5, origin=(2.0, 3.0, 0.0))
    imp = import_file(y, options(tolerance=0.0, unknown="free"))
    polys = [shapely.Polygon(o["polygon"], o.get("holes", [])) for o in imp.data["obstacles"]]
    assert len(polys) == 2
    assert sorted(p.area for p in polys) == [24 * 0.25, (400 - 50) * 0.25]
    assert sorted(len(o.get("holes", [])) for o in imp.data["obstacles"]) == [0, 1]
    big = max(polys, key=lambda p: p.area)
    hole = shapely.Polygon(big.interiors[0])
    # hole: image rows 10..14 -> y from the bottom 25..29 -> world 3 + 25 * 0.5 = 15.5 .. 18
    assert hole.bounds == (2.0 + 10 * 0.5, 3.0 + 25 * 0.5, 2.0 + 20 * 0.5, 3.0 + 30 * 0.5)
    # no collinear vertex: a square with a rectangular hole has 4 + 4 vertices
    assert len(big.exterior.coords) - 1 == 4 and len(big.interiors[0].coords) - 1 == 4


def test_simplification_reduces_vertices_and_keeps_cells(tmp_path):
    h = w = 200
    yy, xx = np.mgrid[:h, :w]
    img = np.full((h, w), FREE, np.uint8)
    img[(yy - 100) ** 2 + (xx - 100) ** 2 < 80**2] = OCC  # a big disk: a long staircase
    y = write_map(tmp_path, img, resolution=0.1, origin=(0.0, 0.0, 0.0))
    exact = import_file(y, options(tolerance=0.0, unknown="free"))
    simple = import_file(y, options(tolerance=0.3, unknown="free"))
    n_exact = sum(len(o["polygon"]) for o in exact.data["obstacles"])
    n_simple = sum(len(o["polygon"]) for o in simple.data["obstacles"])
    assert n_simple < n_exact / 3, (n_simple, n_exact)
    assert shapely.covers(union_of(simple.data), cell_squares(img == OCC, 0.1, (0, 0))).all()
    assert any("largest error" in line for line in simple.report)


# ------------------------------------------------------------------ thresholds as map_server


def test_trinary_thresholds_and_negate():
    info = MapInfo("m.png", 1.0, (0.0, 0.0, 0.0))
    v = np.array([[0, 89, 90, 204, 205, 206, 254, 255]], np.uint8)
    # p = (255 - v) / 255: occupied when p > 0.65 (v < 89.25), free when p < 0.196 (v > 205.02)
    assert classify(v, None, info).tolist() == [[1, 1, -1, -1, -1, 0, 0, 0]]
    info.negate = True  # p = v / 255: occupied when v > 165.75, free when v < 49.98
    assert classify(v, None, info).tolist() == [[0, -1, -1, 1, 1, 1, 1, 1]]


def test_scale_mode_transparent_is_unknown_and_raw_mode_reads_values():
    info = MapInfo("m.png", 1.0, (0.0, 0.0, 0.0), mode="scale")
    v = np.array([[0, 0, 254]], np.uint8)
    assert classify(v, np.array([[255, 0, 255]], np.uint8), info).tolist() == [[1, -1, 0]]
    raw = MapInfo("m.png", 1.0, (0.0, 0.0, 0.0), mode="raw")
    assert classify(np.array([[0, 19, 100, 50, 255, 180]], np.uint8), None, raw).tolist() == [[0, 0, 1, -1, -1, -1]]


@pytest.mark.parametrize("pil_mode", ["L", "RGB", "RGBA", "LA", "P", "1"])
def test_image_modes_give_the_same_cells(tmp_path, pil_mode):
    img = blobs(30, 40, seed=5, unknown=pil_mode != "1")
    if pil_mode == "1":
        img = np.where(img == OCC, 0, 255).astype(np.uint8)
    im = Image.fromarray(img).convert(pil_mode)
    y_ref = write_map(tmp_path, img, name="ref")
    y = write_map(tmp_path, im, name="m")
    a = import_file(y_ref, options(tolerance=0.0)).data["obstacles"]
    b = import_file(y, options(tolerance=0.0)).data["obstacles"]
    assert a == b


def test_unknown_free_leaves_unknown_cells_and_the_outside_open(tmp_path):
    img = np.full((20, 20), UNK, np.uint8)
    img[5:8, 5:8] = OCC
    y = write_map(tmp_path, img, resolution=1.0, origin=(0.0, 0.0, 0.0))
    imp = import_file(y, options(tolerance=0.0, unknown="free"))
    assert [shapely.Polygon(o["polygon"]).area for o in imp.data["obstacles"]] == [9.0]
    blocked = import_file(y, options(tolerance=0.0))
    assert len(blocked.data["obstacles"]) == 1 and union_of(blocked.data).area == 22 * 22 - 0.0


def test_the_flat_yaml_reader():
    text = "# map\nimage: 'my map.pgm'  # quoted\nresolution: 0.050000\norigin: [-10.0, -10.0, 0.0]\n" \
           "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
    d = parse_flat_yaml(text, "m.yaml")
    assert d == {"image": "my map.pgm", "resolution": 0.05, "origin": [-10.0, -10.0, 0.0], "negate": 0,
                 "occupied_thresh": 0.65, "free_thresh": 0.196, "mode": "trinary"}


# ------------------------------------------------------------------ a planned path stays out of every cell


@pytest.mark.parametrize("seed", [0, 1])
def test_a_planned_path_stays_out_of_every_blocked_cell(tmp_path, seed):
    from planners import plan

    img = blobs(80, 100, seed=seed, n=25, unknown=False)
    img[35:45, 0:8] = FREE
    img[35:45, 92:] = FREE
    res, origin = 0.05, (-2.5, 1.0, 0.0)
    y = write_map(tmp_path, img, resolution=res, origin=origin)
    start = (origin[0] + 4 * res, origin[1] + 40 * res)
    goal = (origin[0] + 96 * res, origin[1] + 40 * res)
    sc = load_imported(y, options=ImportOptions(robot={"radius": 0.06}, start=start, goal=goal))
    result = plan(sc, planner="RRTConnect", time=5.0, seed=seed)
    assert result.solved
    cells = shapely.union_all(cell_squares(img <= UNK, res, origin))
    robot = shapely.Polygon(sc.robot[0].polygon)
    path = np.asarray(result.path)
    for a, b in zip(path[:-1], path[1:]):  # the convex robot swept along a segment: the hull of its ends
        swept = shapely.union_all([shapely.affinity.translate(robot, *a), shapely.affinity.translate(robot, *b)])
        assert not swept.convex_hull.intersects(cells)


def test_plan_and_import_on_the_command_line(tmp_path, capsys):
    img = blobs(40, 60, seed=3, unknown=False)
    img[15:25, 0:6] = FREE
    img[15:25, 54:] = FREE
    y = write_map(tmp_path, img, resolution=0.1, origin=(0.0, 0.0, 0.0))
    out = tmp_path / "s.toml"
    argv = ["--radius", "0.1", "--start", "0.3,2.0", "--goal", "5.7,2.0"]
    assert main(["import", y, "--out", str(out), *argv]) == 0
    text = capsys.readouterr().out
    assert "obstacles:" in text and "largest error" in text
    sc = load_scenario(out)
    assert sc.robot_kind == "disk" and sc.start == (0.3, 2.0)
    assert main(["plan", y, *argv]) == 0
    assert main(["plan", str(out)]) == 0


# ------------------------------------------------------------------ bad input: one line, exit 2, nothing written


def run_import(capsys, tmp_path, yaml_path, *extra):
    out = tmp_path / "out.toml"
    code = main(["import", str(yaml_path), "--out", str(out), "--start", "0.5,0.5", "--goal", "1,1", *extra])
    err = capsys.readouterr().err.strip().splitlines()
    return code, err, out


@pytest.mark.parametrize("drop, field", [("resolution", "resolution"), ("image", "image"), ("origin", "origin")])
def test_a_yaml_without_a_key(tmp_path, capsys, drop, field):
    y = write_map(tmp_path, blobs(20, 20, 1))
    text = "".join(line + "\n" for line in open(y).read().splitlines() if not line.startswith(drop + ":"))
    open(y, "w").write(text)
    code, err, out = run_import(capsys, tmp_path, y)
    assert code == 2 and len(err) == 1 and err[0].startswith(f"error: {y}: {field}: ") and not out.exists()


@pytest.mark.parametrize("case", ["missing image", "16-bit", "not an image", "huge", "bad mode", "bad negate",
                                  "thresholds", "nested yaml", "negative resolution"])
def test_bad_maps_are_one_line(tmp_path, capsys, case):
    y = write_map(tmp_path, blobs(20, 20, 1))
    png = os.path.join(tmp_path, "m.png")
    text = open(y).read()
    if case == "missing image":
        os.remove(png)
    elif case == "16-bit":
        Image.fromarray(np.full((20, 20), 40000, np.uint16)).save(png)
    elif case == "not an image":
        open(png, "wb").write(b"\x89PNG\r\n\x1a\n not really")
    elif case == "huge":  # a header claiming 10^8 cells, no data: refused before reading pixels
        open(y, "w").write(text.replace("m.png", "big.pgm"))
        open(os.path.join(tmp_path, "big.pgm"), "wb").write(b"P5\n10000 10000\n255\n")
    elif case == "bad mode":
        open(y, "a").write("mode: quaternary\n")
    elif case == "bad negate":
        open(y, "a").write("negate: 2\n")
    elif case == "thresholds":
        open(y, "w").write(text.replace("free_thresh: 0.196", "free_thresh: 0.9"))
    elif case == "nested yaml":
        open(y, "a").write("extra:\n  nested: 1\n")
    elif case == "negative resolution":
        open(y, "w").write(text.replace("resolution: 0.05", "resolution: -0.05"))
    code, err, out = run_import(capsys, tmp_path, y)
    assert code == 2, err
    assert len(err) == 1 and err[0].startswith("error: ") and len(err[0]) < 300, err
    assert not out.exists()


def test_the_output_is_never_an_input(tmp_path, capsys):
    y = write_map(tmp_path, blobs(20, 20, 1))
    before = open(y, "rb").read()
    assert main(["import", y, "--out", y.replace(".yaml", ".toml"), "--start", "0.5,0.5", "--goal", "1,1"]) in (0, 2)
    code = main(["import", y, "--out", y, "--start", "0.5,0.5", "--goal", "1,1"])
    assert code == 2 and open(y, "rb").read() == before
    capsys.readouterr()


def test_import_options_are_refused_for_a_scenario_toml(capsys):
    from conftest import SCENARIOS

    code = main(["plan", os.path.join(SCENARIOS, "basic.toml"), "--radius", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--radius" in err[0]


def test_a_map_without_start_says_so(tmp_path, capsys):
    y = write_map(tmp_path, blobs(20, 20, 1))
    code = main(["plan", y])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and ": start: " in err[0] and "--start" in err[0]


def test_a_cfg_without_pycollada_says_how_to_get_it(tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "collada", None)  # as if pycollada were not installed
    (tmp_path / "r.dae").write_text("<COLLADA/>")  # present: the missing reader is what is reported
    (tmp_path / "w.dae").write_text("<COLLADA/>")
    cfg = tmp_path / "p.cfg"
    cfg.write_text("[problem]\nrobot = r.dae\nworld = w.dae\nstart.x = 0\nstart.y = 0\ngoal.x = 1\ngoal.y = 1\n")
    out = tmp_path / "s.toml"
    code = main(["import", str(cfg), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "pycollada" in err[0] and ".[io]" in err[0] and not out.exists()


def test_the_bench_script_runs_small(monkeypatch, capsys):
    import sys

    from conftest import load_script

    bench = load_script("bench_import")
    monkeypatch.setattr(sys, "argv", ["bench_import.py", "--size", "300", "--obstacles", "15", "--reps", "1"])
    assert bench.main() == 0
    out = capsys.readouterr().out
    assert "read image (peer)" in out and "C-space build" in out and "targets" in out


def test_show_draws_an_imported_map(tmp_path, capsys):
    y = write_map(tmp_path, blobs(40, 60, seed=2, unknown=False))
    png = tmp_path / "c.png"
    assert main(["show", y, "--radius", "0.05", "--start", "0.1,0.1", "--goal", "0.1,0.1", "--plot", str(png)]) in (0, 2)
    out, err = capsys.readouterr()
    assert ("C-obstacle pieces" in out and png.stat().st_size > 10_000) or ": start: " in err


def test_huge_numbers_in_the_yaml_are_one_line(tmp_path, capsys):
    y = write_map(tmp_path, blobs(20, 20, 1))
    text = open(y).read()
    open(y, "w").write(text.replace("resolution: 0.05", "resolution: " + "9" * 400))
    code, err, out = run_import(capsys, tmp_path, y)
    assert code == 2 and len(err) == 1 and ": resolution: " in err[0] and len(err[0]) < 300


@pytest.mark.parametrize("mode, negate", [("raw", 0), ("scale", 0), ("trinary", 1), ("raw", 1)])
def test_modes_end_to_end_cover_the_cells_map_server_blocks(tmp_path, mode, negate):
    rng = np.random.default_rng(11)
    img = rng.integers(0, 256, (30, 40)).astype(np.uint8)
    img[rng.random((30, 40)) < 0.7] = 0 if (mode == "raw") != bool(negate) else 255  # mostly free
    y = write_map(tmp_path, img, resolution=0.2, origin=(1.0, -1.0, 0.0), mode=mode, extra=f"negate: {negate}\n")
    imp = import_file(y, options(tolerance=0.0))
    # map_server's rule, written out again: v (negated first), raw: p = v / 100 (over 100: unknown),
    # else p = (255 - v) / 255; blocked unless p < free_thresh (occupied and unknown are obstacles).
    v = 255 - img.astype(int) if negate else img.astype(int)
    p = v / 100.0 if mode == "raw" else (255 - v) / 255.0
    free = (p < 0.196) & ~((v > 100) if mode == "raw" else np.zeros(v.shape, bool))
    u = union_of(imp.data)
    assert shapely.covers(u, cell_squares(~free, 0.2, (1.0, -1.0))).all()
    # and no free cell inside, but those filled where blocked cells touched only at a corner (counted)
    filled = sum(int(w.split(": ")[1].split()[0]) for w in imp.warnings if "touched only at a corner" in w)
    inside = shapely.intersects(u, shapely.buffer(cell_squares(free, 0.2, (1.0, -1.0)), -1e-9)).sum()
    assert inside == filled
