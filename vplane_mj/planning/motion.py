"""How a robot of a given body may move near obstacle points: room ahead, turns, speed.

The potential-field planners ask their body (body.py) three things before they answer a
force, each from obstacle points (echoes or map cells) in the world frame, metres:

- `room_ahead`: how far the robot can drive straight along its heading before a point in
  its way comes within a margin of its circumscribed disc. A robot passes a gap aligned with
  it, so the points in its way are those ahead of its front within its width
  (`half_width_m`) plus a small side margin; it stops where its circumscribed disc clears
  them by a margin, so that it can still turn there.
- `free_turn`: how far the footprint can turn in place toward a side before it comes within
  the margin of a point it is not already that close to. Turning is what sweeps the
  circumscribed radius (`radius_m`): a 0.51 x 0.43 m rectangle's corners reach 0.33 m.
  A round robot's turn sweeps nothing new, so it is always free.
- `SpeedPolicy`: the force magnitude that asks the heading controller (v = k_v |F| cos e) for
  no more than the speed the robot can still brake from within the room ahead, after one
  control period at that speed, at most its top speed: v (t + v / 2a) <= room; and, on a
  known way ahead, no more than lets it turn toward each of the way's points before it gets
  there (`bend_speed`).

A robot that brakes from its top speed within `SHAPED_STOP_M` (the default robot: 0.03 m,
the TurtleBot3: 0.01 m) is not slowed by the policy: its fields' own repulsion stops it, and
its decisions stay as they were.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.body import RobotBody
from vplane_mj.planning.vectors import wrap_angle

SHAPED_STOP_M = 0.1
"""A robot whose braking distance from its top speed is at most this (m) is not slowed."""
TURN_STEP_RAD = math.radians(7.5)
"""Turns in place are checked at orientations this far apart (rad)."""
BLOCKED_TURN_RAD = math.radians(2.0)
"""A turn that sweeps free less far than this (rad) counts as impossible that way."""


def body_frame(points: np.ndarray, position: np.ndarray, yaw: float) -> np.ndarray:
    """World points (N, 2) in the robot's frame at `position`, `yaw` (x forward, y left; m)."""
    rel = np.asarray(points, float).reshape(-1, 2) - position
    c, s = math.cos(yaw), math.sin(yaw)
    return np.column_stack((c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]))


def room_ahead(body: RobotBody, local: np.ndarray, margin_m: float, side_margin_m: float) -> float:
    """Distance (m) the robot can drive straight ahead before a point of `local` (robot frame,
    m) in its way comes within `margin_m` of its circumscribed disc. The points in its way lie
    ahead of the footprint's front in the corridor of the robot's width plus `side_margin_m` on
    each side. inf when the corridor is empty, 0 when a point is already that close ahead."""
    ahead = (local[:, 0] > body.front_m) & (np.abs(local[:, 1]) < body.half_width_m + side_margin_m)
    if not ahead.any():
        return math.inf
    return max(0.0, float(local[ahead, 0].min()) - body.radius_m - margin_m)


def outline_distances(body: RobotBody, local: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Distance (m) from each point of `local` (N, 2; robot frame) to the footprint turned in
    place by each of `angles` (M,; rad, counter-clockwise): (M, N), 0 inside the footprint."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    # The points turned by -angle: the footprint turned by +angle, seen from the footprint.
    x = c * local[None, :, 0] + s * local[None, :, 1]
    y = -s * local[None, :, 0] + c * local[None, :, 1]
    a = body.footprint
    b = np.roll(a, -1, axis=0)
    edge = b - a
    # Each edge's outward normal (the polygon is counter-clockwise): a point is inside when it
    # lies behind every edge.
    normal = np.column_stack((edge[:, 1], -edge[:, 0])) / np.hypot(edge[:, 0], edge[:, 1])[:, None]
    px, py = x[..., None] - a[:, 0], y[..., None] - a[:, 1]  # (M, N, k)
    outside = (px * normal[:, 0] + py * normal[:, 1]).max(axis=-1) > 0.0
    t = np.clip((px * edge[:, 0] + py * edge[:, 1]) / (edge**2).sum(axis=1), 0.0, 1.0)
    gap = np.hypot(px - t * edge[:, 0], py - t * edge[:, 1]).min(axis=-1)
    return np.where(outside, gap, 0.0)


def free_turn(body: RobotBody, local: np.ndarray, side: float, limit_rad: float, margin_m: float) -> float:
    """How far (rad, up to `limit_rad`) the footprint can turn in place toward `side` (+1
    counter-clockwise, -1 clockwise) before it comes within `margin_m` of a point of `local`
    (robot frame, m) that it is not already that close to; `limit_rad` for a round robot."""
    if body.disc or limit_rad <= 0.0:
        return max(0.0, limit_rad)
    near = local[np.hypot(local[:, 0], local[:, 1]) < body.radius_m + margin_m]
    if not len(near):
        return limit_rad
    steps = max(1, math.ceil(limit_rad / TURN_STEP_RAD))
    angles = math.copysign(1.0, side) * np.linspace(0.0, limit_rad, steps + 1)
    distances = outline_distances(body, near, angles)
    # A point counts against the turn where the turn brings the outline closer than both the
    # margin and the point's distance now (a point already close does not freeze the robot).
    limit = np.minimum(margin_m, distances[0] - 1e-9)
    blocked = (distances[1:] < limit).any(axis=1)
    if not blocked.any():
        return limit_rad
    return float(abs(angles[int(np.argmax(blocked))]))  # the last orientation before the first blocked one


def turn_direction(
    body: RobotBody, local: np.ndarray, yaw: float, direction: float, margin_m: float, room_m: float
) -> float:
    """The direction (rad, world) to steer toward instead of `direction` so the robot never
    turns its footprint into a point: `direction` when the turn there is free; else as far
    toward it as is free, so the robot turns while it creeps ahead; else, when that way is
    shut and the robot cannot creep (no room ahead), as far the other way round as is free."""
    error = float(wrap_angle(direction - yaw))
    side = 1.0 if error >= 0 else -1.0
    reach = free_turn(body, local, side, abs(error), margin_m)
    if reach >= abs(error):
        return direction
    if reach >= BLOCKED_TURN_RAD or room_m > 0.0:
        return yaw + side * reach
    other = free_turn(body, local, -side, 2 * math.pi - abs(error), margin_m)
    return yaw - side * other if other >= BLOCKED_TURN_RAD else yaw


@dataclass(frozen=True)
class SpeedPolicy:
    """The largest speed (m/s) a body can brake from within a distance, as a force magnitude
    (see the module docstring). `period_s` is the control period: a command holds that long."""

    body: RobotBody
    period_s: float = 0.05

    @property
    def active(self) -> bool:
        """Whether the policy ever slows this body: its braking distance from its top speed
        exceeds `SHAPED_STOP_M`."""
        limits = self.body.limits
        return limits.max_speed_mps**2 / (2 * limits.max_accel_mps2) > SHAPED_STOP_M

    def safe_speed(self, room_m: float) -> float:
        """The largest speed v (m/s, at most the top speed) with v t + v^2 / 2a <= room_m."""
        limits = self.body.limits
        if not math.isfinite(room_m):
            return limits.max_speed_mps
        a, t = limits.max_accel_mps2, self.period_s
        v = a * (math.sqrt(t * t + 2 * max(0.0, room_m) / a) - t)
        return min(limits.max_speed_mps, v)

    def bend_speed(self, position: np.ndarray, yaw: float, way: np.ndarray) -> float:
        """The largest speed (m/s, at most the top speed) at which the robot at `position`, `yaw`
        turns to face each point of `way` (N, 2; world, m, in order along it) before it has
        travelled the way's length to that point: v <= s / t(theta), s that length, theta the
        turn and t(theta) the time the drive takes to turn it from rest, its turn rate ramped at
        the top turn acceleration alpha and limited to the top turn rate w: sqrt(2 theta / alpha)
        up to theta = w^2 / 2 alpha, theta / w + w / 2 alpha beyond. Points
        within the robot's circumscribed radius along the way do not count: the robot steers
        for points beyond its own outline."""
        limits = self.body.limits
        steps = np.diff(np.vstack((position, way)), axis=0)
        travelled = np.cumsum(np.hypot(steps[:, 0], steps[:, 1]))
        beyond = travelled >= self.body.radius_m
        if not beyond.any():
            return limits.max_speed_mps
        way, travelled = way[beyond], travelled[beyond]
        rel = way - position
        turn = np.abs(wrap_angle(np.arctan2(rel[:, 1], rel[:, 0]) - yaw))
        rate, accel = limits.max_turn_rate_radps, limits.max_turn_accel_radps2
        time = np.where(
            turn <= rate * rate / (2 * accel), np.sqrt(2 * turn / accel), turn / rate + rate / (2 * accel)
        )
        return float(min(limits.max_speed_mps, (travelled / np.maximum(time, 1e-9)).min()))

    def magnitude(self, speed_mps: float) -> float:
        """The force magnitude that asks the heading controller for `speed_mps` when aligned."""
        return speed_mps / self.body.gains.speed_gain

    def limit(self, force: np.ndarray, speed_mps: float) -> np.ndarray:
        """`force` shortened so it asks for at most `speed_mps` (its direction kept: a force too
        short for a speed still turns the robot)."""
        length = float(np.hypot(force[0], force[1]))
        cap = max(self.magnitude(speed_mps), 1e-6)
        return force * (cap / length) if length > cap else force


@dataclass(frozen=True)
class Governor:
    """A planner's last word on its force, for its body: steered away from a turn in place that
    would sweep the footprint into a point (`turn_direction`, margin `turn_margin_m`), then
    shortened to the speed the robot can brake from within the room ahead (`SpeedPolicy`,
    margin `stop_margin_m`). A robot the margins shut in (no turn, no room) moves as long as
    its footprint touches nothing. For a round robot that `SpeedPolicy` never slows, the force
    as it is."""

    body: RobotBody
    stop_margin_m: float
    turn_margin_m: float

    @property
    def policy(self) -> SpeedPolicy:
        return SpeedPolicy(self.body)

    @property
    def reach_m(self) -> float:
        """How far (m) from base_link's origin obstacles matter to the governor: the
        circumscribed radius, one control period at the top speed, the braking from it and the
        larger margin."""
        limits, period = self.body.limits, self.policy.period_s
        travel = limits.max_speed_mps * (period + limits.max_speed_mps / (2 * limits.max_accel_mps2))
        return self.body.radius_m + travel + max(self.stop_margin_m, self.turn_margin_m)

    @property
    def idle(self) -> bool:
        """Whether the governor leaves every force as it is (a round robot that brakes short)."""
        return self.body.disc and not self.policy.active

    def govern(
        self,
        force: np.ndarray,
        position: np.ndarray,
        yaw: float,
        points: np.ndarray,
        speed_mps: float = math.inf,
    ) -> np.ndarray:
        """`force` (world frame) made safe for the body at `position`, `yaw` among obstacle
        `points` (N, 2; world, m), asking for at most `speed_mps` (m/s) besides."""
        length = float(np.hypot(force[0], force[1]))
        if self.idle or length < 1e-9 or not math.isfinite(length):
            return force
        local = body_frame(points, position, yaw)
        room = room_ahead(self.body, local, self.stop_margin_m, self.turn_margin_m)
        if not self.body.disc:
            wanted = math.atan2(force[1], force[0])
            direction = turn_direction(self.body, local, yaw, wanted, self.turn_margin_m, room)
            if direction == yaw and room <= 0.0:
                # Shut in with the margins: move as long as the footprint touches nothing.
                room = room_ahead(self.body, local, 0.0, 0.0)
                direction = turn_direction(self.body, local, yaw, wanted, 0.0, room)
            if direction != wanted:
                force = length * np.array([math.cos(direction), math.sin(direction)])
        policy = self.policy
        return policy.limit(force, min(speed_mps, policy.safe_speed(room))) if policy.active else force
