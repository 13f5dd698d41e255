"""Car scenes for the tests, written from scratch: a room with box obstacles, and a car facing a
wall it cannot turn away from (its answer known by geometry)."""
from __future__ import annotations

import math
import tomllib

from cspace.io.load import scenario_from_dict

# The room's car (1.2 x 0.6, its front 0.95 ahead of the reference point), r = 1, at FACING
# (heading +y) with a wall D ahead: its tightest turn sweeps the outer front corner to
# sqrt(1.3^2 + 0.95^2) = 1.61 ahead, so it turns out where D > 1.61; at D = 1.5 only a radius of
# 0.86 (14 % tighter) would, at D = 1.58 one of 0.96.
FACING, RADIUS = (5.0, 2.0, math.pi / 2), 1.0


def room_toml(obstacles, start, goal, space="dubins") -> str:
    """A room 10 x 8 (the bounds), the alley's car (1.2 x 0.6, r = 1), box obstacles."""
    text = f"""space = "{space}"
turning_radius = 1.0
[bounds]
xmin = 0
xmax = 10
ymin = 0
ymax = 8
[robot]
polygon = [[-0.25, -0.3], [0.95, -0.3], [0.95, 0.3], [-0.25, 0.3]]
[start]
x = {start[0]!r}
y = {start[1]!r}
theta = {start[2]!r}
[goal]
x = {goal[0]!r}
y = {goal[1]!r}
theta = {goal[2]!r}
"""
    for x0, y0, x1, y1 in obstacles:
        text += f"[[obstacles]]\npolygon = [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], [{x0}, {y1}]]\n"
    return text


def wall_scene(d: float, space: str = "dubins"):
    """The room with a wall across it ``d`` ahead of the car at :data:`FACING`, the goal behind it."""
    return scenario_from_dict(tomllib.loads(room_toml([(0, FACING[1] + d, 10, 8)], FACING, (5.0, 1.0, 0.0), space)),
                              "wall")
