"""``cspace stability``: stiff and extreme cases through every layer, against exact references.

This module owns the stability catalogue: a list of :class:`Case` (name, layer, a
function) run through every layer of the toolkit (predicate, hull, sum, erosion,
decomposition, GJK, EPA, C-space query, planning). Each case computes its answer,
measures the error against an exact reference (``fractions.Fraction`` or exact
integers, brute force: all-pairs hulls, vertex-edge distances, separating axes),
and checks it against the guarantee its layer documents (:data:`GUARANTEES`).

A case function returns ``(result, error, passed, seconds)``: a short text of the
answer, the error against the reference (0 for exact layers), whether the layer's
guarantee holds, and the run time of the layer call alone (references not timed).
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from fractions import Fraction
from typing import Callable

import numpy as np

EPS = 2.0 ** -52  # machine epsilon of float64 (one ulp of 1.0)

# What each layer promises; the bound each case checks.
GUARANTEES = {
    "predicate": "exact sign for all finite doubles (error = wrong signs = 0)",
    "hull": "exact: the vertex set equals the exact strict hull of the input (error 0)",
    "sum": "integer input: exact (error 0); floats: vertices within 2 eps*scale of the exact sum, strictly convex",
    "erosion": "exact in rationals (error 0); float vertices are that rounded once (<= eps*scale)",
    "decomposition": "exact cover: convex pieces of input vertices, areas sum exactly to the polygon's (error 0)",
    "gjk": "relation (separated/touching/overlapping) exact; touching distance exactly 0; "
           "separated distance within 1e-9*scale (relative to the local extent)",
    "epa": "touching depth exactly 0; depth within EPA_TOL*scale + 64 eps*scale of the exact depth",
    "cspace": "closed obstacles (touching = collision), repeatable; is_free/segment_free exact on the C-obstacle "
              "pieces (vertices rounded once), so exact on the true geometry when obstacle-robot differences are "
              "representable, else only within 2 eps*|coordinates| of contact; clearance within 1e-9*extent + that",
    "planning": "exact planner: solvable <=> found, unsolvable proven; OMPL paths re-verified exactly",
}


@dataclass(frozen=True)
class Case:
    """One catalogue entry. ``run() -> (result, error, passed, seconds)``."""

    name: str
    layer: str
    run: Callable[[], tuple]
    about: str = ""


# ---------------------------------------------------------------- exact references


def _fr(points) -> list:
    """Float points as exact Fraction pairs."""
    return [(Fraction(x), Fraction(y)) for x, y in np.asarray(points, dtype=np.float64).reshape(-1, 2).tolist()]


def _as_ints(*arrays) -> tuple[list, int]:
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


def _area2(poly: list) -> Fraction:
    """Twice the signed area of an exact polygon."""
    return sum(poly[i][0] * poly[(i + 1) % len(poly)][1] - poly[(i + 1) % len(poly)][0] * poly[i][1]
               for i in range(len(poly)))


def _orient_exact(a, b, c) -> int:
    fa, fb, fc = (tuple(map(Fraction, p)) for p in (a, b, c))
    d = (fb[0] - fa[0]) * (fc[1] - fa[1]) - (fb[1] - fa[1]) * (fc[0] - fa[0])
    return (d > 0) - (d < 0)


def _timed(f, *args, **kw):
    t = time.perf_counter()
    out = f(*args, **kw)
    return out, time.perf_counter() - t


def _scale_of(*arrays) -> float:
    return max(float(np.abs(np.asarray(a, dtype=np.float64)).max()) for a in arrays if len(a))


def _finite(a) -> bool:
    return bool(np.all(np.isfinite(np.asarray(a, dtype=np.float64))))


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def _random_convex(rng, n: int, radius: float, offset: float = 0.0) -> np.ndarray:
    """A random convex polygon: the hull of n random points in a disk (floats, CCW)."""
    from cspace import convex_hull

    t = rng.uniform(0, 2 * np.pi, n)
    r = radius * np.sqrt(rng.uniform(0.2, 1, n))
    return convex_hull(np.c_[offset + r * np.cos(t), offset + r * np.sin(t)])


def _up(x: float, k: int = 1) -> float:
    for _ in range(k):
        x = math.nextafter(x, math.inf)
    return x


def _down(x: float, k: int = 1) -> float:
    for _ in range(k):
        x = math.nextafter(x, -math.inf)
    return x


# ---------------------------------------------------------------- predicate


def _pred_near_line(scale: float, offset: float, n: int = 400, seed: int = 0) -> list:
    """Triples (a, b, c) with c on or within a few ulps of line ab."""
    rng = _rng(seed)
    out = []
    for _ in range(n):
        a = offset + scale * rng.uniform(-1, 1, 2)
        b = offset + scale * rng.uniform(-1, 1, 2)
        t = rng.uniform(-1, 2)
        c = a + t * (b - a)
        k = int(rng.integers(-3, 4))
        cy = _up(float(c[1]), k) if k > 0 else _down(float(c[1]), -k)
        out.append((tuple(a.tolist()), tuple(b.tolist()), (float(c[0]), cy)))
    # exactly collinear triples: c = a + 2^-j (b - a) on a dyadic grid
    for j in range(1, 6):
        a = (offset + scale * 0.25, offset - scale * 0.5)
        b = (offset + scale * 0.75, offset + scale * 0.5)
        c = (a[0] + (b[0] - a[0]) / 2 ** j, a[1] + (b[1] - a[1]) / 2 ** j)
        out.append((a, b, c))
    return out


def _pred_case(triples: list):
    def run():
        from cspace.kernel.predicates import orient2d

        signs, dt = _timed(lambda: [orient2d(a, b, c) for a, b, c in triples])
        ref = [_orient_exact(a, b, c) for a, b, c in triples]
        wrong = sum(s != r for s, r in zip(signs, ref))
        zero = sum(r == 0 for r in ref)
        return f"{len(triples)} triples, {zero} collinear, {wrong} wrong", float(wrong), wrong == 0, dt
    return run


def _near_parallel_triples() -> list:
    """u = (1e6, 1), v = (2e6, 2 + d): cross(u, v) = 1e6 d, within a few ulps of 0."""
    out = []
    for y in (2 + 1e-9, _up(2.0), _down(2.0), 2.0, _up(2.0, 3)):
        for o in (0.0, 1e8):
            out.append(((o, o), (o + 1e6, o + 1), (o + 2e6, o + y)))
    out.append(((0.0, 0.0), (1e-300, 1e-300), (2e-300, _up(2e-300))))  # underflow
    out.append(((0.0, 0.0), (1e300, 1e300), (-1e300, _up(-1e300))))  # overflow
    return out


# ---------------------------------------------------------------- hull


def _hull_case(points, limit_s: float | None = None):
    def run():
        from cspace import convex_hull

        pts = np.asarray(points, dtype=np.float64)
        out, dt = _timed(convex_hull, pts)
        (ip,), D = _as_ints(pts)
        ref = exact_hull(ip)
        (io,), D2 = _as_ints(out)
        got = [(x * (D // D2), y * (D // D2)) for x, y in io] if D % D2 == 0 else None
        wrong = len(ref) + len(io) if got is None else len(set(got) ^ set(ref)) + (got != ref)
        ok = wrong == 0 and (limit_s is None or dt < limit_s)
        res = f"{len(pts)} pts -> {len(out)} vertices (exact {len(ref)})"
        return res, float(wrong), ok, dt
    return run


def _square_with_extras(scale: float, offset: float, seed: int = 1) -> np.ndarray:
    """Corners, exactly collinear edge points, repeats, 1-ulp bumps outward, interior points."""
    rng = _rng(seed)
    lo, hi = offset - scale, offset + scale
    pts = [(lo, lo), (hi, lo), (hi, hi), (lo, hi)] * 3  # repeats
    xs = np.linspace(lo, hi, 17)[1:-1].tolist()
    pts += [(x, lo) for x in xs] + [(hi, x) for x in xs]  # collinear with the edges
    pts += [(xs[3], _down(lo)), (_up(hi), xs[5])]  # one ulp outside: extreme, must be kept
    pts += [(xs[7], _up(hi)), (_down(lo), xs[9])]
    pts += (offset + 0.9 * scale * rng.uniform(-1, 1, (50, 2))).tolist()
    return np.array(pts)


def _sliver(aspect: float = 1e9, offset: float = 0.0, n: int = 20) -> np.ndarray:
    """Points of a triangle of length 1 and height 1/aspect, with points along its long edge."""
    t = np.linspace(0, 1, n)
    pts = np.r_[np.c_[t, np.zeros(n)], [[0.5, 1 / aspect]]]
    return pts + offset


def _circle(n: int, radius: float = 1.0, offset: float = 0.0) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[offset + radius * np.cos(t), offset + radius * np.sin(t)]


def _int_points(rng, n: int, top: int = 2 ** 52) -> np.ndarray:
    return rng.integers(-top, top, (n, 2)).astype(np.float64)


# ---------------------------------------------------------------- sum


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
    outf = _fr(out)
    for p in loose:
        worst = max(worst, _dist_to_boundary2(p, ref))
    for i, p in enumerate(ref):
        if i not in matched:
            worst = max(worst, _dist_to_boundary2(p, outf))
    return _sqrt(worst)


def _strictly_convex(out: np.ndarray) -> bool:
    from cspace.kernel.predicates import orient2d_many

    if len(out) < 3:
        return True
    return bool((orient2d_many(out, np.roll(out, -1, 0), np.roll(out, -2, 0)) > 0).all())


def _sum_case(P, Q, exact: bool, limit_s: float | None = None):
    def run():
        from cspace import minkowski_sum

        p, q = np.asarray(P, dtype=np.float64), np.asarray(Q, dtype=np.float64)
        out, dt = _timed(minkowski_sum, p, q)
        (ip, iq), D = _as_ints(p, q)
        ref_i = exact_sum(ip, iq)
        if len(ref_i) > 5000:  # large: compare as scaled integers, rounding checked per vertex
            err = _big_vertex_error(out, ref_i, D)
        else:
            err = vertex_error(out, [(Fraction(x, D), Fraction(y, D)) for x, y in ref_i])
        scale = _scale_of(out)
        bound = 0.0 if exact else 2 * EPS * scale
        ok = _finite(out) and err <= bound and _strictly_convex(out) and (limit_s is None or dt < limit_s)
        return f"{len(p)}+{len(q)} -> {len(out)} vertices (exact {len(ref_i)})", err, ok, dt
    return run


def _big_vertex_error(out: np.ndarray, ref_i: list, D: int) -> float:
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


def _erode_case(A, B):
    def run():
        from cspace import erode
        from cspace.kernel.halfplane import erode_exact

        a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
        out, dt = _timed(erode, a, b)
        ex = exact_hull(erode_exact(a, b))
        ref = exact_erosion(_fr(a), _fr(b))
        wrong = len(set(ex) ^ set(ref))
        err = math.inf if wrong else (vertex_error(out, ref) if ref else float(len(out)))
        bound = EPS * _scale_of(out) if len(out) else 0.0
        ok = _finite(out) and wrong == 0 and err <= bound
        return f"-> {len(out)} vertices (exact {len(ref)}, rational {'=' if not wrong else '!='} ref)", err, ok, dt
    return run


# ---------------------------------------------------------------- decomposition


def _decomp_case(poly, holes=None):
    def run():
        from cspace import convex_decompose

        p = np.asarray(poly, dtype=np.float64)
        hs = [np.asarray(h, dtype=np.float64) for h in (holes or [])]
        pieces, dt = _timed(convex_decompose, p, hs or None)
        verts = set(map(tuple, p.tolist()))
        for h in hs:
            verts |= set(map(tuple, h.tolist()))
        fp = [_fr(x) for x in pieces]
        area = abs(_area2(_fr(p))) - sum(abs(_area2(_fr(h))) for h in hs)
        total = sum(_area2(x) for x in fp)
        convex = all(_area2(x) > 0 and all(
            _orient_exact(x[i], x[(i + 1) % len(x)], x[(i + 2) % len(x)]) >= 0 for i in range(len(x))) for x in fp)
        from_input = all(tuple(v) in verts for x in pieces for v in x.tolist())
        disjoint = all(exact_relation(fp[i], fp[j]) != "overlapping"
                       for i in range(len(fp)) for j in range(i + 1, len(fp)))
        err = float(abs(total - area) / area)
        ok = err == 0 and convex and from_input and disjoint
        flags = "" if ok else f" convex={convex} input={from_input} disjoint={disjoint}"
        return f"{len(p)} vertices -> {len(pieces)} pieces{flags}", err, ok, dt
    return run


def _l_shape(scale: float, offset: float) -> np.ndarray:
    base = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=np.float64)
    return offset + scale * base


def _comb(teeth: int, aspect: float, offset: float = 0.0) -> np.ndarray:
    """A comb of slivers: teeth of width 1/aspect and height 1 on a base, collinear base points."""
    w = 1.0 / aspect
    pts = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.5)]
    xs = np.linspace(1.0, 0.0, 2 * teeth + 1)
    for k in range(teeth):
        x0 = xs[2 * k + 1]
        pts += [(x0, 0.5), (x0, 1.5), (x0 - w, 1.5), (x0 - w, 0.5)]
    pts.append((0.0, 0.5))
    return np.array(pts) + offset


# ---------------------------------------------------------------- GJK and EPA


def _local_scale(A, B) -> float:
    """The extent GJK and EPA measure tolerances against: max |coordinate - A[0]|."""
    a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
    m = max(float(np.abs(a - a[0]).max()), float(np.abs(b - a[0]).max()))
    return m if m > 0 else 1.0


def _gjk_case(A, B, expect: str | None = None):
    def run():
        from cspace import gjk_distance, gjk_intersects

        a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
        d, dt = _timed(gjk_distance, a, b)
        rel = exact_relation(_fr(a), _fr(b))
        ref = exact_distance(_fr(a), _fr(b))
        err = abs(d.distance - ref)
        bound = 1e-9 * _local_scale(a, b)
        ok = (math.isfinite(d.distance) and d.status == rel and (expect is None or rel == expect)
              and gjk_intersects(a, b) == (rel != "separated")
              and (d.distance == 0.0 if rel != "separated" else err <= bound))
        return f"{d.status} d={d.distance:.6g} (exact {rel} {ref:.6g})", err, ok, dt
    return run


def _epa_case(A, B, expect: str | None = None):
    def run():
        from cspace import epa_penetration
        from cspace.kernel.epa import EPA_TOL

        a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
        p, dt = _timed(epa_penetration, a, b)
        rel = exact_relation(_fr(a), _fr(b))
        ref = exact_depth(_fr(a), _fr(b)) if rel == "overlapping" else 0.0
        err = abs(p.depth - ref)
        scale = _local_scale(a, b)
        bound = (EPA_TOL + 64 * EPS) * scale
        # EPA's own normals are unit; a separated pair's comes from GJK's world points (not checked)
        unit = p.status == "separated" or abs(math.hypot(*p.normal) - 1.0) <= 4 * EPS
        ok = (math.isfinite(p.depth) and unit and p.status == rel and (expect is None or rel == expect)
              and (p.depth == 0.0 if rel == "touching" else err <= bound))
        return f"{p.status} depth={p.depth:.6g} (exact {ref:.6g})", err, ok, dt
    return run


def _box(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)


def _contacts(s: float, o: float) -> list:
    """Touching pairs (edge-edge, vertex-edge, vertex-vertex) at scale s, offset o (exact in floats)."""
    sq = _box(o, o, o + s, o + s)
    return [
        ("edge_edge", sq, _box(o + s, o + s / 2, o + 2 * s, o + 1.5 * s)),
        ("vertex_edge", sq, np.array([[o + s, o + s / 2], [o + 2 * s, o], [o + 2 * s, o + s]])),
        ("vertex_vertex", sq, _box(o + s, o + s, o + 2 * s, o + 2 * s)),
    ]


# ---------------------------------------------------------------- C-space queries


def passage(robot_w: float, slack: float, offset: float = 0.0) -> dict:
    """A scenario dict: a square robot of width ``robot_w`` and a wall with a passage of width
    ``robot_w + slack`` centred at (offset, offset); start and goal on either side."""
    h, g, L = robot_w / 2, (robot_w + slack) / 2, 8 * robot_w
    o = offset
    wall = lambda y0, y1: [[o - robot_w, y0], [o + robot_w, y0], [o + robot_w, y1], [o - robot_w, y1]]
    return {
        "name": f"passage_w{robot_w:g}_s{slack:g}_o{offset:g}",
        "bounds": {"xmin": o - L / 2, "xmax": o + L / 2, "ymin": o - L / 4, "ymax": o + L / 4},
        "robot": {"polygon": [[-h, -h], [h, -h], [h, h], [-h, h]]},
        "obstacles": [{"polygon": wall(o - L, o - g)}, {"polygon": wall(o + g, o + L)}],
        "start": {"x": o - 3 * robot_w, "y": o},
        "goal": {"x": o + 3 * robot_w, "y": o},
    }


def _placed(robot: list, q) -> list:
    qx, qy = Fraction(q[0]), Fraction(q[1])
    return [(x + qx, y + qy) for x, y in robot]


def exact_free(sc, q) -> bool:
    """Is the robot at q clear of every (closed) obstacle and its reference point in bounds? Exact."""
    xmin, xmax, ymin, ymax = sc.bounds
    if not (xmin <= q[0] <= xmax and ymin <= q[1] <= ymax):
        return False
    return all(exact_relation(_placed(_fr(r.polygon), q), _fr(o.polygon)) == "separated"
               for r in sc.robot for o in sc.obstacles)


def exact_segment_free(sc, a, b) -> bool:
    """Is the whole motion a -> b free? The swept robot is the hull of its two end placements."""
    if not (exact_free(sc, a) and exact_free(sc, b)):
        return False
    for r in sc.robot:
        fr = _fr(r.polygon)
        swept = exact_hull(_placed(fr, a) + _placed(fr, b))
        if any(exact_relation(swept, _fr(o.polygon)) != "separated" for o in sc.obstacles):
            return False
    return True


def exact_clearance(sc, q) -> float:
    """Distance from the robot at q to the nearest obstacle, exact before one rounding."""
    return min(exact_distance(_placed(_fr(r.polygon), q), _fr(o.polygon)) for r in sc.robot for o in sc.obstacles)


def _signed_margin(D: list, q) -> Fraction:
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
    return [exact_sum(_fr(o.polygon), [(-x, -y) for x, y in _fr(r.polygon)]) for o in sc.obstacles for r in sc.robot]


def sums_representable(sc) -> bool:
    """Is every obstacle-minus-robot vertex difference exact in floats (integer or dyadic input)?"""
    for o in sc.obstacles:
        for r in sc.robot:
            for a in _fr(o.polygon):
                for b in _fr(r.polygon):
                    for k in (0, 1):
                        if Fraction(float(a[k] - b[k])) != a[k] - b[k]:
                            return False
    return True


def _own_free(cs, q) -> bool:
    """Exact answer on the C-space's own (float) pieces: q outside every closed piece."""
    x, y = Fraction(q[0]), Fraction(q[1])
    for piece in cs.pieces:
        P = _fr(piece)
        if all((P[(i + 1) % len(P)][0] - P[i][0]) * (y - P[i][1]) - (P[(i + 1) % len(P)][1] - P[i][1]) * (x - P[i][0])
               >= 0 for i in range(len(P))):
            return False
    return True


def _own_segment_free(cs, a, b) -> bool:
    seg = exact_hull(_fr([a, b]))
    return _own_free(cs, a) and _own_free(cs, b) and all(exact_relation(seg, _fr(p)) == "separated" for p in cs.pieces)


def _cspace_case(robot_w: float, slack: float, offset: float = 0.0, repeats: int = 5):
    """Passage queries. The C-space is exact on its C-obstacle pieces, whose vertices (obstacle
    minus robot vertex) are rounded once. So: its answers must equal the exact answer on its own
    pieces (always), and the exact answer on the true geometry whenever those differences are
    representable; otherwise they may differ only for states within the rounding band of contact
    (|true margin| <= 2 eps |coordinates|). Clearance within GJK's 1e-9 extent plus that band."""
    def run():
        from cspace import CSpace, scenario_from_dict

        sc = scenario_from_dict(passage(robot_w, slack, offset))
        cs, t_build = _timed(CSpace.from_scenario, sc)
        o = offset
        centre = (o, o)
        probes = [centre, (o, _up(o)), (o, _down(o)), (_up(o), o)]
        left, right = (o - 3 * robot_w, o), (o + 3 * robot_w, o)
        t = time.perf_counter()
        free = [[cs.is_free(p) for _ in range(repeats)] for p in probes]
        seg = [cs.segment_free(left, right) for _ in range(repeats)]
        dt = time.perf_counter() - t
        consistent = all(len(set(f)) == 1 for f in free) and len(set(seg)) == 1
        own_wrong = sum(f[0] != _own_free(cs, p) for f, p in zip(free, probes))
        own_wrong += seg[0] != _own_segment_free(cs, left, right)
        exact_sums = sums_representable(sc)
        band = 2 * EPS * (abs(offset) + 10 * robot_w)
        D = c_obstacles(sc)
        truth_wrong, outside_band = 0, 0
        margins = [min(_signed_margin(d, _fr([p])[0]) for d in D) for p in probes]
        seg_truth = exact_segment_free(sc, left, right)
        # The segment's answer hinges on its narrowest point, the passage centre (probe 0).
        for got, truth, m2 in [(f[0], m > 0, m) for f, m in zip(free, margins)] + [(seg[0], seg_truth, margins[0])]:
            if got != truth:
                truth_wrong += 1
                outside_band += exact_sums or abs(m2) > Fraction(band) ** 2
        c = cs.clearance(centre)
        ref_c = exact_clearance(sc, centre) if exact_free(sc, centre) else 0.0
        c_err = abs(c - ref_c)
        c_bound = 1e-9 * 20 * robot_w + band
        err = max(float(own_wrong + outside_band), c_err)
        ok = consistent and own_wrong == 0 and outside_band == 0 and c_err <= c_bound
        res = (f"free={free[0][0]} seg={seg[0]} clear={c:.3g}; exact free={exact_free(sc, centre)} "
               f"seg={exact_segment_free(sc, left, right)}"
               + ("" if truth_wrong == 0 else f"; {truth_wrong} differ from true geometry within {band:.1g}")
               + ("" if consistent else " INCONSISTENT"))
        return res, err, ok, dt + t_build
    return run


# ---------------------------------------------------------------- planning


def _plan_case(robot_w: float, slack: float, offset: float, planner: str, expect_solved: bool):
    def run():
        from cspace import scenario_from_dict
        from .plan import plan

        sc = scenario_from_dict(passage(robot_w, slack, offset))
        r, dt = _timed(plan, sc, planner=planner, time=1.0, seed=0)
        err, ok = 0.0, r.solved == expect_solved
        if expect_solved and r.solved:
            if planner == "exact":  # the straight line through the passage is the optimum
                err = abs(r.length - 6 * robot_w)
                ok = ok and err <= 1e-12 * 6 * robot_w + 4 * EPS * abs(offset)
            else:  # every segment re-verified independently, in exact arithmetic
                pts = r.path.tolist()
                bad = sum(not exact_segment_free(sc, pts[i], pts[i + 1]) for i in range(len(pts) - 1))
                err = float(bad)
                ok = ok and bad == 0 and pts[0] == list(sc.start) and pts[-1] == list(sc.goal)
        elif not expect_solved and planner == "exact":
            ok = ok and "proven" in r.message
        res = f"{planner}: solved={r.solved} len={r.length:.9g}" + ("" if r.solved else f" ({r.message})")
        return res, err, ok, dt
    return run


# ---------------------------------------------------------------- the catalogue


# 2^±700 (about 1e±211): products of four coordinates leave the double range there.
SCALES = (2.0**-700, 1e-9, 1e-3, 1.0, 1e3, 1e9, 2.0**700)


def _scale_name(s: float) -> str:
    """'1e-09' as :g would print it, or '2^700' for the powers of two at the range's ends."""
    m, e = math.frexp(s)
    return f"2^{e - 1}" if m == 0.5 and abs(e - 1) > 64 else f"{s:g}"


def catalogue() -> list[Case]:
    """Every case, in layer order. Deterministic (fixed seeds)."""
    from cspace import convex_hull as hull

    cases: list[Case] = []
    add = lambda name, layer, fn, about="": cases.append(Case(name, layer, fn, about))
    rng = _rng(7)
    sq = lambda s, o=0.0: _box(o, o, o + s, o + s)

    # predicate
    for s in SCALES:
        add(f"pred_scale_{_scale_name(s)}", "predicate", _pred_case(_pred_near_line(s, 0.0, seed=1)), "near-collinear triples")
    add("pred_offset_1e8", "predicate", _pred_case(_pred_near_line(1.0, 1e8, seed=2)))
    add("pred_near_parallel", "predicate", _pred_case(_near_parallel_triples()), "u=(1e6,1), v=(2e6,2+d), d ~ ulps")
    add("pred_int_2^52", "predicate", _pred_case(_pred_near_line(2.0 ** 51, 0.0, seed=3)
                                                 + [((0.0, 0.0), (2.0 ** 52, 2.0 ** 52 - 1), (2.0 ** 52 - 1, 2.0 ** 52 - 2))]))

    # hull
    for s in SCALES:
        add(f"hull_scale_{_scale_name(s)}", "hull", _hull_case(_square_with_extras(s, 0.0)), "collinear, repeated, 1-ulp bumps")
    add("hull_offset_1e8", "hull", _hull_case(_square_with_extras(1.0, 1e8)))
    add("hull_sliver_1e9", "hull", _hull_case(_sliver(1e9)))
    add("hull_circle_100k", "hull", _hull_case(_circle(100_000), limit_s=3.0), "100 000 vertices, < 3 s")
    add("hull_circle_100k_offset_1e8", "hull", _hull_case(_circle(100_000, 1.0, 1e8), limit_s=3.0))
    add("hull_int_2^52", "hull", _hull_case(np.r_[_int_points(rng, 300), [[0, 2.0 ** 52], [2.0 ** 51, 2.0 ** 52]]]))

    # sum
    for s in SCALES:
        add(f"sum_scale_{_scale_name(s)}", "sum", _sum_case(_random_convex(rng, 40, s), _random_convex(rng, 40, s / 3), False))
    add("sum_offset_1e8", "sum", _sum_case(_random_convex(rng, 40, 1.0, 1e8), _random_convex(rng, 40, 1.0, 1e8), False))
    for name, y in (("sum_near_parallel_1e-9", 2 + 1e-9), ("sum_near_parallel_ulp", _up(2.0)),
                    ("sum_near_parallel_-ulp", _down(2.0))):
        add(name, "sum", _sum_case([[0, 0], [1e6, 1], [0, 1e6]], [[0, 0], [2e6, y], [0, 1e6]], False),
            "edges u=(1e6,1), v=(2e6,y): cross within ulps of 0")
    add("sum_collinear_repeated", "sum", _sum_case(
        [[0, 0], [0, 0], [0.5, 0], [1, 0], [1, 0.25], [1, 1], [1, 1], [0, 1]],
        [[0.1, 0.1], [0.3, 0.1], [0.3, 0.1], [0.2, 0.3], [0.15, 0.2]], False))
    add("sum_sliver_1e9", "sum", _sum_case(hull(_sliver(1e9)), hull(_sliver(1e9)[:, ::-1] * [1, -1]), False))
    add("sum_circle_100k_square", "sum", _sum_case(_circle(100_000), sq(0.5), False, limit_s=3.0),
        "100 000 + 4 vertices, < 3 s")
    add("sum_int_2^52", "sum", _sum_case(hull(_int_points(rng, 60, 2 ** 51)), hull(_int_points(rng, 60, 2 ** 51)), True),
        "integer input: exact")
    add("sum_int_circle_100k", "sum", _sum_case(hull(np.round(_circle(100_000, 2.0 ** 40))), sq(2.0 ** 40), True,
                                                limit_s=3.0), "integer circle of radius 2^40 (hull) + square: exact")

    # erosion
    for s in SCALES:
        add(f"erode_scale_{_scale_name(s)}", "erosion", _erode_case(_random_convex(rng, 30, s), _random_convex(rng, 8, s / 5)))
    add("erode_offset_1e8", "erosion", _erode_case(_random_convex(rng, 30, 1.0, 1e8), _random_convex(rng, 8, 0.2, 1e8)))
    add("erode_exact_fit", "erosion", _erode_case(sq(1.0, 0.3), sq(1.0, 0.7)), "B exactly as big as A: a point")
    add("erode_exact_fit_offset_1e8", "erosion", _erode_case(_box(1e8, 1e8, 1e8 + 1, 1e8 + 3), sq(1.0)),
        "fits in one direction only: a segment")
    add("erode_sliver_1e9", "erosion", _erode_case(hull(_sliver(1e9)), [[0, 0], [1e-3, 0], [0, 1e-12]]))
    add("erode_int_2^52", "erosion", _erode_case(hull(_int_points(rng, 60)), hull(_int_points(rng, 8, 2 ** 48))))

    # decomposition
    for s in SCALES:
        add(f"decomp_L_scale_{_scale_name(s)}", "decomposition", _decomp_case(_l_shape(s, 0.0)))
    add("decomp_L_offset_1e8", "decomposition", _decomp_case(_l_shape(1.0, 1e8)))
    add("decomp_collinear_repeated", "decomposition", _decomp_case(
        [[0, 0], [1, 0], [2, 0], [2, 0], [2, 1], [1.5, 1], [1, 1], [1, 2], [0, 2], [0, 1]]))
    add("decomp_comb_sliver_1e9", "decomposition", _decomp_case(_comb(6, 1e9)), "teeth of aspect 1e9")
    add("decomp_hole_offset_1e8", "decomposition", _decomp_case(_box(1e8, 1e8, 1e8 + 4, 1e8 + 4),
                                                                [_box(1e8 + 1, 1e8 + 1, 1e8 + 3, 1e8 + 3)[::-1]]))
    add("decomp_int_2^52", "decomposition", _decomp_case(_l_shape(2.0 ** 50, 0.0) + [[2.0 ** 50 - 1, 3.0]]))

    # GJK and EPA
    for s in SCALES:
        a = _random_convex(rng, 20, s)
        add(f"gjk_separated_scale_{_scale_name(s)}", "gjk", _gjk_case(a, a + [3 * s, s / 7], "separated"))
        add(f"epa_overlap_scale_{_scale_name(s)}", "epa", _epa_case(a, a + [s / 3, s / 5], "overlapping"))
    a, b = _random_convex(rng, 20, 1.0, 1e8), _random_convex(rng, 20, 1.0, 1e8)
    add("gjk_offset_1e8", "gjk", _gjk_case(a, b + [2.5, 0.0], "separated"))
    add("epa_offset_1e8", "epa", _epa_case(a, b + [0.3, 0.1], "overlapping"))
    for s, o in ((1.0, 0.0), (1.0, 1e8), (1e-9, 0.0), (2.0 ** 30, 2.0 ** 51)):
        tag = f"s{s:g}_o{o:g}"
        for kind, A, B in _contacts(s, o):
            add(f"gjk_touch_{kind}_{tag}", "gjk", _gjk_case(A, B, "touching"))
            add(f"epa_touch_{kind}_{tag}", "epa", _epa_case(A, B, "touching"))
    sl = hull(_sliver(1e9))
    add("gjk_sliver_gap_1ulp", "gjk", _gjk_case(sl, _box(0.0, _up(1e-9), 1.0, 1.0) + [0, 0], "separated"),
        "sliver apex one ulp below a box")
    add("gjk_near_parallel_gap", "gjk", _gjk_case([[0, 0], [1e6, 1], [0, 1]],
                                                  [[0, _up(1.0)], [2e6, _up(3.0)], [0, 5]], None))
    add("epa_sliver_overlap", "epa", _epa_case(sl, sl + [0.25, 0.0], "overlapping"))
    add("gjk_int_2^52", "gjk", _gjk_case(hull(_int_points(rng, 30, 2 ** 50)), hull(_int_points(rng, 30, 2 ** 50)) + 2.0 ** 51))

    # C-space queries: zero clearance, 1e-6 wider, 1e-6 narrower, at several scales and offsets
    for w, o in ((1.0, 0.0), (1.0, 1e8), (1e-9, 0.0), (1e9, 0.0), (0.1, 0.3)):
        for label, slack in (("exact", 0.0), ("wider", 1e-6 * w), ("narrower", -1e-6 * w)):
            add(f"cspace_{label}_w{w:g}_o{o:g}", "cspace", _cspace_case(w, slack, o),
                "closed obstacles: touching is collision")
    # non-dyadic widths far from the origin: the rounded C-obstacle closes a passage the true
    # geometry leaves open by less than one ulp (decided consistently, within the rounding band)
    for w, o in ((0.3, 1e8 + 0.1), (1 / 3, 1e8 / 3)):
        add(f"cspace_exact_w{w:.3g}_o{o:.10g}", "cspace", _cspace_case(w, 0.0, o), "sums not representable")
    # scenes far smaller than their coordinates (extent ~1e-13 |coordinate|): the broad phase's
    # margin spans many grid cells, and its segment walk must still terminate
    for w, o in ((1e-5, 1e8 + 0.1), (1e-3, 1e9)):
        for label, slack in (("exact", 0.0), ("wider", 1e-6 * w)):
            add(f"cspace_tiny_{label}_w{w:g}_o{o:.10g}", "cspace", _cspace_case(w, slack, o),
                "extent near the float resolution of the coordinates")

    # planning (each <= 1 s)
    add("plan_exact_wider", "planning", _plan_case(1.0, 1e-6, 0.0, "exact", True))
    add("plan_exact_wider_o1e8", "planning", _plan_case(1.0, 1e-6, 1e8, "exact", True))
    add("plan_exact_zero_clearance", "planning", _plan_case(1.0, 0.0, 0.0, "exact", False))
    add("plan_exact_narrower", "planning", _plan_case(1.0, -1e-6, 0.0, "exact", False))
    add("plan_exact_narrower_o1e8", "planning", _plan_case(1.0, -1e-6, 1e8, "exact", False))
    add("plan_rrtconnect_o1e8", "planning", _plan_case(1.0, 0.5, 1e8, "RRTConnect", True))
    return cases


def run_case(case: Case) -> dict:
    """Run one case; a crash or a NaN is a failure, reported, never raised."""
    t = time.perf_counter()
    try:
        result, error, passed, seconds = case.run()
    except Exception as exc:  # a crash is a failed guarantee, not a crashed report
        result, error, passed, seconds = f"CRASH {type(exc).__name__}: {exc}", math.inf, False, time.perf_counter() - t
    if not isinstance(error, (int, float)) or math.isnan(error):
        passed = False
    return {"case": case.name, "layer": case.layer, "result": result,
            "error": float(error) if math.isfinite(error) else None,
            "time_ms": 1000.0 * seconds, "passed": bool(passed), "guarantee": GUARANTEES[case.layer]}


def run_all(cases: list[Case] | None = None, progress: bool | None = False) -> list[dict]:
    """Rows of the report, one per case (a bar on a terminal with ``progress=None``)."""
    from .progress import track

    cases = catalogue() if cases is None else cases
    return [run_case(c) for c in track(cases, "stability", enabled=progress, unit="case")]


WIDTH = 80  # the table fits a classic terminal: results go on their own indented line


def format_table(rows: list[dict], width: int = WIDTH) -> str:
    """The report as a text table, one case per two lines: name and numbers, then its result.

    The layer is the case name's prefix (``pred_``, ``hull_``, ``gjk_`` ...), so it
    takes no column; the result is wrapped to ``width`` under its case.

    >>> print(format_table([{"case": "c", "layer": "hull", "result": "ok", "error": 0.0,
    ...                      "time_ms": 1.5, "passed": True}]))
    case     error  time ms  pass
    ----  --------  -------  ----
    c     0.00e+00      1.5  pass
        ok
    """
    import textwrap

    head = ("case", "error", "time ms", "pass")
    body = [(r["case"], "-" if r["error"] is None else f"{r['error']:.2e}", f"{r['time_ms']:.1f}",
             "pass" if r["passed"] else "FAIL") for r in rows]
    w = [max(len(x[i]) for x in [head] + body) for i in range(4)]
    line = lambda x: "  ".join([x[0].ljust(w[0]), x[1].rjust(w[1]), x[2].rjust(w[2]), x[3]]).rstrip()
    out = [line(head), "  ".join("-" * k for k in w)]
    for x, r in zip(body, rows):
        out.append(line(x))
        out += textwrap.wrap(str(r["result"]), width, initial_indent="    ", subsequent_indent="      ",
                             break_on_hyphens=False) or ["    -"]
    return "\n".join(out)


def plot(rows: list[dict], path: str) -> None:
    """Bar chart of run times per case, coloured by pass/fail (matplotlib imported here only)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .output import atomic_path

    fig, ax = plt.subplots(figsize=(max(8, 0.18 * len(rows)), 5))
    times = [max(r["time_ms"], 1e-3) for r in rows]
    ax.bar(range(len(rows)), times, color=["tab:green" if r["passed"] else "tab:red" for r in rows])
    ax.set_yscale("log")
    ax.set_xticks(range(len(rows)), [r["case"] for r in rows], rotation=90, fontsize=6)
    ax.set_ylabel("time of the layer call (ms)")
    ax.set_xlabel("case (its name begins with its layer)")
    from matplotlib.patches import Patch

    ax.legend(handles=[Patch(color="tab:green", label="guarantee holds"), Patch(color="tab:red", label="FAILED")],
              loc="upper left", fontsize=8)
    ax.set_title(f"cspace stability: {sum(r['passed'] for r in rows)}/{len(rows)} cases pass")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def register(sub) -> None:
    p = sub.add_parser("stability", help="run stiff and extreme cases through every layer",
                       description="Run the numerical stability catalogue against exact references.")
    p.add_argument("--json", metavar="FILE", help="write the rows as JSON")
    p.add_argument("--plot", metavar="FILE", help="write a PNG bar chart of times, coloured by pass")
    p.set_defaults(run=run)


def run(args) -> int:
    from .output import check_output, write_json

    if args.json is not None:  # "" is refused by check_output, not skipped
        check_output(args.json, "--json")
    if args.plot is not None:
        check_output(args.plot, "--plot", {".png": "png"})
    import textwrap

    rows = run_all(progress=None)
    print(format_table(rows))
    failed = [r["case"] for r in rows if not r["passed"]]
    print("\n" + textwrap.fill(f"{len(rows) - len(failed)}/{len(rows)} cases pass"
                               + (f"; FAILED: {', '.join(failed)}" if failed else ""), WIDTH,
                               subsequent_indent="  ", break_on_hyphens=False))
    if args.json is not None:
        write_json(args.json, {"cases": rows, "guarantees": GUARANTEES, "passed": not failed})
    if args.plot is not None:
        plot(rows, args.plot)
    sys.stdout.flush()
    return 0 if not failed else 1
