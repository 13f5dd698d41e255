"""Fuzzing the imported ROS maps (issue 36): YAML + PGM/PNG image, written malformed by
hypothesis strategies and run through ``cspace import`` and ``cspace plan`` under the contract
of tests/helpers/fuzzing.py (exit 0, 1 or 2, never 3; exit 2 one line; inputs unchanged; no
temporaries; valid JSON; a hang alarm). The valid files the strategies start from:
tests/helpers/import_files.py. OMPL.app problems (meshes): tests/io/test_fuzz_meshes.py.

The budget is small by default; ``CSPACE_FUZZ_EXAMPLES=N`` runs N examples per test and
``CSPACE_FUZZ_REPORT=FILE`` writes the figures (test_fuzz_meshes.py's last test, shared with
this file and test_fuzz_cli when they run in one process). ``scripts/fuzz_inputs.py`` runs the
large campaign over scenario, map and mesh inputs. With ``CSPACE_FUZZ_KEEP=FOLDER`` a broken
contract does not stop the run: the case's files are copied to FOLDER, counted, and the report
test fails if any was kept.
"""
from __future__ import annotations

import os

import pytest
from hypothesis import given, strategies as st

from fuzzing import budget, check_case, mutate_bytes, run, workdir
from import_files import (ROBOT_BOXES, WORLD_BOXES, dae_text, has_collada, pgm_bytes, png_bytes, png_chunk,
                          write_map, write_problem)

pytest.importorskip("PIL")


# ------------------------------------------------------------------ map images

PIXEL = st.sampled_from([0, 0, 254, 254, 254, 254, 254, 254, 205, 100, 255, 1, 128])


@st.composite
def map_image(draw):
    """(file name, bytes) of a small map image, valid or malformed."""
    w, h = draw(st.sampled_from([(20, 20)] * 8 + [(24, 20), (1, 1), (1, 20), (3, 2), (21, 22), (5, 5)]))
    pixels = [254] * (w * h)
    if draw(st.integers(0, 2)):  # a wall from the bottom, open at the top
        for row in range(h // 3, h):
            for col in (w // 2 - 1, w // 2):
                if 0 <= col < w:
                    pixels[row * w + col] = 0
    for i, v in draw(st.lists(st.tuples(st.integers(0, w * h - 1), PIXEL), max_size=20)):
        pixels[i] = v
    if draw(st.integers(0, 4)):  # the start's and the goal's cells free, mostly
        for col, row in ((3, h - 4), (17, 3)):
            for dc in range(-3, 4):
                for dr in range(-3, 4):
                    if 0 <= col + dc < w and 0 <= row + dr < h:
                        pixels[(row + dr) * w + col + dc] = 254
    kind = draw(st.sampled_from(["P5"] * 6 + ["P2"] * 3 + ["png"] * 6 + ["bad pgm"] * 3 + ["bad png"] * 3
                                + ["bytes", "random", "empty"]))
    if kind in ("P5", "P2"):
        return "m.pgm", pgm_bytes(w, h, pixels, binary=kind == "P5")
    if kind == "png":
        colour, depth = draw(st.sampled_from([(0, 8), (0, 8), (2, 8), (4, 8), (6, 8), (0, 1), (0, 16), (2, 16),
                                              (3, 8), (0, 4)]))
        pal = bytes(draw(st.lists(st.integers(0, 255), min_size=3, max_size=3 * 16))) if colour == 3 else None
        if pal is not None:
            pal = pal[:len(pal) - len(pal) % 3]
        trns = draw(st.sampled_from([None, b"\x00", b"\x80" * 4])) if colour == 3 else None
        return "m.png", png_bytes(w, h, pixels, colour, depth, palette=pal, trns=trns)
    if kind == "bad pgm":
        fault = draw(st.sampled_from(["magic", "size", "maxval", "cut", "extra", "header"]))
        binary = draw(st.booleans())
        if fault == "magic":
            return "m.pgm", pgm_bytes(w, h, pixels, binary, magic=draw(st.sampled_from(
                [b"P6", b"P1", b"P4", b"P7", b"P3", b"PX", b"P", b"", b"p5", b"\xffP5"])))
        if fault == "size":
            ww, hh = draw(st.sampled_from([(0, h), (w, 0), (0, 0), (-1, h), (w, -3), (100000, 100000),
                                           (2**31, 1), (2**32 + 1, 1), (5000, 5000), (4097, 4096),
                                           (w + 1, h), (w, h + 5), ("a", h), (1.5, h)]))
            head = (b"P5" if binary else b"P2") + f"\n{ww} {hh}\n255\n".encode()
            return "m.pgm", head + pgm_bytes(w, h, pixels, binary)[len(f"P5\n{w} {h}\n255\n"):]
        if fault == "maxval":
            mv = draw(st.sampled_from([0, 1, 256, 65535, 65536, -1, 2**40]))
            return "m.pgm", pgm_bytes(w, h, pixels, binary, maxval=mv)
        if fault == "cut":
            data = pgm_bytes(w, h, pixels, binary)
            return "m.pgm", data[:draw(st.integers(0, max(0, len(data) - 1)))]
        if fault == "extra":
            return "m.pgm", pgm_bytes(w, h, pixels, binary, extra=draw(st.binary(min_size=1, max_size=64)))
        head = draw(st.sampled_from([b"P5\n# comment\n", b"P5 ", b"P5\n#", b"P5\n\n\n", b"P5\n# " + b"c" * 5000 + b"\n"]))
        return "m.pgm", head + f"{w} {h}\n255\n".encode() + bytes(pixels)
    if kind == "bad png":
        fault = draw(st.sampled_from(["size", "crc", "cut", "depth", "extra", "iend", "idat"]))
        if fault == "size":
            hw = draw(st.sampled_from([(0, h), (w, 0), (2**31 - 1, 2**31 - 1), (2**32 - 1, 1), (5000, 5000),
                                       (4097, 4096), (w + 3, h), (w, h + 7), (1, 1)]))
            return "m.png", png_bytes(w, h, pixels, hw=hw)
        if fault == "crc":
            return "m.png", png_bytes(w, h, pixels, bad_crc=True)
        if fault == "cut":
            data = png_bytes(w, h, pixels)
            return "m.png", data[:draw(st.integers(0, len(data) - 1))]
        if fault == "depth":
            colour, depth = draw(st.sampled_from([(0, 3), (2, 4), (3, 16), (5, 8), (6, 1), (0, 0), (9, 8)]))
            return "m.png", png_bytes(w, h, pixels, colour, depth)
        if fault == "extra":
            kind_ = draw(st.sampled_from([b"tEXt", b"zTXt", b"iCCP", b"abcd", b"IHDR", b"IDAT", b"PLTE"]))
            return "m.png", png_bytes(w, h, pixels, extra=png_chunk(kind_, draw(st.binary(max_size=40))))
        if fault == "iend":
            return "m.png", png_bytes(w, h, pixels, no_iend=True) + draw(st.binary(max_size=20))
        return "m.png", png_bytes(w, h, pixels)[:33] + png_chunk(b"IDAT", draw(st.binary(max_size=60))) + png_chunk(b"IEND", b"")
    if kind == "bytes":
        base = pgm_bytes(w, h, pixels) if draw(st.booleans()) else png_bytes(w, h, pixels)
        return draw(st.sampled_from(["m.pgm", "m.png"])), mutate_bytes(base, draw)
    if kind == "random":
        return draw(st.sampled_from(["m.pgm", "m.png", "m.jpg"])), draw(st.binary(max_size=200))
    return "m.pgm", b""


# ------------------------------------------------------------------ map YAML

YAML_NUMBER = st.sampled_from(["0.1", "1", "0", "-0.1", "-0", ".nan", "nan", "NaN", ".inf", "inf",
                               "-inf", "1e308", "1e309", "1e-308", "5e-324", "9" * 400, "abc", '"0.1"', "'0.1'", "[0.1]",
                               "{a: 1}", "~", "null", "true", "", "0x10", "1_000", "&a 0.1", "*a", "!!float 0.1",
                               "2e9", "1e-12", "0.1 # c", "|", ">"])
THRESH = st.sampled_from(["0.65", "0.196", "0", "1", "0.5", "-0.1", "1.1", "nan", "inf", "abc", "[]", "", "0.65",
                          "0.196", "1e-300", "true"])
ORIGIN = st.sampled_from(["[0.0, 0.0, 0.0]"] * 6 + ["[0, 0]", "[-1.0, -1.0, 0.0]", "[0, 0, 0.5]", "[0]", "[]",
                         "[0, 0, 0, 0]", "[nan, 0, 0]", "[inf, 0, 0]", "[1e308, 1e308, 0]", "[1e300, 0]", "[a, b, c]",
                         "[0, 0, 0", "0, 0, 0", "{x: 0, y: 0}", "0", '"[0, 0, 0]"', "[0,,0]", "[[0, 0], 0]",
                         "[0, 0, 1e400]", "[-1e5, 2e5, 0]", "&o [0, 0, 0]", "*o"])


@st.composite
def map_yaml(draw, image: str) -> bytes:
    fields = {"image": image, "resolution": "0.05", "origin": "[0.0, 0.0, 0.0]", "negate": "0",
              "occupied_thresh": "0.65", "free_thresh": "0.196", "mode": "trinary"}
    junk = {"image": st.sampled_from(["", "missing.pgm", os.path.join(os.pardir, "m.pgm"), "/dev/zero", "/proc/self/mem", ".",
                                      "m.pgm m.png", '"' + image + '"', "'" + image + "'", "[m.pgm]", "x" * 300,
                                      "/etc/passwd", "m.yaml", "\\0", "m.pgm" if image != "m.pgm" else "m.png"]),
            "resolution": YAML_NUMBER, "origin": ORIGIN, "occupied_thresh": THRESH, "free_thresh": THRESH,
            "negate": st.sampled_from(["1", "true", "false", "2", "-1", "0.5", "yes", "abc", ""]),
            "mode": st.sampled_from(["scale", "raw", "Trinary", "", "x", "1", "[raw]"])}
    for k in draw(st.lists(st.sampled_from(sorted(fields)), max_size=3, unique=True)):
        if draw(st.integers(0, 4)) == 0:
            del fields[k]
        else:
            fields[k] = draw(junk[k])
    lines = [f"{k}: {v}" for k, v in fields.items()]
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 2]))):
        extra = draw(st.sampled_from([
            "zz: 1", "image: other.pgm", "resolution: 0.2", "  indented: 1", "- item", "a: &x [1, 2, 3]",
            "b: [*x, *x, *x, *x]", "c: &y {a: *x}", "d: [*y, *y, *y]", "key without colon", "---", "...",
            "%YAML 1.2", "? complex", "e: |\n  block\n  text", "f: !!python/object/apply:os.system [ls]",
            "g: \"unterminated", "h: 'x' 'y'", ": empty key", "# comment", "\ttab: 1", "i: " + "[" * 200 + "]" * 200,
            "j: " + ",".join(["1"] * 2000), "k: " + "x" * 5000]))
        lines.insert(draw(st.integers(0, len(lines))), extra)
    text = "\n".join(lines) + draw(st.sampled_from(["\n", "", "\r\n", "\n\n"]))
    data = text.encode("utf-8")
    how = draw(st.sampled_from(["text"] * 20 + ["crlf", "bom", "latin1", "utf16", "bytes", "nul", "random"]))
    if how == "crlf":
        data = data.replace(b"\n", b"\r\n")
    elif how == "bom":
        data = b"\xef\xbb\xbf" + data
    elif how == "latin1":
        data = data + b"\nname: caf\xe9\n"
    elif how == "utf16":
        data = text.encode("utf-16")
    elif how == "bytes":
        data = mutate_bytes(data, draw)
    elif how == "nul":
        data = data.replace(b":", b":\0", 1)
    elif how == "random":
        data = draw(st.binary(max_size=200))
    return data


POSE = st.sampled_from(["0.15,0.15"] * 6 + ["0.95,0.95", "0.5,0.5", "0,0", "-1,-1", "nan,0", "inf,0", "1e300,1e300",
                        "abc", "", "1", "1,2,3", "1,2,3,4", "0.15 0.15", "0.15,,0.15"])
GOAL = st.sampled_from(["0.85,0.85"] * 6 + ["0.15,0.15", "0.5,0.5", "5,5", "nan,nan", "1,2,nan", "x,y", ""])
RADIUS = st.sampled_from(["0.04"] * 6 + ["0.01", "0.3", "0", "-1", "nan", "inf", "1e300", "1e-300", "abc", None])


@st.composite
def map_case(draw):
    image = draw(map_image())
    return draw(map_yaml(image[0])), image


def _import_flags(draw_radius, start, goal, extra):
    argv = []
    if draw_radius is not None:
        argv += ["--radius", draw_radius]
    if start is not None:
        argv += ["--start", start]
    if goal is not None:
        argv += ["--goal", goal]
    return argv + list(extra)


MAP_EXTRA = st.sampled_from([[]] * 8 + [["--tolerance", "0"]] * 3 + [["--unknown", "free"], ["--tolerance", "0"], ["--tolerance", "0.5"],
                                        ["--tolerance", "nan"], ["--tolerance", "-1"], ["--polygon", "0,0;0.05,0;0,0.05"],
                                        ["--polygon", "0,0;1e400,0;0,1"], ["--unknown", "obstacle"]])


@budget(30)
@given(case=map_case(), radius=RADIUS, start=POSE, goal=GOAL, extra=MAP_EXTRA)
def test_fuzz_map_import(case, radius, start, goal, extra):
    with workdir() as d:
        y, inputs = write_map(d, *case)
        out = os.path.join(d, "out.toml")
        run(["import", y, "--out", out] + _import_flags(radius, start, goal, extra), d, inputs, "map import", "map")


@budget(10)
@given(case=map_case(), radius=RADIUS, start=POSE, goal=GOAL, extra=MAP_EXTRA,
       planner=st.sampled_from([None, None, "exact", "RRTConnect"]))
def test_fuzz_map_plan(case, radius, start, goal, extra, planner):
    with workdir() as d:
        y, inputs = write_map(d, *case)
        js = os.path.join(d, "out.json")
        argv = ["plan", y, "--json", js, "--time", "0.2"] + _import_flags(radius, start, goal, extra)
        if planner:
            argv += ["--planner", planner]
        run(argv, d, inputs, "map plan", "map", json_out=js)


# ------------------------------------------------------------------ fixed cases

def test_the_templates_are_valid(tmp_path):
    """The unmutated inputs import (exit 0): the fuzz starts from files that reach the geometry."""
    from PIL import Image  # noqa: F401

    pixels = [254] * 400
    pixels[210] = pixels[211] = 0
    for name, img in (("m.pgm", pgm_bytes(20, 20, pixels)), ("m.pgm", pgm_bytes(20, 20, pixels, binary=False)),
                      ("m.png", png_bytes(20, 20, pixels))):
        d = tmp_path / name.replace(".", "") / str(len(img))
        d.mkdir(parents=True, exist_ok=True)
        yaml = (f"image: {name}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
                "free_thresh: 0.196\n").encode()
        y, inputs = write_map(str(d), yaml, (name, img))
        assert check_case(["import", y, "--out", str(d / "o.toml"), "--radius", "0.04", "--start", "0.15,0.15",
                           "--goal", "0.85,0.85"], str(d), inputs, "templates") == 0
    if has_collada():
        d = tmp_path / "mesh"
        d.mkdir()
        for poly in (False, True):
            cfg = ("[problem]\nrobot = robot.dae\nworld = world.dae\nstart.x = -5\nstart.y = 0\nstart.theta = 0\n"
                   "goal.x = 5\ngoal.y = 0\ngoal.theta = 1.57\nvolume.min.x = -10\nvolume.min.y = -10\n"
                   "volume.max.x = 10\nvolume.max.y = 10\n").encode()
            c, inputs = write_problem(str(d), (cfg, dae_text(ROBOT_BOXES, polylist=poly).encode(),
                                               dae_text(WORLD_BOXES, polylist=poly).encode()))
            assert check_case(["import", c, "--out", str(d / f"o{poly}.toml")], str(d), inputs, "templates") == 0
            assert check_case(["plan", c, "--json", str(d / "o.json"), "--time", "0.2"], str(d), inputs,
                              "templates", json_out=str(d / "o.json")) in (0, 1)  # 1: a busy machine


def test_found_a_map_beyond_the_doubles(tmp_path):
    """Found by the campaign: resolution 1e308 made the map's extent infinite, and the tracing's
    growth raised a GEOS error (exit 3); refused as the resolution, exit 2."""
    y, inputs = write_map(str(tmp_path), b"image: m.pgm\nresolution: 1e308\norigin: [0.0, 0.0, 0.0]\n",
                          ("m.pgm", pgm_bytes(20, 20, [254] * 400)))
    assert check_case(["import", y, "--out", str(tmp_path / "o.toml"), "--radius", "0.04", "--start", "0.15,0.15",
                       "--goal", "0.5,0.5"], str(tmp_path), inputs, "found") == 2
