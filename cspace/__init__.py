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
    "orient2d": "predicates", "orient2d_many": "predicates", "cross_sign": "predicates",
    "as_array": "polygon", "signed_area": "polygon", "normalize": "polygon", "is_convex": "polygon",
    "is_simple": "polygon", "lowest_first": "polygon",
    "disk_polygon": "disk", "disk_sides": "disk", "disk_error": "disk",
    "Scenario": "scenario", "Shape": "scenario", "Query": "scenario", "ScenarioError": "scenario",
    "load_scenario": "scenario", "scenario_from_dict": "scenario",
    "convex_hull": "hull",
    "minkowski_sum": "minkowski", "reflect": "minkowski",
    "halfplanes": "halfplane", "support": "halfplane", "support_point": "halfplane", "erode": "halfplane",
    "Distance": "gjk", "gjk_distance": "gjk", "gjk_intersects": "gjk",
    "Penetration": "epa", "epa_penetration": "epa",
    "convex_decompose": "decompose",
    "pairwise_sums": "pairsums",
    "convolution_cycles": "convolution", "convex_sums_with": "convolution",
    "minkowski_pieces": "nonconvex", "minkowski_sum_nonconvex": "nonconvex",
    "CSpace": "cspace", "decompose_obstacles": "cspace", "decompose_robot": "cspace",
    "rotate": "slab", "rotate_piece": "slab", "wrap_angle": "slab", "slab_hull": "slab", "slab_inner": "slab",
    "slab_pad": "slab", "slab_of": "slab", "slab_range": "slab", "inscribed_radius": "slab",
    "inscribed_polygon": "slab", "default_slabs": "slab", "robot_radius": "slab",
    "interpolate": "se2_motion",
    "SE2CSpace": "se2",
    "DirectChecker": "direct", "cspace_band": "direct",
    "ShortestPath": "shortest", "shortest_path": "shortest",
}

__all__ = sorted(_NAMES)
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in _NAMES:
        value = getattr(importlib.import_module("." + _NAMES[name], __name__), name)
        globals()[name] = value
        return value
    try:  # a submodule: ``cspace.se2`` after ``import cspace``, as when every module loaded eagerly
        return importlib.import_module(f".{name}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name != f"{__name__}.{name}":
            raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
