"""Geometry of the paper's escape: extreme points, the virtual new objective, the virtual plane.

Every test is made in the plane's own frame (t along e1 -> e2, n normal to it, pointing
away from the trap), never with fixed x/y comparisons, so it holds for any orientation.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.motion.fields import MIN_DISTANCE_M
from vplane_mj.planning.protocol.vectors import dot, unit


@dataclass(frozen=True)
class VirtualPlane:
    """The segment e1-e2 that closes a trap, with its frame and escape side.

    `normal` points away from the trap's interior; `slide` (+1 or -1) is the direction
    along `tangent` toward the end with the shorter way to the goal.
    """

    e1: np.ndarray
    e2: np.ndarray
    normal: np.ndarray
    slide: float

    @functools.cached_property
    def tangent(self) -> np.ndarray:
        return unit(self.e2 - self.e1)

    @functools.cached_property
    def length(self) -> float:
        return float(np.hypot(*(self.e2 - self.e1)))

    def frame_coordinates(self, point: np.ndarray) -> tuple[float, float]:
        """(along, out): position along e1 -> e2 (m from e1) and signed distance outward (m)."""
        x, y = float(point[0]) - float(self.e1[0]), float(point[1]) - float(self.e1[1])
        (tx, ty), (nx, ny) = self._axes
        return x * tx + y * ty, x * nx + y * ny

    @functools.cached_property
    def _axes(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """The tangent and the normal as floats."""
        return (float(self.tangent[0]), float(self.tangent[1])), (
            float(self.normal[0]),
            float(self.normal[1]),
        )

    def in_corridor(self, point: np.ndarray, influence: float, margin: float) -> bool:
        """Inside the activation corridor: along the segment (+- margin), at most `influence` out."""
        along, out = self.frame_coordinates(point)
        return -margin <= along <= self.length + margin and out <= influence


def make_plane(
    e1: np.ndarray,
    e2: np.ndarray,
    trap_points: np.ndarray,
    robot: np.ndarray,
    goal: np.ndarray,
    extend: float = 0.0,
    to_outermost: bool = True,
) -> VirtualPlane:
    """The plane e1-e2 whose normal points away from the trap's obstacle points (their mean).

    Its normal is never zero: for coincident e1 and e2 it points from the trap's points
    toward the robot.

    Sonar sees a trap's mouth only at its sampled points, so the extreme points lie a
    little inside the true ends: the plane is lengthened by `extend` (m) at both ends and,
    with `to_outermost`, moved out along its normal to the trap's outermost point, so that
    it closes the mouth.
    """
    tangent = unit(e2 - e1)
    normal = np.array([-tangent[1], tangent[0]])
    if not tangent.any():  # e1 = e2: face the robot, away from the trap's points
        normal = unit(robot - np.mean(trap_points, axis=0))
        normal = normal if normal.any() else np.array([1.0, 0.0])
        tangent = np.array([normal[1], -normal[0]])
    if dot(np.mean(trap_points, axis=0) - e1, normal) > 0:
        normal = -normal
    outermost = max(0.0, float(np.max(dot(np.asarray(trap_points) - e1, normal)))) if to_outermost else 0.0
    shift = outermost * normal
    e1, e2 = e1 - extend * tangent + shift, e2 + extend * tangent + shift
    via_e1 = np.hypot(*(e1 - robot)) + np.hypot(*(goal - e1))
    via_e2 = np.hypot(*(e2 - robot)) + np.hypot(*(goal - e2))
    return VirtualPlane(e1=e1, e2=e2, normal=normal, slide=1.0 if via_e2 <= via_e1 else -1.0)


def escape_direction(robot: np.ndarray, e1: np.ndarray, e2: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Unit bisector of the angle e1-robot-e2, turned to point away from the goal (Algorithm 2).

    When the two directions cancel (the robot on the segment) the normal of e1-e2 that
    points away from the goal is used instead.
    """
    bisector = unit(unit(e1 - robot) + unit(e2 - robot))
    if not bisector.any():
        t = unit(e2 - e1)
        bisector = np.array([-t[1], t[0]])
    if dot(bisector, goal - robot) > 0:
        bisector = -bisector
    return bisector


def virtual_objective(
    robot: np.ndarray,
    e1: np.ndarray,
    e2: np.ndarray,
    goal: np.ndarray,
    plane: VirtualPlane,
    clearance: float,
) -> np.ndarray:
    """Algorithm 2: at dis = max(l1, l2) along the escape bisector, then pushed out of the trap.

    Step 3 of the paper moves the objective until it lies outside the trap; here "outside"
    means at least `clearance` (robot radius plus margin) on the plane's outer side.
    """
    direction = escape_direction(robot, e1, e2, goal)
    dis = max(float(np.hypot(*(e1 - robot))), float(np.hypot(*(e2 - robot))))
    objective = robot + dis * direction
    _, out = plane.frame_coordinates(objective)
    if out < clearance:
        push = direction if dot(direction, plane.normal) > 0.2 else plane.normal
        objective = objective + push * (clearance - out) / float(dot(push, plane.normal))
    return objective


def plane_force(
    robot: np.ndarray,
    plane: VirtualPlane,
    gain: float,
    influence: float,
    step: float,
    slide_gain: float,
) -> np.ndarray:
    """Eqs. 8-10: FIRAS repulsion summed over points p_i spaced `step` along the plane.

    Each point's force is weighted by `step` (a line integral), so the total does not grow
    with the number of points. Only the outward (normal) part is kept, computed as if the
    robot stood at least MIN_DISTANCE_M outside, so inside the trap it pushes outward
    hardest. A tangential part `slide_gain` times as large moves the robot along the plane
    toward the end with the shorter way to the goal, so a head-on approach cannot stall.
    """
    from vplane_mj.kernels.motion import fields  # numba: loaded by the first call

    along, out = plane.frame_coordinates(robot)
    return fields.plane_force(
        along,
        out,
        plane.length,
        plane.normal,
        plane.tangent,
        float(plane.slide),
        float(gain),
        float(influence),
        float(step),
        float(slide_gain),
        MIN_DISTANCE_M,
    )
