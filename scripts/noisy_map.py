"""Write a noisy ROS occupancy map (issue 36's hostile input): every cell occupied with
probability ``--noise`` (seeded), the rest free, as ``NAME.pgm`` (or ``.png``) + ``NAME.yaml``.

Usage: python scripts/noisy_map.py OUT_DIR [--size N] [--noise P] [--seed S] [--png] [--res R]
"""
from __future__ import annotations

import argparse
import os

import numpy as np

OCC, FREE = 0, 254


CLEAR = 16  # cells: a free square in the bottom-left and top-right corners, for a start and a goal


def noisy_image(size: int, noise: float = 0.5, seed: int = 0) -> np.ndarray:
    """An (size, size) uint8 map_server image: occupied (0) with probability ``noise``, else free
    (254), but for two free CLEAR x CLEAR squares (bottom-left, top-right) if the map is 4 CLEAR wide."""
    rng = np.random.default_rng(seed)
    img = np.where(rng.random((size, size)) < noise, OCC, FREE).astype(np.uint8)
    if size >= 4 * CLEAR:
        img[-CLEAR:, :CLEAR] = FREE
        img[:CLEAR, -CLEAR:] = FREE
    return img


def start_goal(size: int, res: float = 0.05) -> tuple[tuple[float, float], tuple[float, float]]:
    """A start and a goal in the two free squares (the map's origin at 0, 0)."""
    c = CLEAR / 2 * res
    return (c, c), (size * res - c, size * res - c)


def write_map(folder: str, img: np.ndarray, name: str = "noisy", png: bool = False, res: float = 0.05) -> str:
    """Write ``img`` and its YAML into ``folder``, each atomically; returns the YAML's path."""
    from PIL import Image

    from planners.output import atomic_path, write_text

    image = f"{name}.{'png' if png else 'pgm'}"
    with atomic_path(os.path.join(folder, image), "OUT_DIR") as tmp:
        Image.fromarray(img).save(tmp, format="PNG" if png else "PPM")  # (Pillow's PPM writes a PGM)
    path = os.path.join(folder, f"{name}.yaml")
    write_text(path, f"image: {image}\nresolution: {res}\norigin: [0.0, 0.0, 0.0]\n"
                     "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n", "OUT_DIR")
    return path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--noise", type=float, default=0.5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--res", type=float, default=0.05)
    ap.add_argument("--png", action="store_true")
    args = ap.parse_args(argv)
    import sys

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_out

    check_out(args.out_dir, (), "OUT_DIR", folder=True)  # before any work: created if missing, and writable
    path = write_map(args.out_dir, noisy_image(args.size, args.noise, args.seed),
                     f"noisy{args.size}", args.png, args.res)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
