"""cspace: exact 2-D geometry for configuration-space motion planning.

The geometry layer: numpy + shapely only, never OMPL or matplotlib. Polygons are
``(N, 2)`` float64 arrays, counter-clockwise. See ``docs/architecture.md``.
"""
from .predicates import orient2d, orient2d_many, cross_sign
from .polygon import as_array, signed_area, normalize, is_convex, is_simple, lowest_first
from .disk import disk_polygon, disk_sides, disk_error
from .scenario import Scenario, Shape, Query, ScenarioError, load_scenario, scenario_from_dict
from .hull import convex_hull
from .minkowski import minkowski_sum, reflect
from .halfplane import halfplanes, support, support_point, erode
from .gjk import Distance, gjk_distance, gjk_intersects
from .epa import Penetration, epa_penetration
from .decompose import convex_decompose
from .pairsums import pairwise_sums
from .convolution import convolution_cycles, convex_sums_with
from .nonconvex import minkowski_pieces, minkowski_sum_nonconvex
from .cspace import CSpace, decompose_obstacles, decompose_robot
from .slab import (rotate, rotate_piece, wrap_angle, slab_hull, slab_inner, slab_pad, slab_of, slab_range,
                   inscribed_radius, inscribed_polygon, default_slabs, robot_radius)
from .se2_motion import interpolate
from .se2 import SE2CSpace
from .direct import DirectChecker, cspace_band
from .shortest import ShortestPath, shortest_path

__version__ = "0.1.0"
