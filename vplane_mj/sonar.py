"""Sonar readings from MuJoCo rangefinder rays: one range per sonar, NaN when there is no echo."""

from __future__ import annotations

import numpy as np

from vplane_mj.robot import SONAR_MOUNT_RADIUS_M


class SonarRing:
    """Turns the raw ray readings of the ring into sonar ranges measured from the robot's centre.

    A ray that missed (MuJoCo reads -1) or reached the cutoff is no echo. The shortest
    echo of a sonar's rays wins, as the first echo of a real beam would. Gaussian noise
    (`noise_std`, m) and lost readings (`dropout`, a probability) come from `rng`.
    """

    def __init__(
        self,
        count: int,
        rays_per_sonar: int,
        range_max: float,
        noise_std: float,
        dropout: float,
        rng: np.random.Generator,
    ):
        self.count = count
        self.rays_per_sonar = rays_per_sonar
        self.range_max = range_max
        self.noise_std = noise_std
        self.dropout = dropout
        self.rng = rng

    def read(self, rays: np.ndarray) -> np.ndarray:
        """Ranges (m, from the robot's centre) of each sonar; `rays` is (count * rays_per_sonar,)."""
        per_sonar = np.asarray(rays, float).reshape(self.count, self.rays_per_sonar)
        echo = (per_sonar >= 0.0) & (per_sonar < self.range_max)
        shortest = np.where(echo, per_sonar, np.inf).min(axis=1)
        ranges = np.where(np.isfinite(shortest), shortest + SONAR_MOUNT_RADIUS_M, np.nan)
        if self.noise_std > 0.0:
            ranges = ranges + self.rng.normal(0.0, self.noise_std, self.count)
            ranges = np.maximum(ranges, SONAR_MOUNT_RADIUS_M)
        if self.dropout > 0.0:
            ranges[self.rng.random(self.count) < self.dropout] = np.nan
        return ranges
