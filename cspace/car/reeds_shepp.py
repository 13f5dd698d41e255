"""The Reeds–Shepp families (car driving forward and reverse, Reeds & Shepp 1990) in radius units.

The start is the origin with heading 0, the goal (x, y, φ) in the start's frame, the turning
radius 1. Reeds and Shepp proved that a shortest path is one of 48 words of at most five
segments; their section 8 gives each family in closed form for one "base" word: L+S+L+ (8.1),
L+S+R+ (8.2), L+R−L (8.3/8.4), L+R+L−R− (8.7), L+R−L−R+ (8.8), L+R−S−L− (8.9),
L+R−S−R− (8.10) and L+R−S−L−R+ (8.11) (signs: forward +, reverse −). The other words follow
by symmetry:

- time flip: driving the word in reverse ((x, y, φ) -> (−x, y, −φ)) negates every length;
- reflection across the x axis ((x, y, φ) -> (x, −y, −φ)) swaps L and R;
- backwards: the same path read from the goal back to the start, time-flipped, solves
  (x cos φ + y sin φ, x sin φ − y cos φ, φ) with the segments in reverse order.

A solution is (t, u, v) (turns in radians, straights in radii; signs give the direction); the
fixed quarter turns of the CCSC and CCSCC families are ±π/2. The choice copies OMPL's
``ReedsSheppStateSpace``: the same candidates (the paper's formulas, 8.3 and 8.11 in the form
OMPL corrects them to), the same admissibility tolerance, the same order, and its comparison
(a later candidate replaces the best only when strictly shorter).
"""
from __future__ import annotations

import math

from ..compiled import motions

PI = math.pi
TWO_PI = 2.0 * PI
HALF_PI = 0.5 * PI
# A length counts as having the required sign when it is within a few roundings of it.
ZERO = 10.0 * 2.220446049250313e-16


def angle_pi(x: float) -> float:
    """x reduced into [−π, π] by whole turns (fmod, then one turn added or taken).

    >>> round(angle_pi(3 * math.pi / 2), 12), angle_pi(0.5)
    (-1.570796326795, 0.5)
    """
    v = math.fmod(x, TWO_PI)
    if v < -PI:
        v += TWO_PI
    elif v > PI:
        v -= TWO_PI
    return v


def _polar(x: float, y: float) -> tuple[float, float]:
    return math.sqrt(x * x + y * y), math.atan2(y, x)


def _lsl(x, y, phi):
    # 8.1 L+S+L+: the straight joins the start's left centre (0, 1) to the goal's left centre
    # (x − sin φ, y + cos φ), parallel to it: u its length, t its direction.
    u, t = _polar(x - math.sin(phi), y - 1.0 + math.cos(phi))
    if t >= -ZERO:
        v = angle_pi(phi - t)
        if v >= -ZERO:
            return t, u, v
    return None


def _lsr(x, y, phi):
    # 8.2 L+S+R+: inner tangent between the left centre (0, 1) and the goal's right centre
    # (x + sin φ, y − 1 − cos φ relative to it); the centres are sqrt(u² + 4) apart.
    d, t1 = _polar(x + math.sin(phi), y - 1.0 - math.cos(phi))
    d2 = d * d
    if d2 < 4.0:
        return None
    u = math.sqrt(d2 - 4.0)
    t = angle_pi(t1 + math.atan2(2.0, u))
    v = angle_pi(t - phi)
    return (t, u, v) if t >= -ZERO and v >= -ZERO else None


def _lrl(x, y, phi):
    # 8.3/8.4 L+R−L: the first and last left circles are ρ <= 4 apart and the middle right
    # circle touches both: the middle turn is u = −2 asin(ρ / 4).
    rho, theta = _polar(x - math.sin(phi), y - 1.0 + math.cos(phi))
    if rho > 4.0:
        return None
    u = -2.0 * math.asin(0.25 * rho)
    t = angle_pi(theta + 0.5 * u + PI)
    v = angle_pi(phi - t + u)
    return (t, u, v) if t >= -ZERO and u <= ZERO else None


def _tau_omega(u, v, xi, eta, phi):
    # The first and last turns of a CCCC word whose middle turns are u and v, given the goal's
    # circle centre (ξ, η) relative to the start's: solve the two position equations for τ
    # (atan2 gives it up to a half turn; the sign of t2 picks the branch that closes the
    # chain), then the heading equation gives ω.
    delta = angle_pi(u - v)
    a = math.sin(u) - math.sin(delta)
    b = math.cos(u) - math.cos(delta) - 1.0
    t1 = math.atan2(eta * a - xi * b, xi * a + eta * b)
    t2 = 2.0 * (math.cos(delta) - math.cos(v) - math.cos(u)) + 3.0
    tau = angle_pi(t1 + PI) if t2 < 0.0 else angle_pi(t1)
    return tau, angle_pi(tau - u + v - phi)


def _lrlr_a(x, y, phi):
    # 8.7 L+R+L−R−: the two middle turns have the same size u; the start's left centre and
    # the goal's right centre are then 4 cos u − 2 apart, which gives u = acos((2 + ρ) / 4).
    xi, eta = x + math.sin(phi), y - 1.0 - math.cos(phi)
    rho = 0.25 * (2.0 + math.sqrt(xi * xi + eta * eta))
    if rho > 1.0:
        return None
    u = math.acos(rho)
    t, v = _tau_omega(u, -u, xi, eta, phi)
    return (t, u, v) if t >= -ZERO and v <= ZERO else None


def _lrlr_b(x, y, phi):
    # 8.8 L+R−L−R+: the two middle (reverse) turns are equal, u in [−π/2, 0].
    xi, eta = x + math.sin(phi), y - 1.0 - math.cos(phi)
    rho = (20.0 - xi * xi - eta * eta) / 16.0
    if not 0.0 <= rho <= 1.0:
        return None
    u = -math.acos(rho)
    if u < -HALF_PI:
        return None
    t, v = _tau_omega(u, u, xi, eta, phi)
    return (t, u, v) if t >= -ZERO and v >= -ZERO else None


def _lrsl(x, y, phi):
    # 8.9 L+R−(π/2) S− L−: with ρ the distance between the start's and the goal's left centres,
    # the reverse straight is sqrt(ρ² − 4) − 2 long (u = 2 − sqrt(ρ² − 4) <= 0).
    rho, theta = _polar(x - math.sin(phi), y - 1.0 + math.cos(phi))
    if rho < 2.0:
        return None
    r = math.sqrt(rho * rho - 4.0)
    u = 2.0 - r
    t = angle_pi(theta + math.atan2(r, -2.0))
    v = angle_pi(phi - HALF_PI - t)
    return (t, u, v) if t >= -ZERO and u <= ZERO and v <= ZERO else None


def _lrsr(x, y, phi):
    # 8.10 L+R−(π/2) S− R−: the straight runs between the start's left circle and the goal's
    # right circle along the direction the quarter turn leaves the car in.
    rho, t = _polar(-(y - 1.0 - math.cos(phi)), x + math.sin(phi))
    if rho < 2.0:
        return None
    u = 2.0 - rho
    v = angle_pi(t + HALF_PI - phi)
    return (t, u, v) if t >= -ZERO and u <= ZERO and v <= ZERO else None


def _lrslr(x, y, phi):
    # 8.11 L+R−(π/2) S− L−(π/2) R+: two quarter turns around a reverse straight.
    xi, eta = x + math.sin(phi), y - 1.0 - math.cos(phi)
    rho, _ = _polar(xi, eta)
    if rho < 2.0:
        return None
    u = 4.0 - math.sqrt(rho * rho - 4.0)
    if u > ZERO:
        return None
    t = angle_pi(math.atan2((4.0 - u) * xi - 2.0 * eta, -2.0 * xi + (u - 4.0) * eta))
    v = angle_pi(t - phi)
    return (t, u, v) if t >= -ZERO and v >= -ZERO else None


# The candidates in OMPL's order, by group: (quarter turns fixed in the word, [(formula, base
# word, segment lengths from (t, u, v), solved for the backwards problem)]). A candidate's cost
# is that of its free turns and straight, |t| + |u| + |v| (CCCC: |t| + 2|u| + |v|).
GROUPS = (
    (0.0, ((_lsl, "LSL", lambda t, u, v: (t, u, v), False),
           (_lsr, "LSR", lambda t, u, v: (t, u, v), False))),
    (0.0, ((_lrl, "LRL", lambda t, u, v: (t, u, v), False),
           (_lrl, "LRL", lambda t, u, v: (v, u, t), True))),
    (0.0, ((_lrlr_a, "LRLR", lambda t, u, v: (t, u, -u, v), False),
           (_lrlr_b, "LRLR", lambda t, u, v: (t, u, u, v), False))),
    (HALF_PI, ((_lrsl, "LRSL", lambda t, u, v: (t, -HALF_PI, u, v), False),
               (_lrsr, "LRSR", lambda t, u, v: (t, -HALF_PI, u, v), False),
               (_lrsl, "LSRL", lambda t, u, v: (v, u, -HALF_PI, t), True),
               (_lrsr, "RSRL", lambda t, u, v: (v, u, -HALF_PI, t), True))),
    (PI, ((_lrslr, "LRSLR", lambda t, u, v: (t, -HALF_PI, u, -HALF_PI, v), False),)),
)
_SWAP = str.maketrans("LR", "RL")
_MIRROR = {word: word.translate(_SWAP) for _, group in GROUPS for _, word, _, _ in group}


def reeds_shepp_frame(q0, q1, radius: float) -> tuple[float, float, float]:
    """The goal (x, y, φ) in the start's frame, lengths in radii (φ not wrapped, as OMPL).

    >>> x, y, phi = reeds_shepp_frame((1.0, 1.0, math.pi / 2), (1.0, 3.0, math.pi), 2.0)
    >>> round(x, 12), round(y, 12), phi == math.pi / 2
    (1.0, 0.0, True)
    """
    dx, dy = q1[0] - q0[0], q1[1] - q0[1]
    c, s = math.cos(q0[2]), math.sin(q0[2])
    return (c * dx + s * dy) / radius, (-s * dx + c * dy) / radius, q1[2] - q0[2]


def _group_candidates(x: float, y: float, phi: float, group):
    # Each formula of a group under identity, time flip, reflection and both: (word, lengths,
    # cost of the free part).
    cp, sp = math.cos(phi), math.sin(phi)
    for solve, word, layout, backwards in group:
        bx, by = (x * cp + y * sp, x * sp - y * cp) if backwards else (x, y)
        mirror = _MIRROR[word]
        for gx, gy, gphi, flip, w in (
            (bx, by, phi, False, word),
            (-bx, by, -phi, True, word),
            (bx, -by, -phi, False, mirror),
            (-bx, -by, phi, True, mirror),
        ):
            tuv = solve(gx, gy, gphi)
            if tuv is not None:
                t, u, v = tuv
                cost = abs(t) + 2.0 * abs(u) + abs(v) if word == "LRLR" else abs(t) + abs(u) + abs(v)
                lengths = layout(t, u, v)
                yield w, tuple(-e for e in lengths) if flip else lengths, cost


def reeds_shepp_candidates(x: float, y: float, phi: float) -> list[tuple[str, tuple[float, ...]]]:
    """Every admissible Reeds–Shepp candidate for the goal (x, y, φ), in OMPL's order.

    >>> ("LSL", (0.0, 2.0, 0.0)) in reeds_shepp_candidates(2.0, 0.0, 0.0)
    True
    """
    return [(w, lengths) for _, group in GROUPS for w, lengths, _ in _group_candidates(x, y, phi, group)]


def reeds_shepp_word(x: float, y: float, phi: float) -> tuple[str, tuple[float, ...]]:
    """The shortest Reeds–Shepp word to the goal (x, y, φ) in radius units, as OMPL picks it.

    >>> reeds_shepp_word(2.0, 0.0, 0.0)
    ('LSL', (0.0, 2.0, 0.0))
    >>> reeds_shepp_word(-2.0, 0.0, 0.0)[1][1]
    -2.0
    """
    got = motions.reeds_shepp_word(x, y, phi)  # compiled: the same word, the same doubles
    return got if got is not None else reeds_shepp_word_pure(x, y, phi)


def reeds_shepp_word_pure(x: float, y: float, phi: float) -> tuple[str, tuple[float, ...]]:
    """:func:`reeds_shepp_word` in Python (the oracle of the compiled one).

    >>> reeds_shepp_word_pure(2.0, 0.0, 0.0)
    ('LSL', (0.0, 2.0, 0.0))
    """
    # Ties between words of equal length are common where the goal is symmetric (φ = π, goals
    # on a line): to pick OMPL's word there, compare as OMPL does, the candidate's cost against
    # the best total minus the group's fixed quarter turns, the bound tightening to the cost
    # of each candidate taken within the group.
    best, total = None, math.inf
    for fixed, group in GROUPS:
        bound = total - fixed
        for word, lengths, cost in _group_candidates(x, y, phi, group):
            if cost < bound:
                best, bound = (word, lengths), cost
        if best is not None:
            total = sum(abs(v) for v in best[1])
    if best is None:  # never seen: L+S+L+ under its four symmetries covers every goal
        raise ArithmeticError(f"no Reeds-Shepp word found for {(x, y, phi)}")
    return best
