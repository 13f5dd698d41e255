"""MovingAI grid maps (``.map``) as scenarios, and their scenario files (``.scen``) as queries.

A ``.map`` file (Sturtevant's benchmark format, the city maps Bench-MR plans in) is::

    type octile
    height H
    width W
    map
    H rows of W letters

Passable terrain is ``.`` ``G`` (ground) and ``S`` (swamp); blocked is ``@`` ``O`` (out of
bounds), ``T`` (trees) and ``W`` (water, passable only from water). Each blocked cell is a
closed unit square, and the squares are merged into polygons by the occupancy-grid
machinery of the ROS maps (:mod:`cspace.io.importers.occupancy`: cells touching only at a
corner get one free neighbour filled, reported; the exact staircase traced, holes kept; no
simplification unless ``tolerance`` is given).

Two readings of the grid (``ImportOptions.grid_reading``):

- ``"movingai"`` (the default): as MovingAI draws a map, row 0 at the top: cell (x, y) of a
  ``.scen`` row (column x, row y) is the square [x, x+1] x [H-1-y, H-y] in the plane (y up),
  and a query's point is its centre (x + 1/2, H - y - 1/2). Bounds [0, W] x [0, H].
- ``"bench-mr"``: as Bench-MR's ``GridMaze::createFromMovingAiScenario`` reads it (its code
  says "the map is transposed!"): row y becomes the plane's y upwards (the map mirrored top to
  bottom), a cell is the unit square centred on (x, y) (Bench-MR rounds coordinates to cells)
  and a query's point is (x, y) itself; only ``.`` is passable. Bounds: the cells' union
  [-1/2, W-1/2] x [-1/2, H-1/2] (Bench-MR's state space is [0, W] x [0, H], its last
  half-cells read as the edge cells).

``border`` blocks the grid's outermost cells, as Bench-MR's ``fillBorder`` (its
``create_border``, on by default, off in its published MovingAI runs).

Bounded work: the header's size is checked (at most :data:`MAX_CELLS`) before any row is
read, and every fault is one :class:`ScenarioError` line naming the file and the field.
"""
from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass

import numpy as np

from ..scenario.files import read_input
from ..scenario.messages import ScenarioError
from .import_record import Imported, ImportOptions, robot_and_queries
from .occupancy import MAX_PIXELS

MAX_CELLS = MAX_PIXELS  # 4096 x 4096, as a ROS map
PASSABLE = b".GS"
BLOCKED = b"@OTW"
READINGS = ("movingai", "bench-mr")
_INT = re.compile(r"[0-9]{1,9}")


def read_map(path: str) -> tuple[np.ndarray, str, np.ndarray]:
    """The blocked cells of a ``.map`` file, ``[row, column]`` as in the file (row 0 first),
    its ``type`` and its letters (bytes). The header's size is checked before the rows are read.

    >>> import tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "m.map")
    >>> _ = open(f, "w").write("type octile\\nheight 2\\nwidth 3\\nmap\\n.@.\\nT..\\n")
    >>> read_map(f)[0].astype(int).tolist()
    [[0, 1, 0], [1, 0, 0]]
    """
    raw = read_input(path)
    head, rows = _header(raw, path)
    kind, h, w = head
    if len(rows) < h:
        raise ScenarioError(path, "map", f"{len(rows)} rows of cells, the header says height {h}")
    if any(r.strip() for r in rows[h:]):
        raise ScenarioError(path, "map", f"more rows than the header's height {h}")
    bad = [i for i, r in enumerate(rows[:h]) if len(r) != w]
    if bad:
        raise ScenarioError(path, f"row {bad[0]}", f"{len(rows[bad[0]])} cells, the header says width {w}")
    grid = np.frombuffer(b"".join(rows[:h]), dtype=np.uint8).reshape(h, w)
    known = np.isin(grid, np.frombuffer(PASSABLE + BLOCKED, dtype=np.uint8))
    if not known.all():
        r, c = (int(v[0]) for v in np.nonzero(~known))
        raise ScenarioError(path, f"row {r}, column {c}", f"terrain {chr(grid[r, c])!r} is none of MovingAI's "
                                                          "(passable . G S, blocked @ O T W)")
    return np.isin(grid, np.frombuffer(BLOCKED, dtype=np.uint8)), kind, grid


def _header(raw: bytes, path: str):
    """(type, height, width) and the rows' lines (bytes, line ends removed)."""
    lines = raw.split(b"\n", 4)
    if len(lines) < 4:
        raise ScenarioError(path, "header", "expected the lines type, height, width and map")
    words = [ln.strip().split() for ln in lines[:4]]
    fields = {}
    for want, ws in zip(("type", "height", "width", "map"), words):
        text = b" ".join(ws).decode("ascii", "replace")[:40]
        if not ws or ws[0].decode("ascii", "replace").lower() != want or len(ws) != (1 if want == "map" else 2):
            raise ScenarioError(path, want, f"expected '{want}{'' if want == 'map' else ' VALUE'}', got {text!r}")
        if want in ("height", "width"):
            v = ws[1].decode("ascii", "replace")
            if not _INT.fullmatch(v) or int(v) == 0:
                raise ScenarioError(path, want, f"must be a positive integer, got {v[:20]!r}")
            fields[want] = int(v)
        elif want == "type":
            fields[want] = ws[1].decode("ascii", "replace")
    h, w = fields["height"], fields["width"]
    if h * w > MAX_CELLS:
        raise ScenarioError(path, "height", f"{w} x {h} = {w * h} cells, over the limit of {MAX_CELLS} "
                                            "(4096 x 4096); nothing was read past the header")
    body = lines[4] if len(lines) > 4 else b""
    rows = [r[:-1] if r.endswith(b"\r") else r for r in body.split(b"\n")]
    return (fields["type"], h, w), rows


def grid_frame(blocked_rows: np.ndarray, reading: str) -> tuple[np.ndarray, float]:
    """The blocked grid bottom-up (``[Y, X]`` is the square [X, X+1] x [Y, Y+1] before the
    shift) and the shift of both axes: the map as the reading places it.

    >>> g, s = grid_frame(np.array([[1, 0], [0, 0]], bool), "movingai"); g.astype(int).tolist(), s
    ([[0, 0], [1, 0]], 0.0)
    >>> g, s = grid_frame(np.array([[1, 0], [0, 0]], bool), "bench-mr"); g.astype(int).tolist(), s
    ([[1, 0], [0, 0]], -0.5)
    """
    if reading == "bench-mr":
        return blocked_rows.copy(), -0.5
    return blocked_rows[::-1].copy(), 0.0


def scen_point(x: int, y: int, height: int, reading: str) -> tuple[float, float]:
    """A ``.scen`` cell (column x, row y) as a point of the plane, in the reading's frame.

    >>> scen_point(3, 0, 10, "movingai"), scen_point(3, 0, 10, "bench-mr")
    ((3.5, 9.5), (3.0, 0.0))
    """
    if reading == "bench-mr":
        return float(x), float(y)
    return x + 0.5, height - y - 0.5


def import_movingai(path: str, options: ImportOptions) -> Imported:
    """A MovingAI ``.map`` as a scenario dict (the start and goal from the options).

    >>> import tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "m.map")
    >>> _ = open(f, "w").write("type octile\\nheight 3\\nwidth 4\\nmap\\n....\\n.@@.\\n....\\n")
    >>> imp = import_movingai(f, ImportOptions(start=(0.5, 0.5), goal=(3.5, 2.5)))
    >>> imp.data["obstacles"], imp.data["bounds"]["ymax"]
    ([{'polygon': [[1.0, 1.0], [3.0, 1.0], [3.0, 2.0], [1.0, 2.0]]}], 3.0)
    """
    import shapely

    from .occupancy import check_vertices, fill_corner_touches, polygons_of, simplify_conservative, staircase

    t0 = time.perf_counter()
    reading = options.grid_reading or "movingai"
    if reading not in READINGS:
        raise ScenarioError("--grid-reading", "grid_reading", f"must be movingai or bench-mr, got {reading!r}")
    blocked_rows, kind, letters = read_map(path)
    if reading == "bench-mr":  # Bench-MR: only '.' is passable
        blocked_rows = letters != ord(".")
    h, w = blocked_rows.shape
    if options.border:
        blocked_rows[[0, -1], :] = True
        blocked_rows[:, [0, -1]] = True
    grid, shift = grid_frame(blocked_rows, reading)
    padded = np.pad(grid, 1, constant_values=False)
    filled = fill_corner_touches(padded)
    check_vertices(padded, path)
    exact = staircase(padded)
    exact = shapely.transform(exact, lambda c: c - 1.0 + shift)  # exact: integers and halves
    tol = options.tolerance or 0.0
    result = simplify_conservative(exact, tol) if tol > 0 else exact
    polys = polygons_of(result) if not result.is_empty else []
    obstacles = []
    for p in polys:
        ob = {"polygon": [[float(x), float(y)] for x, y in np.asarray(p.exterior.coords)[:-1]]}
        if p.interiors:
            ob["holes"] = [[[float(x), float(y)] for x, y in np.asarray(r.coords)[:-1]] for r in p.interiors]
        obstacles.append(ob)
    lo, hi = (shift, shift + w), (shift, shift + h)
    bounds = {"xmin": lo[0], "xmax": lo[1], "ymin": hi[0], "ymax": hi[1]}
    data = {"name": os.path.splitext(os.path.basename(path))[0], "bounds": bounds, "obstacles": obstacles}
    imp = Imported(data, inputs=[path])
    robot_and_queries(imp, options, path)
    n_blocked = int(blocked_rows.sum())
    imp.report += [
        f"read {path}: MovingAI map (type {kind}) {w} x {h} cells, {n_blocked} blocked "
        f"({'every letter but .' if reading == 'bench-mr' else '@ O T W'}){', border blocked' if options.border else ''}",
        "frame: " + ("Bench-MR's (row y upwards, cells centred on integer points)" if reading == "bench-mr" else
                     "MovingAI's drawing (row 0 at the top; cell (x, y) is [x, x+1] x [H-1-y, H-y])") +
        f", bounds x [{bounds['xmin']:g}, {bounds['xmax']:g}], y [{bounds['ymin']:g}, {bounds['ymax']:g}]",
        f"obstacles: {len(obstacles)} polygons, the blocked cells' exact union"
        + (f" simplified within {tol:g} (grown to contain every cell)" if tol > 0 else " (closed unit squares)"),
        f"time: {time.perf_counter() - t0:.2f} s",
    ]
    if filled:
        imp.warnings.append(f"{path}: {filled} free cells counted blocked where blocked cells touched only at a "
                            "corner")
    imp.comments += [f"imported from {os.path.basename(path)} (MovingAI map, {w} x {h} cells, {reading} reading)"]
    return imp


@dataclass
class ScenRow:
    """One row of a ``.scen`` file: its index in the file, bucket, map name, the map's size it
    was made for, start and goal cells (column, row) and the octile optimum (in cells)."""

    index: int
    bucket: int
    map: str
    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimum: float


def row_slice(spec: str, n: int, path: str = "--scen-rows") -> range:
    """Python-style row selection: ``A:B``, ``-10:`` (the last ten), ``:5`` or one index ``I``.

    >>> list(row_slice("-3:", 10)), list(row_slice("2:4", 10)), list(row_slice("-1", 10))
    ([7, 8, 9], [2, 3], [9])
    """
    text = spec.strip()
    try:
        if ":" in text:
            a, _, b = text.partition(":")
            return range(n)[slice(int(a) if a.strip() else None, int(b) if b.strip() else None)]
        i = int(text)
    except ValueError:
        raise ScenarioError(path, "--scen-rows", f"expected A:B, A:, :B or I (Python's slices), got {spec[:40]!r}"
                            ) from None
    if not -n <= i < n:
        raise ScenarioError(path, "--scen-rows", f"row {i} of {n} rows")
    return range(n)[i:i + 1] if i >= 0 else range(n)[i:][:1]


def read_scen(path: str, rows: str | None = None) -> list[ScenRow]:
    """The rows of a MovingAI ``.scen`` file (``version`` line, then bucket, map, width,
    height, start x, start y, goal x, goal y, optimal length per line), those ``rows`` select.

    >>> import tempfile
    >>> f = os.path.join(tempfile.mkdtemp(), "m.scen")
    >>> _ = open(f, "w").write("version 1\\n0\\tm.map\\t4\\t3\\t0\\t0\\t3\\t2\\t3.82842712\\n")
    >>> read_scen(f)[0].goal, read_scen(f)[0].optimum
    ((3, 2), 3.82842712)
    """
    text = read_input(path).decode("utf-8", "replace")
    lines = text.splitlines()
    if not lines or not lines[0].lower().startswith("version"):
        raise ScenarioError(path, "line 1", "expected 'version N' (a MovingAI scenario file)")
    out = []
    for n, line in enumerate(lines[1:], 2):
        if not line.strip():
            continue
        f = line.split("\t") if "\t" in line else line.split()
        if len(f) != 9:
            raise ScenarioError(path, f"line {n}", f"expected 9 fields (bucket, map, width, height, start x, start y, "
                                                   f"goal x, goal y, optimal length), got {len(f)}")
        ints = [x.strip() for x in (f[0], f[2], f[3], f[4], f[5], f[6], f[7])]
        if not all(_INT.fullmatch(x) for x in ints):
            raise ScenarioError(path, f"line {n}", "bucket, width, height and the cells must be integers >= 0 "
                                                   "(at most 9 digits)")
        b, w, h, sx, sy, gx, gy = (int(x) for x in ints)
        try:
            opt = float(f[8])
        except ValueError:
            opt = float("nan")
        if not (opt >= 0 and opt < float("inf")):
            raise ScenarioError(path, f"line {n}", f"optimal length must be a finite number >= 0, got {f[8][:20]!r}")
        if not (sx < w and gx < w and sy < h and gy < h):
            raise ScenarioError(path, f"line {n}", f"a cell outside the {w} x {h} map")
        out.append(ScenRow(len(out), b, f[1].strip(), w, h, (sx, sy), (gx, gy), opt))
    if not out:
        raise ScenarioError(path, "rows", "none: a scenario file lists one query per line")
    if rows is not None:
        out = [out[i] for i in row_slice(rows, len(out), path)]
        if not out:
            raise ScenarioError(path, "--scen-rows", f"{rows!r} selects no row")
    return out
