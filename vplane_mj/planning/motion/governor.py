"""How a robot of a given body may move near obstacle points: room ahead, turns, speed.

The potential-field planners hand their force to their body's `Governor`, which answers the
body speed and turn rate to drive (`Steering`), from obstacle points (echoes and map cells)
in the world frame, metres:

- The drive as the governor's commands move it (`DriveModel`): a ramped drive moves the
  command it drives toward the one asked for at its accelerations; the robot's speed follows
  that ramp (or, measured faster by its wheels or its poses, as a skid-steer braking in a hard
  turn, slows from where it is), its turn rate follows it `turn_lag_s` late (a skid-steer
  robot's tyres slip). So the robot goes on turning after its turn command changes: a turn at
  omega coasts omega |omega| / 2 alpha (and the lag's turn) before it stops, as a speed v
  brakes in v^2 / 2a. A robot turning hard brakes slower (`braking`: a skid-steer's tyres
  spend their grip dragging sideways), and the sideways slide its poses show fades at that
  braking too.
- The check of a command (`intrusion`): the footprint along the motion it predicts (the
  command for one control period, then braking to rest) must keep a margin from every point,
  the margin growing with the way the outline sweeps (`PREDICTION_ERROR`: the prediction is
  the less sure the farther it reaches); a point already closer may come no closer.
- The command: the heading controller's (v = k_v |F| cos e, omega = k_w e) with a turn rate
  it can brake from before it faces the force (`brake_speed`), or the nearest one that passes
  the check, slower first, then turning less. The direction is the force's when the turn in
  place there is free (`free_turn`: turning is what sweeps the circumscribed radius, a 0.51 x
  0.43 m rectangle's corners reach 0.33 m), else as far toward it as is free while the robot
  can creep ahead (`room_ahead`). A robot shut in (that way shut, no room ahead, or only
  standing still passing the check) backs off until the turn is free, or if it cannot, turns
  the other way round.
- `SpeedPolicy`: on a known way ahead, no faster than lets the robot turn toward each of the
  way's points before it gets there (`bend_speed`), and the force magnitude of a speed.

A round robot that brakes from its top speed within `SHAPED_STOP_M` (the default robot:
0.03 m) is not governed: its fields' own repulsion stops it, and its decisions stay as they
were.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from vplane_mj.planning.motion.evasion import Evasion
from vplane_mj.planning.protocol.body import DriveLimits, RobotBody
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.planning.protocol.vectors import evenly_spaced, wrap_angle

SHAPED_STOP_M = 0.1
"""A round robot whose braking distance from its top speed is at most this (m) is not governed."""
TURN_STEP_RAD = math.radians(7.5)
"""Turns in place are checked at orientations this far apart (rad)."""
BLOCKED_TURN_RAD = math.radians(2.0)
"""A turn that sweeps free less far than this (rad) counts as impossible that way."""
MOTION_STEP_S = 0.01
"""Time step (s) of a predicted motion (the drive's motor period)."""
CREEP_SHARE = 0.02
"""A command slower than this share of the top speed and of the top turn rate stands still."""
MEMORY_CELL_M = 0.02
"""The governor remembers one obstacle point per square this wide (m)."""
SQUEEZED_SHARE = 1 / 3
"""A robot that no motion keeps its turn margin from obstacles creeps straight on or back
keeping this share of it."""
PREDICTION_ERROR = 0.2
"""How far (m) a predicted motion may be off per metre its outline sweeps (travel plus radius
times turn): the margin it keeps grows by this along it."""
INTRUSION_TOLERANCE_M = 1e-4
"""A predicted motion that intrudes less than this (m) on a point's allowed distance is safe."""
SWEEP_STEP_M = 0.02
"""A predicted motion is checked at poses about this far apart (m of travel plus rad of turn)."""
_NO_PAST = (0.0, np.empty(0), np.empty(0))
"""No ticks to take turn rates from (before the first tick)."""


def room_ahead(body: RobotBody, local: np.ndarray, margin_m: float, side_margin_m: float) -> float:
    """Distance (m) the robot can drive straight ahead before a point of `local` (robot frame,
    m) in its way comes within `margin_m` of its circumscribed disc. The points in its way lie
    ahead of the footprint's front in the corridor of the robot's width plus `side_margin_m` on
    each side. inf when the corridor is empty, 0 when a point is already that close ahead."""
    ahead = (local[:, 0] > body.front_m) & (np.abs(local[:, 1]) < body.half_width_m + side_margin_m)
    if not ahead.any():
        return math.inf
    return max(0.0, float(local[ahead, 0].min()) - body.radius_m - margin_m)


@functools.lru_cache(maxsize=16)
def _outline(body: RobotBody) -> tuple[np.ndarray, np.ndarray]:
    """The footprint (k, 2) and each edge's outward unit normal (k, 2; the polygon is
    counter-clockwise), as the kernels take them; made once per body (a body is hashed by
    identity), shared by every call, so never written."""
    a = np.ascontiguousarray(body.footprint, float)
    edge = np.roll(a, -1, axis=0) - a
    return a, np.column_stack((edge[:, 1], -edge[:, 0])) / np.hypot(edge[:, 0], edge[:, 1])[:, None]


def free_turn(body: RobotBody, local: np.ndarray, side: float, limit_rad: float, margin_m: float) -> float:
    """How far (rad, up to `limit_rad`) the footprint can turn in place toward `side` (+1
    counter-clockwise, -1 clockwise) before it comes within `margin_m` of a point of `local`
    (robot frame, m) that it is not already that close to; `limit_rad` for a round robot."""
    if body.disc or limit_rad <= 0.0:
        return max(0.0, limit_rad)
    from vplane_mj.kernels.motion import outline  # numba: loaded by the first call

    steps = max(1, math.ceil(limit_rad / TURN_STEP_RAD))
    angles = math.copysign(1.0, side) * evenly_spaced(0.0, limit_rad, steps + 1)
    footprint, normals = _outline(body)
    # A point counts against the turn where the turn brings the outline closer than both the
    # margin and the point's distance now (a point already close does not freeze the robot).
    local = np.ascontiguousarray(local, float).reshape(-1, 2)
    blocked = outline.first_blocked_turn(
        footprint, normals, local, body.radius_m + margin_m, angles, margin_m
    )
    return limit_rad if blocked < 0 else float(abs(angles[blocked - 1]))  # the last before it


def brake_speed(distance: float, accel: float, delay_s: float) -> float:
    """The largest speed (or turn rate) v from which a drive that keeps it for `delay_s` (s) and
    then brakes at `accel` stops within `distance`: v t + v^2 / 2a <= distance (any units)."""
    return accel * (math.sqrt(delay_s * delay_s + 2 * max(0.0, distance) / accel) - delay_s)


@dataclass
class DriveModel:
    """The drive as a planner's commands move it: a ramped drive moves the command it drives
    toward the one asked for at its accelerations (m/s^2, rad/s^2), the robot's speed follows
    that ramp (a robot measured faster than its ramp, by its wheels or its poses, as a
    skid-steer braking in a hard turn, slows from its measured speed), its turn rate follows it
    `turn_lag_s` late, and a robot turning hard brakes slower (`braking`). `advance` keeps the
    ramp (and the ramp's turn rates over the last lag) and the robot's motion up to each
    control tick, `commanded` notes each command given, `poses` predicts the motion of the
    next one."""

    limits: DriveLimits
    ramp: tuple[float, float] = (0.0, 0.0)
    """The command (m/s, rad/s) the drive drives now, on its ramp."""
    command: tuple[float, float] = (0.0, 0.0)
    """The command given last."""
    time_s: float | None = None
    period_s: float = 0.05
    """The control period (s): the time between the last two ticks (the default run's 20 Hz
    before the second)."""
    past: list[tuple[float, float]] = field(default_factory=list)
    """(time in s, ramped turn rate in rad/s) at the ticks within the lag, oldest first."""
    speed: float = 0.0
    """The robot's measured speed (m/s) at the last tick: its wheels' or, when faster along its
    heading, its poses' over the last tick."""
    turn: float = 0.0
    """The robot's turn rate (rad/s) its wheels measured at the last tick."""
    slide: float = 0.0
    """The robot's speed (m/s) to its left, across its heading, over the last tick (its poses')."""
    pose: tuple[float, float, float] | None = None
    """The robot's pose (x, y in m; yaw in rad; world) at the last tick, when given."""

    def advance(
        self, time_s: float, measured: tuple[float, float], pose: tuple[float, float, float] | None = None
    ) -> None:
        """The ramp at `time_s` (s): moved toward the last command since the last tick; at the
        first tick, the `measured` speed (m/s) and turn rate (rad/s). With the robot's `pose`
        (x, y in m, yaw in rad; world), its motion since the last tick's: how fast it went
        along its heading and across it."""
        limits = self.limits
        moved = None
        if pose is not None and self.pose is not None and self.time_s is not None and time_s > self.time_s:
            elapsed = time_s - self.time_s
            vx, vy = (pose[0] - self.pose[0]) / elapsed, (pose[1] - self.pose[1]) / elapsed
            c, s = math.cos(pose[2]), math.sin(pose[2])
            moved = (c * vx + s * vy, -s * vx + c * vy)
        self.pose = pose
        if self.time_s is None:
            self.ramp = (float(measured[0]), float(measured[1]))
        else:
            elapsed = max(0.0, time_s - self.time_s)
            self.period_s = elapsed or self.period_s
            dv, dw = limits.max_accel_mps2 * elapsed, limits.max_turn_accel_radps2 * elapsed
            v, w = self.ramp
            self.ramp = (
                v + min(dv, max(-dv, self.command[0] - v)),
                w + min(dw, max(-dw, self.command[1] - w)),
            )
        self.time_s = time_s
        self.speed, self.turn, self.slide = float(measured[0]), float(measured[1]), 0.0
        if moved is not None:
            self.slide = moved[1]
            if abs(moved[0]) > abs(self.speed):
                self.speed = moved[0]
        self.past = [(t, w) for t, w in self.past if t >= time_s - 2 * limits.turn_lag_s - 1e-9]
        self.past.append((time_s, self.ramp[1]))

    def commanded(self, command: tuple[float, float]) -> None:
        """Note the command given at this tick."""
        self.command = command

    def braking(self, command: tuple[float, float]) -> float:
        """The braking (m/s^2) of the motion `command` starts: the top acceleration, less as the
        robot turns harder (the fastest of the command's, the ramp's and the measured turn
        rate), down to the drive's braking in a turn at half the top turn rate and beyond."""
        limits = self.limits
        full, turning = limits.max_accel_mps2, limits.braking_in_turn_mps2
        turn = max(abs(command[1]), abs(self.ramp[1]), abs(self.turn))
        return full - (full - turning) * min(1.0, turn / (limits.max_turn_rate_radps / 2))

    def poses(self, command: tuple[float, float], hold_s: float) -> np.ndarray:
        """The poses (K, 3: x, y in m, yaw in rad; in the robot's frame now) the robot passes
        through when it is given `command` (m/s, rad/s) for `hold_s` (s) and then stops: its
        speed ramps toward `command` for `hold_s` (at the top acceleration speeding up, at
        `braking` slowing) and then to rest at `braking`; its turn rate is first the ramp's of
        the last `turn_lag_s`, then the same ramp late (its coast: the lag's turn and
        omega^2 / 2 alpha); its slide across its heading fades at `braking`. Poses are kept
        where the robot has moved about SWEEP_STEP_M (m of travel plus rad of turn) since the
        last kept one; the first and last are always kept."""
        from vplane_mj.kernels.motion import drive_model  # numba: loaded by the first call

        limits = self.limits
        brake = self.braking(command)
        # A robot faster than its ramp (a skid-steer braking in a hard turn) slows from its speed.
        start = self.speed if abs(self.speed) > abs(self.ramp[0]) else self.ramp[0]
        faster = abs(command[0]) > abs(start) and command[0] * start >= 0
        past = _NO_PAST
        if self.time_s is not None:
            times, rates = np.array(self.past).T
            past = (self.time_s, times, rates)
        return drive_model.command_poses(
            (float(command[0]), float(command[1])),
            float(hold_s),
            (float(start), float(self.ramp[1]), float(self.slide)),
            (limits.max_accel_mps2, brake, limits.max_turn_accel_radps2, 1.0 if faster else 0.0),
            limits.turn_lag_s,
            past,
            (MOTION_STEP_S, SWEEP_STEP_M),
        )


def intrusion(
    body: RobotBody, local: np.ndarray, poses: np.ndarray, margin_m: float, enough: float = math.inf
) -> float:
    """How far (m) the footprint along `poses` (robot frame; the first is where it starts)
    comes closer to a point of `local` (robot frame) than it may: `margin_m` plus
    PREDICTION_ERROR of the way its outline has swept so far (its travel plus radius_m times
    its turn), or for a point already closer, its distance now (a point already close does
    not freeze the robot, but it may come no closer). 0 when the motion keeps every point at
    its distance. With `enough` (m), any value above it once one is found (`kernels.outline`)."""
    from vplane_mj.kernels.motion import outline  # numba: loaded by the first call

    footprint, normals = _outline(body)
    return outline.intrusion(
        footprint,
        normals,
        float(body.radius_m),
        np.ascontiguousarray(local, float).reshape(-1, 2),
        np.ascontiguousarray(poses, float),
        float(margin_m),
        PREDICTION_ERROR,
        float(enough),
    )


@dataclass(frozen=True)
class SpeedPolicy:
    """The speeds (m/s) a body may drive at along a way, and their force magnitudes (see the
    module docstring)."""

    body: RobotBody

    @property
    def active(self) -> bool:
        """Whether the policy ever slows this body: its braking distance from its top speed
        exceeds `SHAPED_STOP_M`."""
        limits = self.body.limits
        return limits.max_speed_mps**2 / (2 * limits.max_accel_mps2) > SHAPED_STOP_M

    def bend_speed(
        self, position: np.ndarray, yaw: float, way: np.ndarray, horizon_m: float = math.inf
    ) -> float:
        """The largest speed (m/s, at most the top speed) at which the robot at `position`, `yaw`
        turns to face each point of `way` (N, 2; world, m, in order along it) before it has
        travelled the way's length to that point: v <= s / t(theta), s that length, theta the
        turn and t(theta) the time the drive takes to turn it from rest, its turn rate ramped at
        the top turn acceleration alpha and limited to the top turn rate w: sqrt(2 theta / alpha)
        up to theta = w^2 / 2 alpha, theta / w + w / 2 alpha beyond. Points
        within the robot's circumscribed radius along the way do not count: the robot steers
        for points beyond its own outline; nor do points beyond `horizon_m` (m) along it
        (`kernels.way`)."""
        from vplane_mj.kernels.motion import way as way_kernels  # numba: loaded by the first call

        limits = self.body.limits
        rel = way - position
        return way_kernels.bend_speed(
            float(position[0]),
            float(position[1]),
            float(yaw),
            np.ascontiguousarray(way, float),
            np.arctan2(rel[:, 1], rel[:, 0]),
            float(horizon_m),
            float(self.body.radius_m),
            (limits.max_speed_mps, limits.max_turn_rate_radps, limits.max_turn_accel_radps2),
        )

    def magnitude(self, speed_mps: float) -> float:
        """The force magnitude that asks the heading controller for `speed_mps` when aligned."""
        return speed_mps / self.body.gains.speed_gain

    def limit(self, force: np.ndarray, speed_mps: float) -> np.ndarray:
        """`force` shortened so it asks for at most `speed_mps` (its direction kept: a force too
        short for a speed still turns the robot)."""
        length = float(np.hypot(force[0], force[1]))
        cap = max(self.magnitude(speed_mps), 1e-6)
        return force * (cap / length) if length > cap else force


def _view(bearings: np.ndarray, beam_width: float) -> tuple[int, float, float]:
    """The field of view of a scan's `bearings` (rad, robot frame), each beam `beam_width` wide
    (rad), as `kernels.memory.recall` takes it: the span of the bearings, widened by half a
    beam each way (1: all round; 0: no beams; else -1, its first bearing (rad, robot frame) and
    its width (rad))."""
    if not len(bearings):
        return 0, 0.0, 0.0
    half = beam_width / 2
    low, high = float(np.min(bearings)) - half, float(np.max(bearings)) + half
    if high - low >= 2 * math.pi:
        return 1, low, 0.0
    return -1, low, high - low


@dataclass(frozen=True)
class Steering:
    """What the governor makes of a force: the force to show (the direction the robot steers
    toward) and the body speed (m/s, negative backing) and turn rate (rad/s) to drive, or None
    for the heading controller's answer to the force."""

    force: np.ndarray
    command: tuple[float, float] | None = None


@dataclass(eq=False)
class Governor:
    """A planner's last word on its force, for its body: the body speed and turn rate to drive
    for it (`steer`, see the module docstring), with margins `stop_margin_m` (the room ahead
    a robot creeps into while it turns, and the braking of its back-off) and `turn_margin_m`
    (what turns and every predicted motion keep from obstacles). It follows its own commands
    (`drive`) and what a shut-in robot is doing about it (`maneuver`). For a round robot that
    `SpeedPolicy` never slows, idle: the force as it is."""

    body: RobotBody
    stop_margin_m: float
    turn_margin_m: float
    evasion: Evasion | None = None
    """The check of commands against the moving tracks in time; None: no such check."""
    drive: DriveModel = field(init=False)
    """The drive as `steer`'s commands move it."""
    maneuver: str | None = field(default=None, init=False)
    """What a shut-in robot is doing about it: "back" (backing off) or "round" (turning the
    other way round), None while it is not shut in."""
    remembered: np.ndarray = field(default_factory=lambda: np.empty((0, 2)), init=False)
    """The obstacle points (N, 2; world, m) of the last tick, one per MEMORY_CELL_M square:
    those it was given, and those out of the sensor's view still within `reach_m`."""
    policy: SpeedPolicy = field(init=False)
    """The speeds the body may drive at along a way."""
    _view: tuple[np.ndarray | None, float, tuple[int, float, float]] = field(
        default=(None, math.nan, (0, 0.0, 0.0)), init=False, repr=False
    )
    """The last scan's bearings and beam width, and its field of view (`_view_of`)."""
    _reach: tuple[float, float] = field(default=(math.nan, 0.0), init=False, repr=False)
    """The control period the reach was last found for, and that reach (`reach_m`)."""

    def __post_init__(self) -> None:
        self.drive = DriveModel(self.body.limits)
        self.policy = SpeedPolicy(self.body)

    @property
    def reach_m(self) -> float:
        """How far (m) from base_link's origin obstacles matter to the governor: the
        circumscribed radius, the longest motion it predicts (one control period at the top
        speed and the braking from it, turning hard), the larger margin and the margin's growth
        along that motion and the longest coast of a turn."""
        period = self.drive.period_s
        if self._reach[0] == period:  # kept while the control period is the same
            return self._reach[1]
        limits = self.body.limits
        top, rate = limits.max_speed_mps, limits.max_turn_rate_radps
        brake = min(limits.max_accel_mps2, limits.braking_in_turn_mps2)
        travel = top * (period + top / (2 * brake))
        turn = rate * (period + limits.turn_lag_s) + rate * rate / (2 * limits.max_turn_accel_radps2)
        swept = travel + self.body.radius_m * turn
        margin = max(self.stop_margin_m, self.turn_margin_m)
        reach = self.body.radius_m + travel + margin + PREDICTION_ERROR * swept
        self._reach = (period, reach)
        return reach

    @property
    def idle(self) -> bool:
        """Whether the governor leaves every force as it is (a round robot that brakes short)."""
        return self.body.disc and not self.policy.active

    def steer(
        self,
        force: np.ndarray,
        obs: Observation,
        points: np.ndarray,
        speed_mps: float = math.inf,
        aim: np.ndarray | None = None,
    ) -> Steering:
        """The body speed and turn rate to drive for `force` among obstacle `points` (N, 2;
        world, m), at most `speed_mps` (m/s) besides, and the force to show (its direction where
        the robot steers): see the class docstring. Among moving tracks, the evasion makes for
        `aim` (m, world; the goal by default), where the planner is going. The idle governor's:
        the force as it is, no command."""
        length = float(np.hypot(force[0], force[1]))
        if self.idle:
            return Steering(force)
        pose = (float(obs.position[0]), float(obs.position[1]), float(obs.yaw))
        self.drive.advance(obs.time_s, obs.velocity, pose)
        if length < 1e-9 or not math.isfinite(length):
            self.maneuver = None
            self.drive.commanded((0.0, 0.0))
            return Steering(force, (0.0, 0.0))
        local = self._local_points(points, obs)
        wanted = math.atan2(force[1], force[0])
        direction, command = self._command(local, obs.yaw, wanted, length, speed_mps, self.turn_margin_m)
        if command is None:
            command = self._creep(local, obs.yaw, wanted) or (0.0, 0.0)
        if self.evasion is not None and obs.tracks:
            command = self._evade(command, obs, local, obs.goal if aim is None else aim)
        self.drive.commanded(command)
        shown = (
            np.array([math.cos(wanted), math.sin(wanted)])
            if direction is None
            else (np.array([math.cos(direction), math.sin(direction)]))
        )
        return Steering(self.policy.limit(length * shown, abs(command[0])), command)

    def _local_points(self, points: np.ndarray, obs: Observation) -> np.ndarray:
        """`points` (N, 2; world, m) and the remembered points within `reach_m` that the sensor
        does not look at now: outside its field of view (the span of its bearings, a half beam
        wider each way; none for a sensor that looks all round), as behind a 270-degree laser;
        in the robot's frame (x forward, y left; m). Remembers `points` and those, one per
        MEMORY_CELL_M square, for the next ticks."""
        from vplane_mj.kernels.motion import memory  # numba: loaded by the first call

        points = np.ascontiguousarray(points, float).reshape(-1, 2)
        x, y = float(obs.position[0]), float(obs.position[1])
        local, self.remembered = memory.recall(
            points, self.remembered, x, y, float(obs.yaw), self.reach_m, *self._view_of(obs), MEMORY_CELL_M
        )
        return local

    def _view_of(self, obs: Observation) -> tuple[int, float, float]:
        """The field of view of the scan of `obs` (`_view`), kept while the scan's bearings are
        the same array (a sensor's, at every tick) and its beam the same."""
        bearings, beam_width, view = self._view
        if bearings is not obs.bearings or beam_width != obs.beam_width:
            view = _view(obs.bearings, obs.beam_width)
            self._view = (obs.bearings, obs.beam_width, view)
        return view

    def _command(
        self, local: np.ndarray, yaw: float, wanted: float, length: float, speed_mps: float, margin: float
    ) -> tuple[float | None, tuple[float, float] | None]:
        """The direction steered toward (None: backing off) and the command for a force of
        `length` toward `wanted` (rad, world), every turn and motion keeping `margin` (m): ahead
        (`_heading`, `_forward`), else backing off, else round the other way or on ahead; None
        when only standing still keeps the margin."""
        side = 1.0 if wrap_angle(wanted - yaw) >= 0 else -1.0
        direction = self._heading(local, yaw, wanted, margin)
        command = (
            None if direction is None else self._forward(local, yaw, direction, length, speed_mps, margin)
        )
        if command is None:
            command = self._back_off(local, side, margin)
        if command is None:  # nowhere to back off to: round the other way, else on ahead
            self.maneuver = "round"
            direction = self._heading(local, yaw, wanted, margin)
            heading = yaw if direction is None else direction
            command = self._forward(local, yaw, heading, length, speed_mps, margin)
        return direction, command

    def _evade(
        self, command: tuple[float, float], obs: Observation, local: np.ndarray, aim: np.ndarray
    ) -> tuple[float, float]:
        """`command`, or when a moving track meets its motion within the evasion's horizon, the
        command of the best of the evasion's candidate motions (`Evasion.ranking`, making for
        `aim`, m, world) that the static points of `local` allow (`_safe`); the best of them
        all when none does."""
        evasion = self.evasion
        assert evasion is not None
        threat = evasion.threat(obs.position, obs.tracks, obs.time_s)
        if not threat:
            evasion.kept = None
            return command
        pose = (float(obs.position[0]), float(obs.position[1]), float(obs.yaw))
        candidates = evasion.candidates(command)
        asked = evasion.risks(candidates[:1], pose, self.drive.ramp, threat, aim)
        if math.isinf(asked[0, 0]):
            evasion.kept = None
            return command  # the command asked for meets no track: the others need no check
        risks = np.vstack((asked, evasion.risks(candidates[1:], pose, self.drive.ramp, threat, aim)))
        ranking = evasion.ranking(candidates, risks)
        chosen = ranking[0]
        for index in ranking:
            candidate = (float(candidates[index, 0]), float(candidates[index, 1]))
            if not self._moves(candidate) or self._safe(candidate, local, self.turn_margin_m):
                chosen = index
                break
        evasion.kept = (float(candidates[chosen, 0]), float(candidates[chosen, 1]))
        return evasion.kept

    def _creep(self, local: np.ndarray, yaw: float, wanted: float) -> tuple[float, float] | None:
        """For a robot that no motion keeps the turn margin: straight on at the back-off speed or
        half of it, toward `wanted` (rad, world) first (ahead or back), keeping a SQUEEZED_SHARE
        of the margin; None when that does not either."""
        margin = SQUEEZED_SHARE * self.turn_margin_m
        first = 1.0 if math.cos(wrap_angle(wanted - yaw)) >= 0 else -1.0
        for sign in (first, -first):
            for command in ((sign * self.back_off_speed, 0.0), (sign * self.back_off_speed / 2, 0.0)):
                if self._safe(command, local, margin):
                    return command
        return None

    def _heading(self, local: np.ndarray, yaw: float, wanted: float, margin: float) -> float | None:
        """The direction (rad, world) to steer toward for the `wanted` one, or None to back off:
        `wanted` when the turn in place there is free (`free_turn`); else as far toward it as is
        free, the robot creeping ahead while there is room (`room_ahead`); once that way is shut
        with no room ahead, back off (`maneuver` "back", the caller's) until the turn is free;
        when backing is not safe (the caller sets "round"), turn the other way round as far as is
        free (a quarter turn ahead at a time, so the turn stays that way round), and when that is
        shut too, the heading itself."""
        body = self.body
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
            return yaw - side * min(other, math.pi / 2)  # a quarter turn at most: the way round stays
        self.maneuver = None
        return yaw

    def _forward(
        self, local: np.ndarray, yaw: float, direction: float, length: float, speed_mps: float, margin: float
    ) -> tuple[float, float] | None:
        """The command toward `direction` for a force of `length`: the heading controller's
        speed (at most `speed_mps`) and a turn rate it can brake from before it faces that
        direction, or the nearest safe one (`_admissible`); None when only standing still is
        safe and the robot should move."""
        limits, gains = self.body.limits, self.body.gains
        error = float(wrap_angle(direction - yaw))
        speed = min(limits.max_speed_mps, gains.speed_gain * length * max(0.0, math.cos(error)), speed_mps)
        delay = limits.turn_lag_s + self.drive.period_s
        rate = min(
            limits.max_turn_rate_radps,
            gains.turn_gain * abs(error),
            brake_speed(abs(error), limits.max_turn_accel_radps2, delay),
        )
        return self._admissible((speed, math.copysign(rate, error)), local, margin)

    def _admissible(
        self, wanted: tuple[float, float], local: np.ndarray, margin: float
    ) -> tuple[float, float] | None:
        """The command nearest `wanted` (v, omega) whose predicted motion keeps the footprint
        `margin` (m) from every point of `local` (robot frame; `intrusion`): slower first,
        then turning less. None when only standing still is safe but `wanted` moves (a
        command slower than a CREEP_SHARE of the top speed and turn rate stands still)."""
        if not self._moves(wanted):
            return (0.0, 0.0)
        speed, turn = wanted
        candidates = dict.fromkeys(
            (speed * f, turn * g) for g in (1.0, 0.5, 0.0) for f in (1.0, 0.5, 0.25, 0.0)
        )
        for command in candidates:
            if self._moves(command) and self._safe(command, local, margin):
                return command
        return None

    def _moves(self, command: tuple[float, float]) -> bool:
        """Whether `command` (m/s, rad/s) moves the robot more than a creep (`CREEP_SHARE`)."""
        limits = self.body.limits
        return (
            abs(command[0]) > CREEP_SHARE * limits.max_speed_mps
            or abs(command[1]) > CREEP_SHARE * limits.max_turn_rate_radps
        )

    def _back_off(self, local: np.ndarray, side: float, margin: float) -> tuple[float, float] | None:
        """A safe command that backs the robot off, turning its front toward `side` (+1 left) if
        that is safe; None when no back-off is safe."""
        back = -self.back_off_speed
        for command in ((back, side * self.back_off_turn), (back, 0.0), (back / 2, 0.0)):
            if self._safe(command, local, margin):
                self.maneuver = "back"
                return command
        return None

    def _safe(self, command: tuple[float, float], local: np.ndarray, margin: float) -> bool:
        """Whether the motion predicted for `command` keeps `margin` (m) and its growth (`intrusion`)."""
        poses = self.drive.poses(command, self.drive.period_s)
        return intrusion(self.body, local, poses, margin, INTRUSION_TOLERANCE_M) <= INTRUSION_TOLERANCE_M

    @property
    def back_off_speed(self) -> float:
        """The speed (m/s) at which a shut-in robot backs off: what it brakes from within
        `stop_margin_m`, at most its top speed."""
        limits = self.body.limits
        return min(
            limits.max_speed_mps, brake_speed(self.stop_margin_m, limits.max_accel_mps2, self.drive.period_s)
        )

    @property
    def back_off_turn(self) -> float:
        """The turn rate (rad/s) with which a backing robot swings its front toward the way it
        wants to go: a quarter of its top turn rate."""
        return self.body.limits.max_turn_rate_radps / 4
