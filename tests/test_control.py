"""Heading control, differential-drive kinematics and the wheel PI loop (pure parts)."""

import math

import pytest

from vplane_mj.robots.profiles import DEFAULT
from vplane_mj.sim.control import WheelPI, heading_command, wheel_targets, wrap_angle

GAINS, LIMITS = DEFAULT.gains, DEFAULT.limits


def test_aligned_force_drives_straight_at_limited_speed():
    v, w = heading_command(10.0, 0.0, 0.0, GAINS, LIMITS)
    assert v == pytest.approx(LIMITS.max_speed_mps) and w == 0.0


def test_force_behind_turns_in_place_toward_it():
    v, w = heading_command(-1.0, 0.1, 0.0, GAINS, LIMITS)
    assert v == 0.0 and w == pytest.approx(LIMITS.max_turn_rate_radps)
    v, w = heading_command(-1.0, -0.1, 0.0, GAINS, LIMITS)
    assert w == pytest.approx(-LIMITS.max_turn_rate_radps)


def test_zero_force_stops():
    assert heading_command(0.0, 0.0, 1.0, GAINS, LIMITS) == (0.0, 0.0)


def test_wrap_angle_range():
    for a in (-10.0, -math.pi, 0.0, math.pi, 7.0):
        assert -math.pi <= wrap_angle(a) < math.pi
        assert math.isclose(math.cos(wrap_angle(a)), math.cos(a), abs_tol=1e-12)


def test_wheel_targets_keep_curvature_when_limited():
    left, right = wheel_targets(0.5, 2.0, 0.15, 0.04, 10.0)
    assert max(abs(left), abs(right)) == pytest.approx(10.0)
    # curvature omega / v = (right - left) / (track/2 * (right + left)) is kept
    assert (right - left) / (0.075 * (right + left)) == pytest.approx(2.0 / 0.5)
    assert wheel_targets(0.0, 1.0, 0.15, 0.04, 100.0) == pytest.approx((-1.875, 1.875))


def test_wheel_pi_saturates_and_does_not_wind_up():
    pi = WheelPI(kp=0.1, ki=1.0, torque_limit=0.3)
    for _ in range(1000):  # a blocked wheel: large error for 10 s
        assert abs(pi.torque(10.0, 0.0, 0.01)) <= 0.3
    # when the wheel catches up the torque drops below the limit within a few updates
    torques = [pi.torque(10.0, 10.5, 0.01) for _ in range(5)]
    assert torques[-1] < 0.3


def test_wheel_pi_removes_steady_error():
    pi = WheelPI(kp=0.1, ki=1.0, torque_limit=1.0)
    speed = 0.0
    for _ in range(2000):  # a first-order wheel with friction torque 0.05 N m
        torque = pi.torque(5.0, speed, 0.01)
        speed += 0.01 * (torque - 0.05 - 0.01 * speed) / 0.01
    assert speed == pytest.approx(5.0, abs=0.01)
