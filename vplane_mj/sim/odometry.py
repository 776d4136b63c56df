"""Dead reckoning from the wheel encoders: the pose a robot without a localiser believes in."""

from __future__ import annotations

import math

import numpy as np


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
