"""Sonar readings: the ring's rays cast in MuJoCo when the sonar pings, one range per sonar.

`SonarRays` evaluates the ring's MuJoCo rangefinders on demand, so the rays are cast only
at the sonar's rate, not at every physics step; `SonarRing` turns the raw ray readings
into ranges (shortest echo, faults), NaN when there is no echo.
"""

from __future__ import annotations

import mujoco
import numpy as np


class SonarRays:
    """The rangefinders of the sonar ring, evaluated on the robot's current kinematics.

    The run steps a model without rangefinders (MuJoCo would cast every ray at every
    physics step). At a ping, the poses of every geom and site in `source`, as the last
    physics step computed them, are copied into `model` (the same world with the
    rangefinders) and MuJoCo's position-stage sensors run there once: the readings are
    exactly those the rangefinders would have given in that step (m from the ray sites,
    -1 for no hit, `range_max` at the cutoff).
    """

    def __init__(self, model: mujoco.MjModel, first_sensor: int, rays: int, source: mujoco.MjData):
        self.model = model
        self.data = mujoco.MjData(model)
        adr = model.sensor_adr[first_sensor]
        self.readings = self.data.sensordata[adr : adr + rays]
        poses = ("geom_xpos", "geom_xmat", "site_xpos", "site_xmat")
        self._copies = [(getattr(self.data, name), getattr(source, name)) for name in poses]

    def cast(self) -> np.ndarray:
        """The rays' readings (rays,) from the kinematics of `source` (a view, valid until the next cast)."""
        for mine, theirs in self._copies:
            np.copyto(mine, theirs)
        mujoco.mj_sensorPos(self.model, self.data)
        return self.readings


class SonarRing:
    """Turns the raw ray readings of the sonars into ranges measured from the robot's centre.

    Each sonar's range is its own reading plus its mount's `reach` along its bearing (m).

    A ray that missed (MuJoCo reads -1) or reached the cutoff is no echo. The shortest
    echo of a sonar's rays wins, as the first echo of a real beam would. The faults, in
    this order, all drawn from `rng`: Gaussian noise (`noise_std`, m); lost readings
    (`dropout`, a probability); crosstalk (`crosstalk`, a probability), a spurious echo
    from another sonar's ping, uniformly distributed between the transducer and the true
    echo (or the range limit); and the `dead` sonars, which never echo.
    """

    def __init__(
        self,
        reach: np.ndarray,
        rays_per_sonar: int,
        range_max: float,
        rng: np.random.Generator,
        noise_std: float = 0.0,
        dropout: float = 0.0,
        crosstalk: float = 0.0,
        dead: tuple[int, ...] = (),
    ):
        self.reach = np.asarray(reach, dtype=float)
        self.count = len(self.reach)
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
        # Misses (-1) never win; a cutoff reading (range_max) wins only when no ray echoed.
        shortest = np.where(per_sonar >= 0.0, per_sonar, np.inf).min(axis=1)
        ranges = np.where(shortest < self.range_max, shortest + self.reach, np.nan)
        if self.noise_std > 0.0:
            ranges = ranges + self.rng.normal(0.0, self.noise_std, self.count)
            ranges = np.maximum(ranges, self.reach)
        if self.dropout > 0.0:
            ranges[self.rng.random(self.count) < self.dropout] = np.nan
        if self.crosstalk > 0.0:
            heard = self.rng.random(self.count) < self.crosstalk
            farthest = np.where(np.isnan(ranges), self.range_max + self.reach, ranges)
            spurious = self.rng.uniform(self.reach, farthest)
            ranges = np.where(heard, spurious, ranges)
        if len(self.dead):
            ranges[self.dead] = np.nan
        return ranges
