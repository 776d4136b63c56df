"""From a planner's force vector to wheel torques.

Three stages, each a pure function or a small stateful loop:
1. heading control: force F (world frame) -> body speed v (m/s) and turn rate omega (rad/s),
   v = k_v |F| max(0, cos e), omega = k_w e, e = angle from the heading to F, both limited;
2. differential-drive kinematics: (v, omega) -> wheel speed targets (rad/s), scaled together
   so neither wheel exceeds its limit and the path's curvature is kept;
3. a PI loop per wheel: wheel speed error -> torque (N m), clamped to the motor limit, with
   the integrator frozen while the output saturates (anti-windup).
"""

from __future__ import annotations

import math

from vplane_mj.planning.protocol.body import DriveLimits
from vplane_mj.planning.protocol.vectors import wrap_angle
from vplane_mj.robots.profiles import ControllerGains


def heading_command(
    fx: float, fy: float, yaw: float, gains: ControllerGains, limits: DriveLimits
) -> tuple[float, float]:
    """(v, omega) in m/s and rad/s that turns the robot toward the force and drives along it
    when aligned, within the drive's top speed and turn rate.

    A force too weak to have a direction, or not finite, stops the robot.
    """
    magnitude = math.hypot(fx, fy)
    if magnitude < 1e-9 or not math.isfinite(magnitude):
        return 0.0, 0.0
    error = wrap_angle(math.atan2(fy, fx) - yaw)
    top_speed, top_turn = limits.max_speed_mps, limits.max_turn_rate_radps
    speed = min(top_speed, gains.speed_gain * magnitude * max(0.0, math.cos(error)))
    turn = max(-top_turn, min(top_turn, gains.turn_gain * error))
    return speed, turn


def within_limits(command: tuple[float, float], limits: DriveLimits) -> tuple[float, float]:
    """A body speed (m/s, either way) and turn rate (rad/s) clamped to the drive's top ones; a
    non-finite value stops the robot."""
    speed, turn = command
    if not (math.isfinite(speed) and math.isfinite(turn)):
        return 0.0, 0.0
    top_speed, top_turn = limits.max_speed_mps, limits.max_turn_rate_radps
    return max(-top_speed, min(top_speed, float(speed))), max(-top_turn, min(top_turn, float(turn)))


def wheel_targets(
    speed: float, turn: float, track: float, wheel_radius: float, max_wheel_speed: float
) -> tuple[float, float]:
    """Left and right wheel speeds (rad/s) for body speed (m/s) and turn rate (rad/s)."""
    left = (speed - turn * track / 2) / wheel_radius
    right = (speed + turn * track / 2) / wheel_radius
    excess = max(abs(left), abs(right)) / max_wheel_speed
    if excess > 1.0:
        left, right = left / excess, right / excess
    return left, right


class CommandRamp:
    """The (speed, turn rate) command driven, moved toward the one asked for at most by the
    drive's accelerations (m/s^2, rad/s^2) per motor period; braking as fast as accelerating."""

    def __init__(self, limits: DriveLimits):
        self.limits = limits
        self.speed = 0.0
        self.turn = 0.0

    def toward(self, command: tuple[float, float], dt: float) -> tuple[float, float]:
        """The command to drive for the next `dt` seconds on the way to `command`."""
        dv = self.limits.max_accel_mps2 * dt
        dw = self.limits.max_turn_accel_radps2 * dt
        self.speed = min(self.speed + dv, max(self.speed - dv, command[0]))
        self.turn = min(self.turn + dw, max(self.turn - dw, command[1]))
        return self.speed, self.turn


class WheelPI:
    """PI speed loop of one wheel: torque = kp e + ki integral(e), clamped to +-limit (N m)."""

    def __init__(self, kp: float, ki: float, torque_limit: float):
        self.kp = kp
        self.ki = ki
        self.limit = torque_limit
        self.integral = 0.0

    def torque(self, target: float, measured: float, dt: float) -> float:
        error = target - measured
        candidate = self.integral + error * dt
        raw = self.kp * error + self.ki * candidate
        if -self.limit < raw < self.limit:
            self.integral = candidate
            return raw
        # Saturated: keep the integral unless this error would unwind it.
        if (raw > 0) != (error > 0):
            self.integral = candidate
        return max(-self.limit, min(self.limit, self.kp * error + self.ki * self.integral))
