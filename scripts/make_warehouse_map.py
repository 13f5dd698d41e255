"""A warehouse as mobile robots map it: a ROS map (PNG + YAML) and seeded start/goal pairs.

2000 x 2000 cells of 5 cm (100 m x 100 m): an outer wall, a row of offices along the north side
(walls 15 cm thick, 1 m doors), a loading area with docks along the south wall, and between them
blocks of shelf racks (1 m deep, 12-20 m long) in rows along x with aisles 2.4-3 m wide, cross
aisles 4 m wide between the blocks, and pillars (40 cm square) on a 10 m grid. Grey levels are
map_server's: 0 occupied, 254 free. Everything follows from the seed.

The queries file holds ``--pairs`` start/goal poses (x, y, theta) for a rectangular footprint
(default 0.62 x 0.9 m, the robot's length along x): each pose is checked free with a margin on
the grid (every cell the footprint, grown by two cells, covers is free), so it is free after the
import too (the import's obstacles grow by at most two fifths of a cell beyond the occupied
cells). The file is TOML ``[[queries]]`` with ``start = [x, y, theta]`` and ``goal = [...]``, as
``cspace plan MAP.yaml --queries FILE`` reads it.

Usage: python scripts/make_warehouse_map.py --out DIR [--seed N] [--pairs N] [--size CELLS]
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

OCC, FREE = 0, 254
RES = 0.05
FOOTPRINT = (0.9, 0.62)  # length along the robot's x, width


def warehouse(size: int = 2000, seed: int = 0) -> np.ndarray:
    """The map as a (size, size) uint8 image, row 0 at the top (north)."""
    rng = np.random.default_rng(seed)
    img = np.full((size, size), FREE, np.uint8)
    m = lambda metres: int(round(metres / RES * size / 2000))  # noqa: E731 (metres to cells, scaled maps)
    wall = max(m(0.3), 2)
    img[:wall], img[-wall:], img[:, :wall], img[:, -wall:] = OCC, OCC, OCC, OCC
    # offices along the north side: a corridor wall with doors, rooms divided by thin walls
    north = m(8.0)
    img[north:north + m(0.15) + 1, :] = OCC
    x = m(2.0)
    while x < size - m(6.0):
        width = m(rng.uniform(5.0, 9.0))
        img[:north, x:x + m(0.15) + 1] = OCC
        door = x + m(1.0) + int(rng.integers(0, max(width - m(2.5), 1)))
        img[north:north + m(0.15) + 1, door:door + m(1.0)] = FREE
        x += width
    # docks along the south wall: bays between short walls
    south = size - m(6.0)
    for x in range(m(4.0), size - m(4.0), m(5.0)):
        img[south:size, x:x + m(0.3)] = OCC
    # shelf blocks between the offices and the docks
    top, bottom = north + m(4.0), south - m(4.0)
    x0 = m(3.0)
    while x0 < size - m(15.0):
        length = m(rng.uniform(12.0, 20.0))
        x1 = min(x0 + length, size - m(3.0))
        y = top
        while y < bottom - m(1.0):
            img[y:y + m(1.0), x0:x1] = OCC  # a rack, 1 m deep
            y += m(1.0) + m(rng.uniform(2.4, 3.0))
        x0 = x1 + m(4.0)  # a cross aisle
    # pillars on a 10 m grid, where they do not close an aisle
    p = m(0.4)
    for r in range(top, bottom, m(10.0)):
        for c in range(m(5.0), size - m(5.0), m(10.0)):
            if (img[r - m(1.2):r + p + m(1.2), c - m(1.2):c + p + m(1.2)] == FREE).all():
                img[r:r + p, c:c + p] = OCC
    return img


def footprint_free(img: np.ndarray, x: float, y: float, theta: float, grow: int = 2) -> bool:
    """Whether every cell that the footprint at (x, y, theta), grown by ``grow`` cells, covers is free.
    The map's origin is its lower left corner at (0, 0)."""
    n = img.shape[0]
    L, W = FOOTPRINT
    half = 0.5 * math.hypot(L, W) + (grow + 1) * RES
    c0, c1 = int((x - half) / RES), int((x + half) / RES) + 1
    r0, r1 = int((y - half) / RES), int((y + half) / RES) + 1
    if c0 < 0 or r0 < 0 or c1 >= n or r1 >= n:
        return False
    cs, ss = math.cos(theta), math.sin(theta)
    xs = (np.arange(c0, c1 + 1) + 0.5) * RES - x
    ys = (np.arange(r0, r1 + 1) + 0.5) * RES - y
    X, Y = np.meshgrid(xs, ys)
    u, v = X * cs + Y * ss, -X * ss + Y * cs  # the cell centres in the robot's frame
    pad = (grow + 0.75) * RES  # a cell centre within half a diagonal of the footprint: the cell meets it
    inside = (np.abs(u) <= L / 2 + pad) & (np.abs(v) <= W / 2 + pad)
    rows = n - 1 - np.arange(r0, r1 + 1)  # image rows run from the top
    block = img[rows[:, None], np.arange(c0, c1 + 1)[None, :]]
    return bool((block[inside] == FREE).all())


def pairs(img: np.ndarray, count: int, seed: int = 0) -> list[tuple]:
    """``count`` (start, goal) poses, free with a margin, at least 20 m apart."""
    rng = np.random.default_rng(seed + 1)
    extent = img.shape[0] * RES
    out = []

    def pose():
        while True:
            p = (float(rng.uniform(1, extent - 1)), float(rng.uniform(1, extent - 1)), float(rng.uniform(-math.pi, math.pi)))
            if footprint_free(img, *p):
                return tuple(round(v, 4) for v in p)

    while len(out) < count:
        s, g = pose(), pose()
        if math.hypot(s[0] - g[0], s[1] - g[1]) >= 20.0:
            out.append((s, g))
    return out


def write(out: str, size: int, seed: int, count: int) -> tuple[str, str]:
    """Write warehouse.png, warehouse.yaml and warehouse_queries.toml into ``out``, each atomically."""
    from PIL import Image

    from planners.output import atomic_path, write_text

    os.makedirs(out, exist_ok=True)
    img = warehouse(size, seed)
    with atomic_path(os.path.join(out, "warehouse.png"), "--out") as tmp:
        Image.fromarray(img).save(tmp, format="PNG")
    yaml = os.path.join(out, "warehouse.yaml")
    write_text(yaml, "image: warehouse.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
                     "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n", "--out")
    queries = os.path.join(out, "warehouse_queries.toml")
    text = (f"# {count} start/goal pairs for a {FOOTPRINT[0]} x {FOOTPRINT[1]} m footprint "
            f"(scripts/make_warehouse_map.py, seed {seed})\n")
    for s, g in pairs(img, count, seed):
        text += f"\n[[queries]]\nstart = [{s[0]}, {s[1]}, {s[2]}]\ngoal = [{g[0]}, {g[1]}, {g[2]}]\n"
    write_text(queries, text, "--out")
    return yaml, queries


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder for warehouse.png, .yaml and _queries.toml")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--size", type=int, default=2000, help="cells per side (5 cm each)")
    args = ap.parse_args(argv)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_out

    check_out(args.out, (), "--out", folder=True)  # before any work: created if missing, and writable
    yaml, queries = write(args.out, args.size, args.seed, args.pairs)
    print(f"{yaml}: {args.size} x {args.size} cells of {RES} m; {queries}: {args.pairs} pairs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
