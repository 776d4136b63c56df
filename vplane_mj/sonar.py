"""Sonar readings from MuJoCo rangefinder rays: one range per sonar, NaN when there is no echo."""

from __future__ import annotations

import numpy as np

from vplane_mj.robot import SONAR_MOUNT_RADIUS_M


class SonarRing:
    """Turns the raw ray readings of the ring into sonar ranges measured from the robot's centre.

    A ray that missed (MuJoCo reads -1) or reached the cutoff is no echo. The shortest
    echo of a sonar's rays wins, as the first echo of a real beam would. The faults, in
    this order, all drawn from `rng`: Gaussian noise (`noise_std`, m); lost readings
    (`dropout`, a probability); crosstalk (`crosstalk`, a probability), a spurious echo
    from another sonar's ping, uniformly distributed between the transducer and the true
    echo (or the range limit); and the `dead` sonars, which never echo.
    """

    def __init__(
        self,
        count: int,
        rays_per_sonar: int,
        range_max: float,
        rng: np.random.Generator,
        noise_std: float = 0.0,
        dropout: float = 0.0,
        crosstalk: float = 0.0,
        dead: tuple[int, ...] = (),
    ):
        self.count = count
        self.rays_per_sonar = rays_per_sonar
        self.range_max = range_max
        self.rng = rng
        self.noise_std = noise_std
        self.dropout = dropout
        self.crosstalk = crosstalk
        self.dead = np.array(dead, dtype=int)

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
        if self.crosstalk > 0.0:
            heard = self.rng.random(self.count) < self.crosstalk
            farthest = np.where(np.isnan(ranges), self.range_max + SONAR_MOUNT_RADIUS_M, ranges)
            spurious = self.rng.uniform(SONAR_MOUNT_RADIUS_M, farthest)
            ranges = np.where(heard, spurious, ranges)
        ranges[self.dead] = np.nan
        return ranges
