"""The robot in MuJoCo: its pose, its wheels driven by PI loops, the pose its planner believes,
its contacts with obstacles, and the warnings after which the simulation cannot go on."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from vplane_mj.robots.facts import BASE_BODY, WHEEL_JOINTS, WHEEL_MOTORS, robot_geometry
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario import Scenario
from vplane_mj.sim.control import CommandRamp, WheelPI, wheel_targets
from vplane_mj.sim.imu import Gyro
from vplane_mj.sim.moving import MovingObstacles
from vplane_mj.sim.odometry import FusedOdometry, WheelOdometry
from vplane_mj.sim.world import BUMP_FLOOR, BUMP_SENSOR, OBSTACLES_BODY, ROBOT_PREFIX

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


class Drive:
    """The robot in MuJoCo: its pose, and its wheels driven by PI loops at the motor rate.

    One control tick is `chunks_per_tick` motor periods of `motor_steps` physics steps;
    every wheel torque applied is recorded (for replay by the overhead benchmark). The gains,
    limits and wheel geometry are the robot profile's; the wheel targets use its track times
    its `track_scale` (a skid-steer robot turns slower than its wheels' track predicts), and
    a profile with `ramped` commands has them ramped at its accelerations every motor period.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        control_hz: float,
        profile: str = "default",
        moving: MovingObstacles | None = None,
    ):
        self.model, self.data = model, data
        robot = robot_profile(profile)
        self.gains = robot.gains
        self.limits = robot.limits
        self.geometry = robot_geometry(profile)
        self.track_m = self.geometry["track_m"] * robot.track_scale
        self.ramp = CommandRamp(self.limits) if robot.ramped else None
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
        self.moving = moving if moving is not None and moving.count else None
        """The world's moving obstacles, placed before every physics step; None without any."""
        self._warnings = data.warning.number  # counts per warning kind, a view into mjData
        self._no_warnings = bytes(self._warnings.nbytes)

    def yaw(self) -> float:
        return math.atan2(self.xmat[3], self.xmat[0])

    def planar_speed(self) -> float:
        qvel = self.data.qvel
        return math.hypot(qvel[self.root_dof], qvel[self.root_dof + 1])

    def body_velocity(self) -> tuple[float, float]:
        """The speed along the heading (m/s, negative when reversing) and the turn rate about +z
        (rad/s): the free joint's linear velocity is in the world frame, its angular one in
        base_link's."""
        qvel, yaw = self.data.qvel, self.yaw()
        forward = qvel[self.root_dof] * math.cos(yaw) + qvel[self.root_dof + 1] * math.sin(yaw)
        return float(forward), float(qvel[self.root_dof + 5])

    def wheel_velocity(self) -> tuple[float, float]:
        """The speed along the heading (m/s) and the turn rate (rad/s) that the wheels' speeds
        give, as encoders measure them (the track is the effective one of a skid-steer robot)."""
        radius = self.geometry["wheel_radius_m"]
        left, right = (float(self.data.qvel[dof]) for dof in self.wheel_dofs)
        return radius * (left + right) / 2, radius * (right - left) / self.track_m

    def wheel_angles(self) -> tuple[float, float]:
        """The wheels' encoder angles (rad), left and right."""
        return float(self.data.qpos[self.wheel_qpos[0]]), float(self.data.qpos[self.wheel_qpos[1]])

    def run_tick(
        self, command: tuple[float, float], after_step
    ) -> tuple[np.ndarray, float, np.ndarray | None]:
        """Drive one control tick; return base_link's x, y (m) and yaw (rad) after every motor
        period (chunks, 3), the length (m) of the path through them from the pose before the
        tick (each step's straight length, added in order), and where the moving obstacles
        stood at those poses (chunks, count, 2; m), None without any (`moving`, whose mocap
        bodies are placed before every physics step)."""
        target_left, target_right = self._wheel_targets(command)
        (left_pi, right_pi), (left_dof, right_dof) = self.wheels, self.wheel_dofs
        left_motor, right_motor = self.motors
        model, data, steps, dt = self.model, self.data, self.motor_steps, self.motor_dt
        qvel, ctrl, xpos, xmat, torques = data.qvel, data.ctrl, self.xpos, self.xmat, self.torques
        moving = self.moving
        trace = []
        places = []
        x0, y0 = float(xpos[0]), float(xpos[1])
        length = 0.0
        for _ in range(self.chunks_per_tick):
            if self.ramp is not None:
                target_left, target_right = self._wheel_targets(self.ramp.toward(command, dt))
            left = left_pi.torque(target_left, float(qvel[left_dof]), dt)
            right = right_pi.torque(target_right, float(qvel[right_dof]), dt)
            ctrl[left_motor] = left
            ctrl[right_motor] = right
            torques.append((left, right))
            if moving is None:
                mujoco.mj_step(model, data, steps)
            else:
                for _ in range(steps):
                    moving.place(data.time)
                    mujoco.mj_step(model, data)
                places.append(moving.xy.copy())
            x, y = float(xpos[0]), float(xpos[1])
            trace.append((x, y, math.atan2(xmat[3], xmat[0])))
            length += math.hypot(x - x0, y - y0)
            x0, y0 = x, y
            after_step()
        self.steps += self.motor_steps * self.chunks_per_tick
        return np.array(trace), length, np.array(places) if moving is not None else None

    def _wheel_targets(self, command: tuple[float, float]) -> tuple[float, float]:
        """Left and right wheel speeds (rad/s) for a body speed (m/s) and turn rate (rad/s)."""
        return wheel_targets(
            *command, self.track_m, self.geometry["wheel_radius_m"], self.gains.max_wheel_speed
        )

    def fatal_warning(self) -> str | None:
        """Why the simulation cannot go on (a fatal MuJoCo warning, a non-finite state), or None."""
        data = self.data
        if self._warnings.tobytes() != self._no_warnings:  # some warning: is it a fatal one?
            for warning, meaning in FATAL_WARNINGS.items():
                if data.warning[warning].number:
                    return f"MuJoCo warning at t = {data.time:.3f} s: {meaning}"
        qpos = data.qpos
        if not math.isfinite(qpos.dot(qpos)):  # a non-finite coordinate (or one beyond 1e154)
            return f"the simulation diverged (non-finite state) at t = {data.time:.3f} s"
        return None


class Localiser:
    """The pose the planner sees: the simulator's (`sensors.pose = "truth"`), the belief of
    wheel odometry (`"odometry"`), or an EKF's over the wheel odometry and the IMU's gyro
    (`"ekf"`), updated at each control tick; both odometries with the wheel separation the
    robot's own odometry uses (its profile's `odometry_track_scale`)."""

    def __init__(self, drive: Drive, scenario: Scenario):
        self._drive = drive
        self._arrived_at: float | None = None
        self._time = drive.data.time
        self.odometry: WheelOdometry | FusedOdometry | None = None
        self.largest_error = 0.0
        pose = (*scenario.robot.start, scenario.robot.start_yaw)
        profile = robot_profile(scenario.robot.profile)
        radius, track = (
            drive.geometry["wheel_radius_m"],
            drive.geometry["track_m"] * profile.odometry_track_scale,
        )
        rng = np.random.default_rng((scenario.run.seed, ODOMETRY_STREAM))
        noise = scenario.sensors.odometry_noise
        if scenario.sensors.pose == "odometry":
            self.odometry = WheelOdometry(pose, drive.wheel_angles(), radius, track, noise, rng)
        elif scenario.sensors.pose == "ekf":
            gyro = Gyro(drive.model, drive.data, profile.gyro_noise_radps, profile.gyro_drift_radps, rng)
            limits = profile.limits
            accelerations = (limits.max_accel_mps2, limits.max_turn_accel_radps2)
            self.odometry = FusedOdometry(
                pose, drive.wheel_angles(), (radius, track), noise, rng, gyro, accelerations
            )

    def pose(self, position: np.ndarray, yaw: float) -> tuple[np.ndarray, float]:
        """The planner's position (m) and yaw (rad), given the true ones."""
        if self.odometry is None:
            return position, yaw
        time_s = self._drive.data.time
        if isinstance(self.odometry, FusedOdometry):
            x, y, believed_yaw = self.odometry.update(self._drive.wheel_angles(), time_s - self._time)
        else:
            x, y, believed_yaw = self.odometry.update(self._drive.wheel_angles())
        self._time = time_s
        self.largest_error = max(self.largest_error, math.hypot(x - position[0], y - position[1]))
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

    def largest(self, position: np.ndarray) -> float | None:
        """The largest distance (m) between the believed and the true position over the run, now
        included; None when the planner uses the true pose."""
        error = self.error(position)
        return None if error is None else max(self.largest_error, error)

    def error(self, position: np.ndarray) -> float | None:
        """Distance (m) between the believed and the true position, None without odometry."""
        if self.odometry is None:
            return None
        return math.hypot(self.odometry.x - position[0], self.odometry.y - position[1])


class CollisionCounter:
    """Separate contact episodes between the robot and the obstacles body.

    MuJoCo's contact sensor counts the contacts; only when an episode starts are the
    contacts scanned in Python for the point of impact.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData):
        bump = model.sensor_adr[model.sensor(BUMP_SENSOR).id]
        self.found = data.sensordata[bump : bump + 1]
        """The robot's contacts with the obstacles (`vplane_mj.sim.world.BUMP_SENSOR`), or in a
        world with moving obstacles with anything, floor included."""
        floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, BUMP_FLOOR)
        self.floor = np.zeros(1) if floor < 0 else data.sensordata[model.sensor_adr[floor] :][:1]
        """The robot's contacts with the floor, counted among `found`; none counted (zero)
        without moving obstacles."""
        names = [
            OBSTACLES_BODY,
            *(model.body(i).name for i in range(model.nbody) if model.body_mocapid[i] >= 0),
        ]
        self._obstacles = {model.body(name).id for name in names}
        self._geom_body = model.geom_bodyid
        self._base = model.body(ROBOT_PREFIX + BASE_BODY).id
        self.touching = False
        self.points: list[tuple[float, float]] = []

    def in_contact(self) -> bool:
        """Whether the robot touches an obstacle now (after the last physics step)."""
        return bool(self.found[0] > self.floor[0])

    def update(self, data: mujoco.MjData) -> tuple[float, float] | None:
        """Return the contact point when a new episode starts, else None."""
        touching = self.in_contact()
        started = touching and not self.touching
        self.touching = touching
        if not started:
            return None
        body = self._geom_body
        for contact in data.contact[: data.ncon]:
            if body[contact.geom[0]] in self._obstacles or body[contact.geom[1]] in self._obstacles:
                point = (float(contact.pos[0]), float(contact.pos[1]))
                break
        else:  # unreachable while the sensor and the contact list agree; keep the robot's place
            point = (float(data.xpos[self._base][0]), float(data.xpos[self._base][1]))
        self.points.append(point)
        return point
