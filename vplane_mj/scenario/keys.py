"""Every key a scenario file may hold, as data: its type, bounds and where its value goes.

The contract these tables encode is docs/interface.md section 1 (and docs/scenarios.md
for the further keys); `fields.py` is the engine that applies them.
Lengths in metres, times in seconds, angles in degrees in the file (radians once read).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from vplane_mj.geometry.shapes import Box, Cup, Cylinder, HShape, Obstacle, Wall
from vplane_mj.robots.profiles import DEFAULT, PROFILES
from vplane_mj.scenario.fields import Field, Invalid, join_key

FORMAT = 1
"""The only value of `format` this version reads."""

NAME_PATTERN = re.compile(r"[a-z0-9_]+")
"""What a scenario `name` must match in full (it names output files)."""
MAX_NAME_LENGTH = 100
"""The longest `name`: output files are `<name>-<planner>-<seed>.<ext>` (at most 255 bytes)."""
MAX_ARENA_M = 150.0
"""The largest side of the arena (m): the top camera that renders runs cannot see wider than 180 m."""
MAX_NOISE_STD_M = 10.0
"""The largest sonar noise (m): more is meaningless, and huge readings overflow the sonar map."""
MAX_GOAL_TOLERANCE_M = 5.0
"""The widest goal disc (m): five times BARN's 1 m; wider, a run "reaches" a goal it never nears."""
MAX_YAW_DEG = 360.0
"""A start yaw lies within +-MAX_YAW_DEG (deg): more turns mean nothing, and huge angles lose precision."""
MAX_TIME_LIMIT_S = 24 * 3600.0
"""The longest run (s of simulated time): a day; a longer limit is a slip, not an experiment."""
MAX_TICKS_PER_SCAN = 10
"""The planner decides at most this many times per sensor reading (`[run] control_hz` over
`[sensors] rate_hz`): more, and it steers on one stale scan into what it has not seen."""
MIN_OBSTACLE_M, MAX_OBSTACLE_M = 0.001, 1000.0
"""Obstacle sizes and thicknesses (m) lie in [MIN_OBSTACLE_M, MAX_OBSTACLE_M], coordinates within
+-MAX_OBSTACLE_M: beyond these a size or a thickness can vanish in floating point (MuJoCo rejects
the geom) and distances overflow."""

SECTIONS = ("world", "robot", "planner", "sensors", "run")
"""The tables of a scenario file besides its top-level keys."""

TOP_FIELDS = {
    "format": Field("int", required=True),
    "name": Field("str", required=True),
    "description": Field("str"),
}

WORLD_FIELDS = {
    "size": Field("point", required=True, gt=0, le=MAX_ARENA_M),
    "border": Field("bool"),
    "score_path_m": Field("number", gt=0, le=MAX_ARENA_M * 100),
}

ROBOT_FIELDS = {
    "profile": Field("str", choices=tuple(PROFILES)),
    "start": Field("point", required=True),
    "start_yaw_deg": Field("number", ge=-MAX_YAW_DEG, le=MAX_YAW_DEG, attr="start_yaw", convert=math.radians),
    "goal": Field("point", required=True),
    "goal_tolerance": Field("number", gt=0, le=MAX_GOAL_TOLERANCE_M),
    "wheel_friction": Field("number", ge=0.01, le=5),
    "motor_gain": Field("pair", gt=0, le=2),
    "motor_bias_nm": Field("pair"),
}

SENSOR_KINDS = ("sonar", "laser")
MAX_SONAR_RANGE_M, MAX_LASER_RANGE_M = 20.0, 100.0
"""The longest range (m) of each sensor kind: beyond them a reading means nothing in an arena."""

SENSOR_FIELDS = {
    "kind": Field("str", choices=SENSOR_KINDS),
    "noise_std": Field("number", ge=0, le=MAX_NOISE_STD_M),
    "dropout": Field("number", ge=0, lt=1),
    "crosstalk": Field("number", ge=0, lt=1),
    "dead": Field("ints", ge=0),
    "pose": Field("str", choices=("truth", "odometry", "ekf")),
    "odometry_noise": Field("number", ge=0, le=1),
    "count": Field("int", ge=4, le=128),
    "rays_per_sonar": Field("int", ge=1, le=15),
    "beam_deg": Field("number", gt=0, le=60),
    "fov_deg": Field("number", gt=0, le=360),
    "beams": Field("int", ge=2, le=2048),
    "range_min": Field("number", ge=0, le=MAX_LASER_RANGE_M),
    "range_max": Field("number", gt=0.2, le=MAX_LASER_RANGE_M),
    "rate_hz": Field("number", gt=0, le=100),  # and at least control_hz / MAX_TICKS_PER_SCAN
}
KIND_KEYS = {
    "sonar": ("count", "rays_per_sonar", "beam_deg", "crosstalk", "dead"),
    "laser": ("fov_deg", "beams", "range_min"),
}
"""The `[sensors]` keys that belong to one kind of sensor; the rest apply to both."""
GENERIC_SENSORS: dict[str, Mapping[str, str | int | float]] = {
    "sonar": DEFAULT.sensors,
    "laser": {
        "kind": "laser",
        "fov_deg": 360.0,
        "beams": 360,
        "range_min": 0.1,
        "range_max": 10.0,
        "rate_hz": 10.0,
    },
}
"""The `[sensors]` defaults of a kind the robot's profile does not carry (a laser on the default
robot, say): the default robot's own sonar ring (its profile's table, read), a 360-degree laser
of 1-degree beams. `SensorSpec`'s defaults are these tables too."""

RUN_FIELDS = {
    "seed": Field("int", ge=0, lt=2**32),
    "time_limit_s": Field("number", gt=0, le=MAX_TIME_LIMIT_S),
    "physics_dt_s": Field("number", ge=0.0005, le=0.01),
    "control_hz": Field("number", ge=1, le=200),  # one control tick is simulated whole
}

STRING = Field("str")
"""Any string: an obstacle's `kind`, the planner's `name`."""
GOVERNOR = Field("bool")
"""`planner.governor`: whether the run drives the forces of a planner that does not drive its
body itself through the governor (true by default)."""
PLANNER_KEYS = ("name", "governor")
"""The `[planner]` keys that are not the planner's parameters."""
_CENTER = Field("point", required=True, ge=-MAX_OBSTACLE_M, le=MAX_OBSTACLE_M)
_LENGTH = Field("number", required=True, gt=0, ge=MIN_OBSTACLE_M, le=MAX_OBSTACLE_M)
_YAW = Field("number", attr="yaw", convert=math.radians)
_THICKNESS = Field("number", gt=0, ge=MIN_OBSTACLE_M, le=MAX_OBSTACLE_M)


def _check_wall(wall: Wall, path: str) -> None:
    """A wall needs a length: `from` and `to` differ."""
    if wall.start == wall.end:
        raise Invalid(join_key(path, "to"), "must differ from `from` (a wall needs a length)")


def _check_thin_walls(width: float, along: float, along_key: str, thickness: float, path: str) -> None:
    """u, c and h shapes: width > 2*thickness and depth/length > thickness."""
    if not width > 2 * thickness:
        reason = f"must be greater than 2*thickness ({2 * thickness:g}), got {width!r}"
        raise Invalid(join_key(path, "width"), reason)
    if not along > thickness:
        reason = f"must be greater than thickness ({thickness:g}), got {along!r}"
        raise Invalid(join_key(path, along_key), reason)


def _check_cup(cup: Cup, path: str) -> None:
    """A cup's arms and back wall must leave room inside."""
    _check_thin_walls(cup.width, cup.depth, "depth", cup.thickness, path)


def _check_h(shape: HShape, path: str) -> None:
    """An H's posts and crossbar must leave room inside."""
    _check_thin_walls(shape.width, shape.length, "length", shape.thickness, path)


@dataclass(frozen=True)
class ObstacleKind:
    """An obstacle kind: its keys besides `kind`, the shape it builds, its extra rule."""

    fields: Mapping[str, Field]
    shape: Callable[..., Obstacle]
    check: Callable[[Any, str], None] | None = None


_BOX_FIELDS = {
    "center": _CENTER,
    "size": Field("point", required=True, gt=0, ge=MIN_OBSTACLE_M, le=MAX_OBSTACLE_M),
    "yaw_deg": _YAW,
}
_WALL_FIELDS = {
    "from": Field("point", required=True, ge=-MAX_OBSTACLE_M, le=MAX_OBSTACLE_M, attr="start"),
    "to": Field("point", required=True, ge=-MAX_OBSTACLE_M, le=MAX_OBSTACLE_M, attr="end"),
    "thickness": _THICKNESS,
}
_CYLINDER_FIELDS = {"center": _CENTER, "radius": _LENGTH}
_CUP_FIELDS = {
    "center": _CENTER,
    "width": _LENGTH,
    "depth": _LENGTH,
    "yaw_deg": _YAW,
    "thickness": _THICKNESS,
}
_H_FIELDS = {
    "center": _CENTER,
    "length": _LENGTH,
    "width": _LENGTH,
    "yaw_deg": _YAW,
    "thickness": _THICKNESS,
}

OBSTACLE_KINDS: dict[str, ObstacleKind] = {
    "box": ObstacleKind(_BOX_FIELDS, Box),
    "wall": ObstacleKind(_WALL_FIELDS, Wall, _check_wall),
    "cylinder": ObstacleKind(_CYLINDER_FIELDS, Cylinder),
    "u": ObstacleKind(_CUP_FIELDS, Cup, _check_cup),
    "c": ObstacleKind(_CUP_FIELDS, Cup, _check_cup),  # "c" is the contract's alias of "u"
    "h": ObstacleKind(_H_FIELDS, HShape, _check_h),
}
