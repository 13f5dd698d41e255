"""Input checks of the SE(2) C-space's public queries and construction.

:class:`cspace.se2.cspace.SE2CSpace`'s ``is_free`` and ``motion_free`` (and a car's ``curve_free``) take
poses ``(x, y, theta)``: three finite real numbers (a string, a wrong length or a nested
sequence is a TypeError or ValueError naming the argument, never an IndexError or a silent
False), as the translation C-space's :func:`cspace.translation.inputs.query_points` refuses
non-finite points. A car curve's segments are bounded so that checking one is bounded work.

>>> se2_pose((1, 2.5, 0), "q")
(1.0, 2.5, 0.0)
>>> se2_pose((1, float("nan"), 0), "q")
Traceback (most recent call last):
ValueError: q: a pose must be finite, got (1.0, nan, 0.0)
>>> se2_pose("abc", "q")
Traceback (most recent call last):
TypeError: q: a pose is three numbers (x, y, theta), got 'abc'
"""
from __future__ import annotations

import itertools
import math
import numbers

import numpy as np

# A segment of a car curve is at most this many scene extents long, and an arc turns at
# most this many full turns: anything longer is refused (ValueError) before any work.
MAX_SEGMENT_EXTENTS = 1e6
MAX_ARC_TURNS = 64
# The turning radius of curve_free: within these factors of the scene's extent (as a
# scenario's turning_radius, cspace.io.scenario.schema.TURNING_RADIUS_RANGE).
RADIUS_RANGE = (1e-9, 1e9)


def _real(v, what: str, expect: str = "a pose is three numbers (x, y, theta)") -> float:
    """A real number as a float (an int beyond the doubles: inf), else a TypeError."""
    if isinstance(v, (str, bytes)) or not isinstance(v, (numbers.Real, np.number)) or isinstance(v, np.complexfloating):
        raise TypeError(f"{what}: {expect}, got {_show(v)}")
    try:
        return float(v)
    except OverflowError:  # an int beyond the doubles: refused as a non-finite number is
        return math.inf if v > 0 else -math.inf


def _show(v) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def se2_pose(q, what: str) -> tuple[float, float, float]:
    """``q`` as three finite floats (x, y, theta), else a TypeError (not three numbers) or a
    ValueError (a non-finite number or a wrong length) naming ``what``."""
    if type(q) is tuple and len(q) == 3:  # the usual call: three finite floats, checked fast
        x, y, th = q
        if type(x) is float and type(y) is float and type(th) is float and x - x == y - y == th - th == 0.0:
            return q
    return _slow_pose(q, what)


def _slow_pose(q, what: str) -> tuple[float, float, float]:
    if isinstance(q, (str, bytes)) or isinstance(q, dict):
        raise TypeError(f"{what}: a pose is three numbers (x, y, theta), got {_show(q)}")
    if isinstance(q, np.ndarray):
        if q.shape != (3,):
            raise ValueError(f"{what}: a pose is three numbers (x, y, theta), got an array of shape {q.shape}")
        items = q.tolist()
    else:
        try:
            items = list(itertools.islice(iter(q), 4))  # never more: an endless iterable is refused too
        except TypeError:
            raise TypeError(f"{what}: a pose is three numbers (x, y, theta), got {_show(q)}") from None
        if len(items) != 3:
            raise ValueError(f"{what}: a pose is three numbers (x, y, theta), got {'more' if len(items) > 3 else len(items)}")
    x, y, th = (_real(v, what) for v in items)
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(th)):
        raise ValueError(f"{what}: a pose must be finite, got {(x, y, th)}")
    return x, y, th


def check_robot(robot) -> None:
    """Each robot part of an SE(2) C-space: at least 3 points (a polygon)."""
    for i, part in enumerate(robot or []):
        shape = np.shape(part)
        if len(shape) != 2 or shape[1] != 2 or shape[0] < 3:
            raise ValueError(f"robot[{i}]: a robot part is a polygon of at least 3 (x, y) points, got shape {shape}")


def check_pieces(pieces: list, limit: int) -> None:
    """The robot's convex pieces (grown by the margin) have at most ``limit`` vertices."""
    for i, p in enumerate(pieces):
        if len(p) > limit:
            raise ValueError(f"robot: a convex piece of {len(p)} vertices (with the margin); a rotating robot's "
                             f"pieces have at most {limit} (the slab build is quadratic in them)")


def curve_radius(radius, extent: float) -> float:
    """The turning radius of a curve check: a real number within :data:`RADIUS_RANGE` x extent."""
    lo, hi = RADIUS_RANGE[0] * extent, RADIUS_RANGE[1] * extent
    if type(radius) is float and lo <= radius <= hi:  # the usual call (NaN fails the comparison)
        return radius
    if isinstance(radius, bool):
        raise TypeError(f"radius: the turning radius is a number, got {radius!r}")
    r = _real(radius, "radius", "the turning radius is a number")
    if not lo <= r <= hi:
        raise ValueError(f"radius: the turning radius must lie in [{lo:.3g}, {hi:.3g}] (1e-9 to 1e9 times the "
                         f"scene's extent), got {r!r}")
    return r


def curve_segments(segments, radius: float, extent: float) -> list[tuple[str, float]]:
    """The segments as (kind, float length) pairs: kind "L", "S" or "R", the length finite, at
    most :data:`MAX_SEGMENT_EXTENTS` extents, an arc at most :data:`MAX_ARC_TURNS` turns."""
    if type(segments) is list:  # the usual call (a car's curve from car_curves): checked fast
        fast = _segments_fast(segments, radius, extent)
        if fast is not None:
            return fast
    if isinstance(segments, (str, bytes, dict)):
        raise TypeError(f"segments: a list of (kind, length) pairs, got {_show(segments)}")
    try:
        items = list(segments)
    except TypeError:
        raise TypeError(f"segments: a list of (kind, length) pairs, got {_show(segments)}") from None
    out = []
    longest = MAX_SEGMENT_EXTENTS * extent
    for i, seg in enumerate(items):
        if isinstance(seg, (str, bytes)):
            raise TypeError(f"segments[{i}]: a (kind, length) pair, got {_show(seg)}")
        try:
            kind, length = seg
        except (TypeError, ValueError):
            raise TypeError(f"segments[{i}]: a (kind, length) pair, got {_show(seg)}") from None
        if kind not in ("L", "S", "R") or not isinstance(kind, str):
            raise ValueError(f"segments[{i}]: the kind is 'L', 'S' or 'R', got {_show(kind)}")
        v = _real(length, f"segments[{i}]", "a segment's length is a number")
        if not math.isfinite(v) or abs(v) > longest:
            raise ValueError(f"segments[{i}]: the length must be finite and at most {longest:.3g} "
                             f"({MAX_SEGMENT_EXTENTS:g} times the scene's extent), got {v!r}")
        if kind != "S" and abs(v) > MAX_ARC_TURNS * 2.0 * math.pi * radius:
            raise ValueError(f"segments[{i}]: an arc turns at most {MAX_ARC_TURNS} full turns, got "
                             f"{abs(v) / radius / (2 * math.pi):.3g}")
        out.append((kind, v))
    return out


def _segments_fast(segments: list, radius: float, extent: float) -> list[tuple[str, float]] | None:
    """:func:`curve_segments` for a list of (kind, float) tuples that pass its every bound (the
    same tests, without the type dispatch), else None: the full check decides and words the error."""
    longest = MAX_SEGMENT_EXTENTS * extent
    turns = MAX_ARC_TURNS * 2.0 * math.pi * radius
    for seg in segments:
        if type(seg) is not tuple or len(seg) != 2:
            return None
        kind, v = seg
        if type(v) is not float or not abs(v) <= longest:  # NaN fails the comparison; inf exceeds it
            return None
        if type(kind) is not str or (kind != "S" and (kind not in ("L", "R") or abs(v) > turns)):
            return None
    return list(segments)
