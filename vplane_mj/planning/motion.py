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
from dataclasses import dataclass, field

import numpy as np

from vplane_mj.planning.body import DriveLimits, RobotBody
from vplane_mj.planning.types import Observation
from vplane_mj.planning.vectors import wrap_angle

SHAPED_STOP_M = 0.1
"""A robot whose braking distance from its top speed is at most this (m) is not slowed."""
TURN_STEP_RAD = math.radians(7.5)
"""Turns in place are checked at orientations this far apart (rad)."""
BLOCKED_TURN_RAD = math.radians(2.0)
"""A turn that sweeps free less far than this (rad) counts as impossible that way."""
MOTION_STEP_S = 0.01
"""Time step (s) of a predicted motion (the drive's motor period)."""
CREEP_SHARE = 0.02
"""A command slower than this share of the top speed and of the top turn rate stands still."""
PREDICTION_ERROR = 0.2
"""How far (m) a predicted motion may be off per metre its outline sweeps (travel plus radius
times turn): the margin it keeps grows by this along it."""
INTRUSION_TOLERANCE_M = 1e-4
"""A predicted motion that intrudes less than this (m) on a point's allowed distance is safe."""
SWEEP_STEP_M = 0.02
"""A predicted motion is checked at poses about this far apart (m of travel plus rad of turn)."""


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
    angles = np.asarray(angles, float)
    return pose_distances(body, local, np.column_stack((np.zeros((len(angles), 2)), angles)))


def pose_distances(body: RobotBody, local: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Distance (m) from each point of `local` (N, 2; robot frame) to the footprint at each of
    `poses` (M, 3: x, y in m and yaw in rad, in the robot frame): (M, N), 0 inside the footprint."""
    c, s = np.cos(poses[:, 2])[:, None], np.sin(poses[:, 2])[:, None]
    # The points in the frame of each pose: the footprint moved there, seen from the footprint.
    dx, dy = local[None, :, 0] - poses[:, 0, None], local[None, :, 1] - poses[:, 1, None]
    x, y = c * dx + s * dy, -s * dx + c * dy
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


def brake_speed(distance: float, accel: float, delay_s: float) -> float:
    """The largest speed (or turn rate) v from which a drive that keeps it for `delay_s` (s) and
    then brakes at `accel` stops within `distance`: v t + v^2 / 2a <= distance (any units)."""
    return accel * (math.sqrt(delay_s * delay_s + 2 * max(0.0, distance) / accel) - delay_s)


def ramped(start: float, phases: list[tuple[float, float]], rate: float, time_s: np.ndarray) -> np.ndarray:
    """A ramped drive's speed (or turn rate) at each of `time_s` (s from now): from `start` it
    moves toward each phase's target at `rate` (per s) for the phase's duration (s), in turn;
    after the last phase it holds."""
    value = np.full(len(time_s), float(start))
    begin = 0.0
    for target, duration in phases:
        inside = time_s > begin
        step = np.clip(time_s[inside] - begin, 0.0, duration) * rate
        value[inside] = start + np.clip(target - start, -step, step)
        start += float(np.clip(target - start, -rate * duration, rate * duration))
        begin += duration
    return value


@dataclass
class DriveModel:
    """The drive as a planner's commands move it: a ramped drive moves the command it drives
    toward the one asked for at its accelerations (m/s^2, rad/s^2), the robot's speed follows
    that ramp, and its turn rate follows it `turn_lag_s` late. `advance` keeps the ramp (and
    the ramp's turn rates over the last lag) up to each control tick, `commanded` notes each
    command given, `poses` predicts the motion of the next one."""

    limits: DriveLimits
    ramp: tuple[float, float] = (0.0, 0.0)
    """The command (m/s, rad/s) the drive drives now, on its ramp."""
    command: tuple[float, float] = (0.0, 0.0)
    """The command given last."""
    time_s: float | None = None
    past: list[tuple[float, float]] = field(default_factory=list)
    """(time in s, ramped turn rate in rad/s) at the ticks within the lag, oldest first."""

    def advance(self, time_s: float, measured: tuple[float, float]) -> None:
        """The ramp at `time_s` (s): moved toward the last command since the last tick; at the
        first tick, the `measured` speed (m/s) and turn rate (rad/s)."""
        limits = self.limits
        if self.time_s is None:
            self.ramp = (float(measured[0]), float(measured[1]))
        else:
            elapsed = max(0.0, time_s - self.time_s)
            dv, dw = limits.max_accel_mps2 * elapsed, limits.max_turn_accel_radps2 * elapsed
            v, w = self.ramp
            self.ramp = (
                v + min(dv, max(-dv, self.command[0] - v)),
                w + min(dw, max(-dw, self.command[1] - w)),
            )
        self.time_s = time_s
        self.past = [(t, w) for t, w in self.past if t >= time_s - 2 * limits.turn_lag_s - 1e-9]
        self.past.append((time_s, self.ramp[1]))

    def commanded(self, command: tuple[float, float]) -> None:
        """Note the command given at this tick."""
        self.command = command

    def poses(self, command: tuple[float, float], hold_s: float) -> np.ndarray:
        """The poses (K, 3: x, y in m, yaw in rad; in the robot's frame now) the robot passes
        through when it is given `command` (m/s, rad/s) for `hold_s` (s) and then stops: its
        speed ramps toward `command` for `hold_s` and then to rest; its turn rate is first the
        ramp's of the last `turn_lag_s`, then the same ramp late (its coast: the lag's turn and
        omega^2 / 2 alpha). Poses are kept where the robot has moved about SWEEP_STEP_M (m of
        travel plus rad of turn) since the last kept one; the first and last are always kept."""
        limits = self.limits
        a, alpha, lag = limits.max_accel_mps2, limits.max_turn_accel_radps2, limits.turn_lag_s
        speeds, turns = [(command[0], hold_s), (0.0, math.inf)], [(command[1], hold_s), (0.0, math.inf)]
        end_of_hold = np.array([hold_s])
        v1, w1 = (
            ramped(self.ramp[0], speeds, a, end_of_hold)[0],
            ramped(self.ramp[1], turns, alpha, end_of_hold)[0],
        )
        end = lag + hold_s + max(abs(v1) / a, abs(w1) / alpha)
        t = np.arange(0.0, end + MOTION_STEP_S, MOTION_STEP_S)
        v = ramped(self.ramp[0], speeds, a, t)
        w = ramped(self.ramp[1], turns, alpha, t - lag)
        if lag > 0 and self.time_s is not None:
            times, rates = np.array(self.past).T
            late = t < lag
            w[late] = np.interp(self.time_s + t[late] - lag, times, rates)
        return _integrated(t, v, w)


def _integrated(t: np.ndarray, v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The poses (K, 3) of a robot starting at the origin with speeds `v` (m/s) and turn rates
    `w` (rad/s) at times `t` (s), kept about SWEEP_STEP_M apart (see `DriveModel.poses`)."""
    dt = np.diff(t)
    yaw = np.concatenate(([0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * dt)))
    mid = 0.5 * (yaw[1:] + yaw[:-1])
    ds = 0.5 * (v[1:] + v[:-1]) * dt
    x = np.concatenate(([0.0], np.cumsum(ds * np.cos(mid))))
    y = np.concatenate(([0.0], np.cumsum(ds * np.sin(mid))))
    moved = np.concatenate(([0.0], np.cumsum(np.abs(ds) + np.abs(np.diff(yaw)))))
    keep = np.flatnonzero(np.diff(np.floor(moved / SWEEP_STEP_M), prepend=-1.0) > 0)
    keep = np.union1d(keep, [len(t) - 1])
    return np.column_stack((x[keep], y[keep], yaw[keep]))


def intrusion(body: RobotBody, local: np.ndarray, poses: np.ndarray, margin_m: float) -> float:
    """How far (m) the footprint along `poses` (robot frame; the first is where it starts)
    comes closer to a point of `local` (robot frame) than it may: `margin_m` plus
    PREDICTION_ERROR of the way its outline has swept so far (its travel plus radius_m times
    its turn), or for a point already closer, its distance now (a point already close does
    not freeze the robot, but it may come no closer). 0 when the motion keeps every point at
    its distance."""
    swept = np.concatenate(
        (
            [0.0],
            np.cumsum(
                np.hypot(*np.diff(poses[:, :2], axis=0).T) + body.radius_m * np.abs(np.diff(poses[:, 2]))
            ),
        )
    )
    margins = margin_m + PREDICTION_ERROR * swept
    reach = np.hypot(poses[:, 0], poses[:, 1]).max() + body.radius_m + margins[-1]
    near = local[np.hypot(local[:, 0], local[:, 1]) < reach]
    if not len(near):
        return 0.0
    distances = pose_distances(body, near, poses)
    allowed = np.minimum(margins[:, None], distances[0])
    return float(max(0.0, (allowed - distances).max()))


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
class Steering:
    """What the governor makes of a force: the force to show (the direction the robot steers
    toward) and the body speed (m/s, negative backing) and turn rate (rad/s) to drive, or None
    for the heading controller's answer to the force."""

    force: np.ndarray
    command: tuple[float, float] | None = None


@dataclass(eq=False)
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
    drive: DriveModel = field(init=False)
    """The drive as `steer`'s commands move it."""
    maneuver: str | None = field(default=None, init=False)
    """What a shut-in robot is doing about it: "back" (backing off) or "round" (turning the
    other way round), None while it is not shut in."""

    def __post_init__(self) -> None:
        self.drive = DriveModel(self.body.limits)

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

    def steer(
        self, force: np.ndarray, obs: Observation, points: np.ndarray, speed_mps: float = math.inf
    ) -> Steering:
        """The body speed and turn rate to drive for `force` among obstacle `points` (N, 2;
        world, m), at most `speed_mps` (m/s) besides, and the force to show (its direction where
        the robot steers): see the class docstring. The idle governor's: the force as it is, no
        command."""
        length = float(np.hypot(force[0], force[1]))
        if self.idle:
            return Steering(force)
        self.drive.advance(obs.time_s, obs.velocity)
        if length < 1e-9 or not math.isfinite(length):
            self.maneuver = None
            self.drive.commanded((0.0, 0.0))
            return Steering(force, (0.0, 0.0))
        local = body_frame(points, obs.position, obs.yaw)
        wanted = math.atan2(force[1], force[0])
        side = 1.0 if wrap_angle(wanted - obs.yaw) >= 0 else -1.0
        direction = self._heading(local, obs.yaw, wanted)
        command = None if direction is None else self._forward(local, obs.yaw, direction, length, speed_mps)
        if command is None:
            command = self._back_off(local, side)
        if command is None:  # nowhere to back off to: round the other way
            self.maneuver = "round"
            direction = self._heading(local, obs.yaw, wanted)
            command = (
                (0.0, 0.0) if direction is None else self._forward(local, obs.yaw, direction, length, 0.0)
            )
        command = command or (0.0, 0.0)
        self.drive.commanded(command)
        shown = (
            np.array([math.cos(wanted), math.sin(wanted)])
            if direction is None
            else (np.array([math.cos(direction), math.sin(direction)]))
        )
        return Steering(self.policy.limit(length * shown, abs(command[0])), command)

    def _heading(self, local: np.ndarray, yaw: float, wanted: float) -> float | None:
        """The direction (rad, world) to steer toward for the `wanted` one, or None to back off:
        `wanted` when the turn in place there is free (`free_turn`); else as far toward it as is
        free, the robot creeping ahead while there is room (`room_ahead`); once that way is shut
        with no room ahead, back off (`maneuver` "back") until the turn is free, or when backing
        is not safe, turn the other way round ("round") as far as is free."""
        body, margin = self.body, self.turn_margin_m
        error = float(wrap_angle(wanted - yaw))
        side = 1.0 if error >= 0 else -1.0
        reach = abs(error) if body.disc else free_turn(body, local, side, abs(error), margin)
        if reach >= abs(error):
            self.maneuver = None
            return wanted
        if self.maneuver is None:
            room = room_ahead(body, local, self.stop_margin_m, margin)
            if reach >= BLOCKED_TURN_RAD or room > 0.0:
                return yaw + side * reach
            self.maneuver = "back"
        if self.maneuver == "back":
            return None
        other = free_turn(body, local, -side, 2 * math.pi - abs(error), margin)
        if other >= BLOCKED_TURN_RAD:
            return yaw - side * other
        self.maneuver = None
        return yaw

    def _forward(
        self, local: np.ndarray, yaw: float, direction: float, length: float, speed_mps: float
    ) -> tuple[float, float] | None:
        """The command toward `direction` for a force of `length`: the heading controller's
        speed (at most `speed_mps`) and a turn rate it can brake from before it faces that
        direction, or the nearest safe one (`_admissible`); None when only standing still is
        safe and the robot should move."""
        limits, gains = self.body.limits, self.body.gains
        error = float(wrap_angle(direction - yaw))
        speed = min(limits.max_speed_mps, gains.speed_gain * length * max(0.0, math.cos(error)), speed_mps)
        delay = limits.turn_lag_s + self.policy.period_s
        rate = min(
            limits.max_turn_rate_radps,
            gains.turn_gain * abs(error),
            brake_speed(abs(error), limits.max_turn_accel_radps2, delay),
        )
        return self._admissible((speed, math.copysign(rate, error)), local)

    def _admissible(self, wanted: tuple[float, float], local: np.ndarray) -> tuple[float, float] | None:
        """The command nearest `wanted` (v, omega) whose predicted motion keeps the footprint
        `turn_margin_m` from every point of `local` (robot frame; `intrusion`): slower first,
        then turning less. None when only standing still is safe but `wanted` moves (a
        command slower than a CREEP_SHARE of the top speed and turn rate stands still)."""
        if not self._moves(wanted):
            return (0.0, 0.0)
        speed, turn = wanted
        candidates = dict.fromkeys(
            (speed * f, turn * g) for g in (1.0, 0.5, 0.0) for f in (1.0, 0.5, 0.25, 0.0)
        )
        for command in candidates:
            if self._moves(command) and self._safe(command, local):
                return command
        return None

    def _moves(self, command: tuple[float, float]) -> bool:
        """Whether `command` (m/s, rad/s) moves the robot more than a creep (`CREEP_SHARE`)."""
        limits = self.body.limits
        return (
            abs(command[0]) > CREEP_SHARE * limits.max_speed_mps
            or abs(command[1]) > CREEP_SHARE * limits.max_turn_rate_radps
        )

    def _back_off(self, local: np.ndarray, side: float) -> tuple[float, float] | None:
        """A safe command that backs the robot off, turning its front toward `side` (+1 left) if
        that is safe; None when no back-off is safe."""
        back = -self.back_off_speed
        for command in ((back, side * self.back_off_turn), (back, 0.0), (back / 2, 0.0)):
            if self._safe(command, local):
                self.maneuver = "back"
                return command
        return None

    def _safe(self, command: tuple[float, float], local: np.ndarray) -> bool:
        """Whether the motion predicted for `command` keeps its margins (`intrusion`)."""
        poses = self.drive.poses(command, self.policy.period_s)
        return intrusion(self.body, local, poses, self.turn_margin_m) <= INTRUSION_TOLERANCE_M

    @property
    def back_off_speed(self) -> float:
        """The speed (m/s) at which a shut-in robot backs off: what it brakes from within
        `stop_margin_m`, at most its top speed."""
        limits = self.body.limits
        return min(
            limits.max_speed_mps, brake_speed(self.stop_margin_m, limits.max_accel_mps2, self.policy.period_s)
        )

    @property
    def back_off_turn(self) -> float:
        """The turn rate (rad/s) with which a backing robot swings its front toward the way it
        wants to go: a quarter of its top turn rate."""
        return self.body.limits.max_turn_rate_radps / 4
