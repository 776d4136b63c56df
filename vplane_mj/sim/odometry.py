"""Dead reckoning from the wheel encoders, alone (the pose a robot without a localiser believes
in) or fused with a gyro in an EKF (the pose a navigation stack sees)."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.sim.ekf import GYRO_ROW, ODOMETRY_ROWS, PoseFilter
from vplane_mj.sim.imu import Gyro

ODOMETRY_STDS = np.array([math.sqrt(0.001), math.sqrt(0.03)])
"""1-sigma of the wheel odometry's v (m/s) and w (rad/s): the twist covariance the Jackal's
controller publishes (jackal_control/config/control.yaml, twist_covariance_diagonal)."""
GYRO_STD_FLOOR_RADPS = 0.005
"""The gyro's w is trusted no more than to this (rad/s): its bias is not in the state."""


class WheelOdometry:
    """Integrates the wheels' turned angles (rad) into a planar pose (m, m, rad).

    Each update's wheel travel carries a relative Gaussian error of `noise` (a fraction),
    drawn from `rng`; wheel slip is not seen by the encoders. Both make the belief drift.
    Between updates each wheel is assumed to turn at a constant rate (an exact arc).
    """

    def __init__(
        self,
        pose: tuple[float, float, float],
        wheel_angles: tuple[float, float],
        wheel_radius: float,
        track: float,
        noise: float,
        rng: np.random.Generator,
    ):
        self.x, self.y, self.yaw = pose
        self._angles = wheel_angles
        self._radius = wheel_radius
        self._track = track
        self._noise = noise
        self._rng = rng

    def update(self, wheel_angles: tuple[float, float]) -> tuple[float, float, float]:
        """Advance the belief by the wheels' turn since the last update; the new pose."""
        travel = self._radius * (np.asarray(wheel_angles) - np.asarray(self._angles))
        self._angles = wheel_angles
        if self._noise > 0.0:
            travel = travel * (1.0 + self._rng.normal(0.0, self._noise, 2))
        left, right = float(travel[0]), float(travel[1])
        distance, turn = (left + right) / 2, (right - left) / self._track
        chord = distance if abs(turn) < 1e-9 else 2 * distance / turn * math.sin(turn / 2)
        heading = self.yaw + turn / 2
        self.x += chord * math.cos(heading)
        self.y += chord * math.sin(heading)
        self.yaw = math.remainder(self.yaw + turn, 2 * math.pi)
        return self.x, self.y, self.yaw


class FusedOdometry:
    """The pose of an EKF (`sim.ekf.PoseFilter`) over the wheel odometry's and a gyro's rates,
    updated as `WheelOdometry` is, at each control tick: the wheels' travel since the last
    update (relative noise `noise`, drawn from `rng`) over the tick's `dt` gives (v, w), w with
    the separation the robot's own odometry uses; the gyro gives w (`sim.imu.Gyro`).

    The measurement 1-sigmas are those the Jackal's controller publishes with its odometry
    (ODOMETRY_STDS) and the gyro's own noise; the process noise the drive's accelerations.
    """

    def __init__(
        self,
        pose: tuple[float, float, float],
        wheel_angles: tuple[float, float],
        geometry: tuple[float, float],
        noise: float,
        rng: np.random.Generator,
        gyro: Gyro,
        accelerations: tuple[float, float],
    ):
        self._angles = wheel_angles
        self._radius, self._track = geometry
        self._noise, self._rng, self._gyro = noise, rng, gyro
        self._filter = PoseFilter(pose, *accelerations)
        self._gyro_std = max(gyro.noise_radps, GYRO_STD_FLOOR_RADPS)
        self._last_rate = 0.0  # at rest
        self.x, self.y, self.yaw = pose

    def update(self, wheel_angles: tuple[float, float], dt: float) -> tuple[float, float, float]:
        """Fold in the wheels' turn and the gyro over the last `dt` (s); the new pose."""
        travel = self._radius * (np.asarray(wheel_angles) - np.asarray(self._angles))
        self._angles = wheel_angles
        if dt <= 0.0:
            return self.x, self.y, self.yaw
        if self._noise > 0.0:
            travel = travel * (1.0 + self._rng.normal(0.0, self._noise, 2))
        left, right = float(travel[0]), float(travel[1])
        rates = np.array([(left + right) / 2 / dt, (right - left) / self._track / dt])
        # the rates are the interval's, so they move the pose over it: corrected, then predicted
        self._filter.correct(ODOMETRY_ROWS, rates, ODOMETRY_STDS)
        rate, self._last_rate = self._last_rate, self._gyro.read(dt)
        interval_rate = 0.5 * (rate + self._last_rate)  # the gyro reads instants: the interval's mean
        self._filter.correct(GYRO_ROW, np.array([interval_rate]), np.array([self._gyro_std]))
        self._filter.predict(dt)
        self.x, self.y, self.yaw = self._filter.pose
        return self.x, self.y, self.yaw
