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
    "orient2d": "kernel.polygons.predicates", "orient2d_many": "kernel.polygons.predicates", "cross_sign": "kernel.polygons.predicates",
    "as_array": "kernel.polygons.polygon", "signed_area": "kernel.polygons.polygon", "normalize": "kernel.polygons.polygon", "is_convex": "kernel.polygons.polygon",
    "is_simple": "kernel.polygons.polygon", "lowest_first": "kernel.polygons.polygon",
    "disk_polygon": "kernel.polygons.disk", "disk_sides": "kernel.polygons.disk", "disk_error": "kernel.polygons.disk",
    "Scenario": "io.scenario.schema", "Shape": "io.scenario.schema", "Query": "io.scenario.schema", "ScenarioError": "io.scenario.messages",
    "load_scenario": "io.load", "scenario_from_dict": "io.scenario.validate",
    "convex_hull": "kernel.polygons.hull",
    "minkowski_sum": "kernel.minkowski.merge", "reflect": "kernel.minkowski.merge",
    "halfplanes": "kernel.polygons.halfplane", "support": "kernel.polygons.halfplane", "support_point": "kernel.polygons.halfplane", "erode": "kernel.polygons.halfplane",
    "Distance": "kernel.distance.gjk", "gjk_distance": "kernel.distance.gjk", "gjk_intersects": "kernel.distance.gjk",
    "Penetration": "kernel.distance.epa", "epa_penetration": "kernel.distance.epa",
    "convex_decompose": "kernel.polygons.decompose",
    "pairwise_sums": "kernel.minkowski.pairsums",
    "convolution_cycles": "kernel.minkowski.convolution", "convex_sums_with": "kernel.minkowski.convolution",
    "minkowski_pieces": "kernel.minkowski.nonconvex", "minkowski_sum_nonconvex": "kernel.minkowski.nonconvex", "UnionError": "kernel.minkowski.union",
    "CSpace": "translation.cspace", "decompose_obstacles": "translation.build", "decompose_robot": "translation.build",
    "rotate": "kernel.polygons.rotation", "rotate_piece": "kernel.polygons.rotation", "wrap_angle": "kernel.polygons.rotation", "slab_hull": "kernel.slabs.slab", "slab_inner": "kernel.slabs.slab",
    "slab_pad": "kernel.slabs.slab", "slab_of": "kernel.slabs.slab", "slab_range": "kernel.slabs.slab", "inscribed_radius": "kernel.slabs.slab",
    "inscribed_polygon": "kernel.slabs.slab", "default_slabs": "kernel.slabs.slab", "robot_radius": "kernel.slabs.slab",
    "interpolate": "se2.motion",
    "SE2CSpace": "se2.cspace", "CarCSpace": "car.motion",
    "DirectChecker": "translation.direct", "cspace_band": "translation.direct",
    "ShortestPath": "paths.shortest", "shortest_path": "paths.shortest",
}

__all__ = sorted(_NAMES)
# Names whose fast route another module registers on import (the compiled pair sum of minkowski_sum).
_WITH = {"minkowski_sum": "compiled.fastpath"}
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in _NAMES:
        if name in _WITH:
            importlib.import_module("." + _WITH[name], __name__)
        value = getattr(importlib.import_module("." + _NAMES[name], __name__), name)
        globals()[name] = value
        return value
    try:  # a submodule: ``cspace.se2.cspace`` after ``import cspace``, as when every module loaded eagerly
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
