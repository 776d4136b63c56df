"""The run loop: physics at a fixed step, wheel PI at the motor rate, sonar + planner at control_hz.

The planner sees only an Observation (pose, goal, sonar ranges). The simulator's obstacle
geometry is used only to score the run (clearance) and to draw it, never to plan.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass, field
from typing import Protocol

import mujoco
import numpy as np

from vplane_mj import __version__, shapes
from vplane_mj.control import ControllerGains, WheelPI, heading_command, wheel_targets
from vplane_mj.odometry import WheelOdometry
from vplane_mj.planning.registry import make_planner
from vplane_mj.planning.types import Decision, Observation
from vplane_mj.reference import shortest_path_length
from vplane_mj.render import Track
from vplane_mj.robot import BASE_BODY, WHEEL_JOINTS, WHEEL_MOTORS, robot_geometry
from vplane_mj.scenario import Scenario
from vplane_mj.sonar import SonarRays, SonarRing
from vplane_mj.world import BUMP_SENSOR, OBSTACLES_BODY, ROBOT_PREFIX, SonarLayout, build_model

SUMMARY_FORMAT = 1
TIMING_KEYS = ("wall_time_s", "planner_cpu_ms_mean", "planner_cpu_ms_max")
"""Summary keys measured on the wall clock: the only ones that differ between identical runs."""
CLEARANCE_BATCH = 200
"""Positions collected before one vectorised clearance query (2 s at the 100 Hz motor rate)."""
ODOMETRY_STREAM = 1
"""Second word of the odometry noise's seed, (seed, 1): a stream apart from the sonar's."""
BELIEF_PATIENCE_S = 3.0
"""Simulated time the odometry may hold the robot at the goal while it truly is not, before
the run ends as `stuck` (the planner then drives to where it believes the goal is)."""
FATAL_WARNINGS: dict[mujoco.mjtWarning, str] = {
    mujoco.mjtWarning.mjWARN_BADQACC: "bad acceleration (the simulation became unstable)",
    mujoco.mjtWarning.mjWARN_BADQVEL: "bad velocity (the simulation became unstable)",
    mujoco.mjtWarning.mjWARN_BADQPOS: "bad position (the simulation became unstable)",
    mujoco.mjtWarning.mjWARN_BADCTRL: "bad control (a non-finite wheel torque)",
    mujoco.mjtWarning.mjWARN_CONTACTFULL: "contact buffer full (too many contacts)",
    mujoco.mjtWarning.mjWARN_CNSTRFULL: "constraint buffer full (too many constraints)",
}
"""MuJoCo warnings that end a run as outcome `error`: after them MuJoCo resets or drops state."""


@dataclass(frozen=True)
class Tick:
    """Everything known at one control tick, for observers (logs, renders)."""

    time_s: float
    position: np.ndarray
    yaw: float
    speed: float
    ranges: np.ndarray
    decision: Decision
    command: tuple[float, float]
    believed_pose: tuple[float, float, float] | None = None
    """The pose the planner used, when it comes from odometry rather than the simulator."""


class Observer(Protocol):
    """Something that watches a run: every control tick and every event.

    After the last control tick it sees one more tick, the state the run ended in, with
    mode "finished" and no force (unless the run ended on a tick it already saw).
    """

    def on_tick(self, tick: Tick) -> None: ...

    def on_event(self, time_s: float, text: str) -> None: ...


@dataclass
class RunResult:
    """The summary of docs/interface.md section 3, the path at control ticks and the wheel torques."""

    summary: dict
    times: np.ndarray
    positions: np.ndarray
    modes: list[str]
    final_pose: tuple[float, float, float]
    """base_link's x, y (m) and yaw (rad) when the run ended."""
    torques: np.ndarray
    """(motor updates, 2) left and right wheel torques (N m), one row per motor period."""
    collision_points: list[tuple[float, float]] = field(default_factory=list)
    objectives: list[tuple[float, float]] = field(default_factory=list)
    """Every virtual new objective the planner placed, in order."""
    planes: list[tuple[tuple[float, float], tuple[float, float]]] = field(default_factory=list)
    """Every virtual plane the planner created, as (e1, e2)."""

    def track(self) -> Track:
        """What a render of this run shows."""
        return Track(
            self.positions,
            self.modes,
            self.final_pose,
            self.collision_points,
            self.objectives,
            self.planes,
        )


class _CollisionCounter:
    """Separate contact episodes between the robot and the obstacles body.

    MuJoCo's contact sensor counts the contacts; only when an episode starts are the
    contacts scanned in Python for the point of impact.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        self.found = data.sensordata[model.sensor_adr[model.sensor(BUMP_SENSOR).id] :][:1]
        self._obstacles = model.body(OBSTACLES_BODY).id
        self._geom_body = model.geom_bodyid
        self._base = model.body(ROBOT_PREFIX + BASE_BODY).id
        self.touching = False
        self.points: list[tuple[float, float]] = []

    def update(self, data: mujoco.MjData) -> tuple[float, float] | None:
        """Return the contact point when a new episode starts, else None."""
        touching = self.found[0] > 0
        started = touching and not self.touching
        self.touching = touching
        if not started:
            return None
        for contact in data.contact[: data.ncon]:
            if self._obstacles in (self._geom_body[contact.geom[0]], self._geom_body[contact.geom[1]]):
                point = (float(contact.pos[0]), float(contact.pos[1]))
                break
        else:  # unreachable while the sensor and the contact list agree; keep the robot's place
            point = (float(data.xpos[self._base][0]), float(data.xpos[self._base][1]))
        self.points.append(point)
        return point


class _Clearance:
    """Smallest and mean distance from base_link's centre to any obstacle or border (m), batched."""

    def __init__(self, footprints: shapes.Footprints):
        self._footprints = footprints
        self._pending: list[np.ndarray] = []
        self._pending_count = 0
        self.minimum = math.inf
        self._total = 0.0
        self._count = 0

    @property
    def mean(self) -> float:
        return self._total / self._count if self._count else math.inf

    def add(self, positions: np.ndarray) -> None:
        self._pending.append(positions)
        self._pending_count += len(positions)
        if self._pending_count >= CLEARANCE_BATCH:
            self.flush()

    def flush(self) -> None:
        if self._pending and len(self._footprints):
            distances = self._footprints.distance(np.vstack(self._pending))
            self.minimum = min(self.minimum, float(distances.min()))
            self._total += float(distances.sum())
            self._count += len(distances)
        self._pending.clear()
        self._pending_count = 0


class _Drive:
    """The robot in MuJoCo: its pose, and its wheels driven by PI loops at the motor rate.

    One control tick is `chunks_per_tick` motor periods of `motor_steps` physics steps;
    every wheel torque applied is recorded (for replay by the overhead benchmark).
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, control_hz: float):
        self.model, self.data = model, data
        self.gains = ControllerGains()
        self.geometry = robot_geometry()
        dt = model.opt.timestep
        self.motor_steps = max(1, round(1.0 / (self.gains.motor_rate_hz * dt)))
        self.motor_dt = self.motor_steps * dt
        self.chunks_per_tick = max(1, round(1.0 / (control_hz * self.motor_dt)))
        base = model.body(ROBOT_PREFIX + BASE_BODY).id
        self.xpos, self.xmat = data.xpos[base], data.xmat[base]
        free_joint = int(np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0])
        self.root_dof = model.jnt_dofadr[free_joint]
        wheel_joints = [model.joint(ROBOT_PREFIX + j).id for j in WHEEL_JOINTS]
        self.wheel_dofs = [model.jnt_dofadr[j] for j in wheel_joints]
        self.wheel_qpos = [model.jnt_qposadr[j] for j in wheel_joints]
        self.motors = [model.actuator(ROBOT_PREFIX + a).id for a in WHEEL_MOTORS]
        limit = self.geometry["torque_limit_nm"]
        self.wheels = [WheelPI(self.gains.wheel_kp, self.gains.wheel_ki, limit) for _ in self.motors]
        self.torques: list[tuple[float, float]] = []
        self.steps = 0

    def yaw(self) -> float:
        return math.atan2(self.xmat[3], self.xmat[0])

    def planar_speed(self) -> float:
        qvel = self.data.qvel
        return math.hypot(qvel[self.root_dof], qvel[self.root_dof + 1])

    def wheel_angles(self) -> tuple[float, float]:
        """The wheels' encoder angles (rad), left and right."""
        return float(self.data.qpos[self.wheel_qpos[0]]), float(self.data.qpos[self.wheel_qpos[1]])

    def run_tick(self, command: tuple[float, float], after_step) -> np.ndarray:
        """Drive one control tick; return base_link's xy after every motor period (chunks, 2)."""
        target_left, target_right = wheel_targets(
            *command,
            self.geometry["track_m"],
            self.geometry["wheel_radius_m"],
            self.gains.max_wheel_speed,
        )
        (left_pi, right_pi), (left_dof, right_dof) = self.wheels, self.wheel_dofs
        left_motor, right_motor = self.motors
        model, data, steps, dt = self.model, self.data, self.motor_steps, self.motor_dt
        qvel, ctrl, xpos, torques = data.qvel, data.ctrl, self.xpos, self.torques
        trace = np.empty((self.chunks_per_tick, 2))
        for chunk in range(self.chunks_per_tick):
            left = left_pi.torque(target_left, float(qvel[left_dof]), dt)
            right = right_pi.torque(target_right, float(qvel[right_dof]), dt)
            ctrl[left_motor] = left
            ctrl[right_motor] = right
            torques.append((left, right))
            mujoco.mj_step(model, data, steps)
            trace[chunk] = xpos[:2]
            after_step()
        self.steps += self.motor_steps * self.chunks_per_tick
        return trace


def run_scenario(scenario: Scenario, observers: tuple[Observer, ...] = ()) -> RunResult:
    """Simulate one scenario to the goal, the time limit, or the planner giving up."""
    model = build_model(scenario, rangefinders=False)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    drive = _Drive(model, data, scenario.run.control_hz)
    sensors = scenario.sensors
    layout = SonarLayout.from_spec(sensors)
    sonar = SonarRing(
        sensors.count,
        sensors.rays_per_sonar,
        sensors.range_max,
        np.random.default_rng(scenario.run.seed),
        noise_std=sensors.noise_std,
        dropout=sensors.dropout,
        crosstalk=sensors.crosstalk,
        dead=sensors.dead,
    )
    sonar_model = build_model(scenario, rangefinders=True)
    rays = SonarRays(
        sonar_model,
        sonar_model.sensor(ROBOT_PREFIX + "sonar0_ray0").id,
        sensors.count * sensors.rays_per_sonar,
        data,
    )
    localiser = _Localiser(drive, scenario)
    radius = drive.geometry["radius_m"]
    planner = make_planner(scenario.planner, scenario.planner_params, radius)
    clearance = _Clearance(
        shapes.scene_footprints(
            scenario.world.obstacles, scenario.world.size if scenario.world.border else None
        )
    )
    collisions = _CollisionCounter(model, data)
    goal = np.asarray(scenario.robot.goal, float)
    goal_x, goal_y = float(goal[0]), float(goal[1])
    tolerance = scenario.robot.goal_tolerance
    time_limit = scenario.run.time_limit_s - 1e-9
    sonar_period = 1.0 / sensors.rate_hz
    beam = math.radians(sensors.beam_deg)
    next_sonar = 0.0
    ranges = np.full(sensors.count, np.nan)
    warnings = data.warning.number  # counts per warning kind, a view into mjData
    fatal = [int(kind) for kind in FATAL_WARNINGS]

    times: list[float] = []
    positions: list[np.ndarray] = []
    modes: list[str] = []
    yaws: list[float] = []
    planner_cpu: list[float] = []
    objectives: list[tuple[float, float]] = []
    planes: list[tuple[tuple[float, float], tuple[float, float]]] = []
    path_length = 0.0
    local_minima = escapes = 0
    time_to_goal = None
    outcome, message = "timeout", ""

    def note(text: str) -> None:
        for observer in observers:
            observer.on_event(data.time, text)

    found = collisions.found  # robot-obstacle contact count, a view into sensordata

    def check_contacts() -> None:
        if found[0] > 0 or collisions.touching:
            point = collisions.update(data)
            if point is not None:
                note(f"collision at ({point[0]:.2f}, {point[1]:.2f})")

    start_wall = time.perf_counter()
    position = drive.xpos[:2].copy()
    clearance.add(position[None, :])
    while True:
        message = _fatal_warning(data) if any(warnings[kind] for kind in fatal) else None
        if message is None and not np.isfinite(data.qpos).all():
            message = f"the simulation diverged (non-finite state) at t = {data.time:.3f} s"
        if message is not None:
            outcome = "error"
            note(message)
            break
        if math.hypot(goal_x - position[0], goal_y - position[1]) <= tolerance:
            outcome, time_to_goal = "reached", data.time
            note("goal reached")
            break
        if data.time >= time_limit:
            note("time limit reached")
            break
        if data.time >= next_sonar - 1e-9:  # the sonar pings: cast its rays now
            ranges = sonar.read(rays.cast())
            while next_sonar <= data.time + 1e-9:
                next_sonar += sonar_period
        yaw = drive.yaw()
        yaws.append(yaw)
        believed_xy, believed_yaw = localiser.pose(position, yaw)
        if localiser.believes_arrived(data.time, believed_xy, goal, tolerance):
            outcome = "stuck"
            message = (
                f"odometry has put the robot at the goal for {BELIEF_PATIENCE_S:g} s, but it is "
                f"{math.dist(position, goal):.3f} m away: the planner has nowhere left to go"
            )
            note(message)
            break
        cpu_start = time.perf_counter()
        decision = planner.step(
            Observation(data.time, believed_xy, believed_yaw, goal, tolerance, layout.bearings, ranges, beam)
        )
        planner_cpu.append(time.perf_counter() - cpu_start)
        force_x, force_y = float(decision.force[0]), float(decision.force[1])
        if not (math.isfinite(force_x) and math.isfinite(force_y)):
            outcome = "error"
            message = f"planner {scenario.planner!r} gave a non-finite force at t = {data.time:.3f} s"
            note(message)
            break
        local_minima += decision.local_minimum
        escapes += decision.escape_completed
        for event in decision.events:
            note(event.text)
        if decision.objective is not None or decision.planes:
            _collect_virtual(decision, objectives, planes)
        command = heading_command(force_x, force_y, believed_yaw, drive.gains)
        times.append(data.time)
        positions.append(position)
        modes.append(decision.mode)
        if observers:
            belief = localiser.belief(believed_xy, believed_yaw)
            tick = Tick(data.time, position, yaw, drive.planar_speed(), ranges, decision, command, belief)
            for observer in observers:
                observer.on_tick(tick)
        if decision.gave_up:
            outcome = "stuck"
            break
        trace = drive.run_tick(command, check_contacts)
        clearance.add(trace)
        first, rest = _travelled(position, trace)
        path_length += first
        path_length += rest
        position = trace[-1].copy()
    wall_time = time.perf_counter() - start_wall
    clearance.flush()
    if observers and (not times or data.time > times[-1]):  # the state the run ended in
        final = Decision(force=np.zeros(2), mode="finished")
        tick = Tick(data.time, position, drive.yaw(), drive.planar_speed(), ranges, final, (0.0, 0.0))
        for observer in observers:
            observer.on_tick(tick)

    reached = outcome == "reached"
    summary = {
        "format": SUMMARY_FORMAT,
        "scenario": scenario.name,
        "planner": scenario.planner,
        "seed": scenario.run.seed,
        "outcome": outcome,
        "reached": reached,
        "success": reached and not collisions.points,
        "time_to_goal_s": None if time_to_goal is None else round(time_to_goal, 9),
        "sim_time_s": round(data.time, 9),
        "steps": drive.steps,
        "physics_dt_s": model.opt.timestep,
        "control_hz": scenario.run.control_hz,
        "wall_time_s": wall_time,
        "path_length_m": path_length,
        "collisions": len(collisions.points),
        "min_clearance_m": None if math.isinf(clearance.minimum) else clearance.minimum - radius,
        "mean_clearance_m": None if math.isinf(clearance.mean) else clearance.mean - radius,
        **_motion_quality(np.array(yaws), path_length),
        "planner_cpu_ms_mean": 1e3 * float(np.mean(planner_cpu)) if planner_cpu else None,
        "planner_cpu_ms_max": 1e3 * float(np.max(planner_cpu)) if planner_cpu else None,
        "local_minima": local_minima,
        "escapes": escapes,
        "robot_radius_m": radius,
        **_path_quality(scenario, radius, reached and not collisions.points, path_length, time_to_goal),
        "final_distance_to_goal_m": math.hypot(goal[0] - position[0], goal[1] - position[1]),
        "odometry_error_m": localiser.error(position),
        "trajectory_sha256": _trajectory_digest(positions, position, drive.yaw()),
        "message": message,
        "planner_params": planner.params,
        "version": __version__,
    }
    return RunResult(
        summary=summary,
        times=np.array(times),
        positions=np.array(positions).reshape(-1, 2),
        modes=modes,
        final_pose=(float(position[0]), float(position[1]), drive.yaw()),
        torques=np.array(drive.torques).reshape(-1, 2),
        collision_points=collisions.points,
        objectives=objectives,
        planes=planes,
    )


def _travelled(start: np.ndarray, trace: np.ndarray) -> tuple[float, float]:
    """Lengths (m) of the step from `start` to the first point of `trace` (N, 2) and of the rest."""
    steps = trace[1:] - trace[:-1]
    first = math.hypot(trace[0, 0] - start[0], trace[0, 1] - start[1])
    return first, float(np.hypot(steps[:, 0], steps[:, 1]).sum())


class _Localiser:
    """The pose the planner sees: the simulator's (`sensors.pose = "truth"`), or the belief of
    wheel odometry (`"odometry"`), updated at each control tick from the wheel encoders."""

    def __init__(self, drive: _Drive, scenario: Scenario):
        self._drive = drive
        self._arrived_at: float | None = None
        self.odometry = None
        if scenario.sensors.pose == "odometry":
            self.odometry = WheelOdometry(
                (*scenario.robot.start, scenario.robot.start_yaw),
                drive.wheel_angles(),
                drive.geometry["wheel_radius_m"],
                drive.geometry["track_m"],
                scenario.sensors.odometry_noise,
                np.random.default_rng((scenario.run.seed, ODOMETRY_STREAM)),
            )

    def pose(self, position: np.ndarray, yaw: float) -> tuple[np.ndarray, float]:
        """The planner's position (m) and yaw (rad), given the true ones."""
        if self.odometry is None:
            return position, yaw
        x, y, believed_yaw = self.odometry.update(self._drive.wheel_angles())
        return np.array([x, y]), believed_yaw

    def believes_arrived(self, time_s: float, xy: np.ndarray, goal: np.ndarray, tolerance: float) -> bool:
        """True once the believed position has stayed within the goal tolerance for
        BELIEF_PATIENCE_S (s); never with the true pose (the run has ended on arrival)."""
        if self.odometry is None or math.dist(xy, goal) > tolerance:
            self._arrived_at = None
            return False
        if self._arrived_at is None:
            self._arrived_at = time_s
        return time_s - self._arrived_at >= BELIEF_PATIENCE_S - 1e-9

    def belief(self, xy: np.ndarray, yaw: float) -> tuple[float, float, float] | None:
        """The believed pose for observers, None when the planner uses the true pose."""
        return None if self.odometry is None else (float(xy[0]), float(xy[1]), yaw)

    def error(self, position: np.ndarray) -> float | None:
        """Distance (m) between the believed and the true position, None without odometry."""
        if self.odometry is None:
            return None
        return math.hypot(self.odometry.x - position[0], self.odometry.y - position[1])


def _fatal_warning(data: mujoco.MjData) -> str | None:
    """A message for the first fatal MuJoCo warning raised so far, else None."""
    for warning, meaning in FATAL_WARNINGS.items():
        if data.warning[warning].number:
            return f"MuJoCo warning at t = {data.time:.3f} s: {meaning}"
    return None


def _trajectory_digest(positions: list[np.ndarray], final: np.ndarray, final_yaw: float) -> str:
    """SHA-256 of the positions at every control tick and the final pose, bit for bit:
    equal digests mean identical trajectories (the determinism check of bench sweeps)."""
    digest = hashlib.sha256()
    for position in positions:
        digest.update(np.asarray(position, dtype=np.float64).tobytes())
    digest.update(np.array([final[0], final[1], final_yaw], dtype=np.float64).tobytes())
    return digest.hexdigest()


def _path_quality(
    scenario: Scenario, radius: float, success: bool, path_length: float, time_to_goal: float | None
) -> dict:
    """The reference shortest path to the goal tolerance disc, the path length over it, and the
    BARN score (`barn_score`)."""
    reference = shortest_path_length(scenario, radius)
    optimal = None if reference is None else max(reference - scenario.robot.goal_tolerance, 0.0)
    ratio = path_length / optimal if time_to_goal is not None and optimal else None
    return {
        "optimal_length_m": optimal,
        "path_ratio": ratio,
        "score": barn_score(success, optimal, time_to_goal, ControllerGains().max_speed),
    }


def barn_score(
    success: bool, optimal_length_m: float | None, time_to_goal_s: float | None, top_speed_mps: float
) -> float | None:
    """The BARN benchmark's score (Perille et al. 2020; Xiao et al. 2022): success x OT / clip(T,
    2 OT, 8 OT), with OT the reference path length over the top speed (s) and T the time to goal
    (s). In [1/8, 1/2] for a success, 0 otherwise; None when no reference path exists."""
    if optimal_length_m is None:
        return None
    if not success or time_to_goal_s is None:
        return 0.0
    optimal_time = optimal_length_m / top_speed_mps
    if optimal_time <= 0:
        return 0.5  # the run began within the goal tolerance
    return optimal_time / min(max(time_to_goal_s, 2 * optimal_time), 8 * optimal_time)


TURN_NOISE_RAD = 1e-3
"""Heading changes per tick smaller than this do not count as turning (oscillation metric)."""


def _motion_quality(yaws: np.ndarray, path_length: float) -> dict:
    """Smoothness: total absolute heading change per metre travelled (rad/m); oscillation:
    reversals of the turning direction per metre (1/m). None when the robot did not move."""
    if len(yaws) < 2 or path_length < 1e-6:
        return {"smoothness_rad_per_m": None, "oscillation_per_m": None}
    turns = (np.diff(yaws) + math.pi) % (2 * math.pi) - math.pi
    signs = np.sign(turns[np.abs(turns) > TURN_NOISE_RAD])
    reversals = int(np.count_nonzero(np.diff(signs)))
    return {
        "smoothness_rad_per_m": float(np.sum(np.abs(turns))) / path_length,
        "oscillation_per_m": reversals / path_length,
    }


def _collect_virtual(decision: Decision, objectives: list, planes: list) -> None:
    """Remember each new virtual objective and virtual plane of a decision (for renders)."""
    if decision.objective is not None:
        objective = (float(decision.objective[0]), float(decision.objective[1]))
        if not objectives or objectives[-1] != objective:
            objectives.append(objective)
    for e1, e2 in decision.planes:
        plane = ((float(e1[0]), float(e1[1])), (float(e2[0]), float(e2[1])))
        if plane not in planes:
            planes.append(plane)
