"""Building every slab of an SE(2) C-space: the batched route against the slab-by-slab one.

For each scene, one round builds all K slabs of a fresh ``SE2CSpace`` twice, interleaved:
``new`` with ``cs.slab(k)`` for every k (on the compiled path, runs of slabs built
together by cspace.se2.slab_build), ``legacy`` with the previous route, one slab at a
time (its code kept below as it was: a ``CSpace`` per slab from the obstacles and the slab
hulls, the inner sums by ``minkowski_sum`` pair by pair, the inner grid). The C-space's
own setup (decomposition, pair grid) is outside the timing. Medians over the rounds,
and their ratio; before timing, the two routes' slabs are checked equal (pieces, pairs,
grids, combined grids).

Scenes: a generated random scene of about 256 obstacle vertices with a car-shaped robot,
scenarios/se2/car_maze.toml, scenarios/maze.toml (its square robot, and the car).
Usage: python scripts/bench_slabs.py [--slabs K] [--rounds R] [--size N]
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

import numpy as np

from cspace import CSpace, SE2CSpace, load_scenario
from cspace.kernel.minkowski.merge import minkowski_sum, reflect
from cspace.kernel.slabs.slab import slab_hull, slab_inner
from cspace.compiled import fastpath
from cspace.translation.broadphase import BLOCKED, FREE, GridIndex
from cspace.se2.cspace import SLAB_GRID_CELLS

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CAR = np.array([[-0.6, -0.25], [0.5, -0.25], [0.7, -0.1], [0.7, 0.1], [0.5, 0.25], [-0.6, 0.25]])


def legacy_build(cs, k: int) -> None:
    """Slab k as SE2CSpace._build made it before the batched route (K > 1, a robot)."""
    t = time.perf_counter()
    a, b = cs._lo[k], cs._hi[k]
    hulls = [slab_hull(p, a, b, scale=cs.scale) for p in cs.robot_pieces]
    outer = CSpace(cs.bounds, cs.obstacle_pieces, hulls, grid_cells=cs.grid_cells or SLAB_GRID_CELLS, normalized=True)
    t_outer = time.perf_counter() - t
    inner_pieces = [j for j in (slab_inner(p, a, b, cs.pad) for p in cs.robot_pieces) if len(j) >= 3]
    g = outer.index
    inner = False
    if inner_pieces and cs.obstacle_pieces:
        neg = [reflect(p) for p in inner_pieces]
        sums = [minkowski_sum(o, r) for o in cs.obstacle_pieces for r in neg]
        inner = GridIndex(sums, cs.bounds, shape=(g.nx, g.ny))
    cs._outer[k], cs._inner[k] = outer, inner
    cs._tests[k] = (outer.point_test(), None)
    cs._grids[k] = legacy_combined_grid(cs, k, outer, inner)
    cs._built.append({"slab": k, "seconds": time.perf_counter() - t, "outer_seconds": t_outer,
                      "pieces": len(outer.pieces), "inner_pieces": len(inner_pieces)})


def legacy_combined_grid(cs, k: int, outer, inner) -> tuple:
    """SE2CSpace._combined_grid as it was (the inner grid a whole GridIndex)."""
    g = outer.index
    state = np.where(g.state == FREE, 0, 1).astype(np.uint8)
    if inner:
        h = inner
        assert (h.nx, h.ny, h.x0, h.y0, h.inv_w, h.inv_h) == (g.nx, g.ny, g.x0, g.y0, g.inv_w, g.inv_h)
        state[(h.state == BLOCKED) & (state == 1)] = 2
    flat = state.tobytes()
    nx, ny = g.nx, g.ny
    rows = [flat[r * nx:(r + 1) * nx] + b"\x03" for r in range(ny)] + [b"\x03" * (nx + 1)]
    outer_test = cs._tests[k][0]

    def slow(x: float, y: float, th: float) -> bool:
        if outer_test(x, y):
            return True
        return cs._exact(x, y, th, k)

    slow = fastpath.se2_slow_test(outer._fast, cs._fast, slow, cs.checks)
    return rows, g.inv_w, g.x0 * g.inv_w, g.inv_h, g.y0 * g.inv_h, slow


def build_all(make, legacy: bool) -> tuple[float, SE2CSpace]:
    cs = make()
    t = time.perf_counter()
    for k in range(cs.slabs):
        if legacy:
            legacy_build(cs, k)
        else:
            cs.slab(k)
    return time.perf_counter() - t, cs


def _grid_arrays(g) -> list:
    return [g.state, g.blocker, g._cand, g._starts, np.asarray(g.cand_masks_list), np.array([g.nx, g.ny, g.margin])]


def same_slabs(a: SE2CSpace, b: SE2CSpace) -> bool:
    for k in range(a.slabs):
        x, y = a.slab(k), b.slab(k)
        if len(x.pieces) != len(y.pieces) or not all(np.array_equal(p, q) for p, q in zip(x.pieces, y.pieces)):
            return False
        if x.piece_pairs != y.piece_pairs or a._grids[k][:5] != b._grids[k][:5]:
            return False
        if not all(np.array_equal(p, q) for p, q in zip(_grid_arrays(x.index), _grid_arrays(y.index))):
            return False
        i, j = a._inner[k], b._inner[k]  # the legacy route's inner GridIndex, the new one's BLOCKED cells
        if (i is False) != (j is False) or (i is not False and not np.array_equal(i.state == BLOCKED, j)):
            return False
    return True


def scenes(size: int, slabs: int) -> list:
    from planners.cli.generate import generate

    path = os.path.join(tempfile.mkdtemp(), "random.toml")
    with open(path, "w") as f:
        f.write(generate("random", seed=1, size=size))
    out = []

    def scene(name, file, robot=None):
        sc = load_scenario(file, space="se2")
        if robot is None:
            make = lambda: SE2CSpace.from_scenario(sc, slabs=slabs)  # noqa: E731
        else:
            make = lambda: SE2CSpace(sc.bounds, [o.polygon for o in sc.obstacles], [robot],  # noqa: E731
                                     obstacle_holes=[o.holes for o in sc.obstacles], slabs=slabs)
        verts = sum(len(o.polygon) for o in sc.obstacles)
        out.append((f"{name} ({verts} obstacle vertices)", make))

    scene(f"random --size {size}, car", path, CAR)
    scene("se2/car_maze", os.path.join(ROOT, "scenarios", "se2", "car_maze.toml"))
    scene("maze", os.path.join(ROOT, "scenarios", "maze.toml"))
    scene("maze, car", os.path.join(ROOT, "scenarios", "maze.toml"), CAR)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slabs", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--size", type=int, default=44, help="obstacles of the random scene (44: about 256 vertices)")
    args = ap.parse_args(argv)
    print(f"compiled fast path: {fastpath.compiled()}; K = {args.slabs}; {args.rounds} rounds, interleaved; medians")
    todo = scenes(args.size, args.slabs)
    for name, make in todo:
        if not same_slabs(build_all(make, True)[1], build_all(make, False)[1]):
            print(f"{name}: the two routes' slabs DIFFER")
            return 1
    times = {name: ([], []) for name, _ in todo}
    for r in range(args.rounds):
        for name, make in todo:
            first = r % 2 == 0
            for legacy in ((True, False) if first else (False, True)):
                times[name][0 if legacy else 1].append(build_all(make, legacy)[0])
    print(f"{'scene':<44} {'legacy ms':>10} {'new ms':>10} {'ratio':>7}")
    for name, (old, new) in times.items():
        a, b = statistics.median(old), statistics.median(new)
        print(f"{name:<44} {a * 1e3:>10.1f} {b * 1e3:>10.1f} {a / b:>6.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
