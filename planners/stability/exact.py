"""Exact references for the stability catalogue (:mod:`planners.stability`).

Brute force in exact arithmetic (``fractions.Fraction`` or integers scaled by one power
of two): all-pairs hulls and sums, separating axes, vertex-edge distances, half-plane
erosion, and the exact answers of a scene's point and segment queries, both on the true
geometry and on a C-space's own (once-rounded) pieces. Each measured layer's answer is
compared against these; they are slow and simple on purpose.
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np


# ---------------------------------------------------------------- polygons


def to_fractions(points) -> list:
    """Float points as exact Fraction pairs."""
    return [(Fraction(x), Fraction(y)) for x, y in np.asarray(points, dtype=np.float64).reshape(-1, 2).tolist()]


def as_ints(*arrays) -> tuple[list, int]:
    """Float arrays as exact integer points scaled by one power of two D (x = X / D exactly)."""
    dens = [1]
    flat = []
    for a in arrays:
        pts = np.asarray(a, dtype=np.float64).reshape(-1, 2).tolist()
        flat.append(pts)
        for x, y in pts:
            dens.append(x.as_integer_ratio()[1])
            dens.append(y.as_integer_ratio()[1])
    D = max(dens)  # all denominators are powers of two

    def conv(v: float) -> int:
        n, d = v.as_integer_ratio()
        return n * (D // d)

    return [[(conv(x), conv(y)) for x, y in pts] for pts in flat], D


def exact_hull(points: list) -> list:
    """Strict convex hull (CCW, lowest-then-leftmost first) of exact points (ints or Fractions)."""
    pts = sorted(set(points), key=lambda p: (p[0], p[1]))
    if len(pts) <= 2:
        return sorted(pts, key=lambda p: (p[1], p[0]))

    def chain(seq):
        out = []
        for p in seq:
            while len(out) >= 2:
                (ax, ay), (bx, by) = out[-2], out[-1]
                if (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax) > 0:
                    break
                out.pop()
            out.append(p)
        return out

    hull = chain(pts)[:-1] + chain(pts[::-1])[:-1]
    k = min(range(len(hull)), key=lambda i: (hull[i][1], hull[i][0]))
    return hull[k:] + hull[:k]


def exact_sum(A: list, B: list) -> list:
    """A ⊕ B of exact convex point sets: the hull of all pairwise sums (brute force)."""
    ha, hb = exact_hull(A), exact_hull(B)
    return exact_hull([(ax + bx, ay + by) for ax, ay in ha for bx, by in hb])


def exact_relation(A: list, B: list) -> str:
    """Separated / touching / overlapping of two exact convex polygons (>= 3 vertices), SAT."""
    ha, hb = exact_hull(A), exact_hull(B)
    weak = False
    for h in (ha, hb):
        for i in range(len(h)):
            (x0, y0), (x1, y1) = h[i], h[(i + 1) % len(h)]
            nx, ny = y1 - y0, x0 - x1
            pa = [nx * x + ny * y for x, y in ha]
            pb = [nx * x + ny * y for x, y in hb]
            if max(pa) < min(pb) or max(pb) < min(pa):
                return "separated"
            if max(pa) == min(pb) or max(pb) == min(pa):
                weak = True
    return "touching" if weak else "overlapping"


def _seg_dist2(p, q0, q1) -> Fraction:
    """Exact squared distance from point p to segment q0-q1."""
    ex, ey = q1[0] - q0[0], q1[1] - q0[1]
    px, py = p[0] - q0[0], p[1] - q0[1]
    ee = ex * ex + ey * ey
    t = Fraction(0) if ee == 0 else min(Fraction(1), max(Fraction(0), Fraction(px * ex + py * ey) / ee))
    dx, dy = px - t * ex, py - t * ey
    return dx * dx + dy * dy


def exact_distance(A: list, B: list) -> float:
    """Distance between two exact convex polygons: 0 if they meet, else min vertex-edge distance."""
    if exact_relation(A, B) != "separated":
        return 0.0
    best = None
    for P, Q in ((A, B), (B, A)):
        for p in P:
            for i in range(len(Q)):
                d2 = _seg_dist2(p, Q[i], Q[(i + 1) % len(Q)])
                best = d2 if best is None or d2 < best else best
    return _sqrt(best)


def exact_depth(A: list, B: list) -> float:
    """Penetration depth of overlapping convex A, B: distance from 0 to the boundary of A ⊕ (−B)."""
    D = exact_sum(A, [(-x, -y) for x, y in B])
    best = None
    for i in range(len(D)):
        (px, py), (qx, qy) = D[i], D[(i + 1) % len(D)]
        ex, ey = qx - px, qy - py
        c = ey * px - ex * py  # cross(q - p, 0 - p): |e| times the origin's distance inside this edge
        d2 = Fraction(c * c, 1) / (ex * ex + ey * ey)
        d2 = d2 if c >= 0 else -d2
        best = d2 if best is None or d2 < best else best
    return _sqrt(best) if best > 0 else 0.0


def _sqrt(q: Fraction) -> float:
    """Square root of a non-negative Fraction, correctly rounded to about one ulp."""
    if q <= 0:
        return 0.0
    n, d = q.numerator, q.denominator
    shift = max(0, 120 - (n.bit_length() - d.bit_length()))
    shift += shift % 2
    r = math.isqrt((n << shift) // d)
    return math.ldexp(float(r), -shift // 2)


def area2(poly: list) -> Fraction:
    """Twice the signed area of an exact polygon."""
    return sum(poly[i][0] * poly[(i + 1) % len(poly)][1] - poly[(i + 1) % len(poly)][0] * poly[i][1]
               for i in range(len(poly)))


def orient_exact(a, b, c) -> int:
    fa, fb, fc = (tuple(map(Fraction, p)) for p in (a, b, c))
    d = (fb[0] - fa[0]) * (fc[1] - fa[1]) - (fb[1] - fa[1]) * (fc[0] - fa[0])
    return (d > 0) - (d < 0)


# ---------------------------------------------------------------- float output against an exact polygon


def _dist_to_boundary2(p, poly: list) -> Fraction:
    """Exact squared distance from p to the boundary of an exact polygon (or point/segment)."""
    if len(poly) == 1:
        return _seg_dist2(p, poly[0], poly[0])
    return min(_seg_dist2(p, poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))


def vertex_error(out: np.ndarray, ref: list) -> float:
    """Hausdorff-type error of a float polygon against an exact one.

    Each output vertex that rounds from an exact vertex is measured against it; any
    other output vertex against the exact boundary; any exact vertex left unmatched
    against the output's boundary. All in exact arithmetic, rounded once at the end.
    """
    refr = {(float(x), float(y)): i for i, (x, y) in enumerate(ref)}
    worst, matched, loose = Fraction(0), set(), []
    for x, y in out.tolist():
        i = refr.get((x, y))
        if i is None:
            loose.append((Fraction(x), Fraction(y)))
            continue
        matched.add(i)
        dx, dy = Fraction(x) - ref[i][0], Fraction(y) - ref[i][1]
        worst = max(worst, dx * dx + dy * dy)
    outf = to_fractions(out)
    for p in loose:
        worst = max(worst, _dist_to_boundary2(p, ref))
    for i, p in enumerate(ref):
        if i not in matched:
            worst = max(worst, _dist_to_boundary2(p, outf))
    return _sqrt(worst)


def big_vertex_error(out: np.ndarray, ref_i: list, D: int) -> float:
    """vertex_error for large polygons: every output vertex must be a correctly rounded exact vertex."""
    refr = {(float(Fraction(x, D)), float(Fraction(y, D))): (x, y) for x, y in ref_i}
    if len(refr) != len(out):
        return math.inf
    worst = 0
    for x, y in out.tolist():
        r = refr.get((x, y))
        if r is None:
            return math.inf
        for v, e in ((x, r[0]), (y, r[1])):
            n, d = v.as_integer_ratio()
            diff = Fraction(n * D - e * d, d * D)
            worst = max(worst, abs(diff))
    return float(worst) * math.sqrt(2.0)


# ---------------------------------------------------------------- erosion


def exact_erosion(A: list, B: list) -> list:
    """A ⊖ B of exact convex polygons by brute force: all pairwise intersections of the
    shifted edge lines of A, kept where every shifted half-plane holds, then their hull."""
    ha = exact_hull(A)
    cons = []
    for i in range(len(ha)):
        (px, py), (qx, qy) = ha[i], ha[(i + 1) % len(ha)]
        nx, ny = qy - py, px - qx  # outward normal of a CCW edge
        cons.append((nx, ny, nx * px + ny * py - max(nx * x + ny * y for x, y in B)))
    pts = []
    for i in range(len(cons)):
        for j in range(i + 1, len(cons)):
            a1, b1, c1 = cons[i]
            a2, b2, c2 = cons[j]
            det = a1 * b2 - a2 * b1
            if det == 0:
                continue
            x, y = Fraction(c1 * b2 - c2 * b1, det), Fraction(a1 * c2 - a2 * c1, det)
            if all(a * x + b * y <= c for a, b, c in cons):
                pts.append((x, y))
    return exact_hull(pts)


# ---------------------------------------------------------------- C-space queries


def _placed(robot: list, q) -> list:
    qx, qy = Fraction(q[0]), Fraction(q[1])
    return [(x + qx, y + qy) for x, y in robot]


def exact_free(sc, q) -> bool:
    """Is the robot at q clear of every (closed) obstacle and its reference point in bounds? Exact."""
    xmin, xmax, ymin, ymax = sc.bounds
    if not (xmin <= q[0] <= xmax and ymin <= q[1] <= ymax):
        return False
    return all(exact_relation(_placed(to_fractions(r.polygon), q), to_fractions(o.polygon)) == "separated"
               for r in sc.robot for o in sc.obstacles)


def exact_segment_free(sc, a, b) -> bool:
    """Is the whole motion a -> b free? The swept robot is the hull of its two end placements."""
    if not (exact_free(sc, a) and exact_free(sc, b)):
        return False
    for r in sc.robot:
        fr = to_fractions(r.polygon)
        swept = exact_hull(_placed(fr, a) + _placed(fr, b))
        if any(exact_relation(swept, to_fractions(o.polygon)) != "separated" for o in sc.obstacles):
            return False
    return True


def exact_clearance(sc, q) -> float:
    """Distance from the robot at q to the nearest obstacle, exact before one rounding."""
    return min(exact_distance(_placed(to_fractions(r.polygon), q), to_fractions(o.polygon)) for r in sc.robot for o in sc.obstacles)


def signed_margin(D: list, q) -> Fraction:
    """Exact signed squared distance of point q to convex D: > 0 outside, <= 0 in the closed set
    (minus the squared depth)."""
    inward = []
    for i in range(len(D)):
        (px, py), (qx, qy) = D[i], D[(i + 1) % len(D)]
        ex, ey = qx - px, qy - py
        c = ex * (q[1] - py) - ey * (q[0] - px)  # |e| times q's inward distance from this edge
        inward.append((c, ex * ex + ey * ey))
    if all(c >= 0 for c, _ in inward):
        return -min(Fraction(c * c) / n2 for c, n2 in inward)
    return _dist_to_boundary2(q, D)


def c_obstacles(sc) -> list:
    """The true C-obstacles, exact: obstacle ⊕ (−robot part), for every pair."""
    return [exact_sum(to_fractions(o.polygon), [(-x, -y) for x, y in to_fractions(r.polygon)]) for o in sc.obstacles for r in sc.robot]


def sums_representable(sc) -> bool:
    """Is every obstacle-minus-robot vertex difference exact in floats (integer or dyadic input)?"""
    for o in sc.obstacles:
        for r in sc.robot:
            for a in to_fractions(o.polygon):
                for b in to_fractions(r.polygon):
                    for k in (0, 1):
                        if Fraction(float(a[k] - b[k])) != a[k] - b[k]:
                            return False
    return True


def own_free(cs, q) -> bool:
    """Exact answer on the C-space's own (float) pieces: q outside every closed piece."""
    x, y = Fraction(q[0]), Fraction(q[1])
    for piece in cs.pieces:
        P = to_fractions(piece)
        if all((P[(i + 1) % len(P)][0] - P[i][0]) * (y - P[i][1]) - (P[(i + 1) % len(P)][1] - P[i][1]) * (x - P[i][0])
               >= 0 for i in range(len(P))):
            return False
    return True


def own_segment_free(cs, a, b) -> bool:
    seg = exact_hull(to_fractions([a, b]))
    return own_free(cs, a) and own_free(cs, b) and all(exact_relation(seg, to_fractions(p)) == "separated" for p in cs.pieces)
