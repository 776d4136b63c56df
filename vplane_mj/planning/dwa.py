"""The dynamic window approach (`dwa`), after Fox, Burgard and Thrun (1997).

DWA searches the space of commands (v, omega) rather than of directions. Each control tick:

1. Velocity: the robot's average over the last control period, from its last two poses (v
   along the heading in m/s, omega in rad/s); at rest on the first tick.
2. Dynamic window: the commands reachable from that velocity within one control period under
   the acceleration limits `accel_mps2` and `turn_accel_radps2`, within 0 <= v <= `max_speed`
   and |omega| <= `max_turn_rate`, sampled `speed_samples` x `turn_samples` evenly. Forward
   only: the heading controller never drives backwards (v = k_v |F| max(0, cos e) >= 0).
3. dist(v, omega): each sample's circle (curvature omega / v; a turn on the spot when v = 0) is
   followed for `lookahead_m` through the sonar map's clearance field (the distance transform
   of its obstacle cells, bilinear between cell centres). dist is the length travelled before
   the robot's disc plus `margin_m` reaches an obstacle cell, `lookahead_m` (Fox's "large
   constant") when it does not; the arc after it enters the goal tolerance does not count.
   When the map already puts a cell within the disc plus margin, an arc is blocked only
   where it comes closer to a cell than the robot already is.
4. Admissible: the robot stops within dist: one control period at v (a command holds until
   the next tick), then braking at `accel_mps2`.
5. Objective: G = sigma(alpha heading + beta dist + gamma velocity), each term in [0, 1]:
   heading = 1 - |theta| / pi, theta the goal's bearing from the pose reached after one
   control period at (v, omega) and braking at both limits; dist / `lookahead_m`; v /
   `max_speed`. sigma is a Gaussian over neighbouring samples (`smoothing`, in samples) in
   which inadmissible samples count 0, so the choice keeps off blocked arcs. The admissible
   sample of greatest G is the command.
6. Force: the one the heading controller (vplane_mj/control.py) turns into that command,
   direction yaw + omega / k_w and magnitude v / (k_v cos(omega / k_w)).

With no admissible sample the robot brakes as hard as the window allows (mode "blocked").
The local-minimum detector of the peers makes it give up after `patience_s` trapped
(outcome `stuck`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.base import Planner
from vplane_mj.planning.body import RobotBody
from vplane_mj.planning.events import Event, EventKind
from vplane_mj.planning.groups import LocalMapParams, MinimumParams
from vplane_mj.planning.minima import report_trap
from vplane_mj.planning.params import param
from vplane_mj.planning.types import Decision, Observation
from vplane_mj.planning.vectors import wrap_angle

SPEED_GAIN, TURN_GAIN = 0.5, 3.0
"""The heading controller's k_v ((m/s) per unit of force) and k_w (1/s), whose law the force
inverts (vplane_mj/control.py)."""
CONTROLLER_MAX_SPEED, CONTROLLER_MAX_TURN_RATE = 0.5, 2.5
"""The heading controller's limits (m/s, rad/s): the window never asks for more."""
CREEP_SPEED = 1e-6
"""Speed (m/s) that a turn on the spot asks for: the force needs a length to have a direction."""
FIRST_PERIOD_S = 0.05
"""Control period (s) assumed on the first tick, before two observations give it (20 Hz)."""


@dataclass(frozen=True)
class DwaParams(LocalMapParams, MinimumParams):
    """The detector's and the patience's parameters, the sonar map's and the window's."""

    accel_mps2: float = param(4.0, "m/s^2", "forward acceleration and braking limit (the robot: ~4.4)", gt=0)
    turn_accel_radps2: float = param(30.0, "rad/s^2", "turn-rate acceleration limit (the robot: ~32)", gt=0)
    max_speed: float = param(
        CONTROLLER_MAX_SPEED,
        "m/s",
        "top forward speed (at most the controller's)",
        gt=0,
        le=CONTROLLER_MAX_SPEED,
    )
    max_turn_rate: float = param(
        CONTROLLER_MAX_TURN_RATE,
        "rad/s",
        "top turn rate (at most the controller's)",
        gt=0,
        le=CONTROLLER_MAX_TURN_RATE,
    )
    speed_samples: int = param(7, "", "forward speeds sampled across the window", ge=2, le=30, integer=True)
    turn_samples: int = param(31, "", "turn rates sampled across the window", ge=2, le=60, integer=True)
    lookahead_m: float = param(
        1.0, "m", "length of each arc checked for obstacles (dist's cap)", gt=0, le=5.0
    )
    margin_m: float = param(0.05, "m", "clearance added to the robot radius on the arcs", ge=0, le=1.0)
    heading_weight: float = param(2.0, "", "alpha: weight of the heading to the goal", ge=0)
    clearance_weight: float = param(0.2, "", "beta: weight of the free distance along the arc", ge=0)
    velocity_weight: float = param(0.2, "", "gamma: weight of the forward speed", ge=0)
    smoothing: float = param(1.0, "", "sigma: Gaussian smoothing of G across samples (0: none)", ge=0, le=10)


def dynamic_window(
    speed: float, turn: float, period_s: float, params: DwaParams
) -> tuple[np.ndarray, np.ndarray]:
    """Sampled forward speeds (m/s) and turn rates (rad/s) reachable from (speed, turn) within
    `period_s` under the acceleration limits, inside the speed and turn-rate limits."""
    top, top_turn = params.max_speed, params.max_turn_rate
    dv, dw = params.accel_mps2 * period_s, params.turn_accel_radps2 * period_s
    slow, fast = min(max(speed - dv, 0.0), top), min(max(speed + dv, 0.0), top)
    left, right = min(max(turn - dw, -top_turn), top_turn), min(max(turn + dw, -top_turn), top_turn)
    return np.linspace(slow, fast, params.speed_samples), np.linspace(left, right, params.turn_samples)


def arc_poses(
    position: np.ndarray, yaw: float, travel: np.ndarray, turn: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Points (..., 2) and headings (...) after travelling `travel` (m) along a circle while
    turning by `turn` (rad), from `position` at `yaw` (a straight line when turn = 0)."""
    half = np.asarray(turn, float) / 2
    sin_half, cos_half = np.sin(half), np.cos(half)
    bent = np.abs(half) > 1e-12
    chord = travel * np.where(bent, sin_half / np.where(bent, half, 1.0), 1.0)  # 2 sin(turn/2) / curvature
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    x = position[0] + chord * (cos_yaw * cos_half - sin_yaw * sin_half)
    y = position[1] + chord * (sin_yaw * cos_half + cos_yaw * sin_half)
    return np.stack((x, y), axis=-1), yaw + turn


def force_for_command(speed: float, turn: float, yaw: float) -> np.ndarray:
    """The force (world frame) that the heading controller turns into (speed, turn) at `yaw`:
    the inverse of v = k_v |F| max(0, cos e), omega = k_w e (|turn| <= 2.5 rad/s, so |e| < pi/2)."""
    if speed <= 0.0 and turn == 0.0:
        return np.zeros(2)
    error = turn / TURN_GAIN
    magnitude = max(speed, CREEP_SPEED) / (SPEED_GAIN * math.cos(error))
    return magnitude * np.array([math.cos(yaw + error), math.sin(yaw + error)])


def smoothing_matrix(count: int, sigma: float) -> np.ndarray:
    """(count, count) weights of a Gaussian of `sigma` samples along one axis of the sample grid,
    each row summing to 1; beyond the ends the end samples repeat. The identity when sigma is 0."""
    if sigma <= 0:
        return np.eye(count)
    reach = math.ceil(4 * sigma)
    offsets = np.arange(-reach, reach + 1)
    weights = np.exp(-0.5 * (offsets / sigma) ** 2)
    matrix = np.zeros((count, count))
    for row in range(count):
        np.add.at(matrix[row], np.clip(row + offsets, 0, count - 1), weights)
    return matrix / matrix.sum(axis=1, keepdims=True)


class DwaPlanner(Planner):
    """Chooses the admissible command of the dynamic window that maximises G (module docstring)."""

    name = "dwa"
    summary = "dynamic window approach: the best reachable (v, omega) arc on the sonar grid"
    citation = (
        "D. Fox, W. Burgard, S. Thrun, The dynamic window approach to collision avoidance, "
        "IEEE Robotics & Automation Magazine 4(1), 1997"
    )
    Params = DwaParams
    params: DwaParams

    def __init__(self, params: DwaParams, robot: RobotBody | float):
        super().__init__(params, robot)
        p = params
        self.detector = p.detector()
        self.map = p.local_map()
        # Points checked along an arc, a map cell apart: between two of them the clearance to a
        # cell centre dips by at most sqrt(d^2 + (cell / 2)^2) - d (8 mm at d = 0.16 m).
        self.step_m = p.map_cell_m
        count = max(1, math.ceil(p.lookahead_m / self.step_m - 1e-9))
        self.arc_lengths = self.step_m * np.arange(1, count + 1)
        self.smooth_speeds = smoothing_matrix(p.speed_samples, p.smoothing)
        self.smooth_turns = smoothing_matrix(p.turn_samples, p.smoothing)
        self.previous: tuple[float, np.ndarray, float] | None = None  # time, position, yaw
        self.period = FIRST_PERIOD_S
        self.blocked = False

    def step(self, obs: Observation) -> Decision:
        p = self.params
        self.map.update(obs.position, obs.yaw, obs.bearings, obs.ranges, obs.beam_width)
        speeds, turns = dynamic_window(*self._velocity(obs), self.period, p)
        dist = self._free_distance(obs, speeds, turns)
        admissible = (speeds * self.period + speeds**2 / (2 * p.accel_mps2))[:, None] <= dist
        decision = Decision(force=np.zeros(2), mode="normal")
        if admissible.any():
            score = np.where(admissible, self._objective(obs, speeds, turns, dist), 0.0)
            score = self.smooth_speeds @ score @ self.smooth_turns.T
            i, j = np.unravel_index(np.argmax(np.where(admissible, score, -np.inf)), score.shape)
            command = float(speeds[i]), float(turns[j])
            if self.blocked:
                decision.events.append(Event(EventKind.UNBLOCKED, "an admissible arc again"))
            self.blocked = False
        else:  # brake as hard as the window allows, without turning when it can
            command = float(speeds[0]), min(max(0.0, float(turns[0])), float(turns[-1]))
            decision.mode = "blocked"
            if not self.blocked:
                decision.events.append(Event(EventKind.BLOCKED, "no admissible arc: braking"))
            self.blocked = True
        decision.force = force_for_command(*command, obs.yaw)
        decision.components = {"command": decision.force}
        report_trap(self.detector, obs, decision, p.patience_s)
        return decision

    def _velocity(self, obs: Observation) -> tuple[float, float]:
        """(v, omega) averaged over the last control period (m/s, rad/s); it also times the period."""
        previous, self.previous = self.previous, (obs.time_s, np.array(obs.position, float), obs.yaw)
        if previous is None or obs.time_s <= previous[0]:
            return 0.0, 0.0
        time0, position0, yaw0 = previous
        self.period = obs.time_s - time0
        turned = wrap_angle(obs.yaw - yaw0)
        heading = yaw0 + turned / 2
        moved = obs.position - position0
        speed = (moved[0] * math.cos(heading) + moved[1] * math.sin(heading)) / self.period
        return float(speed), turned / self.period

    def _free_distance(self, obs: Observation, speeds: np.ndarray, turns: np.ndarray) -> np.ndarray:
        """dist(v, omega) (speeds, turns): length (m) along each arc before the disc plus margin
        meets an obstacle cell, `lookahead_m` when it never does (step 3 of the module docstring)."""
        p = self.params
        dist = np.full((len(speeds), len(turns)), p.lookahead_m)
        moving = speeds > 0  # a turn on the spot sweeps nothing the disc does not already cover
        if not moving.any():
            return dist
        curvature = turns / speeds[moving, None]
        points, _ = arc_poses(
            obs.position, obs.yaw, self.arc_lengths, curvature[..., None] * self.arc_lengths
        )
        safe = self.radius + p.margin_m
        field = self.map.clearance_field(p.map_threshold, obs.position, p.lookahead_m + safe + self.step_m)
        clearance = field.at(np.vstack((obs.position, points.reshape(-1, 2))))
        limit = min(safe, clearance[0])  # never closer than the robot already is
        hits = clearance[1:].reshape(points.shape[:-1]) < limit
        if obs.distance_to_goal() < p.lookahead_m + obs.goal_tolerance:  # arcs may enter the goal
            arrived = np.hypot(*np.moveaxis(points - obs.goal, -1, 0)) <= obs.goal_tolerance
            hits &= ~np.logical_or.accumulate(arrived, axis=-1)
        dist[moving] = np.where(hits.any(axis=-1), np.argmax(hits, axis=-1) * self.step_m, p.lookahead_m)
        return dist

    def _objective(
        self, obs: Observation, speeds: np.ndarray, turns: np.ndarray, dist: np.ndarray
    ) -> np.ndarray:
        """alpha heading + beta dist + gamma velocity (speeds, turns), each term in [0, 1]."""
        p = self.params
        travel = (speeds * self.period + speeds**2 / (2 * p.accel_mps2))[:, None]
        turned = (turns * self.period + turns * np.abs(turns) / (2 * p.turn_accel_radps2))[None, :]
        points, headings = arc_poses(obs.position, obs.yaw, travel, turned)
        to_goal = obs.goal - points
        theta = wrap_angle(np.arctan2(to_goal[..., 1], to_goal[..., 0]) - headings)
        return (
            p.heading_weight * (1 - np.abs(theta) / math.pi)
            + p.clearance_weight * dist / p.lookahead_m
            + p.velocity_weight * (speeds / p.max_speed)[:, None]
        )
