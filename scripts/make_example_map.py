"""Draw scenarios/maps/office.pgm, the guide's ROS-style occupancy map (deterministic).

An office floor as a SLAM run leaves it: 240 x 180 cells of 5 cm (12 m x 9 m), walls
three cells thick with doors, furniture (desks, round pillars, a shelf at an angle),
speckles of sensor noise, and unknown (grey 205) outside the building. Grey levels are
map_server's: 0 occupied, 254 free, 205 unknown. Run from the repository root:

    python scripts/make_example_map.py [--out scenarios/maps/office.pgm]

``--out`` (.pgm or .png) is checked before any work and written atomically.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OCC, FREE, UNK = 0, 254, 205


def office(h: int = 180, w: int = 240, seed: int = 7) -> np.ndarray:
    """The map as an (h, w) uint8 image, row 0 at the top."""
    rng = np.random.default_rng(seed)
    img = np.full((h, w), UNK, np.uint8)
    img[12:h - 12, 12:w - 12] = OCC            # the building's outer wall ...
    img[15:h - 15, 15:w - 15] = FREE           # ... three cells thick
    img[15:h - 15, 118:121] = OCC              # a wall across, two doors in it
    img[40:58, 118:121] = FREE
    img[125:143, 118:121] = FREE
    img[88:91, 15:118] = OCC                   # a wall along the left half, one door
    img[88:91, 70:90] = FREE
    for r, c, hh, ww in ((30, 30, 14, 30), (120, 40, 12, 34), (30, 150, 40, 12), (130, 170, 14, 40)):
        img[r:r + hh, c:c + ww] = OCC          # desks
    yy, xx = np.mgrid[:h, :w]
    for r, c, rad in ((60, 80, 6), (100, 180, 7), (150, 95, 5)):
        img[(yy - r) ** 2 + (xx - c) ** 2 <= rad * rad] = OCC  # pillars
    t = np.linspace(0.0, 1.0, 400)             # a shelf at 30 degrees: a staircase edge
    for o in range(4):
        rows = (75 - 30 * t + o * 0.87).astype(int)
        cols = (150 + 52 * t + o * 0.5).astype(int)
        img[rows, cols] = OCC
    inside = img[15:h - 15, 15:w - 15]
    noise = rng.random(inside.shape)
    inside[(noise < 0.0015) & (inside == FREE)] = OCC  # sensor speckles
    inside[(noise > 0.999) & (inside == FREE)] = UNK   # and cells never seen
    return img


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "scenarios", "maps", "office.pgm"))
    args = ap.parse_args(argv)
    from PIL import Image

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_out
    from planners.output import atomic_path

    fmt = check_out(args.out, (), "--out", {".pgm": "PPM", ".png": "PNG"})  # (Pillow's PPM writes a PGM)
    img = office()
    with atomic_path(args.out, "--out") as tmp:
        Image.fromarray(img).save(tmp, format=fmt)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
