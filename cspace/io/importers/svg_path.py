"""SVG path data and transforms as plain numbers: the ``d`` of a ``<path>`` read into
subpaths (lists of points), and a ``transform`` attribute read into a 3 x 3 affine matrix.

Lines are read exactly as SVG 1.1 defines them: ``M``/``m`` (a move, its further pairs
are lines), ``L``/``l``, ``H``/``h``, ``V``/``v``, ``Z``/``z`` (close: the current point
returns to the subpath's start), absolute (upper case) or relative to the current point
(lower case). Curves (``C S Q T A`` and their relative forms) are refused with
:class:`CurveError` unless a flattening tolerance is given; then each curve is replaced by
chords within that distance of it (Béziers subdivided until their control points lie within
the tolerance of the chord: the curve lies in their hull; elliptical arcs stepped by the
angle whose sagitta on the larger radius is the tolerance).

Every fault is a :class:`PathDataError` (a ``ValueError``) with a short message; the
importer names the file and the path. Numbers are SVG's (no ``nan``, ``inf`` or hex);
a number that overflows to infinity is refused.
"""
from __future__ import annotations

import math
import re

import numpy as np

MAX_POINTS = 2**20  # per file, flattened curves included: the work is bounded by this
_TOKEN = re.compile(r"\s*,?\s*(?:([MmLlHhVvZzCcSsQqTtAa])|([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?))")
_ARGS = {"m": 2, "l": 2, "h": 1, "v": 1, "z": 0, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7}
_TRANSFORM = re.compile(r"\s*,?\s*(matrix|translate|scale|rotate|skewX|skewY)\s*\(([^()]*)\)\s*")


class PathDataError(ValueError):
    """A fault in path data or a transform: the message names what and where."""


class CurveError(PathDataError):
    """A curve command met without a flattening tolerance."""


def tokens(d: str) -> list:
    """Commands (one letter) and numbers (floats) of path data, in order.

    >>> tokens("m 1,2.5 -3e1.5z")
    ['m', 1.0, 2.5, -30.0, 0.5, 'z']
    """
    out, pos, n = [], 0, len(d)
    while pos < n:
        m = _TOKEN.match(d, pos)
        if m is None or m.end() == pos:
            rest = d[pos:].strip()
            if not rest:
                break
            raise PathDataError(f"unknown command or number {rest[:12]!r} at character {pos}")
        pos = m.end()
        if m.group(1):
            out.append(m.group(1))
        else:
            v = float(m.group(2))
            if not math.isfinite(v):
                raise PathDataError(f"number {m.group(2)[:24]!r} at character {m.start(2)} overflows")
            out.append(v)
    return out


def parse_path(d: str, flatten: float | None = None, scale: float = 1.0) -> tuple[list[np.ndarray], np.ndarray, int]:
    """The subpaths of path data (each an (N, 2) array of its points in order, closed or not),
    the end points of its move and line commands in order (Bench-MR's point list: what it
    centres a robot on), and the number of curves flattened. ``flatten`` is the largest distance
    of a chord from its curve, in the units the points end up in after a linear map of norm
    ``scale`` (the path's transform); None refuses curves.

    >>> subs, pts, curves = parse_path("m 0,0 h 2 v 1 h -2 z m 3,0 l 1,0 0,1 z")
    >>> [s.tolist() for s in subs]
    [[[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]], [[3.0, 0.0], [4.0, 0.0], [4.0, 1.0]]]
    >>> parse_path("M 0 0 C 1 1 2 1 3 0 Z")
    Traceback (most recent call last):
    ...
    cspace.io.importers.svg_path.CurveError: a curve (the first C at character 6): give --flatten-curves TOL to replace curves by chords
    """
    toks = tokens(d)
    tol = None if flatten is None else flatten / max(scale, 1e-300)
    subs: list[list] = []
    ends: list = []
    cur = np.zeros(2)
    start = np.zeros(2)
    last_ctrl, last_cmd = None, ""
    count, curves, i, cmd, closed = 0, 0, 0, None, False
    while i < len(toks):
        t = toks[i]
        if isinstance(t, str):
            cmd, i = t, i + 1
            if cmd in "zZ":
                cur, closed = start.copy(), True
                last_cmd = "z"
                continue
        elif cmd is None:
            raise PathDataError(f"path data starts with the number {t!r}, not a command (M or m)")
        lower = cmd.lower()
        k = _ARGS[lower]
        if lower == "z":
            raise PathDataError("numbers after a close command (z)")
        args = toks[i:i + k]
        if len(args) < k or any(isinstance(a, str) for a in args):
            raise PathDataError(f"command {cmd} needs {k} numbers, got {len([a for a in args if not isinstance(a, str)])}")
        i += k
        rel = cmd.islower()
        base = cur if rel else np.zeros(2)
        if closed and lower != "m":  # drawing on after a close: a new subpath from the same start
            subs.append([start.copy()])
        closed = False
        if lower in "ml":
            p = base + args
            if lower == "m":
                subs.append([])
                start = p.copy()
                cmd = "l" if rel else "L"  # further pairs are lines
            subs[-1].append(p) if subs else _no_move()
            ends.append(p)
            cur = p
        elif lower in "hv":
            if not subs:
                _no_move()
            p = cur.copy()
            j = 0 if lower == "h" else 1
            p[j] = (cur[j] if rel else 0.0) + args[0]
            subs[-1].append(p)
            ends.append(p)
            cur = p
        else:
            if tol is None:
                raise CurveError(f"a curve (the first {cmd} at character {d.find(cmd)}): give --flatten-curves TOL "
                                 "to replace curves by chords")
            if not subs:
                _no_move()
            pts, last_ctrl = _curve(lower, np.asarray(args, float), base, cur, last_ctrl, last_cmd, tol)
            subs[-1].extend(pts)
            cur = pts[-1] if pts else cur
            curves += 1
        if lower not in "csqt":
            last_ctrl = None
        last_cmd = lower
        count = sum(len(s) for s in subs)
        if count > MAX_POINTS:
            raise PathDataError(f"over {MAX_POINTS} points (lower the curve flattening's precision)")
    for s in subs:
        for p in s:
            if not (np.isfinite(p).all()):
                raise PathDataError("a coordinate overflows")
    return [np.array(s, dtype=float) for s in subs if s], np.array(ends, dtype=float).reshape(-1, 2), curves


def _no_move():
    raise PathDataError("a drawing command before the first move (M or m)")


def _curve(kind: str, a: np.ndarray, base: np.ndarray, cur: np.ndarray, last_ctrl, last_cmd: str, tol: float):
    """The chords of one curve command (its end point last) and its last control point."""
    if kind == "a":
        end = base + a[5:7]
        return _arc(cur, a[0], a[1], a[2], a[3] != 0, a[4] != 0, end, tol), None
    if kind in "st":
        refl = 2 * cur - last_ctrl if last_ctrl is not None and last_cmd in ("cs" if kind == "s" else "qt") else cur
    if kind == "c":
        c1, c2, end = base + a[0:2], base + a[2:4], base + a[4:6]
    elif kind == "s":
        c1, c2, end = refl, base + a[0:2], base + a[2:4]
    else:
        q = base + a[0:2] if kind == "q" else refl
        end = base + a[2:4] if kind == "q" else base + a[0:2]
        c1, c2 = cur + 2.0 / 3.0 * (q - cur), end + 2.0 / 3.0 * (q - end)  # the same curve as a cubic
        last = q
    # Wang's bound: this many uniform pieces put a cubic within tol of its chords; past the
    # point budget the curve is refused before any subdivision (bounded work).
    dd = max(float(np.hypot(*(cur - 2 * c1 + c2))), float(np.hypot(*(c1 - 2 * c2 + end))))
    if math.sqrt(0.75 * dd / tol) > MAX_POINTS:
        raise PathDataError(f"a curve needs over {MAX_POINTS} chords within the tolerance (raise --flatten-curves)")
    pts: list = []
    _cubic(cur, c1, c2, end, tol, pts, 0)
    return pts, (c2 if kind in "cs" else last)


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    den = float(ab @ ab)
    t = 0.0 if den == 0 else min(1.0, max(0.0, float((p - a) @ ab) / den))
    return float(np.hypot(*(p - a - t * ab)))


def _cubic(p0, p1, p2, p3, tol: float, out: list, depth: int) -> None:
    """Append the chords' ends of a cubic Bézier (p0 excluded): split in halves (de Casteljau)
    until both inner control points lie within ``tol`` of the chord p0 p3."""
    if depth >= 24 or max(_segment_distance(p1, p0, p3), _segment_distance(p2, p0, p3)) <= tol:
        out.append(p3)
        if len(out) > MAX_POINTS:
            raise PathDataError(f"over {MAX_POINTS} points from one curve (raise --flatten-curves)")
        return
    a, b, c = (p0 + p1) / 2, (p1 + p2) / 2, (p2 + p3) / 2
    d, e = (a + b) / 2, (b + c) / 2
    m = (d + e) / 2
    _cubic(p0, a, d, m, tol, out, depth + 1)
    _cubic(m, e, c, p3, tol, out, depth + 1)


def _arc(p0, rx, ry, phi_deg, large: bool, sweep: bool, p1, tol: float) -> list:
    """Chords of an SVG elliptical arc (endpoint form, SVG 1.1 appendix F.6), end included."""
    rx, ry = abs(rx), abs(ry)
    if rx == 0 or ry == 0 or np.array_equal(p0, p1):
        return [p1]  # a straight line (F.6.2)
    phi = math.radians(phi_deg % 360.0)
    c, s = math.cos(phi), math.sin(phi)
    dx, dy = (p0 - p1) / 2
    x1, y1 = c * dx + s * dy, -s * dx + c * dy
    lam = (x1 / rx) ** 2 + (y1 / ry) ** 2
    if lam > 1:  # radii too small: scaled up (F.6.6)
        rx, ry = rx * math.sqrt(lam), ry * math.sqrt(lam)
    num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1
    den = rx * rx * y1 * y1 + ry * ry * x1 * x1
    if not den > 0:  # the ends closer than the squares resolve: a point-sized arc
        return [p1]
    k = math.sqrt(max(0.0, num / den)) * (-1 if large == sweep else 1)
    cx1, cy1 = k * rx * y1 / ry, -k * ry * x1 / rx
    cx, cy = c * cx1 - s * cy1 + (p0[0] + p1[0]) / 2, s * cx1 + c * cy1 + (p0[1] + p1[1]) / 2
    t0 = math.atan2((y1 - cy1) / ry, (x1 - cx1) / rx)
    t1 = math.atan2((-y1 - cy1) / ry, (-x1 - cx1) / rx)
    dt = t1 - t0
    if sweep and dt < 0:
        dt += 2 * math.pi
    elif not sweep and dt > 0:
        dt -= 2 * math.pi
    r = max(rx, ry)
    step = 2 * math.acos(max(-1.0, 1 - tol / r)) if tol < r else math.pi / 2
    n = max(1, math.ceil(abs(dt) / max(step, 1e-9)))
    if n > MAX_POINTS:
        raise PathDataError(f"over {MAX_POINTS} points from one arc (raise --flatten-curves)")
    ts = t0 + dt * np.arange(1, n + 1) / n
    xs, ys = rx * np.cos(ts), ry * np.sin(ts)
    pts = np.column_stack((c * xs - s * ys + cx, s * xs + c * ys + cy))
    pts[-1] = p1
    return list(pts)


def parse_transform(text: str) -> np.ndarray:
    """A ``transform`` attribute as a 3 x 3 matrix (the list's first transform applied last,
    as SVG composes them).

    >>> parse_transform("translate(1, 2) scale(2)").tolist()
    [[2.0, 0.0, 1.0], [0.0, 2.0, 2.0], [0.0, 0.0, 1.0]]
    >>> parse_transform("matrix(1,0,0,1,5,6) rotate(90)").round(12).tolist()
    [[0.0, -1.0, 5.0], [1.0, 0.0, 6.0], [0.0, 0.0, 1.0]]
    """
    out, pos = np.eye(3), 0
    while pos < len(text) and text[pos:].strip():
        m = _TRANSFORM.match(text, pos)
        if m is None:
            raise PathDataError(f"transform {text[pos:pos + 24].strip()!r}: expected matrix, translate, scale, "
                                "rotate, skewX or skewY (...)")
        pos = m.end()
        args = [t for t in tokens(m.group(2)) if not isinstance(t, str)]
        if len(args) != len(tokens(m.group(2))):
            raise PathDataError(f"transform {m.group(0).strip()[:40]!r}: only numbers in the parentheses")
        out = out @ _one_transform(m.group(1), args)
    if not np.isfinite(out).all():
        raise PathDataError(f"transform {text[:40]!r} overflows")
    return out


def _one_transform(name: str, a: list) -> np.ndarray:
    counts = {"matrix": (6,), "translate": (1, 2), "scale": (1, 2), "rotate": (1, 3), "skewX": (1,), "skewY": (1,)}
    if len(a) not in counts[name]:
        raise PathDataError(f"{name}(...) takes {' or '.join(map(str, counts[name]))} numbers, got {len(a)}")
    m = np.eye(3)
    if name == "matrix":
        m[0], m[1] = (a[0], a[2], a[4]), (a[1], a[3], a[5])
    elif name == "translate":
        m[0, 2], m[1, 2] = a[0], (a[1] if len(a) > 1 else 0.0)
    elif name == "scale":
        m[0, 0], m[1, 1] = a[0], (a[1] if len(a) > 1 else a[0])
    elif name == "rotate":
        c, s = _cos_sin_degrees(a[0])
        m[:2, :2] = ((c, -s), (s, c))
        if len(a) == 3:  # about (cx, cy): translate(cx, cy) rotate(a) translate(-cx, -cy)
            t = np.eye(3)
            t[:2, 2] = a[1], a[2]
            back = np.eye(3)
            back[:2, 2] = -a[1], -a[2]
            m = t @ m @ back
    else:
        v = math.tan(math.radians(a[0]))
        m[0 if name == "skewX" else 1, 1 if name == "skewX" else 0] = v
    return m


def _cos_sin_degrees(deg: float) -> tuple[float, float]:
    """cos and sin of an angle in degrees, exact at the multiples of 90 (a quarter turn of a
    drawing keeps its axis-parallel edges parallel)."""
    q, r = divmod(deg, 90.0)
    if r == 0:
        return [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][int(q) % 4]
    return math.cos(math.radians(deg)), math.sin(math.radians(deg))


def apply(matrix: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Points (N, 2) mapped by a 3 x 3 affine matrix.

    >>> apply(parse_transform("translate(1,2)"), np.array([[0.0, 0.0]])).tolist()
    [[1.0, 2.0]]
    """
    return pts @ matrix[:2, :2].T + matrix[:2, 2]
