"""The dynamic window approach (`dwa`), after Fox, Burgard and Thrun (1997).

DWA searches the space of commands (v, omega) rather than of directions, for the robot it is
built for (`RobotBody`: its limits, its heading controller's gains, its footprint). Each
control tick:

1. Velocity, the centre of the window. A round robot (the default robot, whose drive steps
   its commands): its average over the last control period T, from its last two poses (v
   along the heading in m/s, omega in rad/s). A polygon robot: the command it asked for last.
   The profiles' drives ramp their commands at the limits' accelerations, so that command is
   where the drive stands a period later, while the measured velocity lags it and, on a
   skid-steer, overshoots its turn rate (the Jackal's turns up to 1.7 times faster than asked
   at speed): a window about the measured turn rate would hold no gentler turn than the one
   that overshoots, and the turn would tighten tick after tick. At rest on the first tick.
2. Dynamic window: the commands reachable from that velocity within T under the robot's
   accelerations a and alpha, within 0 <= v <= its top speed and |omega| <= its top turn rate,
   sampled `speed_samples` x `turn_samples` evenly. Each limit is the robot's
   (`RobotBody.limits`) when its parameter (`accel_mps2`, `turn_accel_radps2`, `max_speed`,
   `max_turn_rate`) is 0, the default, and the lower of the two otherwise; the turn rate also
   stays within k_w MAX_HEADING_ERROR, where the controller still drives forward. Forward
   only: the heading controller never drives backwards (v = k_v |F| max(0, cos e) >= 0).
3. dist(v, omega): each sample's circle (curvature omega / v; a turn on the spot when v = 0)
   is followed for the look-ahead L (`lookahead_m`; when 0, the default, the larger of
   MIN_LOOKAHEAD_M and LOOKAHEAD_BRAKINGS braking distances from the top speed) through the
   map's obstacle cells; the arc after it enters the goal tolerance does not count.
   - A round robot (`RobotBody.disc`): its centre's path through the map's clearance field
     (the distance transform of its obstacle cells, bilinear between cell centres), a cell
     apart. dist is the length travelled before the disc plus `margin_m` reaches an obstacle
     cell, L (Fox's "large constant") when it does not. A turn on the spot sweeps nothing
     the disc does not already cover: its dist is L.
   - A polygon robot: its footprint at poses along the arc, no point of it moving more than
     half a cell between two, and the signed distance from the footprint to the obstacle
     cells' centres there (kernels/footprint_clearance.py); with a dense scan (a laser's), also from
     this scan's echoes, where they are, in the cells the map does not hold (it judges a cell
     by the beam nearest its centre, which along a wall seen at a grazing angle passes the
     wall and clears it). dist is the length the centre travels before that
     distance falls below the margin, `margin_m` plus DRIFT_PERIODS T v: the robot drifts
     from the arc it was asked for while its drive catches up with the command (a skid-steer
     also turns faster than asked), the more the faster it goes. An arc is followed at most
     one full circle, after which it repeats. A turn on the spot sweeps the sector that the
     footprint turns through, up to the whole circumscribed disc: its dist is the length the
     outermost point (at the circumscribed radius R) travels, turning that way, before the
     footprint comes within `margin_m` of a cell.
   When the map already puts a cell within the margin, an arc is blocked only where the robot
   comes closer to a cell than it already is.
4. Admissible: the robot stops within dist, a command holding until the next tick. A round
   robot: one period at v, then braking at a (its turning sweeps nothing). A polygon robot,
   whose corners sweep as it turns: one period at (v, omega), then v and omega braked
   together in the longer of their braking times t_b = max(v / a, |omega| / alpha), so that it
   stays on its circle: a length v (T + t_b / 2); turning on the spot, its outermost point
   travels R |omega| (T + |omega| / (2 alpha)).
5. Objective: G = sigma(alpha_h heading + beta dist + gamma velocity), each term in [0, 1]:
   heading = 1 - |theta| / pi, theta the aim's bearing from the pose reached after one
   control period at (v, omega) and braking at both limits; dist / L; v / top speed. The
   aim is the goal (Fox), or with `follow_way` a point along the map's shortest way to it
   (as the global planner under BARN's DWA baseline, move_base, gives its local planner;
   Brock and Khatib's global dynamic window approach): the way keeps the robot's centre half
   its width plus the margin from the obstacle cells and, of a dense scan, the cells of its
   echoes (gridsearch.py, with a costmap's inflation), and the aim lies `look_ahead_m` of
   the last command's speed along it. sigma is a Gaussian over neighbouring samples
   (`smoothing`, in samples) in which inadmissible samples count 0, so the choice keeps off
   blocked arcs. The admissible sample of greatest G is the command. A robot that turns
   slowly (the Jackal: 4 rad/s^2) reaches headings little apart within one window, so the
   heading term varies little across it and the clearance term leads; following a way,
   which already keeps off obstacles, it does better with less of it (`clearance_weight`
   0.05).
6. Force: the one the heading controller (vplane_mj/sim/control.py) turns into that command with
   the robot's gains k_v and k_w (`RobotBody.gains`): direction yaw + omega / k_w and
   magnitude v / (k_v cos(omega / k_w)).

The map is the `LocalMapParams` grid, at least 4 (L + R + margin + a cell) on a side: the
robot stays in its middle half, so every arc lies inside it. With no admissible sample the
robot brakes as hard as the window allows (mode "blocked"). The local-minimum detector of
the peers makes it give up after `patience_s` trapped (outcome `stuck`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.motion import gridsearch
from vplane_mj.planning.motion.evasion import STEP_S
from vplane_mj.planning.perception import scan
from vplane_mj.planning.perception.minima import report_trap
from vplane_mj.planning.planners.groups import EvasionParams, LocalMapParams, MinimumParams
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import DriveLimits, HeadingGains, RobotBody
from vplane_mj.planning.protocol.events import Event, EventKind
from vplane_mj.planning.protocol.matrices import product
from vplane_mj.planning.protocol.params import param
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.planning.protocol.vectors import evenly_spaced, wrap_angle

MIN_LOOKAHEAD_M = 1.0
"""The shortest look-ahead (m) when `lookahead_m` is 0 (the default robot's, at 0.5 m/s)."""
LOOKAHEAD_BRAKINGS = 2.0
"""When `lookahead_m` is 0, the look-ahead is at least this many braking distances v^2 / (2 a)
from the top speed (2 m at the Jackal's 2 m/s and 2 m/s^2)."""
MAX_HEADING_ERROR = 1.4
"""The largest heading error (rad) a force asks for: the window's turn rate stays within k_w
times this, since the controller's speed k_v |F| cos e vanishes as e nears pi / 2 (cos 1.4 =
0.17). It binds for no robot whose top turn rate is below 1.4 k_w (the default: 2.5 < 4.2)."""
CREEP_SPEED = 1e-6
"""Speed (m/s) that a turn on the spot asks for: the force needs a length to have a direction."""
WAY_INFLATION_M, WAY_INFLATION_WEIGHT = 0.3, 4.0
"""The map's ways (`follow_way`) pay for passing closer than this (m) beyond the passage radius,
up to this much more per metre right at it (a costmap's inflation, as `vplane_plus`'s)."""
DRIFT_PERIODS = 2
"""A polygon robot's margin grows by its travel in this many control periods: its drive ramps
to a command within a period, and its wheels follow a period later (the Jackal model's true
speed and turn rate trail the command so), while it stays on the arc it was asked for."""
FIRST_PERIOD_S = 0.05
"""Control period (s) assumed on the first tick, before two observations give it (20 Hz)."""
ROBOTS = "0: the robot's, else at most this"
"""How the limit parameters read (their text in `vplane-mj list`)."""


@dataclass(frozen=True)
class DwaParams(LocalMapParams, MinimumParams, EvasionParams):
    """The check against moving tracks, the detector's and the patience's parameters, the map's
    and the window's.

    The limits default to the robot's (0); a positive value caps the robot's (a scenario may
    drive a fast robot slower, e.g. `--set planner.max_speed=0.5`).
    """

    accel_mps2: float = param(0.0, "m/s^2", f"forward acceleration and braking ({ROBOTS})", ge=0)
    turn_accel_radps2: float = param(0.0, "rad/s^2", f"turn-rate acceleration ({ROBOTS})", ge=0)
    max_speed: float = param(0.0, "m/s", f"top forward speed ({ROBOTS})", ge=0)
    max_turn_rate: float = param(0.0, "rad/s", f"top turn rate ({ROBOTS})", ge=0)
    speed_samples: int = param(7, "", "forward speeds sampled across the window", ge=2, le=30, integer=True)
    turn_samples: int = param(31, "", "turn rates sampled across the window", ge=2, le=60, integer=True)
    lookahead_m: float = param(
        0.0,
        "m",
        "length of each arc checked for obstacles (dist's cap); "
        "0: the larger of 1 m and two braking distances from the top speed",
        ge=0,
        le=5.0,
    )
    margin_m: float = param(
        0.05, "m", "clearance kept between the robot's outline and obstacle cells", ge=0, le=1.0
    )
    heading_weight: float = param(2.0, "", "alpha: weight of the heading to the goal", ge=0)
    follow_way: int = param(
        0,
        "",
        "the heading's aim: 0 the goal (Fox); 1 a look-ahead along the map's shortest way to it",
        ge=0,
        le=1,
        integer=True,
    )
    clearance_weight: float = param(0.2, "", "beta: weight of the free distance along the arc", ge=0)
    velocity_weight: float = param(0.2, "", "gamma: weight of the forward speed", ge=0)
    smoothing: float = param(1.0, "", "sigma: Gaussian smoothing of G across samples (0: none)", ge=0, le=10)


def window_limits(params: DwaParams, robot: RobotBody) -> DriveLimits:
    """The limits the window keeps to: the robot's, each capped by its parameter when that is
    positive; the turn rate also within k_w MAX_HEADING_ERROR."""
    own = robot.limits

    def capped(limit: float, cap: float) -> float:
        return min(limit, cap) if cap > 0 else limit

    return DriveLimits(
        max_speed_mps=capped(own.max_speed_mps, params.max_speed),
        max_turn_rate_radps=min(
            capped(own.max_turn_rate_radps, params.max_turn_rate),
            robot.gains.turn_gain * MAX_HEADING_ERROR,
        ),
        max_accel_mps2=capped(own.max_accel_mps2, params.accel_mps2),
        max_turn_accel_radps2=capped(own.max_turn_accel_radps2, params.turn_accel_radps2),
    )


def lookahead(params: DwaParams, limits: DriveLimits) -> float:
    """The arcs' length L (m): `lookahead_m`, or when that is 0 `look_ahead_m` of the top speed."""
    if params.lookahead_m > 0:
        return params.lookahead_m
    return look_ahead_m(limits.max_speed_mps, limits.max_accel_mps2)


def look_ahead_m(speed: float, accel: float) -> float:
    """How far ahead (m) a robot at `speed` (m/s) that brakes at `accel` (m/s^2) looks: the larger
    of MIN_LOOKAHEAD_M and LOOKAHEAD_BRAKINGS braking distances."""
    return max(MIN_LOOKAHEAD_M, LOOKAHEAD_BRAKINGS * speed**2 / (2 * accel))


def dynamic_window(
    speed: float, turn: float, period_s: float, limits: DriveLimits, speed_samples: int, turn_samples: int
) -> tuple[np.ndarray, np.ndarray]:
    """Sampled forward speeds (m/s) and turn rates (rad/s) reachable from (speed, turn) within
    `period_s` under the acceleration limits, inside the speed and turn-rate limits."""
    top, top_turn = limits.max_speed_mps, limits.max_turn_rate_radps
    dv, dw = limits.max_accel_mps2 * period_s, limits.max_turn_accel_radps2 * period_s
    slow, fast = min(max(speed - dv, 0.0), top), min(max(speed + dv, 0.0), top)
    left, right = min(max(turn - dw, -top_turn), top_turn), min(max(turn + dw, -top_turn), top_turn)
    return evenly_spaced(slow, fast, speed_samples), evenly_spaced(left, right, turn_samples)


def arc_poses(
    position: np.ndarray, yaw: float, travel: np.ndarray, turn: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Points (..., 2) and headings (...) after travelling `travel` (m) along a circle while
    turning by `turn` (rad), from `position` at `yaw` (a straight line when turn = 0;
    `kernels.arcs`)."""
    from vplane_mj.kernels.motion import arcs  # numba: loaded by the first call

    shape = np.broadcast_shapes(np.shape(travel), np.shape(turn))
    travels, turns = np.empty(shape), np.empty(shape)
    travels[...], turns[...] = travel, turn
    x, y = float(position[0]), float(position[1])
    points = arcs.arc_points(x, y, float(yaw), travels.ravel(), turns.ravel())
    return points.reshape(*shape, 2), yaw + turns


def force_for_command(speed: float, turn: float, yaw: float, gains: HeadingGains) -> np.ndarray:
    """The force (world frame) that the heading controller turns into (speed, turn) at `yaw`:
    the inverse of v = k_v |F| max(0, cos e), omega = k_w e (|turn| / k_w < pi / 2)."""
    if speed <= 0.0 and turn == 0.0:
        return np.zeros(2)
    error = turn / gains.turn_gain
    magnitude = max(speed, CREEP_SPEED) / (gains.speed_gain * math.cos(error))
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
    summary = "dynamic window approach: the best reachable (v, omega) arc on the local map"
    governs_itself = True
    citation = (
        "D. Fox, W. Burgard, S. Thrun, The dynamic window approach to collision avoidance, "
        "IEEE Robotics & Automation Magazine 4(1), 1997"
    )
    Params = DwaParams
    params: DwaParams

    def __init__(self, params: DwaParams, robot: RobotBody | float):
        super().__init__(params, robot)
        p = params
        self.limits = window_limits(p, self.robot)
        self.lookahead = lookahead(p, self.limits)
        self.detector = p.detector()
        self.map = p.local_map(least_size_m=4 * (self.lookahead + self.radius + p.margin_m + p.map_cell_m))
        if self.robot.disc:
            # Points checked along an arc, a map cell apart: between two of them the clearance to
            # a cell centre dips by at most sqrt(d^2 + (cell / 2)^2) - d (8 mm at d = 0.16 m).
            self.step_m = p.map_cell_m
            count = max(1, math.ceil(self.lookahead / self.step_m - 1e-9))
            self.arc_lengths = self.step_m * np.arange(1, count + 1)
        else:
            # Poses checked along an arc, no point of the footprint moving more than half a cell
            # between two: a corner passing a cell centre at d comes at most
            # sqrt(d^2 + (cell / 4)^2) - d closer between them (6 mm at d = 5 cm).
            self.step_m = p.map_cell_m / 2
            from vplane_mj.kernels.motion.footprint_clearance import footprint_clearance  # imports numba

            self.footprint_clearance = footprint_clearance
        self.smooth_speeds = smoothing_matrix(p.speed_samples, p.smoothing)
        self.smooth_turns = smoothing_matrix(p.turn_samples, p.smoothing)
        self.previous: tuple[float, np.ndarray, float] | None = None  # time, position, yaw
        self.period = FIRST_PERIOD_S
        self.command = (0.0, 0.0)  # the last one asked for (m/s, rad/s): at rest at the start
        self.blocked = False
        self.evasion = p.evasion(self.robot)

    def step(self, obs: Observation) -> Decision:
        p = self.params
        self.map.update(obs.position, obs.yaw, obs.bearings, obs.static_ranges(), obs.beam_width)
        self.map.forget(obs.tracks, obs.time_s)
        speeds, turns = self.window(obs)
        dist = self.free_distance(obs, speeds, turns)
        admissible = self.stopping_length(speeds, turns) <= dist
        decision = Decision(force=np.zeros(2), mode="normal")
        if admissible.any():
            score = np.where(admissible, self._objective(obs, self.aim(obs), speeds, turns, dist), 0.0)
            score = product(product(self.smooth_speeds, score), self.smooth_turns.T)
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
        self.command = command
        decision.force = force_for_command(*command, obs.yaw, self.robot.gains)
        decision.components = {"command": decision.force}
        report_trap(self.detector, obs, decision, p.patience_s)
        return decision

    def window(self, obs: Observation) -> tuple[np.ndarray, np.ndarray]:
        """The dynamic window's speeds (m/s) and turn rates (rad/s) for this tick (step 2 of the
        module docstring), about the velocity of the last period for a round robot and the last
        command for a polygon robot."""
        speed, turn = self._velocity(obs)
        if not self.robot.disc:
            speed, turn = self.command
        p = self.params
        return dynamic_window(speed, turn, self.period, self.limits, p.speed_samples, p.turn_samples)

    def free_distance(self, obs: Observation, speeds: np.ndarray, turns: np.ndarray) -> np.ndarray:
        """dist(v, omega) (speeds, turns) in m on the map as `obs` left it (step 3 of the module
        docstring)."""
        dist = (
            self._free_distance(obs, speeds, turns)
            if self.robot.disc
            else self._swept_free_distance(obs, speeds, turns)
        )
        if obs.tracks:
            dist = np.minimum(dist, self._moving_free_distance(obs, speeds, turns))
        return dist

    def _moving_free_distance(self, obs: Observation, speeds: np.ndarray, turns: np.ndarray) -> np.ndarray:
        """dist (speeds, turns) among the moving tracks: the length (m) each arc's centre (on the
        spot: its outermost point) travels, at its speed, before the footprint comes within the
        evasion's margin of a track's predicted disc (`kernels.evasion.arc_hits`, over the
        evasion's horizon), L when none does."""
        threat = self.evasion.threat(obs.position, obs.tracks, obs.time_s)
        dist = np.full((len(speeds), len(turns)), self.lookahead)
        if not threat:
            return dist
        from vplane_mj.kernels.motion import evasion  # numba: loaded by the first call

        commands = np.stack(np.broadcast_arrays(speeds[:, None], turns[None, :]), axis=-1).reshape(-1, 2)
        hits = evasion.arc_hits(
            np.ascontiguousarray(commands),
            (float(obs.position[0]), float(obs.position[1]), float(obs.yaw)),
            (self.evasion.horizon_s, STEP_S),
            np.ascontiguousarray(self.robot.footprint, float),
            float(self.radius),
            threat.tracks,
            float(self.evasion.margin_m),
        ).reshape(dist.shape)
        rate = np.where(speeds[:, None] > 0, speeds[:, None], self.radius * np.abs(turns)[None, :])
        met = np.isfinite(hits)
        return np.where(met, np.minimum(rate * np.where(met, hits, 0.0), self.lookahead), self.lookahead)

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

    def stopping_length(self, speeds: np.ndarray, turns: np.ndarray) -> np.ndarray:
        """How far (m) each sample goes before it stands still, to compare with dist (step 4 of
        the module docstring): (speeds, 1) for a round robot, (speeds, turns) for a polygon."""
        period, accel = self.period, self.limits.max_accel_mps2
        if self.robot.disc:
            return (speeds * period + speeds**2 / (2 * accel))[:, None]
        turn_accel = self.limits.max_turn_accel_radps2
        speed, rate = speeds[:, None], np.abs(turns)[None, :]
        along = speed * (period + np.maximum(speed / accel, rate / turn_accel) / 2)
        spinning = self.radius * rate * (period + rate / (2 * turn_accel))
        return np.where(speed > 0, along, spinning)

    def _free_distance(self, obs: Observation, speeds: np.ndarray, turns: np.ndarray) -> np.ndarray:
        """A round robot's dist(v, omega) (speeds, turns): length (m) along each arc before the
        disc plus margin meets an obstacle cell, L when it never does (step 3 of the module
        docstring)."""
        p = self.params
        dist = np.full((len(speeds), len(turns)), self.lookahead)
        moving = speeds > 0  # a turn on the spot sweeps nothing the disc does not already cover
        if not moving.any():
            return dist
        from vplane_mj.kernels.motion import arcs  # numba: loaded by the first call

        curvature = turns / speeds[moving, None]
        safe = self.radius + p.margin_m
        field = self.map.clearance_field(p.map_threshold, obs.position, self.lookahead + safe + self.step_m)
        first = arcs.first_hits(
            float(obs.position[0]),
            float(obs.position[1]),
            float(obs.yaw),
            curvature,
            self.arc_lengths,
            np.ascontiguousarray(field.values, float),
            float(field.first_cell[0]),
            float(field.first_cell[1]),
            field.cell_m,
            safe,
            np.asarray(obs.goal, float),
            self._arrival_tolerance(obs),
        )
        dist[moving] = np.where(first >= 0, first * self.step_m, self.lookahead)
        return dist

    def _swept_free_distance(self, obs: Observation, speeds: np.ndarray, turns: np.ndarray) -> np.ndarray:
        """A polygon robot's dist(v, omega) (speeds, turns): length (m) along each arc before the
        footprint comes within the margin of an obstacle, L when it never does; for a turn on
        the spot, the length its outermost point travels (step 3 of the module docstring)."""
        p, reach = self.params, self.lookahead
        occupied, origin, echoes = self._obstacles(obs)
        first_cell = (int(origin[0]), int(origin[1]))

        margins = p.margin_m + DRIFT_PERIODS * self.period * speeds  # wider the faster (step 3)
        cap = float(margins.max())

        def clearance(poses: np.ndarray) -> np.ndarray:
            flat = self.footprint_clearance(
                occupied, first_cell, self.map.cell_m, self.robot.footprint, poses.reshape(-1, 3), cap, echoes
            )
            return flat.reshape(poses.shape[:-1])

        here = clearance(np.array([obs.position[0], obs.position[1], obs.yaw]))
        limits = np.minimum(margins, float(here[()]))  # never closer than the robot already is
        dist = np.full((len(speeds), len(turns)), reach)
        moving = speeds > 0
        if moving.any():
            dist[moving] = self._arcs_free_distance(obs, speeds[moving], turns, clearance, limits[moving])
        if not moving[0]:
            dist[0] = self._turns_free_distance(obs, turns, clearance, float(limits[0]))
        return dist

    def _obstacles(self, obs: Observation) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The map's obstacle cells (n, n), its origin (world cell index of [0, 0]) and, of a
        dense scan (a laser's narrow beams, each echo where its beam says), the echoes (N, 2)
        in cells the map does not hold: the map judges a cell by the beam nearest its centre,
        which along a wall seen at a grazing angle passes the wall and clears it."""
        origin = self.map.origin
        assert origin is not None, "the map's update places its origin"
        occupied = self.map.grid >= self.params.map_threshold
        if not scan.is_dense(obs):
            return occupied, origin, np.empty((0, 2))
        echoes = obs.static_echo_points()
        cells = np.floor(echoes / self.map.cell_m).astype(int) - origin
        unmapped = np.all((cells >= 0) & (cells < self.map.n), axis=1)
        unmapped[unmapped] = ~occupied[cells[unmapped, 0], cells[unmapped, 1]]
        return occupied, origin, echoes[unmapped]

    def _arcs_free_distance(
        self,
        obs: Observation,
        speeds: np.ndarray,
        turns: np.ndarray,
        clearance: Callable[[np.ndarray], np.ndarray],
        limits: np.ndarray,
    ) -> np.ndarray:
        """dist (speeds, turns) of a polygon robot's arcs, all speeds > 0, each speed's arcs
        blocked where the clearance falls below its limit (speeds,) in m."""
        reach, radius = self.lookahead, self.radius
        curvature = turns / speeds[:, None]
        bend = np.abs(curvature)
        spread = 1 + radius * bend  # the most a footprint point moves per metre of the centre's path
        whole_circle = 2 * math.pi / np.maximum(bend, 1e-300)
        end = np.minimum(reach, whole_circle)
        count = max(1, math.ceil(float(np.max(end * spread)) / self.step_m - 1e-9))
        steps = self.step_m * np.arange(1, count + 1)
        travel = np.minimum(steps / spread[..., None], end[..., None])  # (speeds, turns, count)
        points, headings = arc_poses(obs.position, obs.yaw, travel, curvature[..., None] * travel)
        hits = clearance(np.concatenate((points, headings[..., None]), axis=-1)) < limits[:, None, None]
        hits = self._past_the_goal_free(obs, points, hits)
        first = np.argmax(hits, axis=-1)
        before = np.take_along_axis(travel, np.maximum(first - 1, 0)[..., None], axis=-1)[..., 0]
        return np.where(hits.any(axis=-1), np.where(first > 0, before, 0.0), reach)

    def _turns_free_distance(
        self,
        obs: Observation,
        turns: np.ndarray,
        clearance: Callable[[np.ndarray], np.ndarray],
        limit: float,
    ) -> np.ndarray:
        """dist (turns,) of a polygon robot's turns on the spot: the length its outermost point
        travels turning that way before the footprint comes within the margin of a cell, L when
        it never does within L or a whole turn; L when it stands still."""
        reach, radius = self.lookahead, self.radius
        end = min(reach / radius, 2 * math.pi)
        count = max(1, math.ceil(end * radius / self.step_m - 1e-9))
        angles = np.minimum(self.step_m / radius * np.arange(1, count + 1), end)
        dist = np.full(len(turns), reach)
        for side in (1.0, -1.0):
            turning = turns * side > 0
            if not turning.any():
                continue
            poses = np.column_stack(
                (np.full(count, obs.position[0]), np.full(count, obs.position[1]), obs.yaw + side * angles)
            )
            hits = clearance(poses) < limit
            if hits.any():
                first = int(np.argmax(hits))
                dist[turning] = radius * angles[first - 1] if first > 0 else 0.0
        return dist

    def _past_the_goal_free(self, obs: Observation, points: np.ndarray, hits: np.ndarray) -> np.ndarray:
        """The hits (..., count) of arcs whose points (..., count, 2) go on, without those after
        an arc enters the goal tolerance."""
        tolerance = self._arrival_tolerance(obs)
        if tolerance >= 0.0:
            arrived = np.hypot(*np.moveaxis(points - obs.goal, -1, 0)) <= tolerance
            hits &= ~np.logical_or.accumulate(arrived, axis=-1)
        return hits

    def _arrival_tolerance(self, obs: Observation) -> float:
        """The goal tolerance (m) when an arc of the look-ahead may enter the goal (and its points
        past the goal then count as arrived, not hit), else -1: none can."""
        tolerance = float(obs.goal_tolerance)
        return tolerance if obs.distance_to_goal() < self.lookahead + tolerance else -1.0

    def aim(self, obs: Observation) -> np.ndarray:
        """The point (m) the heading term aims at (step 5 of the module docstring): the goal; with
        `follow_way`, the point `look_ahead_m` of the last command's speed along the map's
        shortest way to it for the robot's centre kept a passage radius (half the width, plus
        the margin) from the obstacle cells, or the goal when the way is shorter or the map
        holds none."""
        p, cell = self.params, self.map.cell_m
        if not p.follow_way:
            return obs.goal
        occupied, origin, echoes = self._obstacles(obs)
        cells = np.floor(echoes / cell).astype(int) - origin
        occupied[cells[:, 0], cells[:, 1]] = True
        passage = self.robot.half_width_m + p.margin_m
        cost = gridsearch.step_costs(
            occupied, np.zeros_like(occupied), cell, passage, WAY_INFLATION_M, WAY_INFLATION_WEIGHT, 0.0
        )
        window = gridsearch.Window(cost, origin * cell, cell, np.zeros_like(occupied))
        window.clear_disc(obs.position, passage)  # the robot stands there
        cells = gridsearch.way_to(window, obs.position, obs.goal, passage)
        if cells is None:
            return obs.goal
        way = window.centres_of(cells[1:])
        travelled = np.cumsum(np.hypot(*np.diff(np.vstack((obs.position, way)), axis=0).T))
        limits = self.limits
        ahead = np.flatnonzero(travelled >= look_ahead_m(self.command[0], limits.max_accel_mps2))
        return way[ahead[0]] if len(ahead) else obs.goal

    def _objective(
        self, obs: Observation, aim: np.ndarray, speeds: np.ndarray, turns: np.ndarray, dist: np.ndarray
    ) -> np.ndarray:
        """alpha heading + beta dist + gamma velocity (speeds, turns), each term in [0, 1]; the
        heading toward `aim` (m)."""
        from vplane_mj.kernels.motion import arcs  # numba: loaded by the first call

        p, limits = self.params, self.limits
        travel = speeds * self.period + speeds**2 / (2 * limits.max_accel_mps2)
        turned = turns * self.period + turns * np.abs(turns) / (2 * limits.max_turn_accel_radps2)
        return arcs.objective(
            float(obs.position[0]),
            float(obs.position[1]),
            float(obs.yaw),
            travel,
            turned,
            np.asarray(aim, float),
            np.ascontiguousarray(dist, float),
            np.asarray(speeds, float),
            np.array([p.heading_weight, p.clearance_weight, p.velocity_weight], float),
            float(self.lookahead),
            float(limits.max_speed_mps),
        )
