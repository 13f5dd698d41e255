"""cspace: exact 2-D geometry for configuration-space motion planning.

The geometry layer: numpy + shapely only, never OMPL or matplotlib. Polygons are
``(N, 2)`` float64 arrays, counter-clockwise. See ``docs/architecture.md``.

Names load on first use (PEP 562): ``import cspace`` costs numpy and little more, and
``cspace.X`` or ``from cspace import X`` imports X's module then.
"""
from __future__ import annotations

import importlib

# name -> the module (of this package) that defines it
_NAMES = {
    "orient2d": "kernel.predicates", "orient2d_many": "kernel.predicates", "cross_sign": "kernel.predicates",
    "as_array": "kernel.polygon", "signed_area": "kernel.polygon", "normalize": "kernel.polygon", "is_convex": "kernel.polygon",
    "is_simple": "kernel.polygon", "lowest_first": "kernel.polygon",
    "disk_polygon": "kernel.disk", "disk_sides": "kernel.disk", "disk_error": "kernel.disk",
    "Scenario": "io.schema", "Shape": "io.schema", "Query": "io.schema", "ScenarioError": "io.messages",
    "load_scenario": "io.scenario", "scenario_from_dict": "io.validate",
    "convex_hull": "kernel.hull",
    "minkowski_sum": "kernel.minkowski", "reflect": "kernel.minkowski",
    "halfplanes": "kernel.halfplane", "support": "kernel.halfplane", "support_point": "kernel.halfplane", "erode": "kernel.halfplane",
    "Distance": "kernel.gjk", "gjk_distance": "kernel.gjk", "gjk_intersects": "kernel.gjk",
    "Penetration": "kernel.epa", "epa_penetration": "kernel.epa",
    "convex_decompose": "kernel.decompose",
    "pairwise_sums": "kernel.pairsums",
    "convolution_cycles": "kernel.convolution", "convex_sums_with": "kernel.convolution",
    "minkowski_pieces": "kernel.nonconvex", "minkowski_sum_nonconvex": "kernel.nonconvex", "UnionError": "kernel.union",
    "CSpace": "spaces.cspace", "decompose_obstacles": "spaces.cspace_build", "decompose_robot": "spaces.cspace_build",
    "rotate": "kernel.slab", "rotate_piece": "kernel.slab", "wrap_angle": "kernel.slab", "slab_hull": "kernel.slab", "slab_inner": "kernel.slab",
    "slab_pad": "kernel.slab", "slab_of": "kernel.slab", "slab_range": "kernel.slab", "inscribed_radius": "kernel.slab",
    "inscribed_polygon": "kernel.slab", "default_slabs": "kernel.slab", "robot_radius": "kernel.slab",
    "interpolate": "spaces.se2_motion",
    "SE2CSpace": "spaces.se2",
    "DirectChecker": "spaces.direct", "cspace_band": "spaces.direct",
    "ShortestPath": "spaces.shortest", "shortest_path": "spaces.shortest",
}

__all__ = sorted(_NAMES)
# Names whose fast route another module registers on import (the compiled pair sum of minkowski_sum).
_WITH = {"minkowski_sum": "spaces.fastpath"}
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in _NAMES:
        if name in _WITH:
            importlib.import_module("." + _WITH[name], __name__)
        value = getattr(importlib.import_module("." + _NAMES[name], __name__), name)
        globals()[name] = value
        return value
    try:  # a submodule: ``cspace.spaces.se2`` after ``import cspace``, as when every module loaded eagerly
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
