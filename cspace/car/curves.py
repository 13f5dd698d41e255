"""Car curves as segments: the shortest Dubins / Reeds–Shepp path between two poses, and poses on it.

A car-like robot moves its reference point along straights and arcs of the turning radius r.
A curve is a list of segments ``(kind, length)``: kind "L" (turn left, the centre one radius to
the left of the car), "S" (straight) or "R" (turn right); length is the arc length the reference
point travels, in world units, signed (< 0: driving in reverse; Reeds–Shepp only). Along an arc
of length s the heading turns by s / r (left: +, right: −), so a reverse left arc turns the
heading clockwise while the centre stays on the car's left.

The words themselves come from :mod:`cspace.car.dubins` and :mod:`cspace.car.reeds_shepp`, which work
in units of the radius; this module scales, walks and interpolates them exactly as OMPL's
``DubinsStateSpace`` / ``ReedsSheppStateSpace::interpolate`` do (relative coordinates in radii,
scaled and added to the start at the end), so poses agree with OMPL's to rounding.

Two things to know when certifying these curves:

- Ties: where two words have exactly the same length (a Dubins goal straight behind the start:
  LSL or RSR), OMPL may drive the other one. Poses along a motion must therefore come from
  :func:`pose_along` / :func:`knots` on these segments, never from OMPL's ``interpolate``.
- Dubins between poses closer than about 1e-3 radii: OMPL's tolerances (a squared tangent length
  down to −1e-7 read as 0, a turn within 0.5e-6 of a full one read as none, a single straight
  step along the heading for poses under 1e-6 radii apart) leave its curve, and ours, up to
  2e-6 radii and 1e-6 rad short of q1; OMPL's ``interpolate`` then jumps to q1 at t = 1. The
  end of :func:`knots` is the curve's true end, to be compared with q1. Reeds–Shepp curves end
  at q1 to rounding.
"""
from __future__ import annotations

import math

from .dubins import dubins_frame, dubins_word
from .reeds_shepp import reeds_shepp_frame, reeds_shepp_word
from ..kernel.polygons.rotation import wrap_angle

Segment = tuple[str, float]
Pose = tuple[float, float, float]


def _pose(q, name: str) -> Pose:
    if type(q) is tuple and len(q) == 3:  # the usual call: three finite floats, returned as they are
        x, y, th = q
        if type(x) is float and type(y) is float and type(th) is float and x - x == y - y == th - th == 0.0:
            return q
    try:
        x, y, th = (float(v) for v in q)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: a pose is three numbers (x, y, theta)") from None
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(th)):
        raise ValueError(f"{name}: a pose must be finite")
    return x, y, th


# Headings beyond this magnitude are wrapped (exactly: fmod) before a curve is computed; the
# words' own reductions lose the heading's digits there (a goal heading of 1e17 read as 0).
WRAP_ABOVE = 2.0**20


def _wrapped(q: Pose) -> Pose:
    return q if abs(q[2]) <= WRAP_ABOVE else (q[0], q[1], wrap_angle(q[2]))


# A turning radius lies in the magnitudes a scene may have (cspace.io.scenario.schema's MIN_EXTENT and
# MAX_MAGNITUDE): a subnormal radius would scale every length of the curve to 0.
RADIUS_LIMITS = (2.0**-400, 2.0**400)


def _radius(radius) -> float:
    r = float(radius)
    if not (math.isfinite(r) and r > 0.0):
        raise ValueError("radius: the turning radius must be finite and positive")
    if not RADIUS_LIMITS[0] <= r <= RADIUS_LIMITS[1]:
        raise ValueError(f"radius: the turning radius must lie in [2^-400, 2^400], got {r!r}")
    return r


# The poses of a curve are at most this many turning radii apart (far beyond any scene:
# the words' arithmetic overflows near 1e300 radii).
MAX_RADII = 1e100


def _frame(frame: tuple[float, float, float]) -> tuple[float, float, float]:
    x, y = frame[0], frame[1]
    if not (abs(x) <= MAX_RADII and abs(y) <= MAX_RADII):  # NaN fails the comparison, as inf exceeds it
        raise ValueError(f"radius: the poses are more than {MAX_RADII:g} turning radii apart (the radius is too "
                         "small for them)")
    return frame


def _segments(word: str, lengths, r: float) -> list[Segment]:
    # Scale radii to world units; a segment of exactly zero length is dropped.
    out = [(k, float(v) * r) for k, v in zip(word, lengths) if v != 0.0]
    if not all(v - v == 0.0 for _, v in out):  # finite (inf - inf and NaN are NaN)
        raise ValueError("radius: the turning radius is too large (a segment's length overflows)")
    return out


def dubins_segments(q0, q1, radius: float) -> list[Segment]:
    """The shortest forward-only (Dubins) curve from pose q0 to q1, as OMPL's DubinsStateSpace picks it.

    >>> dubins_segments((0.0, 0.0, 0.0), (4.0, 0.0, 0.0), 1.0)
    [('S', 4.0)]
    >>> [k for k, _ in dubins_segments((0.0, 0.0, 0.0), (0.0, 0.0, math.pi), 1.0)]
    ['R', 'L', 'R']
    """
    q0, q1, r = _pose(q0, "q0"), _pose(q1, "q1"), _radius(radius)
    word, lengths = dubins_word(*_frame(dubins_frame(_wrapped(q0), _wrapped(q1), r)))
    return _segments(word, lengths, r)


def reeds_shepp_segments(q0, q1, radius: float) -> list[Segment]:
    """The shortest forward-and-reverse (Reeds–Shepp) curve from q0 to q1, as OMPL's ReedsSheppStateSpace.

    >>> reeds_shepp_segments((0.0, 0.0, 0.0), (-4.0, 0.0, 0.0), 1.0)
    [('S', -4.0)]
    >>> [(k, round(v, 6)) for k, v in reeds_shepp_segments((0.0, 0.0, 0.0), (0.0, 0.0, math.pi), 1.0)]
    [('L', 1.047198), ('R', -1.047198), ('L', 1.047198)]
    """
    q0, q1, r = _pose(q0, "q0"), _pose(q1, "q1"), _radius(radius)
    word, lengths = reeds_shepp_word(*_frame(reeds_shepp_frame(_wrapped(q0), _wrapped(q1), r)))
    return _segments(word, lengths, r)


def curve_length(segments) -> float:
    """Total distance driven along the curve: the sum of |length|.

    >>> curve_length([("L", 1.5), ("S", -2.0)])
    3.5
    """
    return float(sum(abs(v) for _, v in segments))


def _step(x: float, y: float, th: float, kind: str, v: float) -> Pose:
    # One segment at radius 1 from (x, y, th), v signed. A left arc keeps the point at distance 1
    # from the centre (x − sin th, y + cos th) and turns th to th + v; a right arc uses the centre
    # (x + sin th, y − cos th) and turns th to th − v.
    if kind == "L":
        return x + math.sin(th + v) - math.sin(th), y - math.cos(th + v) + math.cos(th), th + v
    if kind == "R":
        return x - math.sin(th - v) + math.sin(th), y + math.cos(th - v) - math.cos(th), th - v
    if kind == "S":
        return x + v * math.cos(th), y + v * math.sin(th), th
    raise ValueError(f"kind: a segment is 'L', 'S' or 'R', not {kind!r}")


def advance(pose, kind: str, length: float, radius: float) -> Pose:
    """The pose after driving one segment (signed length, world units) from pose; heading not wrapped.

    >>> x, y, th = advance((0.0, 0.0, 0.0), "L", math.pi / 2, 1.0)
    >>> round(x, 12), round(y, 12), round(th, 12)
    (1.0, 1.0, 1.570796326795)
    >>> advance((1.0, 2.0, 0.0), "S", -3.0, 5.0)
    (-2.0, 2.0, 0.0)
    """
    x, y, th = _pose(pose, "pose")
    r = _radius(radius)
    dx, dy, th1 = _step(0.0, 0.0, th, kind, float(length) / r)
    return x + dx * r, y + dy * r, th1


def turning_centre(pose, kind: str, radius: float) -> tuple[float, float]:
    """The centre of the turn of an "L" (one radius to the left) or "R" (to the right) from pose.

    >>> turning_centre((1.0, 1.0, 0.0), "L", 2.0), turning_centre((1.0, 1.0, 0.0), "R", 2.0)
    ((1.0, 3.0), (1.0, -1.0))
    """
    x, y, th = _pose(pose, "pose")
    r = _radius(radius)
    if kind == "L":
        return x - r * math.sin(th), y + r * math.cos(th)
    if kind == "R":
        return x + r * math.sin(th), y - r * math.cos(th)
    raise ValueError(f"kind: only an 'L' or 'R' segment turns about a centre, not {kind!r}")


def _walk(q0: Pose, segments, r: float, budget: float | None) -> list[Pose]:
    # OMPL's interpolation: relative coordinates in radii from (0, 0, θ0), each segment cut to
    # what remains of the budget (all of it when budget is None), scaled and moved to q0 last.
    x, y, th = 0.0, 0.0, q0[2]
    out = [q0]
    seg = budget
    for kind, length in segments:
        if seg is not None and not seg > 0.0:
            break
        v = float(length) / r
        if seg is not None:
            v = max(-seg, v) if v < 0.0 else min(seg, v)
            seg -= abs(v)
        x, y, th = _step(x, y, th, kind, v)
        out.append((x * r + q0[0], y * r + q0[1], th))
    return out


def knots(q0, segments, radius: float) -> list[Pose]:
    """The poses at the segment boundaries: q0, then the end of each segment (headings not wrapped).

    >>> [tuple(round(v, 9) for v in k) for k in knots((0.0, 0.0, 0.0), [("S", 1.0), ("L", math.pi)], 1.0)]
    [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 2.0, 3.141592654)]
    """
    return _walk(_pose(q0, "q0"), segments, _radius(radius), None)


def pose_along(q0, segments, radius: float, t: float) -> Pose:
    """The pose at fraction t of the curve's length, as OMPL's interpolate computes it (θ in [−π, π)).

    t <= 0 gives q0 and t >= 1 the end of the curve, both with θ wrapped like the rest; OMPL
    returns its two input states unchanged there.

    >>> pose_along((0.0, 0.0, 0.0), [("S", 2.0), ("L", math.pi)], 1.0, 2.0 / (2.0 + math.pi))
    (2.0, 0.0, 0.0)
    >>> x, y, th = pose_along((0.0, 0.0, 0.0), [("S", 2.0), ("L", math.pi)], 1.0, 1.0)
    >>> round(x, 9), round(y, 9), th
    (2.0, 2.0, -3.141592653589793)
    """
    q0, r, t = _pose(q0, "q0"), _radius(radius), float(t)
    if not math.isfinite(t):
        raise ValueError("t: the fraction must be finite")
    total = sum(abs(float(v)) for _, v in segments) / r
    if t <= 0.0:
        x, y, th = q0
    else:
        x, y, th = _walk(q0, segments, r, total * min(t, 1.0))[-1]
    return x, y, wrap_angle(th)
