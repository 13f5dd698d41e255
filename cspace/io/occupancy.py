"""Occupancy-grid maps (ROS ``map_server`` format): thresholds, and obstacles traced to polygons.

A map is a YAML file (``image``, ``resolution``, ``origin``, ``occupied_thresh``,
``free_thresh``, ``negate``, optional ``mode``) next to an 8-bit image. This module
reads both, classifies every cell as ``map_server`` does, and traces the blocked
cells (occupied, and unknown unless told otherwise) to polygons that contain every
blocked cell's square: conservative, never a blocked cell left outside.

Geometry, in cell units (a cell is the unit square, x to the right, y up, row 0 of
the image at the top as ``map_server`` reads it):

1. Cells that touch only at a corner (a 2 x 2 checkerboard) would give a polygon
   whose boundary touches itself; one free cell of each such block is filled
   (conservative), until none is left.
2. Each row's runs of blocked cells, runs repeated in the next row merged into one
   rectangle, are united (GEOS): the exact staircase union, integer vertices.
3. With a tolerance t > 0 the union is simplified (Douglas-Peucker, topology kept)
   within a = t / 2.5, then grown by a with mitred corners (limit 1.5 a: right angles
   stay sharp, sharper corners are bevelled 1.5 a out, so the growth contains the
   disk of radius a): every blocked cell stays inside (a cell left outside by the
   simplification is within a of it), and every point of the result is within
   a + 1.5 a = t of a blocked cell. A free pocket narrower than about
   2a closes; the report counts what changed.
4. World coordinates: x = origin_x + X * resolution, y = origin_y + Y * resolution,
   the same expression for a cell's corners, so the staircase (t = 0) contains the
   cells exactly; with t > 0 the growth carries a margin far above rounding.

The YAML reader is a small strict one for the flat ``key: value`` lines of these
files (scalars, quoted strings, ``[a, b, c]`` lists, ``#`` comments): PyYAML is not a
dependency, and a map's YAML is never more than that.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from .files import read_input, utf8_text
from .messages import ScenarioError

MODES = ("trinary", "scale", "raw")
MAX_PIXELS = 2**26  # 64 Mi cells (8192 x 8192): a bigger map is refused, not read
MITRE = 1.5  # mitre limit of the growth: right angles stay sharp, sharper corners are bevelled
KEYS = {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode"}


@dataclass
class MapInfo:
    """A map's YAML: the image path (resolved against the YAML's folder) and the thresholds."""

    image: str
    resolution: float
    origin: tuple[float, float, float]
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    negate: bool = False
    mode: str = "trinary"
    warnings: list[str] = field(default_factory=list)


def parse_flat_yaml(text: str, path: str) -> dict:
    """The ``key: value`` lines of a map YAML as a dict of strings, numbers and lists.

    >>> parse_flat_yaml("image: m.pgm  # the picture\\norigin: [-1, 2.5, 0]\\nnegate: 0\\n", "m.yaml")
    {'image': 'm.pgm', 'origin': [-1, 2.5, 0], 'negate': 0}
    """
    out: dict = {}
    for n, line in enumerate(text.splitlines(), 1):
        body = _strip_comment(line).rstrip()
        if not body.strip() or body.strip() in ("---", "..."):
            continue
        if body[0].isspace() or ":" not in body:
            raise ScenarioError(path, f"line {n}", f"expected a flat `key: value` line, got {body.strip()[:60]!r}")
        key, _, value = body.partition(":")
        key = key.strip().strip("'\"")
        if key in out:
            raise ScenarioError(path, key, f"given twice (line {n})")
        out[key] = _scalar_or_list(value.strip(), path, key)
    return out


def _strip_comment(line: str) -> str:
    quote = None
    for i, ch in enumerate(line):
        if ch in "'\"" and quote in (None, ch):
            quote = None if quote else ch
        elif ch == "#" and quote is None and (i == 0 or line[i - 1].isspace()):
            return line[:i]
    return line


def _scalar_or_list(v: str, path: str, key: str):
    if v.startswith("["):
        if not v.endswith("]"):
            raise ScenarioError(path, key, f"unterminated list {v[:60]!r}")
        inner = v[1:-1].strip()
        return [_scalar(x.strip(), path, key) for x in inner.split(",")] if inner else []
    return _scalar(v, path, key)


def _scalar(v: str, path: str, key: str):
    if len(v) >= 2 and v[0] == v[-1] and v[0] in "'\"":
        return v[1:-1]
    low = v.lower()
    if low in ("true", "yes", "on"):
        return True
    if low in ("false", "no", "off"):
        return False
    try:
        return int(v)
    except ValueError:
        pass
    try:
        return float(v)
    except ValueError:
        return v


def read_map_yaml(path) -> MapInfo:
    """Read and check a map YAML; faults are one-line :class:`ScenarioError` s naming the key.

    >>> import tempfile
    >>> d = tempfile.mkdtemp(); f = os.path.join(d, "m.yaml")
    >>> _ = open(f, "w").write("image: m.pgm\\nresolution: 0.05\\norigin: [-1.0, 0, 0]\\n")
    >>> info = read_map_yaml(f); info.resolution, info.origin, info.mode, os.path.basename(info.image)
    (0.05, (-1.0, 0.0, 0.0), 'trinary', 'm.pgm')
    """
    path = os.fspath(path)
    text = utf8_text(read_input(path), path)
    data = parse_flat_yaml(text, path)
    warnings = [f"{path}: {k}: unknown key, ignored" for k in data if k not in KEYS]
    for key in ("image", "resolution", "origin"):
        if key not in data:
            raise ScenarioError(path, key, "missing (a map YAML needs image, resolution and origin)")
    image = data["image"]
    if not isinstance(image, str) or not image:
        raise ScenarioError(path, "image", f"must be a file name, got {image!r}")
    res = _number(data["resolution"], path, "resolution", positive=True)
    origin = data["origin"]
    if not isinstance(origin, list) or len(origin) not in (2, 3):
        raise ScenarioError(path, "origin", f"must be [x, y, yaw], got {origin!r}")
    ox, oy = (_number(v, path, f"origin[{i}]") for i, v in enumerate(origin[:2]))
    yaw = _number(origin[2], path, "origin[2]") if len(origin) == 3 else 0.0
    if yaw != 0.0:
        warnings.append(f"{path}: origin: yaw {yaw} ignored, as map_server's users (costmaps) do")
    occ = _number(data.get("occupied_thresh", 0.65), path, "occupied_thresh")
    free = _number(data.get("free_thresh", 0.196), path, "free_thresh")
    if not 0.0 <= free <= occ <= 1.0:
        raise ScenarioError(path, "free_thresh", f"need 0 <= free_thresh ({free}) <= occupied_thresh ({occ}) <= 1")
    negate = data.get("negate", 0)
    if negate not in (0, 1, True, False):
        raise ScenarioError(path, "negate", f"must be 0 or 1, got {negate!r}")
    mode = data.get("mode", "trinary")
    if mode not in MODES:
        raise ScenarioError(path, "mode", f"must be one of {', '.join(MODES)}, got {mode!r}")
    img = image if os.path.isabs(image) else os.path.join(os.path.dirname(os.path.abspath(path)), image)
    return MapInfo(img, res, (ox, oy, yaw), occ, free, bool(negate), mode, warnings)


def _number(x, path: str, key: str, positive: bool = False) -> float:
    try:
        finite = not isinstance(x, bool) and isinstance(x, (int, float)) and math.isfinite(float(x))
    except OverflowError:  # an integer beyond the doubles
        finite = False
    if not finite:
        raise ScenarioError(path, key, f"must be a finite number, got {str(x)[:60]}")
    if positive and not x > 0:
        raise ScenarioError(path, key, f"must be positive, got {x!r}")
    return float(x)


def read_image(info: MapInfo, yaml_path: str) -> tuple[np.ndarray, np.ndarray | None]:
    """The image as (H, W) uint8 channel averages (``map_server``'s value) and its alpha
    channel or None; 8-bit grey, grey+alpha, RGB, RGBA, palette and 1-bit images.

    >>> f = os.path.join(os.path.dirname(__file__), "..", "..", "scenarios", "maps", "office.yaml")
    >>> values, alpha = read_image(read_map_yaml(f), f); values.shape, values.dtype.name, alpha
    ((180, 240), 'uint8', None)
    """
    field_ = "image"
    try:
        from PIL import Image
    except ImportError:  # pragma: no cover - Pillow comes with matplotlib
        raise ScenarioError(yaml_path, field_, "reading a map image needs Pillow (pip install pillow)") from None
    if os.path.exists(info.image):
        read_input(info.image)  # a regular file within the size limit, not a FIFO or device
    try:
        with Image.open(info.image) as im:
            w, h = im.size
            if w < 1 or h < 1 or w * h > MAX_PIXELS:
                raise ScenarioError(info.image, field_, f"{w} x {h} pixels: a map needs 1 to {MAX_PIXELS} cells")
            if im.mode in ("I", "I;16", "I;16B", "I;16L", "F"):
                raise ScenarioError(info.image, field_, f"mode {im.mode} (16-bit or float): map_server reads "
                                                        "8-bit images (grey, RGB, with or without alpha)")
            if im.mode == "P":
                im = im.convert("RGBA" if "transparency" in im.info else "RGB")
            elif im.mode == "1":
                im = im.convert("L")
            elif im.mode not in ("L", "LA", "RGB", "RGBA"):
                raise ScenarioError(info.image, field_, f"unsupported image mode {im.mode}")
            arr = np.asarray(im)
    except FileNotFoundError:
        raise ScenarioError(yaml_path, field_, f"{info.image}: no such file") from None
    except ScenarioError:
        raise
    except Image.DecompressionBombError:
        raise ScenarioError(info.image, field_, f"over {MAX_PIXELS} pixels: a map needs 1 to {MAX_PIXELS} "
                                                "cells") from None
    except (OSError, ValueError, SyntaxError) as exc:  # Pillow: unreadable, truncated, not an image
        raise ScenarioError(info.image, field_, f"cannot read the image ({str(exc)[:120]})") from None
    if arr.ndim == 2:
        return arr.astype(np.uint8), None
    alpha = arr[..., -1] if arr.shape[2] in (2, 4) else None
    colour = arr[..., :-1] if alpha is not None else arr
    # map_server's value: the average of the colour channels (integer division, as it does).
    avg = (colour.astype(np.uint16).sum(axis=2) // colour.shape[2]).astype(np.uint8)
    return avg, alpha


def classify(values: np.ndarray, alpha: np.ndarray | None, info: MapInfo) -> np.ndarray:
    """Cells as ``map_server`` classifies them: 1 occupied, 0 free, -1 unknown (int8, image rows).

    trinary and scale: p = (255 - v) / 255 (v negated first with ``negate``); p >
    occupied_thresh is occupied, p < free_thresh free, else unknown (scale's
    in-between costs are counted unknown here; a transparent pixel is unknown in
    scale). raw: the value itself is the cell, 0..100 compared as p = v / 100, 255
    unknown.

    >>> info = MapInfo("m.pgm", 1.0, (0.0, 0.0, 0.0))
    >>> classify(np.array([[0, 254, 205]], dtype=np.uint8), None, info).tolist()
    [[1, 0, -1]]
    """
    # One class per grey level (a 256-entry table), then one lookup per cell.
    v = np.arange(256, dtype=np.float64)
    if info.negate:
        v = 255.0 - v
    p = v / 100.0 if info.mode == "raw" else (255.0 - v) / 255.0
    table = np.where(p > info.occupied_thresh, 1, np.where(p < info.free_thresh, 0, -1)).astype(np.int8)
    if info.mode == "raw":
        table[v > 100] = -1  # 255 is unknown; 101..254 are no occupancy value: unknown too
    out = table[values]
    if info.mode == "scale" and alpha is not None:
        out[alpha == 0] = -1
    return out


def fill_corner_touches(blocked: np.ndarray) -> int:
    """Fill free cells (in place) until no two blocked cells touch at a corner only;
    returns how many were filled.

    >>> b = np.array([[1, 0], [0, 1]], dtype=bool); fill_corner_touches(b), b.astype(int).tolist()
    (1, [[1, 1], [0, 1]])
    """
    filled = 0
    while True:
        a, b_, c, d = blocked[:-1, :-1], blocked[:-1, 1:], blocked[1:, :-1], blocked[1:, 1:]
        main = a & d & ~b_ & ~c  # blocked on the main diagonal only: fill the upper right
        anti = b_ & c & ~a & ~d  # on the other diagonal only: fill the upper left
        n = int(main.sum() + anti.sum())
        if n == 0:
            return filled
        before = int(blocked.sum())
        blocked[:-1, 1:] |= main
        blocked[:-1, :-1] |= anti
        filled += int(blocked.sum()) - before


def staircase(blocked: np.ndarray):
    """The exact union of the blocked cells (rows bottom-up: ``blocked[Y, X]`` is the unit
    square [X, X+1] x [Y, Y+1]) as a shapely geometry with integer vertices.

    >>> staircase(np.array([[1, 1], [0, 1]], dtype=bool)).area
    3.0
    """
    import shapely

    h, w = blocked.shape
    z = np.zeros((h, w + 2), dtype=np.int8)
    z[:, 1:-1] = blocked
    d = np.diff(z, axis=1)
    ys, x0 = np.nonzero(d == 1)
    _, x1 = np.nonzero(d == -1)  # row-major order pairs each run's start with its end
    if len(ys) == 0:
        return shapely.Polygon()
    # Runs repeated in consecutive rows become one rectangle.
    order = np.lexsort((ys, x1, x0))
    ys, x0, x1 = ys[order], x0[order], x1[order]
    new = np.ones(len(ys), dtype=bool)
    new[1:] = (x0[1:] != x0[:-1]) | (x1[1:] != x1[:-1]) | (ys[1:] != ys[:-1] + 1)
    first = np.flatnonzero(new)
    last = np.append(first[1:], len(ys)) - 1
    boxes = shapely.box(x0[first], ys[first], x1[first], ys[last] + 1)
    return shapely.simplify(shapely.union_all(boxes), 0.0)  # collinear vertices out (exact on integers)


def simplify_conservative(geom, tolerance: float, margin: float = 0.0):
    """``geom`` simplified within ``tolerance`` and grown so it still contains ``geom``.

    Douglas-Peucker within a = tolerance / 2.5, then a mitred growth by a (limit 1.5 a)
    plus 1e-6 a plus ``margin`` (the rounding of the caller's change of frame): contains
    ``geom``, within ``tolerance`` (+ 2.5 ``margin``) of it.

    >>> import shapely
    >>> g = shapely.Polygon([(0, 0), (10, 0), (10, 1), (9, 1), (9, 1.2), (0, 1.2)])
    >>> s = simplify_conservative(g, 1.0); bool(s.covers(g)), len(s.exterior.coords) < 7
    (True, True)
    """
    import shapely

    if tolerance <= 0 or geom.is_empty:
        return geom
    a = tolerance / (1.0 + MITRE)
    simple = shapely.simplify(geom, a, preserve_topology=True)
    grown = shapely.buffer(simple, a * (1.0 + 1e-6) + margin, join_style="mitre", mitre_limit=MITRE)
    return shapely.simplify(shapely.union(grown, geom), 0.0)  # the union is a no-op but for rounding


def polygons_of(geom) -> list:
    """The polygons of a shapely (Multi)Polygon or collection, largest first.

    >>> import shapely
    >>> len(polygons_of(shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(2, 0, 4, 1)])))
    2
    """
    if geom.is_empty:
        return []
    parts = list(geom.geoms) if hasattr(geom, "geoms") else [geom]
    parts = [p for p in parts if p.geom_type == "Polygon" and not p.is_empty]
    return sorted(parts, key=lambda p: -p.area)
