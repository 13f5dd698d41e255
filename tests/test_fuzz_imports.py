"""Fuzzing the imported inputs (issue 36): ROS maps (YAML + PGM/PNG image) and OMPL.app
problems (.cfg + COLLADA meshes), written malformed by hypothesis strategies and run
through ``cspace import`` and ``cspace plan`` under the contract of
:mod:`test_fuzz_cli` (exit 0, 1 or 2, never 3; exit 2 one line; inputs unchanged; no
temporaries; valid JSON; a hang alarm).

The budget is small by default; ``CSPACE_FUZZ_EXAMPLES=N`` runs N examples per test and
``CSPACE_FUZZ_REPORT=FILE`` writes the figures (shared with test_fuzz_cli when both run in
one process). ``scripts/fuzz_inputs.py`` runs the large campaign over scenario, map and
mesh inputs. With ``CSPACE_FUZZ_KEEP=FOLDER`` a broken contract does not stop the run: the
case's files are copied to FOLDER, counted, and the last test fails if any was kept.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import struct
import zlib

import pytest
from hypothesis import given, strategies as st

import contextlib
import io
import signal
import time

import test_fuzz_cli as cli
from test_fuzz_cli import EXAMPLES, STATS, _mutate_bytes, budget, check_case, workdir

pytest.importorskip("PIL")

KEEP = os.environ.get("CSPACE_FUZZ_KEEP")
FAILURES: list = []
FILES = {"map": 0, "mesh": 0}  # files written per input kind


def check_import_case(argv, folder, inputs, label, json_out=None) -> int:
    """:func:`test_fuzz_cli.check_case` for imported files, but an exit 2 may print the import's
    ``warning:`` lines (``cspace plan`` writes them once the import is done) before its one
    ``error:`` line."""
    before = {p: cli._digest(p) for p in inputs}
    out, err = io.StringIO(), io.StringIO()
    old = signal.signal(signal.SIGALRM, cli._alarm)
    signal.alarm(cli.HANG_SECONDS)
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = cli.main(argv)
            except SystemExit as exc:
                code = exc.code
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    cli._record(label, code, time.perf_counter() - t0, argv)
    text = err.getvalue()
    short = cli._short(argv)
    assert code in (0, 1, 2), f"exit {code} for {short}: {text[-500:]}"
    assert "Traceback" not in text and "internal error" not in text, text[-500:]
    if code == 2:
        lines = text.strip().splitlines()
        assert lines and lines[-1].startswith("error: "), f"{short}: {text[-500:]}"
        assert all(line.startswith("warning: ") for line in lines[:-1]), f"{short}: {text[-500:]}"
        assert len(lines[-1]) <= 600, f"{len(lines[-1])} characters: {lines[-1][:200]}"
    for p, h in before.items():
        assert cli._digest(p) == h, f"input {p} changed by {short}"
    left = [n for _, _, names in os.walk(folder) for n in names if n.startswith((".cspace-tmp-", ".tmp-"))]
    assert not left, f"temporaries left: {left}"
    if code in (0, 1) and json_out and os.path.isfile(json_out) and not os.path.islink(json_out):
        with open(json_out, encoding="utf-8") as fh:
            json.load(fh)
    return code


def run(argv, folder, inputs, label, kind, json_out=None):
    FILES[kind] += len(inputs)
    STATS.setdefault("files", {}).setdefault(kind, 0)
    STATS["files"][kind] += len(inputs)
    try:
        return check_import_case(argv, folder, inputs, label, json_out=json_out)
    except AssertionError as exc:
        if not KEEP:
            raise
        dest = os.path.join(KEEP, f"case-{len(FAILURES):04d}")
        shutil.copytree(folder, dest, symlinks=True, ignore_dangling_symlinks=True)
        with open(os.path.join(dest, "WHY.txt"), "w") as fh:
            fh.write(f"{argv!r}\n{exc}\n")
        FAILURES.append((label, str(exc)[:300], dest))
        return None


# ------------------------------------------------------------------ map images

def _pgm(w, h, pixels, binary=True, maxval=255, magic=None, extra=b"", cut=None):
    magic = magic or (b"P5" if binary else b"P2")
    head = magic + b"\n" + f"{w} {h}\n{maxval}\n".encode()
    if binary:
        body = bytes(p % 256 for p in pixels)
    else:
        body = "\n".join(" ".join(str(p) for p in pixels[i:i + 16]) for i in range(0, len(pixels), 16)).encode() + b"\n"
    data = head + body + extra
    return data[:cut] if cut is not None else data


def _chunk(kind: bytes, data: bytes, crc=None) -> bytes:
    c = zlib.crc32(kind + data) if crc is None else crc
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", c & 0xFFFFFFFF)


def _png(w, h, pixels, colour=0, depth=8, hw=None, bad_crc=False, cut=None, extra=b"", palette=None,
         trns=None, no_iend=False, level=6):
    chans = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}.get(colour, 1)
    rows = []
    it = iter(pixels * (chans * 2 + 1))
    for _ in range(h):
        row = bytes(next(it, 0) % 256 for _ in range(max(1, (w * chans * depth + 7) // 8)))
        rows.append(b"\0" + row)
    raw = zlib.compress(b"".join(rows), level)
    hw_ = hw or (w, h)
    ihdr = struct.pack(">IIBBBBB", hw_[0] & 0xFFFFFFFF, hw_[1] & 0xFFFFFFFF, depth, colour, 0, 0, 0)
    out = b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr, crc=0 if bad_crc else None)
    if palette is not None:
        out += _chunk(b"PLTE", palette)
    if trns is not None:
        out += _chunk(b"tRNS", trns)
    out += _chunk(b"IDAT", raw) + extra
    if not no_iend:
        out += _chunk(b"IEND", b"")
    return out[:cut] if cut is not None else out


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
        return "m.pgm", _pgm(w, h, pixels, binary=kind == "P5")
    if kind == "png":
        colour, depth = draw(st.sampled_from([(0, 8), (0, 8), (2, 8), (4, 8), (6, 8), (0, 1), (0, 16), (2, 16),
                                              (3, 8), (0, 4)]))
        pal = bytes(draw(st.lists(st.integers(0, 255), min_size=3, max_size=3 * 16))) if colour == 3 else None
        if pal is not None:
            pal = pal[:len(pal) - len(pal) % 3]
        trns = draw(st.sampled_from([None, b"\x00", b"\x80" * 4])) if colour == 3 else None
        return "m.png", _png(w, h, pixels, colour, depth, palette=pal, trns=trns)
    if kind == "bad pgm":
        fault = draw(st.sampled_from(["magic", "size", "maxval", "cut", "extra", "header"]))
        binary = draw(st.booleans())
        if fault == "magic":
            return "m.pgm", _pgm(w, h, pixels, binary, magic=draw(st.sampled_from(
                [b"P6", b"P1", b"P4", b"P7", b"P3", b"PX", b"P", b"", b"p5", b"\xffP5"])))
        if fault == "size":
            ww, hh = draw(st.sampled_from([(0, h), (w, 0), (0, 0), (-1, h), (w, -3), (100000, 100000),
                                           (2**31, 1), (2**32 + 1, 1), (5000, 5000), (4097, 4096),
                                           (w + 1, h), (w, h + 5), ("a", h), (1.5, h)]))
            head = (b"P5" if binary else b"P2") + f"\n{ww} {hh}\n255\n".encode()
            return "m.pgm", head + _pgm(w, h, pixels, binary)[len(f"P5\n{w} {h}\n255\n"):]
        if fault == "maxval":
            mv = draw(st.sampled_from([0, 1, 256, 65535, 65536, -1, 2**40]))
            return "m.pgm", _pgm(w, h, pixels, binary, maxval=mv)
        if fault == "cut":
            data = _pgm(w, h, pixels, binary)
            return "m.pgm", data[:draw(st.integers(0, max(0, len(data) - 1)))]
        if fault == "extra":
            return "m.pgm", _pgm(w, h, pixels, binary, extra=draw(st.binary(min_size=1, max_size=64)))
        head = draw(st.sampled_from([b"P5\n# comment\n", b"P5 ", b"P5\n#", b"P5\n\n\n", b"P5\n# " + b"c" * 5000 + b"\n"]))
        return "m.pgm", head + f"{w} {h}\n255\n".encode() + bytes(pixels)
    if kind == "bad png":
        fault = draw(st.sampled_from(["size", "crc", "cut", "depth", "extra", "iend", "idat"]))
        if fault == "size":
            hw = draw(st.sampled_from([(0, h), (w, 0), (2**31 - 1, 2**31 - 1), (2**32 - 1, 1), (5000, 5000),
                                       (4097, 4096), (w + 3, h), (w, h + 7), (1, 1)]))
            return "m.png", _png(w, h, pixels, hw=hw)
        if fault == "crc":
            return "m.png", _png(w, h, pixels, bad_crc=True)
        if fault == "cut":
            data = _png(w, h, pixels)
            return "m.png", data[:draw(st.integers(0, len(data) - 1))]
        if fault == "depth":
            colour, depth = draw(st.sampled_from([(0, 3), (2, 4), (3, 16), (5, 8), (6, 1), (0, 0), (9, 8)]))
            return "m.png", _png(w, h, pixels, colour, depth)
        if fault == "extra":
            return "m.png", _png(w, h, pixels, extra=_chunk(draw(st.sampled_from([b"tEXt", b"zTXt", b"iCCP", b"abcd",
                                                                                 b"IHDR", b"IDAT", b"PLTE"])),
                                                            draw(st.binary(max_size=40))))
        if fault == "iend":
            return "m.png", _png(w, h, pixels, no_iend=True) + draw(st.binary(max_size=20))
        return "m.png", _png(w, h, pixels)[:33] + _chunk(b"IDAT", draw(st.binary(max_size=60))) + _chunk(b"IEND", b"")
    if kind == "bytes":
        base = _pgm(w, h, pixels) if draw(st.booleans()) else _png(w, h, pixels)
        return draw(st.sampled_from(["m.pgm", "m.png"])), _mutate_bytes(base, draw)
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
        data = _mutate_bytes(data, draw)
    elif how == "nul":
        data = data.replace(b":", b":\0", 1)
    elif how == "random":
        data = draw(st.binary(max_size=200))
    return data


POSE = st.sampled_from(["0.15,0.15"] * 6 + ["0.95,0.95", "0.5,0.5", "0,0", "-1,-1", "nan,0", "inf,0", "1e300,1e300",
                        "abc", "", "1", "1,2,3", "1,2,3,4", "0.15 0.15", "0.15,,0.15"])
GOAL = st.sampled_from(["0.85,0.85"] * 6 + ["0.15,0.15", "0.5,0.5", "5,5", "nan,nan", "1,2,nan", "x,y", ""])
RADIUS = st.sampled_from(["0.04"] * 6 + ["0.01", "0.3", "0", "-1", "nan", "inf", "1e300", "1e-300", "abc", None])


def _write_map(d, data_yaml, image):
    name, img = image
    y = os.path.join(d, "m.yaml")
    with open(y, "wb") as fh:
        fh.write(data_yaml)
    i = os.path.join(d, name)
    with open(i, "wb") as fh:
        fh.write(img)
    return y, [y, i]


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
        y, inputs = _write_map(d, *case)
        out = os.path.join(d, "out.toml")
        run(["import", y, "--out", out] + _import_flags(radius, start, goal, extra), d, inputs, "map import", "map")


@budget(10)
@given(case=map_case(), radius=RADIUS, start=POSE, goal=GOAL, extra=MAP_EXTRA,
       planner=st.sampled_from([None, None, "exact", "RRTConnect"]))
def test_fuzz_map_plan(case, radius, start, goal, extra, planner):
    with workdir() as d:
        y, inputs = _write_map(d, *case)
        js = os.path.join(d, "out.json")
        argv = ["plan", y, "--json", js, "--time", "0.2"] + _import_flags(radius, start, goal, extra)
        if planner:
            argv += ["--planner", planner]
        run(argv, d, inputs, "map plan", "map", json_out=js)


# ------------------------------------------------------------------ COLLADA meshes

def _box(x0, x1, y0, y1, z0=-1.0, z1=1.0):
    """8 corners and 12 triangles (indices) of a box; plane (x, y), extrusion z (Y_UP)."""
    pts = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, e in quads:
        tris += [a, b, c, a, c, e]
    return pts, tris


def dae_text(boxes, matrix="1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", up="Y_UP", unit=None, node_extra="",
             library_nodes="", scene_extra="", polylist=False) -> str:
    geoms, nodes = [], []
    for i, b in enumerate(boxes):
        pts, tris = _box(*b)
        arr = " ".join(f"{c:g}" for p in pts for c in p)
        if polylist:
            prim = (f'<polylist count="{len(tris) // 3}"><input offset="0" semantic="VERTEX" source="#v{i}"/>'
                    f'<vcount>{" ".join(["3"] * (len(tris) // 3))}</vcount><p>{" ".join(map(str, tris))}</p></polylist>')
        else:
            prim = (f'<triangles count="{len(tris) // 3}"><input offset="0" semantic="VERTEX" source="#v{i}"/>'
                    f'<p>{" ".join(map(str, tris))}</p></triangles>')
        geoms.append(
            f'<geometry id="g{i}"><mesh><source id="s{i}"><float_array id="a{i}" count="{len(pts) * 3}">{arr}'
            f'</float_array><technique_common><accessor count="{len(pts)}" source="#a{i}" stride="3">'
            f'<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>'
            f'</technique_common></source><vertices id="v{i}"><input semantic="POSITION" source="#s{i}"/></vertices>'
            f'{prim}</mesh></geometry>')
        nodes.append(f'<node id="n{i}" name="n{i}"><matrix>{matrix}</matrix>{node_extra}'
                     f'<instance_geometry url="#g{i}"/></node>')
    unit_ = f'<unit meter="{unit}" name="u"/>' if unit is not None else ""
    return ('<?xml version="1.0" encoding="utf-8"?>\n'
            '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">\n'
            f'<asset>{unit_}<up_axis>{up}</up_axis></asset>\n'
            f'<library_geometries>{"".join(geoms)}</library_geometries>\n{library_nodes}'
            f'<library_visual_scenes><visual_scene id="vs">{"".join(nodes)}{scene_extra}</visual_scene>'
            '</library_visual_scenes>\n<scene><instance_visual_scene url="#vs"/></scene>\n</COLLADA>\n')


ROBOT_BOXES = [(-0.5, 0.5, -0.25, 0.25)]
WORLD_BOXES = [(-1.0, 1.0, -10.0, 3.0), (4.0, 5.0, 5.0, 6.0)]
BAD_NUMBER = st.sampled_from(["nan", "NaN", "inf", "-inf", "INF", "1e308", "-1e308", "1e309", "-0", "-0.0",
                              "99999999999999999999999", "1e-320", "abc", "", "0x1p3", "1,5", "1e", "--1",
                              "1e6", "2e6", "1e5", "3"])
BAD_COUNT = st.sampled_from(["0", "-1", "-8", "1", "2", "7", "9", "25", "1000000", "4294967296", "99999999999999",
                             "abc", "", "1.5", "nan", "3e0"])


def _sub_nth(pattern, text, draw, repl_fn):
    hits = list(re.finditer(pattern, text))
    if not hits:
        return text
    m = hits[draw(st.integers(0, len(hits) - 1))]
    return text[:m.start()] + repl_fn(m) + text[m.end():]


@st.composite
def dae_mutation(draw, text: str) -> bytes:
    for _ in range(draw(st.sampled_from([0, 1, 1, 1, 2, 3]))):
        kind = draw(st.sampled_from(["number", "number", "count", "stride", "index", "index", "vcount", "delete",
                                     "unit", "transform", "up", "instance_node", "doctype", "empty array",
                                     "dup id", "url", "namespace", "comment"]))
        if kind == "number":
            text = _sub_nth(r"(?<=[ >])-?\d+(\.\d+)?(?=[ <])", text, draw, lambda m: draw(BAD_NUMBER))
        elif kind == "count":
            text = _sub_nth(r'count="\d+"', text, draw, lambda m: f'count="{draw(BAD_COUNT)}"')
        elif kind == "stride":
            text = _sub_nth(r'stride="\d+"', text, draw, lambda m: f'stride="{draw(BAD_COUNT)}"')
        elif kind == "index":
            def _idx(m):
                return m.group(1) + draw(st.sampled_from(["8", "9", "-1", "100", "4294967296", "99999999999999999999",
                                                          "x", "1.5", "", "7 7"])) + m.group(3)
            text = _sub_nth(r"(<p>(?:\d+ )*)(\d+)((?: \d+)*</p>)", text, draw, _idx)
        elif kind == "vcount":
            text = text.replace("<triangles", "<polylist").replace("</triangles>", "</polylist>")
            text = _sub_nth(r"<p>", text, draw, lambda m: "<vcount>" + draw(st.sampled_from(
                ["3 3 3", "2 4", "0", "-3 9", "3 " * 12, "3 " * 13, "1000000", "", "x", "4 4 4 4 4 4 4 4 4"]))
                + "</vcount><p>")
        elif kind == "delete":
            tag = draw(st.sampled_from(["float_array", "accessor", "vertices", "triangles", "p", "matrix",
                                        "instance_geometry", "source", "mesh", "scene", "asset", "up_axis",
                                        "library_geometries", "visual_scene", "input", "technique_common"]))
            text = _sub_nth(rf"<{tag}\b[^>]*?/>|<{tag}\b[^>]*>.*?</{tag}>", text, draw, lambda m: "")
        elif kind == "unit":
            u = draw(st.sampled_from(["0", "-1", "nan", "inf", "1e-9", "1e9", "abc", "", "1e308", "0.001", "100",
                                      "1e-6", "1e6"]))
            text = re.sub(r"<unit [^>]*/>", "", text).replace("<asset>", f'<asset><unit meter="{u}" name="u"/>', 1)
        elif kind == "transform":
            el = draw(st.sampled_from([
                "<matrix>nan 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix>", "<matrix>1 0 0</matrix>",
                "<matrix>1e308 0 0 0 0 1e308 0 0 0 0 1e308 0 0 0 0 1</matrix>", "<matrix>0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0</matrix>",
                "<matrix>1 0 0 1e7 0 1 0 0 0 0 1 0 0 0 0 1</matrix>", "<matrix>abc</matrix>", "<matrix/>",
                "<rotate>0 0 1 nan</rotate>", "<rotate>0 0 0 90</rotate>", "<rotate>0 0 1 1e308</rotate>",
                "<rotate>1 0 0 90</rotate>", "<rotate>0 0 1</rotate>", "<translate>inf 0 0</translate>",
                "<translate>1e300 0 0</translate>", "<translate>1 2</translate>", "<scale>0 0 0</scale>",
                "<scale>1e200 1e200 1e200</scale>", "<scale>-1 1 1</scale>", "<scale>1e-300 1 1</scale>",
                "<lookat>0 0 0 0 0 0 0 0 0</lookat>", "<skew>45 1 0 0 0 1 0</skew>", "<translate>2 0 0</translate>"]))
            text = _sub_nth(r"<matrix>[^<]*</matrix>", text, draw, lambda m: draw(st.sampled_from(
                [el, m.group(0) + el, el + m.group(0)])))
        elif kind == "up":
            text = re.sub(r"<up_axis>[^<]*</up_axis>", f"<up_axis>{draw(st.sampled_from(['Z_UP', 'X_UP', 'W_UP', '', 'y_up', 'Z_UP Y_UP']))}</up_axis>", text)
        elif kind == "instance_node":
            depth = draw(st.integers(1, 70))
            cyclic = draw(st.sampled_from([False, False, True]))
            fan = draw(st.sampled_from([1, 1, 2, 3, 10]))
            libs = []
            for k in range(depth):
                child = (f'<instance_node url="#L{k + 1}"/>' * fan) if k + 1 < depth else (
                    '<instance_node url="#L0"/>' if cyclic else '<instance_geometry url="#g0"/>')
                libs.append(f'<node id="L{k}">{child}</node>')
            lib = f'<library_nodes>{"".join(libs)}</library_nodes>\n'
            text = text.replace("<library_visual_scenes>", lib + "<library_visual_scenes>", 1)
            text = text.replace("</visual_scene>", '<node id="top"><instance_node url="#L0"/></node></visual_scene>', 1)
        elif kind == "doctype":
            decl = draw(st.sampled_from([
                '<!DOCTYPE COLLADA [<!ENTITY a "1 2 3">]>', '<!DOCTYPE COLLADA SYSTEM "file:///etc/passwd">',
                '<!DOCTYPE COLLADA [<!ENTITY x SYSTEM "file:///etc/hostname">]>',
                '<!DOCTYPE l [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>']))
            text = text.replace("\n", "\n" + decl + "\n", 1)
            if "ENTITY" in decl and draw(st.booleans()):
                ent = re.search(r"ENTITY (\w+)", decl).group(1)
                text = text.replace("</float_array>", f" &{ent};</float_array>", 1)
        elif kind == "empty array":
            text = _sub_nth(r"(<float_array[^>]*>)[^<]*(</float_array>)", text, draw, lambda m: m.group(1) + m.group(2))
        elif kind == "dup id":
            text = text.replace('id="g1"', 'id="g0"')
        elif kind == "url":
            text = _sub_nth(r'(url|source)="#\w+"', text, draw, lambda m: m.group(1) + '="' + draw(st.sampled_from(
                ["#nothing", "", "#", "file:///etc/passwd", "other.dae#g0", "#vs", "#a0", "#n0"])) + '"')
        elif kind == "namespace":
            text = text.replace('xmlns="http://www.collada.org/2005/11/COLLADASchema"', draw(st.sampled_from(
                ['', 'xmlns="http://www.collada.org/2008/03/COLLADASchema"', 'xmlns="urn:x"'])))
        else:
            text = text.replace("<asset>", "<!-- " + "c" * draw(st.integers(0, 3000)) + " --><asset>", 1)
    data = text.encode("utf-8")
    how = draw(st.sampled_from(["text"] * 24 + ["cut", "bytes", "latin1", "utf16", "nonutf8", "random", "empty",
                                                "deep"]))
    if how == "cut":
        data = data[:draw(st.integers(0, len(data) - 1))]
    elif how == "bytes":
        data = _mutate_bytes(data, draw)
    elif how == "latin1":
        data = data.replace(b"utf-8", b"iso-8859-1").replace(b'name="n0"', b'name="n\xe90"')
    elif how == "utf16":
        data = text.replace('encoding="utf-8"', 'encoding="utf-16"').encode("utf-16")
    elif how == "nonutf8":
        data = data.replace(b'name="n0"', b'name="n\xff\xfe0"')
    elif how == "random":
        data = draw(st.binary(max_size=300))
    elif how == "empty":
        data = b""
    elif how == "deep":
        k = draw(st.sampled_from([100, 255, 257, 2000]))
        data = data.replace(b"</asset>", b"<extra>" + b"<a>" * k + b"</a>" * k + b"</extra></asset>", 1)
    return data


@st.composite
def mesh_problem(draw):
    """(cfg bytes, robot dae bytes, world dae bytes)."""
    opts = dict(up="Y_UP", polylist=draw(st.booleans()))
    if draw(st.booleans()):
        opts["unit"] = draw(st.sampled_from(["1", "0.01", "1"]))
    robot = dae_text(ROBOT_BOXES, **opts)
    world = dae_text(WORLD_BOXES, **opts)
    which = draw(st.sampled_from(["robot", "robot", "world", "world", "both", "neither"]))
    rb = draw(dae_mutation(robot)) if which in ("robot", "both") else robot.encode()
    wb = draw(dae_mutation(world)) if which in ("world", "both") else world.encode()
    unit = float(opts.get("unit", "1"))
    s = 1.0 if unit == 1 else unit
    keys = {"robot": "robot.dae", "world": "world.dae", "start.x": f"{-5 * s:g}", "start.y": "0", "start.theta": "0",
            "goal.x": f"{5 * s:g}", "goal.y": "0", "goal.theta": "1.57", "volume.min.x": f"{-10 * s:g}",
            "volume.min.y": f"{-10 * s:g}", "volume.max.x": f"{10 * s:g}", "volume.max.y": f"{10 * s:g}"}
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 2]))):
        k = draw(st.sampled_from(sorted(keys) + ["start.z", "volume.min.z", "control", "objective", "zz", "name"]))
        act = draw(st.sampled_from(["value", "value", "delete"]))
        if act == "delete":
            keys.pop(k, None)
        else:
            keys[k] = draw(st.sampled_from(["nan", "inf", "-inf", "1e308", "0", "-0", "abc", "", "1e400", "10", "-10",
                                            "100", "robot.dae", "world.dae", "missing.dae", os.path.join(os.pardir, "x.dae"), "/dev/zero",
                                            "p.cfg", "kinematic_car", "dynamic_car", "blimp", "3.14159", "1,2",
                                            "5 # comment", "x" * 300]))
    lines = ["[problem]", "name = fuzz"] + [f"{k} = {v}" for k, v in keys.items()]
    lines += draw(st.sampled_from([[], [], ["", "[benchmark]", "time_limit=10.0", "", "[planner]", "rrt=", "rrt="],
                                   ["robot = robot.dae"], ["no equals sign"], ["[problem"], ["[problem]"],
                                   ["[]", "a=b"], ["start.x = 1"]]))
    cfg = ("\n".join(lines) + "\n").encode()
    how = draw(st.sampled_from(["text"] * 20 + ["bytes", "bom", "latin1", "random", "nofirst"]))
    if how == "bytes":
        cfg = _mutate_bytes(cfg, draw)
    elif how == "bom":
        cfg = b"\xef\xbb\xbf" + cfg
    elif how == "latin1":
        cfg = cfg.replace(b"fuzz", b"f\xfczz")
    elif how == "random":
        cfg = draw(st.binary(max_size=200))
    elif how == "nofirst":
        cfg = cfg.replace(b"[problem]\n", b"", 1)
    return cfg, rb, wb


def _write_problem(d, case):
    cfg, rb, wb = case
    paths = []
    for name, data in (("p.cfg", cfg), ("robot.dae", rb), ("world.dae", wb)):
        p = os.path.join(d, name)
        with open(p, "wb") as fh:
            fh.write(data)
        paths.append(p)
    return paths[0], paths


MESH_FLAGS = st.sampled_from([[]] * 10 + [["--start", "-5,0,0"], ["--goal", "5,0"], ["--goal", "nan,0,0"],
                                          ["--radius", "0.3"], ["--start", "0,0,0"], ["--polygon", "0,0;1,0;0,1"],
                                          ["--tolerance", "0.1"], ["--unknown", "free"]])


def _has_collada():
    try:
        import collada  # noqa: F401
    except ImportError:
        return False
    return True


needs_collada = pytest.mark.skipif(not _has_collada(), reason="pycollada (the io extra) is not installed")


@needs_collada
@budget(30)
@given(case=mesh_problem(), flags=MESH_FLAGS)
def test_fuzz_mesh_import(case, flags):
    with workdir() as d:
        cfg, inputs = _write_problem(d, case)
        run(["import", cfg, "--out", os.path.join(d, "out.toml")] + flags, d, inputs, "mesh import", "mesh")


@needs_collada
@budget(10)
@given(case=mesh_problem(), flags=MESH_FLAGS, planner=st.sampled_from([None, None, "RRTConnect", "exact"]))
def test_fuzz_mesh_plan(case, flags, planner):
    with workdir() as d:
        cfg, inputs = _write_problem(d, case)
        js = os.path.join(d, "out.json")
        argv = ["plan", cfg, "--json", js, "--time", "0.2"] + flags
        if planner:
            argv += ["--planner", planner]
        run(argv, d, inputs, "mesh plan", "mesh", json_out=js)


def test_the_templates_are_valid(tmp_path):
    """The unmutated inputs import (exit 0): the fuzz starts from files that reach the geometry."""
    from PIL import Image  # noqa: F401

    pixels = [254] * 400
    pixels[210] = pixels[211] = 0
    for name, img in (("m.pgm", _pgm(20, 20, pixels)), ("m.pgm", _pgm(20, 20, pixels, binary=False)),
                      ("m.png", _png(20, 20, pixels))):
        d = tmp_path / name.replace(".", "") / str(len(img))
        d.mkdir(parents=True, exist_ok=True)
        yaml = (f"image: {name}\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
                "free_thresh: 0.196\n").encode()
        y, inputs = _write_map(str(d), yaml, (name, img))
        assert check_case(["import", y, "--out", str(d / "o.toml"), "--radius", "0.04", "--start", "0.15,0.15",
                           "--goal", "0.85,0.85"], str(d), inputs, "templates") == 0
    if _has_collada():
        d = tmp_path / "mesh"
        d.mkdir()
        for poly in (False, True):
            cfg = ("[problem]\nrobot = robot.dae\nworld = world.dae\nstart.x = -5\nstart.y = 0\nstart.theta = 0\n"
                   "goal.x = 5\ngoal.y = 0\ngoal.theta = 1.57\nvolume.min.x = -10\nvolume.min.y = -10\n"
                   "volume.max.x = 10\nvolume.max.y = 10\n").encode()
            c, inputs = _write_problem(str(d), (cfg, dae_text(ROBOT_BOXES, polylist=poly).encode(),
                                                dae_text(WORLD_BOXES, polylist=poly).encode()))
            assert check_case(["import", c, "--out", str(d / f"o{poly}.toml")], str(d), inputs, "templates") == 0
            assert check_case(["plan", c, "--json", str(d / "o.json"), "--time", "0.2"], str(d), inputs,
                              "templates", json_out=str(d / "o.json")) in (0, 1)  # 1: a busy machine


def test_found_a_map_beyond_the_doubles(tmp_path):
    """Found by the campaign: resolution 1e308 made the map's extent infinite, and the tracing's
    growth raised a GEOS error (exit 3); refused as the resolution, exit 2."""
    y, inputs = _write_map(str(tmp_path), b"image: m.pgm\nresolution: 1e308\norigin: [0.0, 0.0, 0.0]\n",
                           ("m.pgm", _pgm(20, 20, [254] * 400)))
    assert check_case(["import", y, "--out", str(tmp_path / "o.toml"), "--radius", "0.04", "--start", "0.15,0.15",
                       "--goal", "0.5,0.5"], str(tmp_path), inputs, "found") == 2


@needs_collada
def test_found_an_unknown_xml_encoding(tmp_path):
    """Found by the campaign: ``<?xml encoding="ut8"?>`` raised LookupError in expat (exit 3)."""
    cfg = ("[problem]\nrobot = robot.dae\nworld = world.dae\nstart.x = -5\nstart.y = 0\nstart.theta = 0\n"
           "goal.x = 5\ngoal.y = 0\ngoal.theta = 1.57\n").encode()
    robot = dae_text(ROBOT_BOXES).replace('encoding="utf-8"', 'encoding="ut8"').encode()
    c, inputs = _write_problem(str(tmp_path), (cfg, robot, dae_text(WORLD_BOXES).encode()))
    assert check_case(["import", c, "--out", str(tmp_path / "o.toml")], str(tmp_path), inputs, "found") == 2


def test_zz_imports_report():
    """The figures (scenario cases too when test_fuzz_cli ran in the same process) where
    CSPACE_FUZZ_REPORT says; fails if a kept case broke the contract."""
    path = os.environ.get("CSPACE_FUZZ_REPORT")
    if path:
        rep = {**STATS, "exit": dict(STATS["exit"]), "by_test": dict(STATS["by_test"]),
               "examples_per_test": EXAMPLES or "default", "files": dict(FILES),
               "contract_broken": len(FAILURES), "failures": FAILURES[:50],
               "exit_3": STATS["exit"].get("3", 0),
               "inputs_modified": sum("changed by" in why for _, why, _ in FAILURES)}
        with open(path, "w") as fh:
            json.dump(rep, fh, indent=1)
    assert not FAILURES, FAILURES[:5]
    assert STATS["exit"].get("3", 0) == 0
