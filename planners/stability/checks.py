"""The stability catalogue's checks: one case function per layer (:mod:`planners.stability`).

Each ``_<layer>_case(...)`` returns a ``run()`` that times the layer call alone, measures
its answer's error against the exact references (:mod:`planners.stability.exact`) and
checks it against the layer's documented bound, returning ``(result, error, passed,
seconds)``.
"""
from __future__ import annotations

import math
import time
from fractions import Fraction

import numpy as np

from .exact import (area2, as_ints, big_vertex_error, to_fractions, orient_exact, own_free, own_segment_free,
                              signed_margin, c_obstacles, exact_clearance, exact_depth, exact_distance, exact_erosion,
                              exact_free, exact_hull, exact_relation, exact_segment_free, exact_sum, sums_representable,
                              vertex_error)
from .inputs import ulps_down, ulps_up, passage

EPS = 2.0 ** -52  # machine epsilon of float64 (one ulp of 1.0)


def _timed(f, *args, **kw):
    t = time.perf_counter()
    out = f(*args, **kw)
    return out, time.perf_counter() - t


def _scale_of(*arrays) -> float:
    return max(float(np.abs(np.asarray(a, dtype=np.float64)).max()) for a in arrays if len(a))


def _finite(a) -> bool:
    return bool(np.all(np.isfinite(np.asarray(a, dtype=np.float64))))


# ---------------------------------------------------------------- predicate


def pred_case(triples: list):
    def run():
        from cspace.kernel.polygons.predicates import orient2d

        signs, dt = _timed(lambda: [orient2d(a, b, c) for a, b, c in triples])
        ref = [orient_exact(a, b, c) for a, b, c in triples]
        wrong = sum(s != r for s, r in zip(signs, ref))
        zero = sum(r == 0 for r in ref)
        return f"{len(triples)} triples, {zero} collinear, {wrong} wrong", float(wrong), wrong == 0, dt
    return run


# ---------------------------------------------------------------- hull


def hull_case(points, limit_s: float | None = None):
    def run():
        from cspace import convex_hull

        pts = np.asarray(points, dtype=np.float64)
        out, dt = _timed(convex_hull, pts)
        (ip,), D = as_ints(pts)
        ref = exact_hull(ip)
        (io,), D2 = as_ints(out)
        got = [(x * (D // D2), y * (D // D2)) for x, y in io] if D % D2 == 0 else None
        wrong = len(ref) + len(io) if got is None else len(set(got) ^ set(ref)) + (got != ref)
        ok = wrong == 0 and (limit_s is None or dt < limit_s)
        res = f"{len(pts)} pts -> {len(out)} vertices (exact {len(ref)})"
        return res, float(wrong), ok, dt
    return run


# ---------------------------------------------------------------- sum


def _strictly_convex(out: np.ndarray) -> bool:
    from cspace.kernel.polygons.predicates import orient2d_many

    if len(out) < 3:
        return True
    return bool((orient2d_many(out, np.roll(out, -1, 0), np.roll(out, -2, 0)) > 0).all())


def sum_case(P, Q, exact: bool, limit_s: float | None = None):
    def run():
        from cspace import minkowski_sum

        p, q = np.asarray(P, dtype=np.float64), np.asarray(Q, dtype=np.float64)
        out, dt = _timed(minkowski_sum, p, q)
        (ip, iq), D = as_ints(p, q)
        ref_i = exact_sum(ip, iq)
        if len(ref_i) > 5000:  # large: compare as scaled integers, rounding checked per vertex
            err = big_vertex_error(out, ref_i, D)
        else:
            err = vertex_error(out, [(Fraction(x, D), Fraction(y, D)) for x, y in ref_i])
        scale = _scale_of(out)
        bound = 0.0 if exact else 2 * EPS * scale
        ok = _finite(out) and err <= bound and _strictly_convex(out) and (limit_s is None or dt < limit_s)
        return f"{len(p)}+{len(q)} -> {len(out)} vertices (exact {len(ref_i)})", err, ok, dt
    return run


# ---------------------------------------------------------------- erosion


def erode_case(A, B):
    def run():
        from cspace import erode
        from cspace.kernel.polygons.halfplane import erode_exact

        a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
        out, dt = _timed(erode, a, b)
        ex = exact_hull(erode_exact(a, b))
        ref = exact_erosion(to_fractions(a), to_fractions(b))
        wrong = len(set(ex) ^ set(ref))
        err = math.inf if wrong else (vertex_error(out, ref) if ref else float(len(out)))
        bound = EPS * _scale_of(out) if len(out) else 0.0
        ok = _finite(out) and wrong == 0 and err <= bound
        return f"-> {len(out)} vertices (exact {len(ref)}, rational {'=' if not wrong else '!='} ref)", err, ok, dt
    return run


# ---------------------------------------------------------------- decomposition


def decomp_case(poly, holes=None):
    def run():
        from cspace import convex_decompose

        p = np.asarray(poly, dtype=np.float64)
        hs = [np.asarray(h, dtype=np.float64) for h in (holes or [])]
        pieces, dt = _timed(convex_decompose, p, hs or None)
        verts = set(map(tuple, p.tolist()))
        for h in hs:
            verts |= set(map(tuple, h.tolist()))
        fp = [to_fractions(x) for x in pieces]
        area = abs(area2(to_fractions(p))) - sum(abs(area2(to_fractions(h))) for h in hs)
        total = sum(area2(x) for x in fp)
        convex = all(area2(x) > 0 and all(
            orient_exact(x[i], x[(i + 1) % len(x)], x[(i + 2) % len(x)]) >= 0 for i in range(len(x))) for x in fp)
        from_input = all(tuple(v) in verts for x in pieces for v in x.tolist())
        disjoint = all(exact_relation(fp[i], fp[j]) != "overlapping"
                       for i in range(len(fp)) for j in range(i + 1, len(fp)))
        err = float(abs(total - area) / area)
        ok = err == 0 and convex and from_input and disjoint
        flags = "" if ok else f" convex={convex} input={from_input} disjoint={disjoint}"
        return f"{len(p)} vertices -> {len(pieces)} pieces{flags}", err, ok, dt
    return run


# ---------------------------------------------------------------- GJK and EPA


def _local_scale(A, B) -> float:
    """The extent GJK and EPA measure tolerances against: max |coordinate - A[0]|."""
    a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
    m = max(float(np.abs(a - a[0]).max()), float(np.abs(b - a[0]).max()))
    return m if m > 0 else 1.0


def gjk_case(A, B, expect: str | None = None):
    def run():
        from cspace import gjk_distance, gjk_intersects

        a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
        d, dt = _timed(gjk_distance, a, b)
        rel = exact_relation(to_fractions(a), to_fractions(b))
        ref = exact_distance(to_fractions(a), to_fractions(b))
        err = abs(d.distance - ref)
        bound = 1e-9 * _local_scale(a, b)
        ok = (math.isfinite(d.distance) and d.status == rel and (expect is None or rel == expect)
              and gjk_intersects(a, b) == (rel != "separated")
              and (d.distance == 0.0 if rel != "separated" else err <= bound))
        return f"{d.status} d={d.distance:.6g} (exact {rel} {ref:.6g})", err, ok, dt
    return run


def epa_case(A, B, expect: str | None = None):
    def run():
        from cspace import epa_penetration
        from cspace.kernel.distance.epa import EPA_TOL

        a, b = np.asarray(A, dtype=np.float64), np.asarray(B, dtype=np.float64)
        p, dt = _timed(epa_penetration, a, b)
        rel = exact_relation(to_fractions(a), to_fractions(b))
        ref = exact_depth(to_fractions(a), to_fractions(b)) if rel == "overlapping" else 0.0
        err = abs(p.depth - ref)
        scale = _local_scale(a, b)
        bound = (EPA_TOL + 64 * EPS) * scale
        # EPA's own normals are unit; a separated pair's comes from GJK's world points (not checked)
        unit = p.status == "separated" or abs(math.hypot(*p.normal) - 1.0) <= 4 * EPS
        ok = (math.isfinite(p.depth) and unit and p.status == rel and (expect is None or rel == expect)
              and (p.depth == 0.0 if rel == "touching" else err <= bound))
        return f"{p.status} depth={p.depth:.6g} (exact {ref:.6g})", err, ok, dt
    return run


# ---------------------------------------------------------------- C-space queries


def cspace_case(robot_w: float, slack: float, offset: float = 0.0, repeats: int = 5):
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
        probes = [centre, (o, ulps_up(o)), (o, ulps_down(o)), (ulps_up(o), o)]
        left, right = (o - 3 * robot_w, o), (o + 3 * robot_w, o)
        t = time.perf_counter()
        free = [[cs.is_free(p) for _ in range(repeats)] for p in probes]
        seg = [cs.segment_free(left, right) for _ in range(repeats)]
        dt = time.perf_counter() - t
        consistent = all(len(set(f)) == 1 for f in free) and len(set(seg)) == 1
        own_wrong = sum(f[0] != own_free(cs, p) for f, p in zip(free, probes))
        own_wrong += seg[0] != own_segment_free(cs, left, right)
        exact_sums = sums_representable(sc)
        band = 2 * EPS * (abs(offset) + 10 * robot_w)
        D = c_obstacles(sc)
        truth_wrong, outside_band = 0, 0
        margins = [min(signed_margin(d, to_fractions([p])[0]) for d in D) for p in probes]
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


def plan_case(robot_w: float, slack: float, offset: float, planner: str, expect_solved: bool):
    def run():
        from cspace import scenario_from_dict
        from ..core.plan import plan

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
