"""A validated scenario as frozen dataclasses (the file format: docs/interface.md section 1).

Units: metres and seconds; degrees in the file, radians here. Obstacles are the shapes of
`vplane_mj.geometry.shapes`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import tomli_w

from vplane_mj.files import write_atomically
from vplane_mj.geometry.motion import Moving
from vplane_mj.geometry.shapes import Obstacle
from vplane_mj.scenario.keys import GENERIC_SENSORS

_SONAR, _LASER = GENERIC_SENSORS["sonar"], GENERIC_SENSORS["laser"]


@dataclass(frozen=True)
class WorldSpec:
    """The free arena [0, W] x [0, H] (m), whether border walls surround it, the static
    obstacles, and the moving ones (`geometry.motion.Moving`: each keeps its index among the
    file's `[[world.obstacles]]`; the static ones take the other indices, in order)."""

    size: tuple[float, float]
    border: bool = True
    obstacles: tuple[Obstacle, ...] = ()
    moving: tuple[Moving, ...] = ()
    score_path_m: float | None = None
    """The path length (m) whose time at the top speed is the BARN score's OT, when the world
    comes with its own (a BARN world's `path_N.npy`); None: the reference path's."""

    def static_indices(self) -> tuple[int, ...]:
        """Each static obstacle's index among the file's `[[world.obstacles]]`, in order."""
        taken = {moving.index for moving in self.moving}
        count = len(self.obstacles) + len(self.moving)
        return tuple(index for index in range(count) if index not in taken)


@dataclass(frozen=True)
class RobotSpec:
    """The robot's profile (`vplane_mj.robots.profiles`); start and goal (m); start_yaw in radians,
    resolved (default: facing the goal).

    Actuation faults: `wheel_friction` is the tyres' sliding friction coefficient (lower
    lets the wheels slip; resolved: default the profile's); each motor (left, right)
    delivers `motor_gain` times the commanded torque plus `motor_bias_nm` (N m).
    """

    profile: str
    start: tuple[float, float]
    start_yaw: float
    goal: tuple[float, float]
    goal_tolerance: float = 0.15
    wheel_friction: float = 1.0
    motor_gain: tuple[float, float] = (1.0, 1.0)
    motor_bias_nm: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class SensorSpec:
    """The range sensor, resolved against the robot's profile: its `kind`, noise (m), dropout
    probability, range (m) and rate (Hz); a sonar's layout and beam (deg); a laser's field of
    view (deg), beams and shortest range (m). The keys of the other kind keep their defaults
    and mean nothing. The defaults are the default robot's sonar ring and the generic laser's
    keys (`keys.GENERIC_SENSORS`, read).

    Sensor faults: `crosstalk` is the probability that a reading is a spurious short
    echo, `dead` the indices of sonars that never echo. `pose` is where the planner's
    pose comes from: "truth" (the simulator, an ideal localiser), "odometry" (dead
    reckoning from the wheel encoders, whose travel has relative noise `odometry_noise`) or
    "ekf" (that odometry fused with the IMU's gyro, `sim.odometry.FusedOdometry`).
    """

    noise_std: float = 0.0
    dropout: float = 0.0
    crosstalk: float = 0.0
    dead: tuple[int, ...] = ()
    pose: str = "truth"
    odometry_noise: float = 0.0
    count: int = int(_SONAR["count"])
    rays_per_sonar: int = int(_SONAR["rays_per_sonar"])
    beam_deg: float = float(_SONAR["beam_deg"])
    range_max: float = float(_SONAR["range_max"])
    rate_hz: float = float(_SONAR["rate_hz"])
    fov_deg: float = float(_LASER["fov_deg"])
    beams: int = int(_LASER["beams"])
    range_min: float = float(_LASER["range_min"])
    kind: str = str(_SONAR["kind"])


@dataclass(frozen=True)
class RunSpec:
    """Random seed, simulated time limit (s), physics step (s) and planner rate (Hz)."""

    seed: int = 0
    time_limit_s: float = 300.0
    physics_dt_s: float = 0.002
    control_hz: float = 20.0


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (`load_scenario`, `build_scenario`); two scenarios of the same
    content are equal wherever they came from.

    Attributes:
        name: The scenario's name.
        description: One line about it.
        source: Where it came from, as messages name it (a file, or "<code>").
        world: The arena (m) and its obstacles.
        robot: The robot's profile, start, goal (m), start yaw (rad) and faults.
        planner: The planner's name.
        planner_params: The planner's parameters as given (the rest are its defaults).
        planner_governor: Whether the run drives the forces of a planner that does not drive
            its body itself through the governor (`planner.governor`).
        sensors: The range sensor, resolved against the robot's profile.
        run: Seed, time limit (s), physics step (s) and control rate (Hz).
        raw: The document as read, with overrides applied (read-only).
    """

    name: str
    description: str
    source: str = field(compare=False)
    world: WorldSpec
    robot: RobotSpec
    planner: str
    planner_params: Mapping[str, float]
    planner_governor: bool
    sensors: SensorSpec
    run: RunSpec
    raw: Mapping[str, Any]

    def to_toml(self) -> str:
        """The resolved scenario as TOML text.

        Returns:
            The text of a scenario file; parsing it back gives an equal Scenario.
        """
        return tomli_w.dumps(self.raw)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write `to_toml()` to a file (whole or not at all) that `vplane-mj run` takes and
        that loads back equal.

        Args:
            path: The file to write (replaced when it exists).

        Returns:
            The path written.
        """
        text = self.to_toml()
        return write_atomically(Path(path), lambda tmp: tmp.write_text(text, encoding="utf-8"))
