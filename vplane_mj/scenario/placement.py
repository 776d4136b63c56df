"""Where the robot may start and end: inside the arena, its disc clear of walls and obstacles.

The robot's radius is that of models/robot.xml (`vplane_mj.robot`), in metres.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from vplane_mj.robot import robot_radius_m
from vplane_mj.scenario.fields import Invalid
from vplane_mj.scenario.spec import RobotSpec, WorldSpec
from vplane_mj.shapes import scene_footprints


def _check_in_arena(key: str, point: tuple[float, float], size: tuple[float, float]) -> None:
    """The point lies in the free arena [0, W] x [0, H]."""
    (x, y), (w, h) = point, size
    if not (0 <= x <= w and 0 <= y <= h):
        reason = f"must lie inside the arena [0, {w:g}] x [0, {h:g}], got [{x:g}, {y:g}]"
        raise Invalid(key, reason)


def _check_border_gap(key: str, point: tuple[float, float], size: tuple[float, float]) -> None:
    """With border walls, the robot's disc at the point stays off them."""
    (x, y), (w, h), radius = point, size, robot_radius_m()
    gap = min(x, w - x, y, h - y)
    if gap < radius:
        reason = (
            f"is {gap:.3f} m from the arena edge, less than the robot radius ({radius:.3f} m): "
            "the robot would overlap the border wall"
        )
        raise Invalid(key, reason)


def _check_obstacle_gaps(points: Mapping[str, tuple[float, float]], world: WorldSpec) -> None:
    """The robot's disc at each point stays off every obstacle."""
    if not world.obstacles:
        return
    radius = robot_radius_m()
    xy = np.array(list(points.values()), dtype=float)
    gaps = np.array([scene_footprints([ob]).distance(xy) for ob in world.obstacles])
    for column, key in enumerate(points):
        nearest = int(np.argmin(gaps[:, column]))
        gap = float(gaps[nearest, column])
        where = f"obstacle world.obstacles[{nearest}]"
        if gap < 0:
            raise Invalid(key, f"lies inside {where}")
        if gap < radius:
            limit = f"less than the robot radius ({radius:.3f} m)"
            raise Invalid(key, f"is {gap:.3f} m from {where}, {limit}")


def check_placement(world: WorldSpec, robot: RobotSpec) -> None:
    """Start and goal inside the arena, clear of the border walls and of the obstacles."""
    points = {"robot.start": robot.start, "robot.goal": robot.goal}
    for key, point in points.items():
        _check_in_arena(key, point, world.size)
        if world.border:
            _check_border_gap(key, point, world.size)
    _check_obstacle_gaps(points, world)
