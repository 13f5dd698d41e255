"""The six Dubins words (forward-only car, Dubins 1957) in the normalized frame.

A car that only drives forward with turning radius 1 goes from pose 0 to pose 1 by the shortest
of at most six words: LSL, RSR, RSL, LSR (two arcs joined by a common tangent) and RLR, LRL (three
arcs, the middle one longer than a half turn). Everything here is in the frame of Shkel and
Lumelsky (2001): the radius is 1, pose 0 sits at the origin, pose 1 at (d, 0) on the x axis, and
the two headings are measured from that axis, α at the start, β at the goal, both in [0, 2π).

A left turn of heading h has its centre at the car's position + (−sin h, cos h) (one radius to
the left); a right turn at position + (sin h, −cos h). A word is (t, p, q): the first arc's turn,
the middle part (a straight's length or an arc's turn), the last arc's turn, all >= 0, and its
length is t + p + q (turns in radians are arc lengths at radius 1).

The choice copies OMPL's ``DubinsStateSpace`` (not symmetric): its snapping of angles within
1e-7 of a full turn to 0, its near-coincident rule, and its order of preference on exact ties
(LSL, RSR, RSL, LSR, RLR, LRL; a later word must be strictly shorter to win). OMPL switches, for
far-apart poses, to the Shkel–Lumelsky classification, which evaluates only the CSC word it
predicts; it predicts the shortest, so the answers agree except where two words tie in length.
"""
from __future__ import annotations

import math

from ..compiled import motions

TWO_PI = 2.0 * math.pi
# OMPL's tolerances: a turn in (−1e-7, 0) or within 0.5e-6 of 2π is a rounding of "no turn";
# poses closer than 1e-6 radii with headings within 1e-6 are joined by one straight step.
SNAP_BELOW = 1e-7
SNAP_FULL = 0.5e-6
NEAR = 1e-6

WORDS = ("LSL", "RSR", "RSL", "LSR", "RLR", "LRL")


def turn_angle(x: float) -> float:
    """x reduced to a turn in [0, 2π), with tiny roundings of a zero or full turn read as 0.

    >>> turn_angle(-1e-9), turn_angle(TWO_PI - 1e-8), round(turn_angle(-math.pi / 2), 12)
    (0.0, 0.0, 4.712388980385)
    """
    if -SNAP_BELOW < x < 0.0:
        return 0.0
    m = x - TWO_PI * math.floor(x / TWO_PI)
    return 0.0 if TWO_PI - m < SNAP_FULL else m


def _lsl(d: float, a: float, b: float) -> tuple[float, float, float] | None:
    # Left circles at c0 = (−sin α, cos α) and c1 = (d − sin β, cos β): the outer tangent runs
    # parallel to c1 − c0, so the straight is |c1 − c0| long and heads along c1 − c0.
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    p2 = 2.0 + d * d - 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sa - sb)
    if p2 < -SNAP_BELOW:
        return None
    psi = math.atan2(cb - ca, d + sa - sb)
    return turn_angle(psi - a), math.sqrt(max(p2, 0.0)), turn_angle(b - psi)


def _rsr(d: float, a: float, b: float) -> tuple[float, float, float] | None:
    # Right circles at c0 = (sin α, −cos α) and c1 = (d + sin β, −cos β); mirror of LSL.
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    p2 = 2.0 + d * d - 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sb - sa)
    if p2 < -SNAP_BELOW:
        return None
    psi = math.atan2(ca - cb, d - sa + sb)
    return turn_angle(a - psi), math.sqrt(max(p2, 0.0)), turn_angle(psi - b)


def _rsl(d: float, a: float, b: float) -> tuple[float, float, float] | None:
    # Right circle c0 = (sin α, −cos α), left circle c1 = (d − sin β, cos β): an inner tangent.
    # With u the straight's direction and n its left normal, the tangent points are c0 + n and
    # c1 − n, so c1 − c0 = p·u + 2n: |c1 − c0|² = p² + 4, and c1 − c0 leads u by atan2(2, p).
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    p2 = d * d - 2.0 + 2.0 * (ca * cb + sa * sb) - 2.0 * d * (sa + sb)
    if p2 < -SNAP_BELOW:
        return None
    p = math.sqrt(max(p2, 0.0))
    psi = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
    return turn_angle(a - psi), p, turn_angle(b - psi)


def _lsr(d: float, a: float, b: float) -> tuple[float, float, float] | None:
    # Left circle c0 = (−sin α, cos α), right circle c1 = (d + sin β, −cos β): the tangent points
    # are c0 − n and c1 + n, so c1 − c0 = p·u − 2n and c1 − c0 trails u by atan2(2, p).
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    p2 = d * d - 2.0 + 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sa + sb)
    if p2 < -SNAP_BELOW:
        return None
    p = math.sqrt(max(p2, 0.0))
    psi = math.atan2(-ca - cb, d + sa + sb) + math.atan2(2.0, p)
    return turn_angle(psi - a), p, turn_angle(psi - b)


def _rlr(d: float, a: float, b: float) -> tuple[float, float, float] | None:
    # Right circles c0, c2 a distance D apart (D < 4); the middle left circle c1 touches both,
    # so c0 c1 c2 is isosceles with sides 2, 2, D and apex angle γ = acos(1 − D²/8). The middle
    # arc turns the long way round, 2π − γ; c1 sits at angle ψ − (π/2 − γ/2) seen from c0, ψ the
    # direction of c2 − c0, which fixes the first turn.
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    c = (6.0 - d * d + 2.0 * (ca * cb + sa * sb) + 2.0 * d * (sa - sb)) / 8.0
    if not abs(c) < 1.0:
        return None
    p = TWO_PI - math.acos(c)
    psi = math.atan2(ca - cb, d - sa + sb)
    t = turn_angle(a - psi + 0.5 * p)
    return t, p, turn_angle(a - b - t + p)


def _lrl(d: float, a: float, b: float) -> tuple[float, float, float] | None:
    # Mirror of RLR: left circles at both ends, a right circle between them.
    sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
    c = (6.0 - d * d + 2.0 * (ca * cb + sa * sb) - 2.0 * d * (sa - sb)) / 8.0
    if not abs(c) < 1.0:
        return None
    p = TWO_PI - math.acos(c)
    psi = math.atan2(cb - ca, d + sa - sb)
    t = turn_angle(psi - a + 0.5 * p)
    return t, p, turn_angle(b - a - t + p)


_SOLVERS = (_lsl, _rsr, _rsl, _lsr, _rlr, _lrl)


def dubins_frame(q0, q1, radius: float) -> tuple[float, float, float]:
    """(d, α, β): the distance in radii and the two headings measured from the line q0 -> q1.

    >>> dubins_frame((0.0, 0.0, 0.0), (0.0, 2.0, 0.0), 2.0) == (1.0, 1.5 * math.pi, 1.5 * math.pi)
    True
    """
    dx, dy = q1[0] - q0[0], q1[1] - q0[1]
    th = math.atan2(dy, dx)
    return math.sqrt(dx * dx + dy * dy) / radius, turn_angle(q0[2] - th), turn_angle(q1[2] - th)


def dubins_candidates(d: float, alpha: float, beta: float) -> list[tuple[str, tuple[float, float, float]]]:
    """Every Dubins word that exists for (d, α, β), in OMPL's order of preference.

    >>> [w for w, _ in dubins_candidates(4.0, 0.0, 0.0)]
    ['LSL', 'RSR', 'RSL', 'LSR']
    """
    out = []
    for word, solve in zip(WORDS, _SOLVERS):
        tpq = solve(d, alpha, beta)
        if tpq is not None:
            out.append((word, tpq))
    return out


def dubins_word(d: float, alpha: float, beta: float) -> tuple[str, tuple[float, float, float]]:
    """The shortest Dubins word for (d, α, β) in the normalized frame, as OMPL picks it.

    >>> dubins_word(4.0, 0.0, 0.0)
    ('LSL', (0.0, 4.0, 0.0))
    """
    got = motions.dubins_word(d, alpha, beta)  # compiled: the same word, the same doubles
    return got if got is not None else dubins_word_pure(d, alpha, beta)


def dubins_word_pure(d: float, alpha: float, beta: float) -> tuple[str, tuple[float, float, float]]:
    """:func:`dubins_word` in Python (the oracle of the compiled one).

    >>> dubins_word_pure(4.0, 0.0, 0.0)
    ('LSL', (0.0, 4.0, 0.0))
    """
    if d < NEAR and abs(alpha - beta) < NEAR:
        # OMPL's rule for (almost) the same pose: one straight step along the heading.
        return "LSL", (0.0, d, 0.0)
    best = None
    for word, tpq in dubins_candidates(d, alpha, beta):
        if best is None or sum(tpq) < sum(best[1]):
            best = (word, tpq)
    assert best is not None  # LSL and RSR always exist: p² is a squared distance
    return best
