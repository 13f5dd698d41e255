"""Scenario files: the TOML schema, its loader and its validation.

This module owns what a scenario *is* (:class:`Scenario`) and how a TOML file
becomes one. Every fault in a file is reported as a :class:`ScenarioError` whose
text is ``FILE: FIELD: what is wrong``, one line, so the command line can print it
as it is. Loading never modifies the file.

Schema (all lengths in one unit, angles in radians)::

    name = "..."                       # optional, defaults to the file stem
    expect = "solvable"                # optional: "solvable" (default) or "unsolvable"
    disk_tolerance = 1e-3              # optional: largest disk-to-polygon error, relative to r
    [bounds]   xmin, xmax, ymin, ymax  # bounds of the robot's reference point (the state)
    [robot]    polygon = [[x, y], ...] # body frame, reference point = body origin
               | [[robot.parts]] polygon = ...   (several parts)
               | radius = r            # a disk centred on the reference point
               (no [robot]: a point robot)
    [[obstacles]] polygon = [[x, y], ...], holes = [[[x, y], ...], ...]  (holes optional)
                | center = [x, y], radius = r
    [start]    x, y, theta (optional; the fixed orientation while translating)
    [goal]     x, y, theta (optional; must equal the start's unless space = "se2")
    [planner]  name, time, seed        # optional defaults
    [[queries]] start = [x, y], goal = [x, y]   # optional extra queries ([x, y, theta] in SE(2))
    space = "translation" | "se2" | "dubins" | "reeds-shepp"
                                       # optional: "se2" lets the robot rotate (theta is free;
                                       # pose angles are taken into [-pi, pi), as OMPL's SO(2))
    slabs = K                          # optional, SE(2) only: angle slabs of the sliced C-space
"""
from __future__ import annotations

import difflib
import math
import os
import stat
from dataclasses import dataclass, field

import numpy as np

from ..kernel.disk import DEFAULT_RELATIVE_ERROR, disk_polygon, disk_sides
from ..kernel.polygon import invalid_reason, is_convex, normalize
from ..kernel.slab import wrap_angle



def toml_reader():
    """The TOML reader, imported when a file is read (not by ``import cspace``)."""
    try:  # Python >= 3.11
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib


class ScenarioError(ValueError):
    """A fault in a scenario: ``str(err)`` is ``FILE: FIELD: message``, one short line.

    Each part is clipped (:func:`clip`): an echoed value is never longer than a line.
    """

    def __init__(self, file: str, field: str, message: str):
        self.file, self.field, self.message = clip(str(file)), clip(str(field)), clip(str(message), 240)
        super().__init__(f"{self.file}: {self.field}: {self.message}")


def clip(text: str, limit: int = 120) -> str:
    """``text`` on one line, at most about ``limit`` characters (the rest counted, not shown).

    >>> clip("x" * 1000, 10)
    'xxxxxxxxxx... (990 more characters)'
    """
    text = text.replace("\n", "\\n").replace("\r", "\\r")
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text) - limit} more characters)"


def show(x) -> str:
    """A value as echoed in a message: short, and safe for integers of any size.

    >>> show(10**5000), show([1.5] * 100)[:20]
    ('an integer of 5001 digits', '[1.5, 1.5, 1.5, 1.5,')
    """
    if isinstance(x, int) and not isinstance(x, bool) and x.bit_length() > 200:
        return f"an integer of {len(format(abs(x), 'x')) * 4 * 30103 // 100000 + 1} digits" \
            if x.bit_length() > 14000 else f"an integer of {len(str(abs(x)))} digits"
    if isinstance(x, (list, dict)) and len(x) > 40:  # do not even build a huge repr
        x = x[:40] if isinstance(x, list) else dict(list(x.items())[:40])
        return clip(repr(x)[:-1] + ", ...]" if isinstance(x, list) else repr(x)[:-1] + ", ...}", 80)
    try:
        return clip(repr(x), 80)
    except (ValueError, RecursionError):
        return f"a {type(x).__name__}"


# The largest scenario file read: a scene of about a million vertices. Bigger files
# (or /dev/zero) are refused before reading, as is anything that is not a regular file
# (a FIFO would block the open, a device could be read forever).
MAX_FILE_BYTES = 64 * 2**20
# Seeds: OMPL's are 32-bit and never 0 (planners.ompl_glue.SEED_LIMIT); a seed s is used as s + 1.
MAX_SEED = 2**32 - 2


@dataclass
class Shape:
    """One robot part or obstacle: a simple polygon (CCW exterior, CW holes).

    ``disk`` is ``(cx, cy, r)`` when the shape stands for a disk (then ``polygon``
    is the circumscribed regular polygon).
    """

    polygon: np.ndarray
    holes: list[np.ndarray] = field(default_factory=list)
    disk: tuple[float, float, float] | None = None
    convex: bool = False

    def to_shapely(self):
        """The shape as a shapely Polygon (imported lazily)."""
        import shapely

        return shapely.Polygon(self.polygon, [h for h in self.holes])


@dataclass
class Query:
    """A start and goal: (x, y) of the reference point, or poses (x, y, theta) in SE(2)."""

    start: tuple
    goal: tuple


@dataclass
class Scenario:
    """A planning problem: a robot, obstacles, bounds and queries.

    ``space`` is ``"translation"`` (the robot translates at the fixed orientation
    ``theta``; ``robot`` holds the parts already rotated by it, relative to the
    reference point) or ``"se2"`` (the robot also rotates; ``robot`` holds the parts
    in the body frame, ``theta`` is 0, and start, goal and queries are poses
    ``(x, y, theta)``). An empty ``robot`` is a point robot.
    """

    name: str
    bounds: tuple[float, float, float, float]
    robot: list[Shape]
    obstacles: list[Shape]
    start: tuple[float, float]
    goal: tuple[float, float]
    theta: float = 0.0
    planner: dict = field(default_factory=dict)
    queries: list[Query] = field(default_factory=list)
    expect: str = "solvable"
    path: str | None = None
    robot_kind: str = "point"  # "point", "polygon", "parts" or "disk"
    disk_tolerance: float = DEFAULT_RELATIVE_ERROR
    space: str = "translation"  # or "se2", "dubins", "reeds-shepp"
    slabs: int | None = None  # SE(2): angle slabs of the sliced C-space (None: derived)
    clearance: float = 0.0  # safety margin D: paths keep the robot at least D from obstacles
    margin: np.ndarray | None = None  # anisotropic convex margin (at theta in translation; body frame in SE(2))
    turning_radius: float | None = None  # car-like spaces: the minimum turning radius

    @property
    def rotates(self) -> bool:
        """Whether poses carry an angle: SE(2) and the car-like spaces (a car is a rotating robot
        whose motions are Dubins or Reeds–Shepp curves)."""
        return self.space in ROTATING_SPACES

    def margins(self) -> list[np.ndarray]:
        """The margin operands the robot is inflated by (:func:`cspace.kernel.margin.margin_shapes`);
        empty without a clearance or a margin polygon."""
        from ..kernel.margin import margin_shapes

        return margin_shapes(self.clearance, self.margin, self.disk_tolerance)

    @property
    def dim(self) -> int:
        """Numbers in a state: 2 for translation, 3 for SE(2) and the car-like spaces."""
        return 3 if self.rotates else 2

    @property
    def is_point_robot(self) -> bool:
        return not self.robot

    def all_queries(self) -> list[Query]:
        """The main query first, then the ``[[queries]]`` (the main one not repeated)."""
        main = Query(self.start, self.goal)
        rest = [q for q in self.queries if (q.start, q.goal) != (main.start, main.goal)]
        return [main] + rest

    def robot_at(self, x: float, y: float, theta: float = 0.0) -> list[np.ndarray]:
        """The robot's part polygons with the reference point at (x, y), turned by theta
        (in SE(2); a translating robot is already at its fixed orientation)."""
        if theta:
            from ..kernel.slab import rotate

            return [rotate(s.polygon, theta) + np.array([x, y]) for s in self.robot]
        return [s.polygon + np.array([x, y]) for s in self.robot]


# ---------------------------------------------------------------------------------
# Loading


def load_scenario(path, space: str | None = None, turning_radius: float | None = None, options=None) -> Scenario:
    """Read and validate a TOML scenario file; ``space`` (``"translation"``, ``"se2"``,
    ``"dubins"`` or ``"reeds-shepp"``) overrides the file's ``space`` (``--space`` on the
    command line), ``turning_radius`` its ``turning_radius`` (``--turning-radius``).

    A ROS map (``.yaml``) or an OMPL.app problem (``.cfg``) is imported
    (:mod:`cspace.io.imported`); ``options`` (an :class:`cspace.io.imported.ImportOptions`)
    give what such a file does not say: the robot, a map's start and goal.

    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); f = os.path.join(d, "s.toml")
    >>> _ = open(f, "w").write('[bounds]\\nxmin=0\\nxmax=1\\nymin=0\\nymax=1\\n'
    ...                        '[start]\\nx=0.1\\ny=0.1\\n[goal]\\nx=0.9\\ny=0.9\\n')
    >>> load_scenario(f).goal
    (0.9, 0.9)
    """
    path = os.fspath(path)
    if path.lower().endswith((".yaml", ".yml", ".cfg")):  # the suffixes of cspace.io.imported
        from .imported import load_imported

        return load_imported(path, space=space, options=options, turning_radius=turning_radius)
    raw = read_input(path)
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in raw[:4096]:
        raise ScenarioError(path, "file", "UTF-16 or binary, not UTF-8 text (save the file as UTF-8)")
    text = utf8_text(raw, path)
    tomllib = toml_reader()
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(path, "toml", f"invalid TOML ({exc})") from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise ScenarioError(path, "toml", f"invalid TOML ({exc})") from None
    except RecursionError:
        raise ScenarioError(path, "toml", "invalid TOML (arrays or tables nested too deeply)") from None
    return scenario_from_dict(data, path, space=space, turning_radius=turning_radius)


def check_input(path) -> os.stat_result:
    """Refuse, without opening it, what cannot be a scenario file: a missing path, a
    folder, a FIFO or device (whose open or read may never end), a file over
    :data:`MAX_FILE_BYTES`. Returns the file's ``os.stat``.

    >>> check_input("/dev/zero")
    Traceback (most recent call last):
    ...
    cspace.io.scenario.ScenarioError: /dev/zero: file: is not a regular file (a FIFO, device or socket)
    """
    path = os.fspath(path)
    try:
        st = os.stat(path)
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        raise ScenarioError(path, "file", f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ScenarioError(path, "file", "is a folder, not a scenario file")
    if not stat.S_ISREG(st.st_mode):
        raise ScenarioError(path, "file", "is not a regular file (a FIFO, device or socket)")
    if st.st_size > MAX_FILE_BYTES:
        raise ScenarioError(path, "file", f"is {st.st_size} bytes, over the {MAX_FILE_BYTES >> 20} MiB limit")
    return st


def read_input(path: str) -> bytes:
    """The bytes of a scenario file, read only once :func:`check_input` accepts it.

    Opened without blocking and checked again on the open file (the path may have
    been swapped for a FIFO in between); never more than the limit is read.
    """
    check_input(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise ScenarioError(path, "file", "is not a regular file (a FIFO, device or socket)")
            raw = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ScenarioError(path, "file", f"cannot read ({exc.strerror or exc})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ScenarioError(path, "file", f"is over the {MAX_FILE_BYTES >> 20} MiB limit")
    return raw



def utf8_text(raw: bytes, path: str) -> str:
    """The text of an input file's bytes: UTF-8, a byte-order mark allowed and skipped;
    anything else is a :class:`ScenarioError` naming the first invalid byte.

    >>> utf8_text(b"\\xef\\xbb\\xbfa = 1", "s.toml")
    'a = 1'
    >>> utf8_text(b"a\\xff", "s.toml")
    Traceback (most recent call last):
    ...
    cspace.io.scenario.ScenarioError: s.toml: file: not UTF-8 text (invalid byte at offset 1)
    """
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ScenarioError(path, "file", f"not UTF-8 text (invalid byte at offset {exc.start})") from None


# The scenes the C-space supports: products of two coordinates (or of two extents)
# stay far inside the double range. Within it, plans are the same at every scale: a
# scene scaled by a power of two gives the same path, scaled (tested from 2^-300 to
# 2^300). The geometry functions themselves take any finite doubles.
MAX_MAGNITUDE = 2.0**400
MIN_EXTENT = 2.0**-400


# The keys a scenario may have at its top level (a new section adds its key here).
TOP_LEVEL_KEYS = frozenset({"name", "expect", "disk_tolerance", "bounds", "robot", "obstacles", "start", "goal",
                            "planner", "queries", "space", "slabs", "turning_radius",
                            "clearance", "margin"})
# The forms of a robot table and of a shape (obstacle or robot part), by their keys: keys of two
# different forms in one table exclude each other.
ROBOT_FORMS = {"polygon": {"polygon"}, "parts": {"parts"}, "disk": {"radius"}}
SHAPE_FORMS = {"polygon": {"polygon", "holes"}, "disk": {"center", "radius"}}


def unknown_field_message(key: str, allowed) -> str:
    """The message for a key that is not one of ``allowed``: the closest known key, if any.

    >>> unknown_field_message("polgon", {"polygon", "holes", "center", "radius"})
    'unknown field (did you mean polygon?)'
    >>> unknown_field_message("colour", {"name", "bounds"})
    'unknown field (expected one of: bounds, name)'
    """
    close = difflib.get_close_matches(str(key), sorted(allowed), n=1, cutoff=0.6)
    if close:
        return f"unknown field (did you mean {close[0]}?)"
    return f"unknown field (expected one of: {', '.join(sorted(allowed))})"


def scenario_from_dict(data: dict, path: str = "<scenario>", space: str | None = None,
                       turning_radius: float | None = None) -> Scenario:
    """Validate a parsed scenario (the TOML document as a dict) into a :class:`Scenario`.
    ``space`` and ``turning_radius``, if given, override the document's."""
    v = _Validator(path)
    v.no_extra(data, "", TOP_LEVEL_KEYS)
    name = data.get("name", os.path.splitext(os.path.basename(path))[0])
    if not isinstance(name, str):
        raise v.err("name", "must be a string")
    expect = data.get("expect", "solvable")
    if expect not in ("solvable", "unsolvable"):
        raise v.err("expect", 'must be "solvable" or "unsolvable"')
    tol = v.number(data.get("disk_tolerance", DEFAULT_RELATIVE_ERROR), "disk_tolerance", positive=True)

    b = v.table(data, "bounds", required=True)
    xmin, xmax = v.number(b.get("xmin"), "bounds.xmin"), v.number(b.get("xmax"), "bounds.xmax")
    ymin, ymax = v.number(b.get("ymin"), "bounds.ymin"), v.number(b.get("ymax"), "bounds.ymax")
    v.no_extra(b, "bounds", {"xmin", "xmax", "ymin", "ymax"})
    if not xmin < xmax:
        raise v.err("bounds", f"xmin ({xmin}) must be less than xmax ({xmax})")
    if not ymin < ymax:
        raise v.err("bounds", f"ymin ({ymin}) must be less than ymax ({ymax})")
    if max(xmax - xmin, ymax - ymin) < MIN_EXTENT:
        raise v.err("bounds", f"the scene's extent {max(xmax - xmin, ymax - ymin):.3g} is below the supported "
                              f"2^-400 (about {MIN_EXTENT:.2g})")
    bounds = (xmin, xmax, ymin, ymax)

    if space is not None and space not in SPACES:
        raise ScenarioError("--space", "space", f"must be one of {', '.join(SPACES)}, got {_short(space)}")
    space = space or data.get("space", "translation")
    if space not in SPACES:
        raise v.err("space", f"must be one of {', '.join(repr(s) for s in SPACES)}, got {_short(space)}")
    se2 = space in ROTATING_SPACES
    slabs = data.get("slabs")
    if slabs is not None:
        if not se2:
            raise v.err("slabs", 'applies to a rotating robot only (space = "se2", "dubins" or "reeds-shepp")')
        if isinstance(slabs, bool) or not isinstance(slabs, int) or not 4 <= slabs <= MAX_SLABS:
            raise v.err("slabs", f"must be an integer from 4 to {MAX_SLABS} (a slab spans at most a quarter "
                                 f"turn), got {_short(slabs)}")
    radius = data.get("turning_radius")
    if turning_radius is not None:
        if space not in CAR_SPACES:
            raise ScenarioError("--turning-radius", "turning_radius", 'applies to space = "dubins" or "reeds-shepp" only')
        if isinstance(turning_radius, bool) or not isinstance(turning_radius, (int, float)) \
                or not 0.0 < float(turning_radius) < math.inf:
            raise ScenarioError("--turning-radius", "turning_radius", f"must be a positive number, got {_short(turning_radius)}")
        radius = float(turning_radius)
    if space in CAR_SPACES:
        if radius is None:
            raise v.err("turning_radius", f'is required for space = "{space}" (the car\'s minimum turning radius)')
        radius = v.number(radius, "turning_radius", positive=True)
    elif radius is not None:
        raise v.err("turning_radius", 'applies to space = "dubins" or "reeds-shepp" only')

    start_t = v.table(data, "start", required=True)
    goal_t = v.table(data, "goal", required=True)
    start, theta = v.pose(start_t, "start")
    goal, goal_theta = v.pose(goal_t, "goal")
    if se2:  # angles as OMPL's SO(2) holds them: in [-pi, pi) (pi itself is -pi)
        start, goal = (*start, wrap_angle(theta or 0.0)), (*goal, wrap_angle(goal_theta or 0.0))
        theta = 0.0  # the robot stays in its body frame; poses carry the angle
    else:
        if goal_theta is not None and theta is not None and goal_theta != theta:
            raise v.err("goal.theta", f"{goal_theta} differs from start.theta ({theta}), but the robot only "
                                      'translates here: add space = "se2" to let it rotate')
        theta = theta if theta is not None else (goal_theta or 0.0)

    robot, kind = v.robot(data.get("robot"), theta, tol)
    clearance = v.number(data.get("clearance", 0.0), "clearance")
    if clearance < 0:
        raise v.err("clearance", f"must be a distance >= 0, got {data.get('clearance')}")
    margin = v.margin(data.get("margin"), theta, tol)
    obstacles = v.obstacles(data.get("obstacles", []), tol)
    planner = v.planner(data.get("planner", {}))
    queries = v.queries(data.get("queries", []), se2)

    sc = Scenario(
        name=name, bounds=bounds, robot=robot, obstacles=obstacles, start=start, goal=goal,
        theta=theta, planner=planner, queries=queries, expect=expect, path=path,
        robot_kind=kind, disk_tolerance=tol, space=space, slabs=slabs,
        turning_radius=radius, clearance=clearance, margin=margin,
    )
    probe = CollisionProbe(sc)
    labelled = [(start, "start"), (goal, "goal")]
    for i, q in enumerate(queries):
        labelled += [(q.start, f"queries[{i}].start"), (q.goal, f"queries[{i}].goal")]
    for pt, fld in labelled:
        v.placement(sc, probe, pt, fld)
    return sc


# The state spaces a scenario can ask for, and the largest number of angle slabs.
SPACES = ("translation", "se2", "dubins", "reeds-shepp")
ROTATING_SPACES = ("se2", "dubins", "reeds-shepp")
CAR_SPACES = ("dubins", "reeds-shepp")
MAX_SLABS = 4096


def _short(x, limit: int = 60) -> str:
    """repr(x), cut to ``limit`` characters (messages stay one short line)."""
    r = repr(x)
    return r if len(r) <= limit else r[: limit - 3] + "..."


class _Validator:
    """Field-by-field checks; each failure names the file and the field."""

    def __init__(self, path: str):
        self.path = path

    def err(self, field: str, message: str) -> ScenarioError:
        return ScenarioError(self.path, field, message)

    def table(self, data: dict, key: str, required: bool = False) -> dict:
        t = data.get(key)
        if t is None:
            if required:
                raise self.err(key, "missing (a table is required)")
            return {}
        if not isinstance(t, dict):
            raise self.err(key, "must be a table")
        return t

    def no_extra(self, t: dict, where: str, allowed) -> None:
        for k in t:
            if k not in allowed:
                raise self.err(f"{where}.{k}" if where else str(k), unknown_field_message(k, allowed))

    def one_form(self, t: dict, field: str, forms: dict, hint: str) -> None:
        """Unknown keys, then keys of two forms (say polygon and radius) together, are errors."""
        self.no_extra(t, field, set().union(*forms.values()))
        used = [sorted(k for k in keys if k in t) for keys in forms.values()]
        used = [keys for keys in used if keys]
        if len(used) > 1:
            a, b = sorted((used[0][0], used[1][0]))
            raise self.err(field, f"{a} and {b} exclude each other ({hint})")

    def number(self, x, field: str, positive: bool = False) -> float:
        # The common cases first (a scene may hold 10^6 numbers): a finite float within
        # the supported magnitude (NaN and inf fail the comparison), a modest int.
        if not positive:
            if type(x) is float and -MAX_MAGNITUDE <= x <= MAX_MAGNITUDE:
                return x
            if type(x) is int and -(1 << 53) <= x <= 1 << 53:
                return float(x)
        if x is None:
            raise self.err(field, "missing (a number is required)")
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise self.err(field, f"must be a number, got {type(x).__name__} {show(x)}")
        try:
            xf = float(x)
        except OverflowError:
            raise self.err(field, f"{show(x)} is too large for a double") from None
        if not math.isfinite(xf):
            raise self.err(field, f"must be finite, got {x}")
        if abs(xf) > MAX_MAGNITUDE:
            raise self.err(field, f"{show(x)} is beyond the supported magnitude 2^400 (about {MAX_MAGNITUDE:.2g})")
        if positive and not xf > 0.0:
            raise self.err(field, f"must be positive, got {x}")
        return xf

    def point(self, p, field: str) -> tuple[float, float]:
        if not isinstance(p, list) or len(p) != 2:
            raise self.err(field, f"must be a point [x, y], got {show(p)}")
        return self.number(p[0], f"{field}[0]"), self.number(p[1], f"{field}[1]")

    def pose(self, t: dict, field: str) -> tuple[tuple[float, float], float | None]:
        self.no_extra(t, field, {"x", "y", "theta"})
        xy = (self.number(t.get("x"), f"{field}.x"), self.number(t.get("y"), f"{field}.y"))
        theta = self.number(t["theta"], f"{field}.theta") if "theta" in t else None
        return xy, theta

    def polygon(self, pts, field: str) -> np.ndarray:
        if not isinstance(pts, list):
            raise self.err(field, "must be a list of points [[x, y], ...]")
        arr = np.array([self.point(p, f"{field}[{i}]") for i, p in enumerate(pts)], dtype=np.float64).reshape(-1, 2)
        if len(np.unique(arr, axis=0)) < 3:
            raise self.err(field, f"needs at least 3 distinct vertices, got {len(np.unique(arr, axis=0))}")
        return arr

    def shape(self, t: dict, field: str, tol: float, allow_holes: bool) -> Shape:
        if not isinstance(t, dict):
            raise self.err(field, "must be a table")
        if field == "robot":  # the robot table's forms are checked by robot()
            forms = {"polygon": {"polygon"}, "disk": {"radius"}}
        else:
            forms = SHAPE_FORMS if allow_holes else {"polygon": {"polygon"}, "disk": {"center", "radius"}}
        self.one_form(t, field, forms, "a polygon = [[x, y], ...] or a disk: center = [x, y], radius = r")
        if "polygon" in t:
            ext = self.polygon(t["polygon"], f"{field}.polygon")
            holes_raw = t.get("holes", [])
            if not isinstance(holes_raw, list):
                raise self.err(f"{field}.holes", "must be a list of polygons")
            holes = [self.polygon(h, f"{field}.holes[{i}]") for i, h in enumerate(holes_raw)]
            reason = invalid_reason(ext)  # GEOS's check, on a copy near 1 at extreme scales
            if reason:
                raise self.err(f"{field}.polygon", f"not a simple polygon ({reason})")
            ext_n = normalize(ext, ccw=True)
            if len(ext_n) < 3:  # exact: a float area underflows near 1e-160
                raise self.err(f"{field}.polygon", "has zero area")
            holes_n = []
            for i, h in enumerate(holes):
                holes_n.append(normalize(h, ccw=False))
                if invalid_reason(h) or len(holes_n[-1]) < 3:
                    raise self.err(f"{field}.holes[{i}]", "not a simple polygon of non-zero area")
            if holes:
                reason = invalid_reason(ext, holes)
                if reason:
                    raise self.err(f"{field}.holes", f"holes do not fit the polygon ({reason})")
            return Shape(ext_n, holes_n, None, convex=not holes_n and is_convex(ext_n))
        if "radius" in t:
            if field != "robot" and "center" not in t:
                raise self.err(f"{field}.center", "missing (a disk needs center = [x, y] with its radius)")
            r = self.number(t.get("radius"), f"{field}.radius", positive=True)
            c = self.point(t.get("center", [0.0, 0.0] if field == "robot" else None), f"{field}.center")
            poly = disk_polygon(c, r, max_error=tol * r)
            # A disk far below the spacing of doubles at its centre rounds to a point or a
            # segment, which the C-space cannot represent: refuse it rather than misplace it.
            if r < 1e-6 * max(abs(c[0]), abs(c[1])) and len(normalize(poly)) < 3:
                raise self.err(f"{field}.radius", f"{r} is too small for a disk centred at ({c[0]}, {c[1]}): "
                                                  f"its polygon rounds to a point or a segment in doubles")
            return Shape(poly, [], (c[0], c[1], r), convex=True)
        raise self.err(field, "needs polygon = [[x, y], ...] or center = [x, y] with radius = r")

    def robot(self, t, theta: float, tol: float) -> tuple[list[Shape], str]:
        if t is None:
            return [], "point"
        if not isinstance(t, dict):
            raise self.err("robot", "must be a table")
        if "center" in t and "radius" in t:
            raise self.err("robot.center", "a disk robot is centred on its reference point; give radius only")
        self.one_form(t, "robot", ROBOT_FORMS, "one of polygon = [...], [[robot.parts]] or radius = r")
        if "parts" in t:
            parts = t["parts"]
            if not isinstance(parts, list) or not parts:
                raise self.err("robot.parts", "must be a non-empty array of tables")
            shapes = [self.shape(p, f"robot.parts[{i}]", tol, allow_holes=False) for i, p in enumerate(parts)]
            kind = "parts"
        elif "radius" in t:
            shapes = [self.shape(t, "robot", tol, allow_holes=False)]
            kind = "disk"
        elif "polygon" in t:
            shapes = [self.shape(t, "robot", tol, allow_holes=False)]
            kind = "polygon"
        else:
            raise self.err("robot", "needs polygon, [[robot.parts]] or radius")
        if theta:
            from ..kernel.slab import rotate  # the one rotation used for "the robot at theta"

            for sh in shapes:
                sh.polygon = rotate(sh.polygon, theta)
                if sh.disk is not None:
                    sh.disk = (0.0, 0.0, sh.disk[2])
        return shapes, kind

    def margin(self, t, theta: float, tol: float) -> np.ndarray | None:
        """``[margin] polygon = [...]``: convex, containing the origin, turned by theta like the robot."""
        if t is None:
            return None
        if not isinstance(t, dict):
            raise self.err("margin", "must be a table with polygon = [[x, y], ...]")
        self.no_extra(t, "margin", {"polygon"})
        if "polygon" not in t:
            raise self.err("margin.polygon", "missing (a convex polygon around the reference point)")
        from ..kernel.margin import check_margin_polygon

        p = self.shape({"polygon": t["polygon"]}, "margin", tol, allow_holes=False).polygon
        why = check_margin_polygon(p)
        if why:
            raise self.err("margin.polygon", why)
        if theta:
            from ..kernel.slab import rotate

            p = rotate(p, theta)
        return p

    def obstacles(self, lst, tol: float) -> list[Shape]:
        """The obstacles, in order, as :meth:`shape` reads each one.

        Plain polygons (no holes) have their numbers read here and their geometry
        checked and normalised in batches (:func:`cspace.kernel.polygon_batch.normalize_many`);
        any the batch does not decide, and every other obstacle, go through
        :meth:`shape`. The first faulty obstacle in file order is the one reported,
        as if each were read in turn.
        """
        if not isinstance(lst, list):
            raise self.err("obstacles", "must be an array of tables [[obstacles]]")
        from ..kernel.polygon_batch import normalize_many

        out: list = [None] * len(lst)
        raw: dict = {}  # obstacle -> its plain [[x, y], ...] list
        fault = None
        for i, t in enumerate(lst):
            if isinstance(t, dict) and "polygon" in t and set(t) <= {"polygon", "holes"} and \
                    t.get("holes", []) == [] and _plain_list(t["polygon"]):
                raw[i] = t["polygon"]
                continue
            try:
                out[i] = self.shape(t, f"obstacles[{i}]", tol, allow_holes=True)
            except ScenarioError as exc:
                fault = exc  # raised below, unless an earlier obstacle has a fault
                break
        # Plain lists: converted per vertex count in one numpy call, then checked and
        # normalised in batches; what either step does not accept is read by shape().
        slow = []
        groups: dict = {}
        for i, pts in raw.items():
            groups.setdefault(len(pts), []).append(i)
        for n, idx in groups.items():
            try:
                block = np.array([raw[i] for i in idx], dtype=np.float64).reshape(len(idx), n, 2)
            except (OverflowError, ValueError):  # an int too large for a double, somewhere
                slow += idx
                continue
            fine = (np.abs(block) <= MAX_MAGNITUDE).all(axis=(1, 2)) if n else np.zeros(len(idx), dtype=bool)
            good = [i for i, f in zip(idx, fine.tolist()) if f]
            slow += [i for i, f in zip(idx, fine.tolist()) if not f]
            rows = np.flatnonzero(fine)
            for i, got in zip(good, normalize_many(list(block[rows]))):
                if got is None:
                    slow.append(i)
                else:
                    out[i] = Shape(got[0], [], None, convex=got[1])
        for i in sorted(slow):  # in file order: the first faulty one raises, worded as always
            out[i] = self.shape(lst[i], f"obstacles[{i}]", tol, allow_holes=True)
        if fault is not None:
            raise fault
        return out

    def planner(self, t) -> dict:
        if not isinstance(t, dict):
            raise self.err("planner", "must be a table")
        self.no_extra(t, "planner", {"name", "time", "seed"})
        out = {}
        if "name" in t:
            if not isinstance(t["name"], str) or not t["name"]:
                raise self.err("planner.name", "must be a planner name")
            out["name"] = t["name"]
        if "time" in t:
            out["time"] = self.number(t["time"], "planner.time", positive=True)
        if "seed" in t:
            if isinstance(t["seed"], bool) or not isinstance(t["seed"], int) or not 0 <= t["seed"] <= MAX_SEED:
                raise self.err("planner.seed", f"must be an integer in [0, 2^32 - 1), got {show(t['seed'])}")
            out["seed"] = t["seed"]
        return out

    def queries(self, lst, se2: bool = False) -> list[Query]:
        """``start``/``goal`` as ``[x, y]`` or ``{x, y}``; in SE(2) ``[x, y, theta]`` or
        ``{x, y, theta}`` (theta defaults to 0)."""
        if not isinstance(lst, list):
            raise self.err("queries", "must be an array of tables [[queries]]")
        out = []
        for i, q in enumerate(lst):
            f = f"queries[{i}]"
            if not isinstance(q, dict):
                raise self.err(f, "must be a table")
            self.no_extra(q, f, {"start", "goal"})
            pts = []
            for key in ("start", "goal"):
                p, fk = q.get(key), f"{f}.{key}"
                if isinstance(p, dict):
                    xy, th = self.pose(p, fk)
                    if th is not None and not se2:
                        raise self.err(f"{fk}.theta", 'the robot only translates here: add space = "se2" to give '
                                                      "queries an angle")
                    pts.append((*xy, wrap_angle(th or 0.0)) if se2 else xy)
                elif p is None:
                    raise self.err(fk, "missing")
                elif se2 and isinstance(p, list) and len(p) == 3:
                    pts.append((*self.point(p[:2], fk), wrap_angle(self.number(p[2], f"{fk}[2]"))))
                elif not se2 and isinstance(p, list) and len(p) == 3:
                    raise self.err(fk, 'has an angle, but the robot only translates here: add space = "se2" '
                                       "to let it rotate")
                else:
                    if se2 and not (isinstance(p, list) and len(p) == 2):
                        raise self.err(fk, f"must be a pose [x, y, theta] (or [x, y]), got {_short(p)}")
                    xy = self.point(p, fk)
                    pts.append((*xy, 0.0) if se2 else xy)
            out.append(Query(pts[0], pts[1]))
        return out

    def placement(self, sc: Scenario, probe: "CollisionProbe", pt: tuple, field: str) -> None:
        """The reference point must be in bounds and the robot there (turned by the
        pose's theta in SE(2)) must touch no obstacle."""
        xmin, xmax, ymin, ymax = sc.bounds
        x, y = pt[0], pt[1]
        theta = pt[2] if len(pt) > 2 else 0.0
        where = f"({x}, {y})" if len(pt) == 2 else f"({x}, {y}, theta {theta})"
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            raise self.err(field, f"{where} is outside the bounds [{xmin}, {xmax}] x [{ymin}, {ymax}]")
        hit = probe.first_hit(x, y, theta)
        if hit is not None:
            raise self.err(field, f"{where} puts the robot in collision with obstacles[{hit}]")


class CollisionProbe:
    """Which obstacle does the robot at (x, y) touch? An independent shapely route.

    Closed sets: touching counts, the same convention as the C-space. Used to
    validate starts and goals, and as a test oracle.
    """

    def __init__(self, sc: Scenario):
        import shapely

        self._shapely = shapely
        self._sc = sc
        self._geoms = _shapely_obstacles(sc.obstacles)
        self._tree = shapely.STRtree(self._geoms) if self._geoms else None

    def first_hit(self, x: float, y: float, theta: float = 0.0) -> int | None:
        shapely = self._shapely
        if self._tree is None:
            return None
        if self._sc.robot:
            body = shapely.union_all([shapely.Polygon(p) for p in self._sc.robot_at(x, y, theta)])
        else:
            body = shapely.Point(x, y)
        hits = self._tree.query(body, predicate="intersects")
        return int(hits.min()) if len(hits) else None


def _plain_list(pts) -> bool:
    """Whether ``pts`` is a non-empty ``[[x, y], ...]`` of plain floats and ints (no bool,
    no string): the loader's batched route; the values are checked after conversion.

    >>> _plain_list([[0, 1.5], [2, 3]]), _plain_list([[0, True]]), _plain_list([[0, 1, 2]])
    (True, False, False)
    """
    if type(pts) is not list or not pts:
        return False
    for p in pts:
        if type(p) is not list or len(p) != 2:
            return False
        x, y = p
        if (type(x) is not float and type(x) is not int) or (type(y) is not float and type(y) is not int):
            return False
    return True


def _shapely_obstacles(obstacles: list) -> list:
    """``[ob.to_shapely() for ob in obstacles]``, polygons without holes made in batches of
    one vertex count (one shapely call each instead of one per obstacle)."""
    import shapely

    out = [None] * len(obstacles)
    groups: dict = {}
    for i, ob in enumerate(obstacles):
        if ob.holes:
            out[i] = ob.to_shapely()
        else:
            groups.setdefault(len(ob.polygon), []).append(i)
    for idx in groups.values():
        for i, g in zip(idx, shapely.polygons(np.stack([obstacles[i].polygon for i in idx])).tolist()):
            out[i] = g
    return out


def first_collision(sc: Scenario, x: float, y: float) -> int | None:
    """Index of the first obstacle the robot at (x, y) touches (closed sets), or None."""
    return CollisionProbe(sc).first_hit(x, y)
