"""The IMU's gyro as a navigation stack reads it: MuJoCo's rate at the `imu` site, with noise.

Each reading is the model's true yaw rate (the gyro's z, the site upright on a flat floor) plus
a bias and white noise of the profile's `gyro_noise_radps` (rad/s). The bias starts at 0 and
drifts as a first-order Gauss-Markov process of steady 1-sigma `gyro_drift_radps` (rad/s) and
time constant DRIFT_TIME_S, as Gazebo's IMU plugins drift.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from vplane_mj.sim.world import IMU_GYRO, ROBOT_PREFIX

DRIFT_TIME_S = 3600.0
"""Time constant (s) of the gyro bias's drift (chosen: an hour, a consumer MEMS gyro's)."""


class Gyro:
    """The yaw rate (rad/s) the robot's gyro reports (module docstring)."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        noise_radps: float,
        drift_radps: float,
        rng: np.random.Generator,
    ):
        first = model.sensor_adr[model.sensor(ROBOT_PREFIX + IMU_GYRO).id]
        self._rate = data.sensordata[first : first + 3]
        self.noise_radps, self._drift, self._rng = noise_radps, drift_radps, rng
        self.bias = 0.0

    def read(self, dt: float) -> float:
        """The yaw rate (rad/s) now, `dt` (s) after the last reading (the bias's drift)."""
        keep = math.exp(-dt / DRIFT_TIME_S)
        self.bias = keep * self.bias + self._drift * math.sqrt(1.0 - keep * keep) * float(self._rng.normal())
        return float(self._rate[2]) + self.bias + self.noise_radps * float(self._rng.normal())
