"""The robot's range sensor as the run reads it: sonars through MuJoCo's rangefinders, or a laser
cast in 2D against the world's pieces (`vplane_mj.sim.laser`).

Either is read at control ticks when a reading is due at its rate (never at every physics step)
and gives ranges (m) from the robot's centre along its bearings (rad, robot frame), NaN where
there is no return, with the width (rad) of its beams: what a planner's `Observation` holds.
"""

from __future__ import annotations

import math
from typing import Protocol

import mujoco
import numpy as np

from vplane_mj.geometry import shapes
from vplane_mj.scenario import Scenario
from vplane_mj.sim.moving import MovingObstacles
from vplane_mj.sim.sonar import SonarRays, SonarRing
from vplane_mj.sim.world import ROBOT_PREFIX, SonarLayout, build_model


class RangeSensor(Protocol):
    """A range sensor on the robot: its bearings (rad, robot frame), beam width (rad), rate (Hz)."""

    @property
    def bearings(self) -> np.ndarray: ...

    @property
    def beam_width(self) -> float: ...

    @property
    def rate_hz(self) -> float: ...

    def read(self, x: float, y: float, yaw: float) -> np.ndarray:
        """Ranges (m) from the robot's centre at its pose x, y (m), yaw (rad); NaN: no return."""
        ...


class Sonars:
    """The sonars: their rangefinders evaluated on the run's kinematics when they ping
    (`SonarRays`), their readings turned into ranges with their faults (`SonarRing`)."""

    def __init__(self, scenario: Scenario, data: mujoco.MjData, rng: np.random.Generator):
        spec = scenario.sensors
        layout = SonarLayout.from_spec(spec, scenario.robot.profile)
        self.bearings = layout.bearings
        self.beam_width = math.radians(spec.beam_deg)
        self.rate_hz = spec.rate_hz
        self.ring = SonarRing(
            layout.reach,
            spec.rays_per_sonar,
            spec.range_max,
            rng,
            noise_std=spec.noise_std,
            dropout=spec.dropout,
            crosstalk=spec.crosstalk,
            dead=spec.dead,
        )
        model = build_model(scenario, rangefinders=True)
        first_ray = model.sensor(ROBOT_PREFIX + "sonar0_ray0").id
        self.rays = SonarRays(model, first_ray, len(layout.bearings) * spec.rays_per_sonar, data)

    def read(self, x: float, y: float, yaw: float) -> np.ndarray:
        """The sonars' ranges from the kinematics of the run's last physics step (the pose given
        is that one's)."""
        return self.ring.read(self.rays.cast())


def laser(scenario: Scenario, rng: np.random.Generator, moving: MovingObstacles | None = None) -> RangeSensor:
    """The scenario's laser, cast against its obstacles and border, and its `moving` obstacles
    where they stand at each scan (imports numba)."""
    from vplane_mj.sim.laser import LaserScanner, RayCaster

    world, spec = scenario.world, scenario.sensors
    caster = RayCaster(shapes.scene_footprints(world.obstacles, world.size if world.border else None))
    return LaserScanner(
        caster,
        fov_deg=spec.fov_deg,
        beams=spec.beams,
        range_min=spec.range_min,
        range_max=spec.range_max,
        rate_hz=spec.rate_hz,
        rng=rng,
        noise_std=spec.noise_std,
        dropout=spec.dropout,
        moving=moving.pieces if moving is not None and moving.count else None,
    )


def scan_bearings(scenario: Scenario) -> np.ndarray:
    """The bearings (rad, robot frame) of the scenario's sensor, without building it."""
    if scenario.sensors.kind == "laser":
        from vplane_mj.sim.laser import laser_bearings

        return laser_bearings(scenario.sensors.fov_deg, scenario.sensors.beams)[0]
    return SonarLayout.from_spec(scenario.sensors, scenario.robot.profile).bearings


def range_sensor(
    scenario: Scenario, data: mujoco.MjData, moving: MovingObstacles | None = None
) -> RangeSensor:
    """The scenario's sensor, its faults drawn from a generator seeded with the run's seed. A
    laser sees the `moving` obstacles where they stand at each scan; sonars see them as MuJoCo
    placed them for the last physics step."""
    rng = np.random.default_rng(scenario.run.seed)
    if scenario.sensors.kind == "laser":
        return laser(scenario, rng, moving)
    return Sonars(scenario, data, rng)
