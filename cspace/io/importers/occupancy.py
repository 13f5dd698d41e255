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
2. The blocked cells' boundary is traced edge by edge (:mod:`cspace.io.importers.trace`, time linear
   in the map): the exact staircase union, integer vertices. A map of many vertices is
   cut into regions traced (and simplified) one at a time, so no step is quadratic.
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

from ..scenario.files import read_input, utf8_text
from ..scenario.messages import ScenarioError
from .trace import REGION_VERTICES, corner_points, flat_parts, regions, staircase_polygons

MODES = ("trinary", "scale", "raw")
# Limits (issue 36): a map's cells, checked on the image's header before its pixels are
# decoded, and its traced vertices (boundary corners), counted before any polygon is made.
# A map within both imports in time linear in its cells and vertices (about 2 s for a clean
# 4096 x 4096 map, 8 s for a 1024 x 1024 one of 50 % noise) and well under 1 GB.
MAX_PIXELS = 2**24  # 16 Mi cells (4096 x 4096)
MAX_VERTICES = 2**20  # traced vertices (1 Mi): a 1024 x 1024 map of 50 % noise has 0.56 Mi
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

    >>> f = os.path.join(os.path.dirname(__file__), "..", "..", "..", "scenarios", "maps", "office.yaml")
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
                raise ScenarioError(info.image, field_, f"{w} x {h} pixels: a map has 1 to {MAX_PIXELS} cells "
                                                        "(4096 x 4096); crop it or coarsen its resolution")
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
    # A block's pattern changes only when one of its cells is filled: after one pass over the
    # grid, only the (at most 4) blocks around each newly filled cell are looked at again, so a
    # chain of fills (each making the next touch) costs its length, not its length x the grid.
    h, w = blocked.shape
    if h < 2 or w < 2:
        return 0
    a, b_, c, d = blocked[:-1, :-1], blocked[:-1, 1:], blocked[1:, :-1], blocked[1:, 1:]
    main = a & d & ~b_ & ~c  # blocked on the main diagonal only: fill the upper right
    anti = b_ & c & ~a & ~d  # on the other diagonal only: fill the upper left
    (my, mx), (ay, ax) = np.nonzero(main), np.nonzero(anti)
    del a, b_, c, d, main, anti
    filled = 0
    while len(my) or len(ay):
        cells = np.unique(np.concatenate((my * w + mx + 1, ay * w + ax)))
        fy, fx = cells // w, cells % w
        filled += len(cells)
        blocked[fy, fx] = True
        ny = (fy[:, None] + np.array([-1, -1, 0, 0])).ravel()  # the 4 blocks holding each filled cell
        nx = (fx[:, None] + np.array([-1, 0, -1, 0])).ravel()
        ok = (ny >= 0) & (ny < h - 1) & (nx >= 0) & (nx < w - 1)
        blocks = np.unique(ny[ok] * (w - 1) + nx[ok])
        ys, xs = blocks // (w - 1), blocks % (w - 1)
        a, b_, c, d = blocked[ys, xs], blocked[ys, xs + 1], blocked[ys + 1, xs], blocked[ys + 1, xs + 1]
        main, anti = a & d & ~b_ & ~c, b_ & c & ~a & ~d
        my, mx, ay, ax = ys[main], xs[main], ys[anti], xs[anti]
    return filled


def check_vertices(blocked: np.ndarray, image: str) -> int:
    """The number of vertices tracing ``blocked`` gives (its boundary's corners), or a
    :class:`ScenarioError` naming ``image`` past :data:`MAX_VERTICES`.

    >>> check_vertices(np.ones((3, 3), dtype=bool), "m.pgm")
    4
    """
    n = int(corner_points(blocked).sum())
    if n > MAX_VERTICES:
        raise ScenarioError(image, "image", f"its obstacles trace to {n} vertices, over the limit of {MAX_VERTICES}: "
                                            "clean the map (remove speckle noise) or coarsen its resolution")
    return n


def staircase(blocked: np.ndarray, max_vertices: int = REGION_VERTICES):
    """The exact union of the blocked cells (rows bottom-up: ``blocked[Y, X]`` is the unit
    square [X, X+1] x [Y, Y+1]) as a shapely geometry with integer vertices: a
    (Multi)Polygon, or for a grid of over ``max_vertices`` vertices a GeometryCollection
    of one MultiPolygon per region (:func:`cspace.io.importers.trace.regions`), which abut.
    Traced in O(n log n) (:mod:`cspace.io.importers.trace`); no two blocked cells may touch at a
    corner only (:func:`fill_corner_touches`).

    >>> staircase(np.array([[1, 1], [0, 1]], dtype=bool)).area
    3.0
    """
    import shapely

    parts = []
    for y0, y1, x0, x1 in regions(blocked, max_vertices):
        polys = staircase_polygons(blocked[y0:y1, x0:x1], (x0, y0))
        if len(polys):
            parts.append(shapely.multipolygons(polys))
    if not parts:
        return shapely.Polygon()
    return parts[0] if len(parts) == 1 else shapely.GeometryCollection(parts)


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
    if geom.geom_type == "GeometryCollection":  # regions of a large map, one at a time (linear time)
        return shapely.GeometryCollection([simplify_conservative(g, tolerance, margin) for g in geom.geoms])
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
    import shapely

    if geom.is_empty:
        return []
    parts = [p for p in flat_parts(geom) if p.geom_type == "Polygon" and not p.is_empty]
    return sorted(parts, key=lambda p: -p.area)
