"""Valid inputs of the importers, written from scratch: ROS map images (PGM, PNG) with their
YAML, and OMPL.app problems (a .cfg and COLLADA meshes of boxes). The import fuzz tests
(tests/io/test_fuzz_maps.py, tests/io/test_fuzz_meshes.py) start from these and break them."""
from __future__ import annotations

import os
import struct
import zlib

# ------------------------------------------------------------------ map images and YAML

def pgm_bytes(w, h, pixels, binary=True, maxval=255, magic=None, extra=b"", cut=None):
    magic = magic or (b"P5" if binary else b"P2")
    head = magic + b"\n" + f"{w} {h}\n{maxval}\n".encode()
    if binary:
        body = bytes(p % 256 for p in pixels)
    else:
        body = "\n".join(" ".join(str(p) for p in pixels[i:i + 16]) for i in range(0, len(pixels), 16)).encode() + b"\n"
    data = head + body + extra
    return data[:cut] if cut is not None else data


def png_chunk(kind: bytes, data: bytes, crc=None) -> bytes:
    c = zlib.crc32(kind + data) if crc is None else crc
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", c & 0xFFFFFFFF)


def png_bytes(w, h, pixels, colour=0, depth=8, hw=None, bad_crc=False, cut=None, extra=b"", palette=None,
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
    out = b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", ihdr, crc=0 if bad_crc else None)
    if palette is not None:
        out += png_chunk(b"PLTE", palette)
    if trns is not None:
        out += png_chunk(b"tRNS", trns)
    out += png_chunk(b"IDAT", raw) + extra
    if not no_iend:
        out += png_chunk(b"IEND", b"")
    return out[:cut] if cut is not None else out


def write_map(d, data_yaml, image):
    name, img = image
    y = os.path.join(d, "m.yaml")
    with open(y, "wb") as fh:
        fh.write(data_yaml)
    i = os.path.join(d, name)
    with open(i, "wb") as fh:
        fh.write(img)
    return y, [y, i]


# ------------------------------------------------------------------ OMPL.app problems: COLLADA meshes

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


def write_problem(d, case):
    cfg, rb, wb = case
    paths = []
    for name, data in (("p.cfg", cfg), ("robot.dae", rb), ("world.dae", wb)):
        p = os.path.join(d, name)
        with open(p, "wb") as fh:
            fh.write(data)
        paths.append(p)
    return paths[0], paths


def has_collada():
    try:
        import collada  # noqa: F401
    except ImportError:
        return False
    return True
