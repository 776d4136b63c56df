"""Where the robot may start and end: inside the arena, its footprint clear of walls and obstacles
(moving ones where they are at the run's start).

A round robot (the default profile) is its disc of the model's radius, as it always was; a
robot with an outline polygon (`vplane_mj.robots.profiles`) is that polygon: at the start in its
start heading, at the goal in at least one heading (the heading of arrival is the planner's).
Distances in metres.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from vplane_mj.geometry.shapes import Obstacle, scene_footprints
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario.fields import Invalid
from vplane_mj.scenario.spec import RobotSpec, WorldSpec

GOAL_HEADINGS = 72
"""Headings tried for the footprint at the goal (every 5 degrees)."""


def _check_in_arena(key: str, point: tuple[float, float], size: tuple[float, float]) -> None:
    """The point lies in the free arena [0, W] x [0, H]."""
    (x, y), (w, h) = point, size
    if not (0 <= x <= w and 0 <= y <= h):
        reason = f"must lie inside the arena [0, {w:g}] x [0, {h:g}], got [{x:g}, {y:g}]"
        raise Invalid(key, reason)


def _check_border_gap(key: str, point: tuple[float, float], size: tuple[float, float], radius: float) -> None:
    """With border walls, a round robot's disc at the point stays off them."""
    (x, y), (w, h) = point, size
    gap = min(x, w - x, y, h - y)
    if gap < radius:
        reason = (
            f"is {gap:.3f} m from the arena edge, less than the robot radius ({radius:.3f} m): "
            "the robot would overlap the border wall"
        )
        raise Invalid(key, reason)


def _named_obstacles(world: WorldSpec) -> list[tuple[str, Obstacle]]:
    """Every obstacle with the name messages give it, a moving one where it is at the run's
    start (after its phase)."""
    named = [
        (f"obstacle world.obstacles[{index}]", obstacle)
        for index, obstacle in zip(world.static_indices(), world.obstacles, strict=True)
    ]
    named += [
        (f"moving obstacle world.obstacles[{moving.index}] (where it is at the run's start)", moving.shape)
        for moving in world.moving
    ]
    return named


def _check_obstacle_gaps(points: Mapping[str, tuple[float, float]], world: WorldSpec, radius: float) -> None:
    """A round robot's disc at each point stays off every obstacle."""
    named = _named_obstacles(world)
    if not named:
        return
    xy = np.array(list(points.values()), dtype=float)
    gaps = np.array([scene_footprints([ob]).distance(xy) for _, ob in named])
    for column, key in enumerate(points):
        nearest = int(np.argmin(gaps[:, column]))
        gap = float(gaps[nearest, column])
        where = named[nearest][0]
        if gap < 0:
            raise Invalid(key, f"lies inside {where}")
        if gap < radius:
            limit = f"less than the robot radius ({radius:.3f} m)"
            raise Invalid(key, f"is {gap:.3f} m from {where}, {limit}")


def _check_outline(
    key: str, point: tuple[float, float], headings: np.ndarray, world: WorldSpec, body: RobotBody
) -> None:
    """The robot's outline at the point, in at least one of `headings` (rad), overlaps no
    obstacle and no border wall."""
    things = [(name, scene_footprints([ob])) for name, ob in _named_obstacles(world)]
    if world.border:
        things.append(("the border wall", scene_footprints([], world.size)))
    if not things:
        return
    poses = np.column_stack((np.full(len(headings), point[0]), np.full(len(headings), point[1]), headings))
    gaps = np.array([pieces.outline_distance(body.footprint, poses) for _, pieces in things])
    clearance = gaps.min(axis=0)  # per heading, to the nearest thing
    best = int(np.argmax(clearance))
    if clearance[best] >= 0.0:
        return
    name = things[int(np.argmin(gaps[:, best]))][0]
    where = f"at yaw {math.degrees(headings[0]):g} deg" if len(headings) == 1 else "in every heading"
    reason = f"the {body.profile} robot's footprint {where} overlaps {name} (by {-clearance[best]:.3f} m)"
    raise Invalid(key, reason)


def check_placement(world: WorldSpec, robot: RobotSpec) -> None:
    """Start and goal inside the arena, the robot's footprint there clear of the border walls and
    of the obstacles."""
    points = {"robot.start": robot.start, "robot.goal": robot.goal}
    for key, point in points.items():
        _check_in_arena(key, point, world.size)
    body = robot_body(robot.profile)
    if body.disc:
        if world.border:
            for key, point in points.items():
                _check_border_gap(key, point, world.size, body.radius_m)
        _check_obstacle_gaps(points, world, body.radius_m)
        return
    _check_outline("robot.start", robot.start, np.array([robot.start_yaw]), world, body)
    headings = np.arange(GOAL_HEADINGS) * (2 * math.pi / GOAL_HEADINGS)
    _check_outline("robot.goal", robot.goal, headings, world, body)
