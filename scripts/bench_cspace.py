"""The C-space against peers: validity checking inside OMPL, comb ⊕ comb, build stages.

(A) Validity checking inside OMPL. Scene: ``planners.cli.generate.generate("random", seed,
    200)`` (200 random convex 3..8-gons, triangle robot). Three callbacks are installed
    in turn on the same ``SpaceInformation``:
      - no-op: ``lambda state: True`` (the floor any Python callback pays);
      - ours: ``planners.adapters.translation.validity_function(cspace)`` (grid + exact pieces);
      - shapely: translate the robot polygon to the state, ``STRtree.query`` for the
        obstacles whose boxes meet it, then ``intersects`` against those obstacles,
        prepared with ``shapely.prepare`` (obstacles are closed: touching is a collision;
        the reference point must be in the bounds, as for ours). Also timed: the same
        with ``STRtree.query(..., predicate="intersects")``; the faster is the peer.
    Per-state cost is measured with ``si.probabilityOfValidState(N)``: OMPL's own C++
    loop draws N uniform states with its state sampler and calls the checker once per
    state, so the sampling and calling overhead is identical for the three callbacks
    and no Python loop is timed. Rounds are interleaved (each checker once per round)
    and timed in process CPU time (time.process_time; the machine is shared, and wall
    time counted other processes' slices). Figures: medians over rounds of N / seconds
    (states per second), and the ratios ours/no-op (target <= 5) and shapely/ours
    (target >= 5), all measured in one run. ``ob.AllValidStateValidityChecker`` (C++)
    is shown as the floor of the loop itself. Agreement: ours and the shapely checker
    are called on the same seeded uniform states (numpy); each disagreement is
    classified by the shapely distance from the translated robot to the obstacles
    (below BOUNDARY_TOL: on a boundary, where float translation may round either way).
(B) comb ⊕ comb. A = comb(20 teeth): tooth width 1, gap 1 (pitch 2), depth 4, base bar
    height 1, so 39 x 5 units, 80 vertices. B = comb(10 teeth): tooth width 0.5, gap 1
    (pitch 1.5), depth 3, base 0.5, centred on the origin and rotated 30° CCW, 40
    vertices. Timed (medians): ours ``minkowski_sum_nonconvex(A, B)`` (decompose A into
    21 convex pieces, sum each with the whole of B through its convolution cycle, one
    GEOS region per piece, shapely union of the 21); ours ``minkowski_pieces(A, B)``
    (the 21 x 19 = 399 pairwise convex sums, no union); the C-space route ``CSpace(bounds, [A], [-B])``
    (which stores A ⊕ B as convex pieces and never forms the union), in full and
    without its grid index (the decompose + minkowski + prune stages: the sum itself); pyclipper's
    ``MinkowskiSum(B, A, True)`` on coordinates scaled by CLIP_SCALE and rounded, plus
    the union that makes it the full sum: MinkowskiSum(pattern, closed path) is the
    pattern swept along the path's boundary, and A ⊕ B = (∂A ⊕ ∂B) ∪ (A + b0) ∪ (B + a0)
    for vertices a0 of A and b0 of B (both are connected), so the swept result is
    unioned (CT_UNION) with A + b0 and B + a0. Areas: ours, the C-space pieces' union,
    pyclipper's (/ CLIP_SCALE²), and an independent reference: the shapely union of the
    convex hulls of every triangle pair of constrained Delaunay triangulations of A and B.
(C) The ``report()`` stages of every bundled scenario (scenarios/*.toml and
    scenarios/ompl/*.toml): which stages ran, their times, the piece counts before and
    after pruning.

Usage: python scripts/bench_cspace.py [--quick] [--out-json rows.json] [--parts ABC]
(--out-json is checked before any work, never over a bundled scenario, and written atomically.)
"""
from __future__ import annotations

import argparse
import math
import os
import pathlib
import statistics
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchutil import median_time  # noqa: E402
from cspace import CSpace, load_scenario, minkowski_pieces, minkowski_sum_nonconvex, reflect

ROOT = pathlib.Path(__file__).resolve().parent.parent
BOUNDARY_TOL = 1e-9  # robot-obstacle distance below which a disagreement is a boundary case
CLIP_SCALE = 2.0**20  # pyclipper works on integers: coordinates x 2^20, rounded (|x| < 60)
TARGET_NOOP = 5.0  # ours / no-op per-state cost must be at most this
TARGET_PEER = 5.0  # shapely / ours per-state cost must be at least this
TARGET_CLIP = 0.1  # ours / pyclipper time must be at most this
FINE_GRID = 4  # (A) also times a C-space whose grid has this many times the default cells


# ------------------------------------------------------------------ (A) validity in OMPL


def random_scene(seed: int = 0, size: int = 200):
    """The generated random-polygons scenario (a Scenario) with ``size`` obstacles."""
    from planners.cli.generate import generate

    text = generate("random", seed=seed, size=size)
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "random.toml")
        with open(path, "w") as f:
            f.write(text)
        return load_scenario(path)


def shapely_checker(sc, predicate: bool = False):
    """The peer: ``state -> bool`` with shapely 2 (STRtree candidates, prepared intersects).

    The robot's vertices are translated by the state and made a polygon; the reference
    point must lie in the bounds (as for the C-space); obstacles are closed sets.
    With ``predicate`` the tree does the intersects test itself.
    """
    import shapely

    obstacles = [shapely.Polygon(o.polygon, [h for h in o.holes]) for o in sc.obstacles]
    arr = np.array(obstacles, dtype=object)
    shapely.prepare(arr)
    tree = shapely.STRtree(arr)
    if len(sc.robot) != 1:
        raise ValueError("the shapely peer handles one robot polygon")
    robot = np.asarray(sc.robot[0].polygon, dtype=np.float64)
    xmin, xmax, ymin, ymax = sc.bounds
    make, intersects, query = shapely.polygons, shapely.intersects, tree.query

    def is_valid(state) -> bool:
        x, y = state[0], state[1]
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return False
        moved = make(robot + (x, y))
        if predicate:
            return len(query(moved, predicate="intersects")) == 0
        cand = query(moved)
        return not (len(cand) and intersects(arr[cand], moved).any())

    return is_valid


def ompl_space_information(cs, seed: int):
    """A set-up ``SpaceInformation`` over the C-space's bounds (via ``make_setup``)."""
    from planners.adapters.glue import make_setup
    from planners.adapters.translation import TranslationSpace

    ss, space, checker, validator = make_setup(TranslationSpace(cs), "RRT", seed)
    si = ss.getSpaceInformation()
    si.setup()
    return si, (ss, space, checker, validator)


def states_per_second(si, checkers: dict, reps: int, clock=time.process_time) -> dict:
    """Median states/s of each checker inside OMPL: ``{name: (checker, n)}`` ->
    ``{name: (states_per_s, fraction_valid, [per-round seconds per state])}``.

    Each round times ``si.probabilityOfValidState(n)`` once per checker, in turn, so
    a load change on the (shared) machine hits all checkers alike; ratios are taken
    per round and their median reported by the caller. The clock is this process's
    CPU time by default: on a shared 2-core machine wall time also counts the time
    other processes held the core.
    """
    per = {k: [] for k in checkers}
    frac = {}
    for name, (checker, n) in checkers.items():  # warm-up
        si.setStateValidityChecker(checker)
        si.probabilityOfValidState(min(n, 1000))
    for _ in range(reps):
        for name, (checker, n) in checkers.items():
            si.setStateValidityChecker(checker)
            t = clock()
            frac[name] = si.probabilityOfValidState(n)
            per[name].append((clock() - t) / n)
    return {k: (1.0 / statistics.median(v), frac[k], v) for k, v in per.items()}


def per_round(res: dict, name: str) -> list:
    """Per-round seconds per state of one checker of :func:`states_per_second`."""
    return res[name][2]


def agreement(sc, ours, peer, n: int, seed: int) -> dict:
    """Ours vs the shapely checker on ``n`` seeded uniform states: disagreements, split
    into boundary cases (robot within BOUNDARY_TOL of an obstacle) and the rest."""
    import shapely

    rng = np.random.default_rng(seed)
    xmin, xmax, ymin, ymax = sc.bounds
    pts = rng.uniform((xmin, ymin), (xmax, ymax), (n, 2)).tolist()
    obstacles = shapely.union_all([shapely.Polygon(o.polygon, list(o.holes)) for o in sc.obstacles])
    robot = shapely.union_all([shapely.Polygon(r.polygon) for r in sc.robot])
    boundary = away = valid = 0
    examples = []
    for x, y in pts:
        a, b = ours((x, y)), peer((x, y))
        valid += a
        if a != b:
            d = shapely.distance(shapely.transform(robot, lambda c: c + (x, y)), obstacles)
            if d < BOUNDARY_TOL:
                boundary += 1
            else:
                away += 1
                examples.append((x, y, a, b, d))
    return {"states": n, "valid": valid, "disagree_boundary": boundary, "disagree_away": away,
            "examples": examples[:5]}


def part_a(seed: int, size: int, n: int, reps: int, agree_n: int) -> dict:
    """Part (A): states/s of the four checkers inside OMPL, the two ratios, agreement."""
    from planners.adapters.glue import ompl
    from planners.adapters.translation import validity_function

    ob = ompl()[0]
    sc = random_scene(seed, size)
    t = time.perf_counter()
    cs = CSpace.from_scenario(sc)
    build = time.perf_counter() - t
    # The same C-space with a 4x finer grid (fewer MIXED cells, a slower build): the
    # query/build trade-off of the grid's default size, for reference.
    t = time.perf_counter()
    fine = CSpace.from_scenario(sc, grid_cells=FINE_GRID * cs.index.nx * cs.index.ny)
    build_fine = time.perf_counter() - t
    si, keep = ompl_space_information(cs, seed)
    ours = validity_function(cs)
    peer_plain = shapely_checker(sc)
    peer_pred = shapely_checker(sc, predicate=True)
    noop = lambda state: True  # noqa: E731
    row = {"obstacles": len(sc.obstacles), "pieces": len(cs.pieces), "states": n, "reps": reps}
    peer_n = max(1000, n // 20)  # the peers are slower: fewer states, same per-state figure
    res = states_per_second(si, {
        "cpp": (ob.AllValidStateValidityChecker(si), n), "noop": (noop, n), "ours": (ours, n),
        "ours_fine": (validity_function(fine), n),
        "shapely_candidates": (peer_plain, peer_n), "shapely_predicate": (peer_pred, peer_n)}, reps)
    rate = {k: v[0] for k, v in res.items()}
    peer_key = max(("shapely_candidates", "shapely_predicate"), key=rate.get)
    row.update({f"{k}_per_s": v for k, v in rate.items()})
    row["valid_ours"], row["valid_shapely"] = res["ours"][1], res[peer_key][1]
    row["peer"] = peer_key
    row["grid"], row["grid_fine"] = [cs.index.nx, cs.index.ny], [fine.index.nx, fine.index.ny]
    row["mixed_fraction"] = cs.index.stats()["mixed"] / (cs.index.nx * cs.index.ny)
    row["mixed_fraction_fine"] = fine.index.stats()["mixed"] / (fine.index.nx * fine.index.ny)
    row["build_s"], row["build_fine_s"] = build, build_fine
    row["fine_over_noop"] = statistics.median(o / z for o, z in zip(per_round(res, "ours_fine"), per_round(res, "noop")))
    # cost ratios, per round (same load), then the median over rounds
    per = {k: v[2] for k, v in res.items()}
    row["ours_over_noop"] = statistics.median(o / z for o, z in zip(per["ours"], per["noop"]))
    row["peer_over_ours"] = statistics.median(p / o for p, o in zip(per[peer_key], per["ours"]))
    row["agreement"] = agreement(sc, ours, peer_plain, agree_n, seed + 1)
    del keep
    return row


def print_a(r: dict) -> None:
    print(f"\n(A) validity checking inside OMPL: random scene, {r['obstacles']} obstacles, "
          f"{r['pieces']} C-pieces; si.probabilityOfValidState, median of {r['reps']} interleaved rounds")
    print(f"{'checker':>30} {'states/s':>12} {'us/state':>9}")
    names = [("cpp", "C++ AllValid (loop floor)"), ("noop", "no-op Python lambda"), ("ours", "ours (validity_function)"),
             ("ours_fine", f"ours, {FINE_GRID}x grid cells"),
             ("shapely_candidates", "shapely STRtree+prepared"), ("shapely_predicate", "shapely STRtree predicate")]
    for k, label in names:
        v = r[f"{k}_per_s"]
        print(f"{label:>30} {v:>12,.0f} {1e6 / v:>9.3f}")
    ok1 = "ok" if r["ours_over_noop"] <= TARGET_NOOP else "MISSED"
    ok2 = "ok" if r["peer_over_ours"] >= TARGET_PEER else "MISSED"
    print(f"ours / no-op cost (median of per-round ratios): {r['ours_over_noop']:.2f}x (target <= {TARGET_NOOP:g}: {ok1}); "
          f"{r['peer']} / ours cost: {r['peer_over_ours']:.1f}x (target >= {TARGET_PEER:g}: {ok2})")
    print(f"grid {r['grid'][0]}x{r['grid'][1]}: {r['mixed_fraction']:.1%} MIXED cells, build {r['build_s'] * 1e3:.0f} ms; "
          f"{FINE_GRID}x cells ({r['grid_fine'][0]}x{r['grid_fine'][1]}): {r['mixed_fraction_fine']:.1%} MIXED, "
          f"build {r['build_fine_s'] * 1e3:.0f} ms, ours / no-op {r['fine_over_noop']:.2f}x")
    a = r["agreement"]
    print(f"agreement on {a['states']} seeded states ({a['valid']} free): disagreements away from boundaries "
          f"{a['disagree_away']}, on boundaries (< {BOUNDARY_TOL:g}) {a['disagree_boundary']}")
    for ex in a["examples"]:
        print(f"  disagreement at ({ex[0]!r}, {ex[1]!r}): ours {ex[2]}, shapely {ex[3]}, distance {ex[4]:.3g}")


# ------------------------------------------------------------------ (B) comb ⊕ comb


def comb(teeth: int, width: float, gap: float, depth: float, base: float) -> np.ndarray:
    """A CCW comb: a base bar of height ``base`` with ``teeth`` teeth of ``width`` x
    ``depth`` pointing up (+y), ``gap`` apart; lower-left corner at the origin.

    >>> c = comb(3, 1.0, 1.0, 4.0, 1.0)
    >>> n = np.roll(c, -1, 0)
    >>> len(c), float(abs((c[:, 0] * n[:, 1] - c[:, 1] * n[:, 0]).sum()) / 2)  # the shoelace area
    (12, 17.0)
    """
    pitch = width + gap
    length = teeth * pitch - gap
    pts = [(0.0, 0.0), (length, 0.0)]
    for t in range(teeth - 1, -1, -1):  # the top edge, right to left
        x0 = t * pitch
        pts += [(x0 + width, base + depth), (x0, base + depth)]
        if t:
            pts += [(x0, base), (x0 - gap, base)]
    return np.array(pts, dtype=np.float64)


def rotate(P: np.ndarray, degrees: float) -> np.ndarray:
    """P rotated CCW about the origin.

    >>> np.round(rotate(np.array([[1.0, 0.0]]), 90), 12).tolist()
    [[0.0, 1.0]]
    """
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return P @ np.array([[c, s], [-s, c]])


def combs(teeth_a: int = 20, teeth_b: int = 10, angle: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    """The two operands of (B): A = comb(teeth_a; width 1, gap 1, depth 4, base 1);
    B = comb(teeth_b; width 0.5, gap 1, depth 3, base 0.5), centred on the origin
    (bounding box) and rotated ``angle`` degrees CCW."""
    A = comb(teeth_a, 1.0, 1.0, 4.0, 1.0)
    B = comb(teeth_b, 0.5, 1.0, 3.0, 0.5)
    B = rotate(B - (B.min(axis=0) + B.max(axis=0)) / 2, angle)
    return A, B


def clipper_sum(A_int: list, B_int: list) -> list:
    """The full A ⊕ B with pyclipper on integer paths: the swept boundary sum unioned
    with A + b0 and B + a0 (both CCW), each operand filled by the non-zero rule."""
    import pyclipper

    swept = pyclipper.MinkowskiSum(B_int, A_int, True)
    a0, b0 = A_int[0], B_int[0]
    pc = pyclipper.Pyclipper()
    pc.AddPaths(swept, pyclipper.PT_SUBJECT, True)
    for path in ([[x + b0[0], y + b0[1]] for x, y in A_int], [[x + a0[0], y + a0[1]] for x, y in B_int]):
        pc.AddPath(path if pyclipper.Orientation(path) else path[::-1], pyclipper.PT_CLIP, True)
    return pc.Execute(pyclipper.CT_UNION, pyclipper.PFT_NONZERO, pyclipper.PFT_NONZERO)


def clipper_area(paths: list, scale: float) -> float:
    """Area of Clipper's solution paths (outers positive, holes negative) / scale²."""
    import pyclipper

    return sum(pyclipper.Area(p) for p in paths) / scale**2


def triangle_pair_area(A: np.ndarray, B: np.ndarray) -> float:
    """Independent reference: area of the shapely union of the convex hulls of every
    pair of triangles of A and B (constrained Delaunay triangulations)."""
    import shapely

    def tris(P):
        t = shapely.constrained_delaunay_triangles(shapely.Polygon(P))
        return [np.asarray(g.exterior.coords)[:3] for g in t.geoms]

    ta, tb = tris(A), tris(B)
    pts = np.array([(a[:, None, :] + b[None, :, :]).reshape(9, 2) for a in ta for b in tb])
    hulls = shapely.convex_hull(shapely.multipoints(pts))
    return float(shapely.union_all(hulls).area)


def cspace_route(A: np.ndarray, B: np.ndarray) -> CSpace:
    """A ⊕ B as the C-space's pieces: obstacle A, robot -B (the C-space sums A ⊕ (-R))."""
    lo, hi = A.min(axis=0) + B.min(axis=0) - 1, A.max(axis=0) + B.max(axis=0) + 1
    return CSpace((lo[0], hi[0], lo[1], hi[1]), [A], [reflect(B)])


def _one_thread(fn):
    """fn() with GEOS work kept on one thread (``CSPACE_THREADS=1``)."""
    saved = os.environ.get("CSPACE_THREADS")
    os.environ["CSPACE_THREADS"] = "1"
    try:
        return fn()
    finally:
        if saved is None:
            del os.environ["CSPACE_THREADS"]
        else:
            os.environ["CSPACE_THREADS"] = saved


def part_b(reps: int, with_reference: bool = True) -> dict:
    """Part (B): times of ours, the C-space route and pyclipper, their ratios, the areas."""
    import shapely

    A, B = combs()
    A_int = np.rint(A * CLIP_SCALE).astype(np.int64).tolist()
    B_int = np.rint(B * CLIP_SCALE).astype(np.int64).tolist()
    minkowski_sum_nonconvex(A, B)  # warm-up
    cspace_route(A, B)
    t = {
        "ours_s": median_time(lambda: minkowski_sum_nonconvex(A, B), reps),
        "ours_1t_s": _one_thread(lambda: median_time(lambda: minkowski_sum_nonconvex(A, B), reps)),
        "pieces_s": median_time(lambda: minkowski_pieces(A, B), reps),
        "cspace_s": median_time(lambda: cspace_route(A, B), max(3, reps // 4)),  # slow: the grid
        "clipper_sweep_s": median_time(lambda: __import__("pyclipper").MinkowskiSum(B_int, A_int, True), reps),
        "clipper_s": median_time(lambda: clipper_sum(A_int, B_int), reps),
    }
    ours = minkowski_sum_nonconvex(A, B)
    sum_stages = []
    for _ in range(max(3, reps // 4)):
        cs = cspace_route(A, B)
        sum_stages.append(sum(st.seconds for st in cs.stages if st.name != "index"))
    t["cspace_sum_s"] = statistics.median(sum_stages)
    cs_union = shapely.union_all(shapely.polygons(cs.pieces) if len({len(p) for p in cs.pieces}) == 1
                                 else [shapely.Polygon(p) for p in cs.pieces])
    row = {"teeth_a": 20, "teeth_b": 10, "angle": 30.0, "vertices_a": len(A), "vertices_b": len(B),
           "pairs": len(minkowski_pieces(A, B)), "cspace_pieces": len(cs.pieces), "reps": reps, **t,
           "area_ours": ours.area, "area_cspace": cs_union.area,
           "area_clipper": clipper_area(clipper_sum(A_int, B_int), CLIP_SCALE),
           "holes_ours": sum(len(p.interiors) for p in getattr(ours, "geoms", [ours]))}
    row["area_reference"] = triangle_pair_area(A, B) if with_reference else float("nan")
    row["ours_over_clipper"] = t["ours_s"] / t["clipper_s"]
    row["cspace_over_clipper"] = t["cspace_s"] / t["clipper_s"]
    row["cspace_sum_over_clipper"] = t["cspace_sum_s"] / t["clipper_s"]
    ref = row["area_reference"] if with_reference else row["area_clipper"]
    row["reference_kind"] = "triangle pairs (shapely)" if with_reference else "pyclipper"
    for k in ("ours", "cspace", "clipper"):
        row[f"relerr_{k}"] = abs(row[f"area_{k}"] - ref) / ref
    return row


def print_b(r: dict) -> None:
    print(f"\n(B) comb({r['teeth_a']}) ⊕ comb({r['teeth_b']}) rotated {r['angle']:g}°: {r['vertices_a']} x "
          f"{r['vertices_b']} vertices, {r['pairs']} convex pairs ({r['cspace_pieces']} kept by the C-space), "
          f"median of {r['reps']}")
    print(f"{'method':>44} {'time':>10} {'/ pyclipper':>11} {'area':>16} {'rel. err':>9}")
    rows = [("ours: minkowski_sum_nonconvex (convolution)", r["ours_s"], r["area_ours"], r["relerr_ours"]),
            ("the same on one thread (CSPACE_THREADS=1)", r["ours_1t_s"], None, None),
            ("ours: minkowski_pieces (no union)", r["pieces_s"], None, None),
            ("C-space route: CSpace(bounds, [A], [-B])", r["cspace_s"], r["area_cspace"], r["relerr_cspace"]),
            ("C-space route, stages without the index", r["cspace_sum_s"], None, None),
            ("pyclipper MinkowskiSum (swept boundary)", r["clipper_sweep_s"], None, None),
            ("pyclipper MinkowskiSum + union (full sum)", r["clipper_s"], r["area_clipper"], r["relerr_clipper"])]
    for label, s, area, err in rows:
        a = f"{area:>16.9f}" if area is not None else f"{'':>16}"
        e = f"{err:>9.1e}" if err is not None else f"{'':>9}"
        print(f"{label:>44} {s * 1e3:>8.2f}ms {s / r['clipper_s']:>11.3f} {a} {e}")
    print(f"reference area ({r['reference_kind']}): {r['area_reference']:.9f}; holes in ours: {r['holes_ours']}")
    ratio = r["ours_over_clipper"]
    print(f"ours / pyclipper: {ratio:.3f} (target <= {TARGET_CLIP:g}: {'ok' if ratio <= TARGET_CLIP else 'MISSED'}); "
          f"on one thread: {r['ours_1t_s'] / r['clipper_s']:.3f}")
    for k in ("cspace", "cspace_sum"):  # the C-space keeps the pieces (and builds its grid): no target
        print(f"{k} / pyclipper: {r[f'{k}_over_clipper']:.3f}")


# ------------------------------------------------------------------ (C) stages per scenario


def scenario_files() -> list[pathlib.Path]:
    """Every bundled scenario file."""
    return sorted((ROOT / "scenarios").glob("*.toml")) + sorted((ROOT / "scenarios" / "ompl").glob("*.toml"))


def stage_row(path, reps: int = 1) -> dict:
    """The ``report()`` of one scenario's C-space, flattened to one row; with ``reps`` > 1
    the scenario is loaded and built ``reps`` times, each stage's seconds (and the build's)
    the median of the builds."""
    reports = [CSpace.from_scenario(path).report() for _ in range(max(1, reps))]
    rep = reports[0]
    for k, s in enumerate(rep["stages"]):
        s["seconds"] = statistics.median(r["stages"][k]["seconds"] for r in reports)
    rep["build_seconds"] = statistics.median(r["build_seconds"] for r in reports)
    row = {"scenario": str(pathlib.Path(path).relative_to(ROOT)) if pathlib.Path(path).is_absolute()
           else str(path), "pieces": rep["pieces"], "robot_pieces": rep["robot_pieces"],
           "obstacle_pieces": rep["obstacle_pieces"], "build_s": rep["build_seconds"],
           "stages": rep["stages"]}
    st = {s["stage"]: s for s in rep["stages"]}
    row["ran"] = [s["stage"] for s in rep["stages"] if s["ran"]]
    row["skipped"] = [s["stage"] for s in rep["stages"] if not s["ran"]]
    prune = st.get("prune", {})
    row["before"] = prune.get("pieces_before")
    row["outside"] = prune.get("outside_bounds")
    row["inside"] = prune.get("inside_another")
    row["after"] = prune.get("pieces_after")
    return row


STAGES = ("load", "decompose_obstacles", "decompose_robot", "minkowski", "prune", "index")


def part_c(reps: int = 9) -> list[dict]:
    return [stage_row(p, reps) for p in scenario_files()]


def index_share(row: dict) -> float | None:
    """The grid index's share of the build's stages (load excluded), None without an index."""
    st = {s["stage"]: s["seconds"] for s in row["stages"] if s["ran"]}
    total = sum(v for k, v in st.items() if k != "load")
    return st["index"] / total if "index" in st and total > 0 else None


def print_c(rows: list[dict]) -> None:
    print("\n(C) build stages per bundled scenario (ms; '-' = stage skipped, with its note below)")
    short = {"load": "load", "decompose_obstacles": "dec_obs", "decompose_robot": "dec_rob",
             "minkowski": "sums", "prune": "prune", "index": "index"}
    head = "".join(f"{short[s]:>9}" for s in STAGES)
    print(f"{'scenario':>28} {'obs.pcs':>7} {'rob.pcs':>7} {'before':>7} {'out':>5} {'in':>5} {'after':>6}{head} "
          f"{'total':>9} {'index %':>8}")
    notes = {}
    for r in rows:
        st = {s["stage"]: s for s in r["stages"]}
        cells = ""
        for s in STAGES:
            if s not in st:
                cells += f"{'n/a':>9}"
            elif st[s]["ran"]:
                cells += f"{st[s]['seconds'] * 1e3:>9.2f}"
            else:
                cells += f"{'-':>9}"
                notes.setdefault(st[s]["note"], []).append(pathlib.Path(r["scenario"]).stem)
        share = index_share(r)
        print(f"{r['scenario']:>28} {r['obstacle_pieces']:>7} {r['robot_pieces']:>7} {r['before']:>7} "
              f"{r['outside']:>5} {r['inside']:>5} {r['after']:>6}{cells} {r['build_s'] * 1e3:>9.2f} "
              f"{'-' if share is None else f'{100 * share:.0f}':>8}")
    for note, who in notes.items():
        print(f"  skipped ({note}): {', '.join(sorted(set(who)))}")
    shares = [(index_share(r), r["scenario"]) for r in rows if index_share(r) is not None]
    if shares:
        worst = max(shares)
        print(f"index share of the build (median of each stage over the builds; load excluded): median "
              f"{100 * statistics.median(s for s, _ in shares):.0f} %, max {100 * worst[0]:.0f} % ({worst[1]}); "
              f"at most 50 % on {sum(s <= 0.5 for s, _ in shares)} of {len(shares)} scenes")


# ------------------------------------------------------------------ main


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer states and repetitions")
    ap.add_argument("--parts", default="ABC", help="which parts to run (subset of ABC)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out-json", default=None, help="write all rows as JSON")
    args = ap.parse_args(argv)
    from benchutil import check_json, write_json

    check_json(args.out_json, [ROOT / "scenarios", ROOT / "scenarios" / "ompl"], "--out-json")  # (never over a scene)
    out = {}
    parts = args.parts.upper()
    if "A" in parts:
        n, reps, agree_n = (20000, 5, 2000) if args.quick else (50000, 21, 20000)
        out["A"] = part_a(args.seed, 200, n, reps, agree_n)
        print_a(out["A"])
    if "B" in parts:
        out["B"] = part_b(5 if args.quick else 21)
        print_b(out["B"])
    if "C" in parts:
        out["C"] = part_c(3 if args.quick else 9)
        print_c(out["C"])
    if args.out_json:
        write_json(args.out_json, out, "--out-json", default=str)
    sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
