"""The pose a navigation stack sees: an extended Kalman filter over wheel odometry and a gyro.

The role robot_localization's `ekf_node` plays on the Jackal (Moore and Stouch, "A Generalized
Extended Kalman Filter Implementation for the Robot Operating System", IAS-13, 2014): a
planar state s = (x, y, yaw, v, w) (m, m, rad, m/s, rad/s) predicted at constant velocity and
corrected by the body rates the sensors measure, the wheel odometry's (v, w) and the gyro's w.
Neither measures the pose itself: the estimate integrates the fused rates, and its error grows
with distance, but a gyro that sees the true turn rate keeps the heading where a skid-steer
robot's encoders, which see its wheels skid as turning, would let it drift.

Prediction over dt (the unicycle, along the heading halfway, m = yaw + w dt / 2):
    x' = x + v cos(m) dt,  y' = y + v sin(m) dt,  yaw' = yaw + w dt,  v' = v,  w' = w
with process noise on v and w as accelerations of `accel_std` (m/s^2) and `turn_accel_std`
(rad/s^2). Each measurement z = H s + noise, R diagonal, is folded in by the Kalman update,
its covariance in Joseph's form (Bar-Shalom, Li and Kirubarajan, "Estimation with Applications
to Tracking and Navigation", 2001).
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.planning.protocol.matrices import product, solve

X, Y, YAW, V, W = range(5)
ODOMETRY_ROWS = np.array([[0, 0, 0, 1, 0], [0, 0, 0, 0, 1]], dtype=float)
"""H of the wheel odometry's (v, w)."""
GYRO_ROW = np.array([[0, 0, 0, 0, 1]], dtype=float)
"""H of the gyro's w."""


class PoseFilter:
    """The EKF of the module docstring, started at a known pose at rest."""

    def __init__(
        self,
        pose: tuple[float, float, float],
        accel_std: float,
        turn_accel_std: float,
    ):
        self.state = np.array([pose[0], pose[1], pose[2], 0.0, 0.0])
        self.cov = np.diag([1e-6, 1e-6, 1e-6, 1e-4, 1e-4])
        self.accel_std = accel_std
        self.turn_accel_std = turn_accel_std

    @property
    def pose(self) -> tuple[float, float, float]:
        """The estimate's x (m), y (m) and yaw (rad, in [-pi, pi])."""
        return float(self.state[X]), float(self.state[Y]), float(self.state[YAW])

    def predict(self, dt: float) -> None:
        """Advance the estimate by `dt` (s) at constant velocity."""
        x, y, yaw, v, w = self.state
        mid = yaw + 0.5 * w * dt  # the heading halfway: second order along an arc
        c, s = math.cos(mid), math.sin(mid)
        self.state = np.array([x + v * c * dt, y + v * s * dt, math.remainder(yaw + w * dt, math.tau), v, w])
        jacobian = np.eye(5)
        jacobian[X, YAW], jacobian[X, V], jacobian[X, W] = -v * s * dt, c * dt, -0.5 * v * s * dt * dt
        jacobian[Y, YAW], jacobian[Y, V], jacobian[Y, W] = v * c * dt, s * dt, 0.5 * v * c * dt * dt
        jacobian[YAW, W] = dt
        noise = np.zeros((5, 5))
        noise[V, V] = (self.accel_std**2) * dt
        noise[W, W] = (self.turn_accel_std**2) * dt
        self.cov = product(product(jacobian, self.cov), jacobian.T) + noise

    def correct(self, rows: np.ndarray, measured: np.ndarray, stds: np.ndarray) -> None:
        """Fold in the measurement `measured` of rows @ state with 1-sigma `stds` (same units)."""
        residual = measured - product(rows, self.state)
        innovation_cov = product(product(rows, self.cov), rows.T) + np.diag(np.asarray(stds, float) ** 2)
        gain = solve(innovation_cov, product(rows, self.cov)).T
        self.state = self.state + product(gain, residual)
        self.state[YAW] = math.remainder(self.state[YAW], math.tau)
        keep = np.eye(5) - product(gain, rows)
        noise = product(product(gain, np.diag(np.asarray(stds, float) ** 2)), gain.T)
        self.cov = product(product(keep, self.cov), keep.T) + noise
