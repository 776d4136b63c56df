"""The robot as a planner knows it: its footprint, its limits and its sensor.

Every planner is built with a `RobotBody` (the planner protocol, `Planner.__init__`): the
footprint polygon in base_link (x forward, y left, metres), the radius of the disc about
base_link's origin that holds it (what a turn in place sweeps), the drive's limits, the heading
controller's gains (so a planner that wants a given speed and turn rate can ask for it with a
force) and the kind of range sensor. Pure data and plane geometry; no MuJoCo.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from vplane_mj.planning.protocol.vectors import rotated

DISC_SIDES = 32
"""Sides of the regular polygon that stands for a disc-shaped robot's footprint."""


@dataclass(frozen=True)
class DriveLimits:
    """What the drive can do. The defaults are the default robot's.

    Attributes:
        max_speed_mps: Top speed (m/s).
        max_turn_rate_radps: Top turn rate (rad/s).
        max_accel_mps2: Forward acceleration and braking (m/s^2).
        max_turn_accel_radps2: Turn-rate acceleration (rad/s^2).
        turn_lag_s: How long the robot's turn rate trails its drive's turn command (s): a
            skid-steer robot's tyres slip before they turn it.
        turning_brake_mps2: The braking the body still gets while it turns at half its top
            turn rate or faster (m/s^2): a skid-steer's tyres spend their grip dragging
            sideways; None: `max_accel_mps2`.
    """

    max_speed_mps: float = 0.5
    max_turn_rate_radps: float = 2.5
    max_accel_mps2: float = 4.0
    max_turn_accel_radps2: float = 30.0
    turn_lag_s: float = 0.0
    turning_brake_mps2: float | None = None

    @property
    def braking_in_turn_mps2(self) -> float:
        """The braking (m/s^2) left while turning hard: `turning_brake_mps2`, or
        `max_accel_mps2` when the drive does not say."""
        return self.max_accel_mps2 if self.turning_brake_mps2 is None else self.turning_brake_mps2


@dataclass(frozen=True)
class HeadingGains:
    """The heading controller's law (vplane_mj/sim/control.py): v = speed_gain |F| max(0, cos e)
    and omega = turn_gain e, e the angle from the heading to the force F, both limited by the
    drive. The defaults are the default robot's.

    Attributes:
        speed_gain: Speed per unit of force ((m/s) per unit).
        turn_gain: Turn rate per radian of heading error (1/s).
    """

    speed_gain: float = 0.5
    turn_gain: float = 3.0


@dataclass(frozen=True, eq=False)
class RobotBody:
    """A robot's footprint, limits, controller gains and sensor kind (see the module docstring).

    Attributes:
        footprint: A convex polygon (k, 2), counter-clockwise, in base_link (m; x forward, y
            left), read-only; for a round robot the regular polygon about its disc.
        radius_m: The circumscribed radius about base_link's origin (m): what a turn in
            place sweeps.
        disc: Whether the robot is round (its footprint then stands for the disc of
            `radius_m`).
        limits: What the drive can do.
        gains: The heading controller's gains.
        sensor_kind: "sonar" or "laser".
        profile: The robot profile's name ("default", "jackal", ...).
    """

    footprint: np.ndarray
    radius_m: float
    disc: bool = False
    limits: DriveLimits = field(default_factory=DriveLimits)
    gains: HeadingGains = field(default_factory=HeadingGains)
    sensor_kind: str = "sonar"
    profile: str = "default"

    @classmethod
    def round(cls, radius_m: float, **kwargs) -> RobotBody:
        """A round robot of `radius_m` (m): the default robot, and any planner built with a radius."""
        angles = np.arange(DISC_SIDES) * (2 * math.pi / DISC_SIDES)
        corner = radius_m / math.cos(math.pi / DISC_SIDES)  # the polygon holds the disc
        polygon = corner * np.column_stack((np.cos(angles), np.sin(angles)))
        return cls(_frozen(polygon), float(radius_m), disc=True, **kwargs)

    @classmethod
    def polygon(cls, vertices, **kwargs) -> RobotBody:
        """A robot whose footprint is the convex polygon `vertices` [[x, y], ...] (m, base_link)."""
        polygon = np.asarray(vertices, dtype=float).reshape(-1, 2)
        if _signed_area(polygon) < 0:
            polygon = polygon[::-1]
        radius = float(np.max(np.hypot(polygon[:, 0], polygon[:, 1])))
        return cls(_frozen(polygon), radius, disc=False, **kwargs)

    @functools.cached_property
    def half_width_m(self) -> float:
        """Half the robot's width across its heading (m): max |y| of the footprint, or the radius."""
        return self.radius_m if self.disc else float(np.max(np.abs(self.footprint[:, 1])))

    @functools.cached_property
    def inner_radius_m(self) -> float:
        """Radius (m) of the largest disc about base_link's origin inside the footprint: the
        ground the robot covers whatever its heading; the radius for a round robot."""
        if self.disc:
            return self.radius_m
        a = self.footprint
        edge = np.roll(a, -1, axis=0) - a
        # The origin's distance to each edge's line (it lies inside the convex footprint).
        return float(np.min(np.abs(a[:, 0] * edge[:, 1] - a[:, 1] * edge[:, 0]) / np.hypot(*edge.T)))

    @functools.cached_property
    def front_m(self) -> float:
        """How far the footprint reaches ahead of base_link's origin (m)."""
        return self.radius_m if self.disc else float(np.max(self.footprint[:, 0]))

    @functools.cached_property
    def rear_m(self) -> float:
        """How far the footprint reaches behind base_link's origin (m)."""
        return self.radius_m if self.disc else float(-np.min(self.footprint[:, 0]))

    def outline_at(self, x: float, y: float, yaw: float) -> np.ndarray:
        """The footprint (k, 2) in the world for the pose x, y (m) and yaw (rad)."""
        return rotated(self.footprint, yaw) + np.array([x, y])


def _signed_area(polygon: np.ndarray) -> float:
    x, y = polygon[:, 0], polygon[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1)) - np.sum(np.roll(x, -1) * y))


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array, dtype=float)
    array.flags.writeable = False
    return array
