"""The run loop: physics at a fixed step, wheel PI at the motor rate, sonar + planner at control_hz.

The planner sees only an Observation (pose, goal, sonar ranges). The simulator's obstacle
geometry is used only to score the run (clearance) and to draw it, never to plan.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Protocol

import mujoco
import numpy as np

from vplane_mj import __version__, shapes
from vplane_mj.control import ControllerGains, WheelPI, heading_command, wheel_targets
from vplane_mj.planning.registry import make_planner
from vplane_mj.planning.types import Decision, Observation
from vplane_mj.robot import BASE_BODY, WHEEL_JOINTS, WHEEL_MOTORS, robot_geometry
from vplane_mj.scenario import Scenario
from vplane_mj.sonar import SonarRing
from vplane_mj.world import BORDER_SIDES, ROBOT_PREFIX, SonarLayout, build_model

SUMMARY_FORMAT = 1


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


class Observer(Protocol):
    """Something that watches a run: called at every control tick and once at the end."""

    def on_tick(self, tick: Tick) -> None: ...

    def on_event(self, time_s: float, text: str) -> None: ...


@dataclass
class RunResult:
    """The summary of INTERFACE.md section 3 plus the trajectory at control ticks."""

    summary: dict
    times: np.ndarray
    positions: np.ndarray
    modes: list[str]
    final_qpos: np.ndarray
    collision_points: list[tuple[float, float]] = field(default_factory=list)


class _ContactWatch:
    """Counts separate contact episodes between robot geoms and obstacle or border geoms."""

    def __init__(self, model: mujoco.MjModel):
        robot_body = model.body(ROBOT_PREFIX + BASE_BODY).id
        self.is_robot = np.zeros(model.ngeom, bool)
        self.is_obstacle = np.zeros(model.ngeom, bool)
        for g in range(model.ngeom):
            name = model.geom(g).name
            if model.body_rootid[model.geom_bodyid[g]] == model.body_rootid[robot_body]:
                self.is_robot[g] = True
            elif name.startswith("obstacle") or name in {f"border_{s}" for s in BORDER_SIDES}:
                self.is_obstacle[g] = True
        self.touching = False
        self.episodes = 0

    def update(self, data: mujoco.MjData) -> tuple[float, float] | None:
        """Check the current contacts; return the contact point when a new episode starts."""
        if data.ncon == 0:
            self.touching = False
            return None
        geoms = data.contact.geom
        pairs = (self.is_robot[geoms[:, 0]] & self.is_obstacle[geoms[:, 1]]) | (
            self.is_obstacle[geoms[:, 0]] & self.is_robot[geoms[:, 1]]
        )
        touching = bool(pairs.any())
        started = touching and not self.touching
        self.touching = touching
        if started:
            self.episodes += 1
            point = data.contact.pos[int(np.argmax(pairs))]
            return float(point[0]), float(point[1])
        return None


def run_scenario(scenario: Scenario, observers: tuple[Observer, ...] = ()) -> RunResult:
    """Simulate one scenario to the goal, the time limit, or the planner giving up."""
    model = build_model(scenario)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geometry = robot_geometry()
    gains = ControllerGains()
    layout = SonarLayout.from_spec(scenario.sensors)
    rng = np.random.default_rng(scenario.run.seed)
    sonar = SonarRing(
        scenario.sensors.count, scenario.sensors.rays_per_sonar, scenario.sensors.range_max,
        scenario.sensors.noise_std, scenario.sensors.dropout, rng,
    )
    planner = make_planner(scenario.planner, scenario.planner_params)
    field_of_obstacles = shapes.scene_footprints(
        scenario.world.obstacles, scenario.world.size if scenario.world.border else None
    )
    contacts = _ContactWatch(model)

    dt = model.opt.timestep
    motor_steps = max(1, round(1.0 / (gains.motor_rate_hz * dt)))
    chunks_per_tick = max(1, round(1.0 / (scenario.run.control_hz * dt * motor_steps)))
    base = model.body(ROBOT_PREFIX + BASE_BODY).id
    root_dof = model.jnt_dofadr[int(np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0])]
    wheel_dofs = [model.jnt_dofadr[model.joint(ROBOT_PREFIX + j).id] for j in WHEEL_JOINTS]
    motors = [model.actuator(ROBOT_PREFIX + a).id for a in WHEEL_MOTORS]
    wheels = [WheelPI(gains.wheel_kp, gains.wheel_ki, geometry["torque_limit_nm"]) for _ in motors]
    goal = np.asarray(scenario.robot.goal, float)
    sonar_period = 1.0 / scenario.sensors.rate_hz
    next_sonar = 0.0
    ranges = np.full(scenario.sensors.count, np.nan)

    times: list[float] = []
    positions: list[np.ndarray] = []
    modes: list[str] = []
    collision_points: list[tuple[float, float]] = []
    path_length = 0.0
    min_clearance = math.inf
    local_minima = 0
    escapes = 0
    steps = 0
    time_to_goal = None
    outcome = "timeout"
    message = ""

    def note(text: str) -> None:
        for observer in observers:
            observer.on_event(data.time, text)

    start_wall = time.perf_counter()
    position = data.xpos[base][:2].copy()
    while True:
        if not np.all(np.isfinite(data.qpos)):
            outcome, message = "error", "the simulation diverged (non-finite state)"
            note(message)
            break
        xmat = data.xmat[base]
        yaw = math.atan2(xmat[3], xmat[0])
        distance = float(np.hypot(*(goal - position)))
        if distance <= scenario.robot.goal_tolerance:
            outcome, time_to_goal = "reached", data.time
            note("goal reached")
            break
        if data.time >= scenario.run.time_limit_s - 1e-9:
            note("time limit reached")
            break
        if data.time >= next_sonar - 1e-9:
            ranges = sonar.read(data.sensordata)
            next_sonar += sonar_period
        obs = Observation(
            time_s=data.time, position=position.copy(), yaw=yaw, goal=goal,
            goal_tolerance=scenario.robot.goal_tolerance, bearings=layout.bearings, ranges=ranges,
        )
        decision = planner.step(obs)
        local_minima += decision.local_minimum
        escapes += decision.escape_completed
        for text in decision.events:
            note(text)
        speed = math.hypot(data.qvel[root_dof], data.qvel[root_dof + 1])
        command = heading_command(float(decision.force[0]), float(decision.force[1]), yaw, gains)
        times.append(data.time)
        positions.append(position.copy())
        modes.append(decision.mode)
        tick = Tick(data.time, position.copy(), yaw, speed, ranges, decision, command)
        for observer in observers:
            observer.on_tick(tick)
        if decision.gave_up:
            outcome = "stuck"
            break

        targets = wheel_targets(
            *command, geometry["track_m"], geometry["wheel_radius_m"], gains.max_wheel_speed
        )
        chunk_positions = np.empty((chunks_per_tick + 1, 2))
        chunk_positions[0] = position
        motor_dt = motor_steps * dt
        for chunk in range(chunks_per_tick):
            for pi, motor, dof, target in zip(wheels, motors, wheel_dofs, targets, strict=True):
                data.ctrl[motor] = pi.torque(target, data.qvel[dof], motor_dt)
            mujoco.mj_step(model, data, nstep=motor_steps)
            steps += motor_steps
            chunk_positions[chunk + 1] = data.xpos[base][:2]
            point = contacts.update(data)
            if point is not None:
                collision_points.append(point)
                note(f"collision at ({point[0]:.2f}, {point[1]:.2f})")
        position = chunk_positions[-1].copy()
        path_length += float(np.sum(np.hypot(*np.diff(chunk_positions, axis=0).T)))
        min_clearance = min(min_clearance, float(field_of_obstacles.distance(chunk_positions).min()))
    wall_time = time.perf_counter() - start_wall

    radius = geometry["radius_m"]
    reached = outcome == "reached"
    summary = {
        "format": SUMMARY_FORMAT,
        "scenario": scenario.name,
        "planner": scenario.planner,
        "seed": scenario.run.seed,
        "outcome": outcome,
        "reached": reached,
        "success": reached and contacts.episodes == 0,
        "time_to_goal_s": time_to_goal,
        "sim_time_s": data.time,
        "steps": steps,
        "physics_dt_s": dt,
        "control_hz": scenario.run.control_hz,
        "wall_time_s": wall_time,
        "path_length_m": path_length,
        "collisions": contacts.episodes,
        "min_clearance_m": (min_clearance - radius) if math.isfinite(min_clearance) else None,
        "local_minima": local_minima,
        "escapes": escapes,
        "robot_radius_m": radius,
        "final_distance_to_goal_m": float(np.hypot(*(goal - position))),
        "message": message,
        "planner_params": planner.params,
        "version": __version__,
    }
    return RunResult(
        summary=summary,
        times=np.array(times),
        positions=np.array(positions).reshape(-1, 2),
        modes=modes,
        final_qpos=data.qpos.copy(),
        collision_points=collision_points,
    )
