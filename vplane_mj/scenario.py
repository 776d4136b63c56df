"""Scenario files: TOML text -> validated, frozen dataclasses (docs/interface.md section 1).

Every rule of the contract is checked here, before anything runs. Any failure
is a ScenarioError naming the source, the key path (`world.obstacles[2].width`)
and the reason. The keys each table allows are data (the `Field` tables below),
so an unknown key anywhere is an error. `--set KEY=VALUE` overrides are applied
to the parsed document, which is then validated exactly like the file.
Units: metres and seconds; degrees in the file, radians in the dataclasses.
"""

from __future__ import annotations

import json
import math
import operator
import re
import sys
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
import tomli_w

from vplane_mj.errors import ScenarioError
from vplane_mj.planning import registry
from vplane_mj.planning.params import Param
from vplane_mj.resources import data_dir
from vplane_mj.robot import robot_geometry, robot_radius_m
from vplane_mj.shapes import Box, Cup, Cylinder, HShape, Obstacle, Wall, scene_footprints

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
MIN_OBSTACLE_M, MAX_OBSTACLE_M = 0.001, 1000.0
"""Obstacle sizes and thicknesses (m) lie in [MIN_OBSTACLE_M, MAX_OBSTACLE_M], coordinates within
+-MAX_OBSTACLE_M: beyond these a size or a thickness can vanish in floating point (MuJoCo rejects
the geom) and distances overflow."""


# --------------------------------------------------------------------------- dataclasses


@dataclass(frozen=True)
class WorldSpec:
    """The free arena [0, W] x [0, H] (m), whether border walls surround it, the obstacles."""

    size: tuple[float, float]
    border: bool = True
    obstacles: tuple[Obstacle, ...] = ()


@dataclass(frozen=True)
class RobotSpec:
    """Start and goal (m); start_yaw in radians, resolved (default: facing the goal).

    Actuation faults: `wheel_friction` is the tyres' sliding friction coefficient (lower
    lets the wheels slip); each motor (left, right) delivers `motor_gain` times the
    commanded torque plus `motor_bias_nm` (N m).
    """

    start: tuple[float, float]
    start_yaw: float
    goal: tuple[float, float]
    goal_tolerance: float = 0.15
    wheel_friction: float = 1.0
    motor_gain: tuple[float, float] = (1.0, 1.0)
    motor_bias_nm: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class SensorSpec:
    """The sonar ring: noise (m), dropout probability, layout, beam (deg), range (m), rate.

    Sensor faults: `crosstalk` is the probability that a reading is a spurious short
    echo, `dead` the indices of sonars that never echo. `pose` is where the planner's
    pose comes from: "truth" (the simulator, an ideal localiser) or "odometry" (dead
    reckoning from the wheel encoders, whose travel has relative noise `odometry_noise`).
    """

    noise_std: float = 0.0
    dropout: float = 0.0
    crosstalk: float = 0.0
    dead: tuple[int, ...] = ()
    pose: str = "truth"
    odometry_noise: float = 0.0
    count: int = 16
    rays_per_sonar: int = 3
    beam_deg: float = 20.0
    range_max: float = 3.0
    rate_hz: float = 20.0


@dataclass(frozen=True)
class RunSpec:
    """Random seed, simulated time limit (s), physics step (s) and planner rate (Hz)."""

    seed: int = 0
    time_limit_s: float = 300.0
    physics_dt_s: float = 0.002
    control_hz: float = 20.0


@dataclass(frozen=True)
class Scenario:
    """A validated scenario. `raw` is the document as read, with overrides applied (read-only)."""

    name: str
    description: str
    source: str
    world: WorldSpec
    robot: RobotSpec
    planner: str
    planner_params: Mapping[str, float]
    sensors: SensorSpec
    run: RunSpec
    raw: Mapping[str, Any]

    def to_toml(self) -> str:
        """The resolved scenario as TOML text; parsing it back gives an equal Scenario."""
        return tomli_w.dumps(self.raw)


# --------------------------------------------------------------------------- key tables


class _Invalid(Exception):
    """A rule broken at `key`; parse_scenario turns it into a ScenarioError."""

    def __init__(self, key: str, reason: str):
        super().__init__(key, reason)
        self.key = key
        self.reason = reason


_BOUNDS = (
    ("gt", operator.gt, "greater than"),
    ("ge", operator.ge, "at least"),
    ("lt", operator.lt, "less than"),
    ("le", operator.le, "at most"),
)


@dataclass(frozen=True)
class Field:
    """One allowed key: its type, whether it is required, its bounds, where its value goes.

    `kind` is "number" (int or float, finite), "int", "bool", "str" (one of `choices` when
    given), "point" or "pair" (an array of exactly 2 numbers, [x, y] or [left, right]; the
    bounds apply to each) or "ints" (an array of distinct integers within the bounds).
    `attr` is the dataclass attribute it fills (default: the key itself); `convert` maps
    the checked value (e.g. to radians).
    """

    kind: str
    required: bool = False
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    attr: str | None = None
    convert: Callable[[Any], Any] | None = None
    choices: tuple[str, ...] = ()

    def check(self, value: object) -> str | None:
        """Why `value` is unacceptable for this key, or None when it is fine."""
        return _CHECKS[self.kind](value, self)

    def to_python(self, value: Any) -> Any:
        """The checked value as the dataclasses hold it."""
        converted = _CONVERSIONS[self.kind](value)
        return self.convert(converted) if self.convert else converted


def _type_name(value: object) -> str:
    """The TOML name of a parsed value's type, for messages."""
    names = {bool: "boolean", int: "integer", float: "float", str: "string", list: "array"}
    return "table" if isinstance(value, dict) else names.get(type(value), "date/time")


def _format_bound(bound: float) -> str:
    """A bound as the user would write it (2**32 stays an integer)."""
    return f"{bound:g}" if isinstance(bound, float) else str(bound)


def _bounds_reason(value: float, field: Field) -> str | None:
    """Why a number breaks the field's bounds, or None."""
    for name, holds, words in _BOUNDS:
        bound = getattr(field, name)
        if bound is not None and not holds(value, bound):
            return f"must be {words} {_format_bound(bound)}, got {value!r}"
    return None


def _is_number(value: object) -> bool:
    """An int or a float, but not a bool (TOML booleans are not numbers)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def _is_finite(value: float) -> bool:
    """Finite as a float: false for inf, nan and integers too large for a float."""
    return abs(value) <= sys.float_info.max


def _check_number(value: object, field: Field) -> str | None:
    """A finite number within bounds; integers are accepted."""
    if not _is_number(value):
        return f"must be a number, got {_type_name(value)}"
    if not _is_finite(value):
        return f"must be finite, got {value!r}"
    return _bounds_reason(value, field)


def _check_int(value: object, field: Field) -> str | None:
    """An integer within bounds."""
    if not isinstance(value, int) or isinstance(value, bool):
        return f"must be an integer, got {_type_name(value)}"
    return _bounds_reason(value, field)


def _check_bool(value: object, field: Field) -> str | None:
    """true or false."""
    return None if isinstance(value, bool) else f"must be true or false, got {_type_name(value)}"


def _check_str(value: object, field: Field) -> str | None:
    """A string, one of the field's choices when it has any."""
    if not isinstance(value, str):
        return f"must be a string, got {_type_name(value)}"
    if field.choices and value not in field.choices:
        return f"must be one of {', '.join(map(repr, field.choices))}, got {value!r}"
    return None


def _check_two_numbers(value: object, field: Field, shape: str) -> str | None:
    """An array of exactly 2 finite numbers, each within bounds; `shape` shows their meaning."""
    if not isinstance(value, list):
        return f"must be an array of 2 numbers {shape}, got {_type_name(value)}"
    if len(value) != 2:
        return f"must be an array of exactly 2 numbers {shape}, got {len(value)} items"
    for index, item in enumerate(value):
        reason = _check_number(item, field)
        if reason:
            return f"item {index}: {reason}"
    return None


def _check_point(value: object, field: Field) -> str | None:
    """A point [x, y]."""
    return _check_two_numbers(value, field, "[x, y]")


def _check_pair(value: object, field: Field) -> str | None:
    """A value per wheel, [left, right]."""
    return _check_two_numbers(value, field, "[left, right]")


def _check_ints(value: object, field: Field) -> str | None:
    """An array of distinct integers, each within bounds."""
    if not isinstance(value, list):
        return f"must be an array of integers, got {_type_name(value)}"
    for index, item in enumerate(value):
        reason = _check_int(item, field)
        if reason:
            return f"item {index}: {reason}"
        if item in value[:index]:
            return f"item {index}: {item} is listed twice"
    return None


_CHECKS: dict[str, Callable[[object, Field], str | None]] = {
    "number": _check_number,
    "int": _check_int,
    "bool": _check_bool,
    "str": _check_str,
    "point": _check_point,
    "pair": _check_pair,
    "ints": _check_ints,
}

_CONVERSIONS: dict[str, Callable[[Any], Any]] = {
    "number": float,
    "int": int,
    "bool": bool,
    "str": str,
    "point": lambda xy: (float(xy[0]), float(xy[1])),
    "pair": lambda pair: (float(pair[0]), float(pair[1])),
    "ints": lambda items: tuple(sorted(int(item) for item in items)),
}

_SECTIONS = ("world", "robot", "planner", "sensors", "run")

_TOP_FIELDS = {
    "format": Field("int", required=True),
    "name": Field("str", required=True),
    "description": Field("str"),
}

_WORLD_FIELDS = {
    "size": Field("point", required=True, gt=0, le=MAX_ARENA_M),
    "border": Field("bool"),
}

_ROBOT_FIELDS = {
    "start": Field("point", required=True),
    "start_yaw_deg": Field("number", attr="start_yaw", convert=math.radians),
    "goal": Field("point", required=True),
    "goal_tolerance": Field("number", gt=0),
    "wheel_friction": Field("number", ge=0.01, le=5),
    "motor_gain": Field("pair", gt=0, le=2),
    "motor_bias_nm": Field("pair"),
}

_SENSOR_FIELDS = {
    "noise_std": Field("number", ge=0, le=MAX_NOISE_STD_M),
    "dropout": Field("number", ge=0, lt=1),
    "crosstalk": Field("number", ge=0, lt=1),
    "dead": Field("ints", ge=0),
    "pose": Field("str", choices=("truth", "odometry")),
    "odometry_noise": Field("number", ge=0, le=1),
    "count": Field("int", ge=4, le=128),
    "rays_per_sonar": Field("int", ge=1, le=15),
    "beam_deg": Field("number", gt=0, le=60),
    "range_max": Field("number", gt=0.2, le=20),
    "rate_hz": Field("number", gt=0, le=100),
}

_RUN_FIELDS = {
    "seed": Field("int", ge=0, lt=2**32),
    "time_limit_s": Field("number", gt=0),
    "physics_dt_s": Field("number", ge=0.0005, le=0.01),
    "control_hz": Field("number", ge=1, le=200),  # one control tick is simulated whole
}

_STRING = Field("str")
_CENTER = Field("point", required=True, ge=-MAX_OBSTACLE_M, le=MAX_OBSTACLE_M)
_LENGTH = Field("number", required=True, gt=0, ge=MIN_OBSTACLE_M, le=MAX_OBSTACLE_M)
_YAW = Field("number", attr="yaw", convert=math.radians)
_THICKNESS = Field("number", gt=0, ge=MIN_OBSTACLE_M, le=MAX_OBSTACLE_M)


def _check_wall(wall: Wall, path: str) -> None:
    """A wall needs a length: `from` and `to` differ."""
    if wall.start == wall.end:
        raise _Invalid(_join(path, "to"), "must differ from `from` (a wall needs a length)")


def _check_thin_walls(width: float, along: float, along_key: str, thickness: float, path: str) -> None:
    """u, c and h shapes: width > 2*thickness and depth/length > thickness."""
    if not width > 2 * thickness:
        reason = f"must be greater than 2*thickness ({2 * thickness:g}), got {width!r}"
        raise _Invalid(_join(path, "width"), reason)
    if not along > thickness:
        reason = f"must be greater than thickness ({thickness:g}), got {along!r}"
        raise _Invalid(_join(path, along_key), reason)


def _check_cup(cup: Cup, path: str) -> None:
    """A cup's arms and back wall must leave room inside."""
    _check_thin_walls(cup.width, cup.depth, "depth", cup.thickness, path)


def _check_h(shape: HShape, path: str) -> None:
    """An H's posts and crossbar must leave room inside."""
    _check_thin_walls(shape.width, shape.length, "length", shape.thickness, path)


@dataclass(frozen=True)
class _Kind:
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

_OBSTACLE_KINDS: dict[str, _Kind] = {
    "box": _Kind(_BOX_FIELDS, Box),
    "wall": _Kind(_WALL_FIELDS, Wall, _check_wall),
    "cylinder": _Kind(_CYLINDER_FIELDS, Cylinder),
    "u": _Kind(_CUP_FIELDS, Cup, _check_cup),
    "c": _Kind(_CUP_FIELDS, Cup, _check_cup),  # "c" is the contract's alias of "u"
    "h": _Kind(_H_FIELDS, HShape, _check_h),
}


# --------------------------------------------------------------------------- generic readers

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _join(path: str, key: str) -> str:
    """The key path of `key` inside the table at `path` ("" is the top level).

    A key that is not a bare TOML key (empty, spaces, dots, ...) is shown quoted.
    """
    part = key if _BARE_KEY.fullmatch(key) else json.dumps(key)
    return f"{path}.{part}" if path else part


def _reject_unknown(table: Mapping[str, Any], path: str, allowed: Sequence[str]) -> None:
    """Fail on the first key of `table` that is not in `allowed`."""
    for key in table:
        if key not in allowed:
            raise _Invalid(_join(path, key), f"unknown key (allowed here: {', '.join(allowed)})")


def _checked(value: Any, field: Field, key: str) -> Any:
    """The value of `key` converted for the dataclasses, or an error naming `key`."""
    reason = field.check(value)
    if reason:
        raise _Invalid(key, reason)
    return field.to_python(value)


def _read_fields(
    table: Mapping[str, Any], path: str, fields: Mapping[str, Field], extra: Sequence[str] = ()
) -> dict[str, Any]:
    """Check a table against its allowed keys; the given values by attribute name.

    `extra` are further keys the caller reads itself. Absent optional keys are left
    out, so the dataclasses' own defaults apply.
    """
    _reject_unknown(table, path, [*fields, *extra])
    values = {}
    for key, field in fields.items():
        if key in table:
            values[field.attr or key] = _checked(table[key], field, _join(path, key))
        elif field.required:
            raise _Invalid(_join(path, key), "missing required key")
    return values


def _sub_table(parent: Mapping[str, Any], key: str, path: str = "", required: bool = False):
    """The table `parent[key]`: {} when absent and optional, an error when not a table."""
    full = _join(path, key)
    if key not in parent:
        if required:
            raise _Invalid(full, "missing required table")
        return {}
    table = parent[key]
    if not isinstance(table, dict):
        raise _Invalid(full, f"must be a table, got {_type_name(table)}")
    return table


# --------------------------------------------------------------------------- sections


def _check_format(doc: Mapping[str, Any]) -> None:
    """`format` is present and exactly the integer 1."""
    if "format" not in doc:
        raise _Invalid("format", f"missing required key (this version reads format = {FORMAT})")
    value = doc["format"]
    if type(value) is not int or value != FORMAT:
        raise _Invalid("format", f"must be {FORMAT}, got {value!r}")


def _read_top(doc: Mapping[str, Any]) -> dict[str, Any]:
    """format, name and description, and no unknown top-level key."""
    _check_format(doc)
    top = _read_fields(doc, "", _TOP_FIELDS, extra=_SECTIONS)
    if not NAME_PATTERN.fullmatch(top["name"]):
        raise _Invalid("name", f"must match [a-z0-9_]+ (it names output files), got {top['name']!r}")
    if len(top["name"]) > MAX_NAME_LENGTH:
        length = len(top["name"])
        raise _Invalid("name", f"must be at most {MAX_NAME_LENGTH} characters (it names files), got {length}")
    return top


def _read_obstacle(item: Any, path: str) -> Obstacle:
    """One `[[world.obstacles]]` table as a shapes dataclass."""
    if not isinstance(item, dict):
        raise _Invalid(path, f"must be a table, got {_type_name(item)}")
    if "kind" not in item:
        raise _Invalid(_join(path, "kind"), "missing required key")
    kind_name = _checked(item["kind"], _STRING, _join(path, "kind"))
    kind = _OBSTACLE_KINDS.get(kind_name)
    if kind is None:
        known = ", ".join(_OBSTACLE_KINDS)
        raise _Invalid(_join(path, "kind"), f"unknown obstacle kind {kind_name!r} (known: {known})")
    shape = kind.shape(**_read_fields(item, path, kind.fields, extra=("kind",)))
    if kind.check:
        kind.check(shape, path)
    return shape


def _read_obstacles(world: Mapping[str, Any]) -> tuple[Obstacle, ...]:
    """All `[[world.obstacles]]`, in order."""
    items = world.get("obstacles", [])
    if not isinstance(items, list):
        raise _Invalid("world.obstacles", f"must be an array of tables, got {_type_name(items)}")
    return tuple(_read_obstacle(item, f"world.obstacles[{i}]") for i, item in enumerate(items))


def _read_world(doc: Mapping[str, Any]) -> WorldSpec:
    """The `[world]` table."""
    table = _sub_table(doc, "world", required=True)
    values = _read_fields(table, "world", _WORLD_FIELDS, extra=("obstacles",))
    return WorldSpec(**values, obstacles=_read_obstacles(table))


def _facing(start: tuple[float, float], goal: tuple[float, float]) -> float:
    """The yaw (rad) that faces from `start` toward `goal`."""
    return math.atan2(goal[1] - start[1], goal[0] - start[0])


def _read_robot(doc: Mapping[str, Any]) -> RobotSpec:
    """The `[robot]` table, start_yaw resolved; a motor bias within the torque limit."""
    values = _read_fields(_sub_table(doc, "robot", required=True), "robot", _ROBOT_FIELDS)
    values.setdefault("start_yaw", _facing(values["start"], values["goal"]))
    limit = robot_geometry()["torque_limit_nm"]
    for index, bias in enumerate(values.get("motor_bias_nm", ())):
        if abs(bias) > limit:
            reason = f"item {index}: must be within the motor's torque limit +-{limit:g} N m, got {bias!r}"
            raise _Invalid("robot.motor_bias_nm", reason)
    return RobotSpec(**values)


def _param_reason(param: Param, value: Any) -> str | None:
    """Param.check, also for integers too large for a float."""
    if _is_number(value) and not _is_finite(value):
        return f"must be finite, got {value!r}"
    return param.check(value)


def _read_planner(doc: Mapping[str, Any]) -> tuple[str, Mapping[str, float]]:
    """The planner's name and the parameters the file gives (checked against its table)."""
    table = _sub_table(doc, "planner")
    given = "name" in table
    name = _checked(table.get("name", registry.DEFAULT_PLANNER), _STRING, "planner.name")
    if name not in registry.PLANNERS:
        default = "" if given else " (the default)"
        known = ", ".join(sorted(registry.PLANNERS))
        raise _Invalid("planner.name", f"unknown planner {name!r}{default}; available: {known}")
    info = registry.planner_info(name)
    params = {}
    for key, value in table.items():
        if key == "name":
            continue
        if key not in info.params:
            known = ", ".join(info.params)
            raise _Invalid(_join("planner", key), f"not a parameter of planner {name!r} ({known})")
        reason = _param_reason(info.params[key], value)
        if reason:
            raise _Invalid(_join("planner", key), reason)
        params[key] = value if info.params[key].integer else float(value)
    return name, MappingProxyType(params)


def _read_sensors(doc: Mapping[str, Any]) -> SensorSpec:
    """The optional `[sensors]` table; dead sonars must exist in the ring."""
    sensors = SensorSpec(**_read_fields(_sub_table(doc, "sensors"), "sensors", _SENSOR_FIELDS))
    for index, sonar in enumerate(_sub_table(doc, "sensors").get("dead", [])):
        if sonar >= sensors.count:
            ring = f"a ring of count = {sensors.count} (0 to {sensors.count - 1})"
            raise _Invalid("sensors.dead", f"item {index}: no sonar {sonar} in {ring}")
    return sensors


def _read_run(doc: Mapping[str, Any]) -> RunSpec:
    """The optional `[run]` table; the control period must span at least one physics step."""
    run = RunSpec(**_read_fields(_sub_table(doc, "run"), "run", _RUN_FIELDS))
    if 1.0 / run.control_hz < run.physics_dt_s:
        reason = (
            f"the control period 1/control_hz ({1.0 / run.control_hz:g} s) must be at least "
            f"physics_dt_s ({run.physics_dt_s:g} s)"
        )
        raise _Invalid("run.control_hz", reason)
    return run


# --------------------------------------------------------------------------- placement


def _check_in_arena(key: str, point: tuple[float, float], size: tuple[float, float]) -> None:
    """The point lies in the free arena [0, W] x [0, H]."""
    (x, y), (w, h) = point, size
    if not (0 <= x <= w and 0 <= y <= h):
        reason = f"must lie inside the arena [0, {w:g}] x [0, {h:g}], got [{x:g}, {y:g}]"
        raise _Invalid(key, reason)


def _check_border_gap(key: str, point: tuple[float, float], size: tuple[float, float]) -> None:
    """With border walls, the robot's disc at the point stays off them."""
    (x, y), (w, h), radius = point, size, robot_radius_m()
    gap = min(x, w - x, y, h - y)
    if gap < radius:
        reason = (
            f"is {gap:.3f} m from the arena edge, less than the robot radius ({radius:.3f} m): "
            "the robot would overlap the border wall"
        )
        raise _Invalid(key, reason)


def _check_obstacle_gaps(points: Mapping[str, tuple[float, float]], world: WorldSpec) -> None:
    """The robot's disc at each point stays off every obstacle."""
    if not world.obstacles:
        return
    radius = robot_radius_m()
    xy = np.array(list(points.values()), dtype=float)
    gaps = np.array([scene_footprints([ob]).distance(xy) for ob in world.obstacles])
    for column, key in enumerate(points):
        nearest = int(np.argmin(gaps[:, column]))
        gap = float(gaps[nearest, column])
        where = f"obstacle world.obstacles[{nearest}]"
        if gap < 0:
            raise _Invalid(key, f"lies inside {where}")
        if gap < radius:
            limit = f"less than the robot radius ({radius:.3f} m)"
            raise _Invalid(key, f"is {gap:.3f} m from {where}, {limit}")


def _check_placement(world: WorldSpec, robot: RobotSpec) -> None:
    """Start and goal inside the arena, clear of the border walls and of the obstacles."""
    points = {"robot.start": robot.start, "robot.goal": robot.goal}
    for key, point in points.items():
        _check_in_arena(key, point, world.size)
        if world.border:
            _check_border_gap(key, point, world.size)
    _check_obstacle_gaps(points, world)


# --------------------------------------------------------------------------- overrides

_KEY_SEGMENT = re.compile(r"([A-Za-z0-9_-]+)((?:\[[0-9]{1,9}\])*)")
"""One dotted part of a --set key: a bare key, then optional [N] indices."""


def _parse_key(key: str) -> list[str | int]:
    """`a.b[2].c` or `a.b.2.c` -> ["a", "b", 2, "c"] / ["a", "b", "2", "c"]."""
    tokens: list[str | int] = []
    for part in key.split("."):
        match = _KEY_SEGMENT.fullmatch(part)
        if match is None:
            raise _Invalid(key, f"invalid --set: malformed key segment {part!r}")
        tokens.append(match[1])
        tokens.extend(int(index) for index in re.findall(r"[0-9]+", match[2]))
    return tokens


def _parse_value(text: str) -> Any:
    """A --set VALUE as a TOML value, or the text itself as a string when it is not one."""
    text = text.strip()
    try:
        parsed = tomllib.loads(f"v = {text}")
    except (ValueError, RecursionError):
        return text
    return parsed["v"] if parsed.keys() == {"v"} else text


def _index(token: str | int, array: list, where: str, key: str) -> int:
    """The array index `token` names, within range."""
    if isinstance(token, str):
        if not token.isdigit():
            raise _Invalid(key, f"invalid --set: {where} is an array, index it like {where}[0]")
        token = int(token)
    if token >= len(array):
        reason = f"invalid --set: index {token} is out of range ({where} has length {len(array)})"
        raise _Invalid(key, reason)
    return token


def _slot(node: Any, token: str | int, where: str, key: str) -> tuple[str | int, str]:
    """Where `token` points inside `node` (key or index), and that place's key path."""
    if isinstance(node, list):
        index = _index(token, node, where, key)
        return index, f"{where}[{index}]"
    if isinstance(node, dict) and isinstance(token, str):
        return token, _join(where, token)
    raise _Invalid(key, f"invalid --set: {where} is a {_type_name(node)}, it cannot be indexed")


def _apply_override(doc: dict[str, Any], text: str) -> None:
    """Apply one `KEY=VALUE` of --set to the parsed document, creating missing tables."""
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep:
        raise _Invalid(key, "invalid --set: expected KEY=VALUE")
    if not key:
        raise _Invalid("", f"invalid --set {text!r}: the key before '=' is empty")
    tokens = _parse_key(key)
    node, where = doc, ""
    for token in tokens[:-1]:
        slot, where = _slot(node, token, where, key)
        if isinstance(node, dict) and slot not in node:
            node[slot] = {}
        node = node[slot]
    slot, _ = _slot(node, tokens[-1], where, key)
    node[slot] = _parse_value(value)


# --------------------------------------------------------------------------- public API


def _freeze(value: Any) -> Any:
    """A read-only deep copy of a parsed TOML value: tables as mappingproxies, arrays as tuples."""
    if isinstance(value, dict):
        return MappingProxyType({key: _freeze(item) for key, item in value.items()})
    if isinstance(value, list):
        return tuple(_freeze(item) for item in value)
    return value


def _build_scenario(doc: dict[str, Any], source: str) -> Scenario:
    """Validate a parsed document section by section, then the start and goal placement."""
    top = _read_top(doc)
    world = _read_world(doc)
    robot = _read_robot(doc)
    planner, params = _read_planner(doc)
    scenario = Scenario(
        name=top["name"],
        description=top.get("description", ""),
        source=source,
        world=world,
        robot=robot,
        planner=planner,
        planner_params=params,
        sensors=_read_sensors(doc),
        run=_read_run(doc),
        raw=_freeze(doc),
    )
    _check_placement(world, robot)
    return scenario


def _parse_toml(text: str, source: str) -> dict[str, Any]:
    """The TOML document, or a ScenarioError quoting tomllib (line and column)."""
    try:
        return tomllib.loads(text)
    except (ValueError, RecursionError) as exc:  # TOMLDecodeError, huge integers, deep nesting
        raise ScenarioError(source, "", f"invalid TOML: {exc}") from None


def parse_scenario(text: str, source: str, overrides: Sequence[str] = ()) -> Scenario:
    """Parse TOML text, apply `--set KEY=VALUE` overrides, validate: a Scenario or ScenarioError."""
    doc = _parse_toml(text, source)
    try:
        for override in overrides:
            _apply_override(doc, override)
        return _build_scenario(doc, source)
    except _Invalid as exc:
        raise ScenarioError(source, exc.key, exc.reason) from None
    except Exception as exc:  # promised: no input ever escapes as anything but ScenarioError
        reason = f"cannot be validated (internal error, please report it: {exc!r})"
        raise ScenarioError(source, "", reason) from exc


def _builtin_paths() -> list[Path]:
    """The shipped scenario files, sorted by name."""
    return sorted(data_dir("scenarios").glob("*.toml"), key=lambda path: path.stem)


def resolve_path(ref: str) -> Path:
    """The file `ref` names: a path, else ./scenarios/NAME.toml, else a built-in scenario."""
    path = Path(ref)
    if path.is_file():
        return path
    if NAME_PATTERN.fullmatch(ref):
        for candidate in (Path("scenarios") / f"{ref}.toml", data_dir("scenarios") / f"{ref}.toml"):
            if candidate.is_file():
                return candidate
    if ref and path.is_dir():
        raise ScenarioError(ref, "", "is a directory, not a scenario file")
    names = ", ".join(builtin.stem for builtin in _builtin_paths()) or "none"
    raise ScenarioError(ref, "", f"no such file or built-in scenario (built-in: {names})")


def _read_text(path: Path, source: str) -> str:
    """The file's text, decoded as strict UTF-8 (a leading byte-order mark is dropped)."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(source, "", f"cannot read the file: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        reason = f"is not UTF-8 text (byte {data[exc.start]:#04x} at offset {exc.start})"
        raise ScenarioError(source, "", reason) from None


def load_scenario(ref: str, overrides: Sequence[str] = ()) -> Scenario:
    """Read, parse, override and validate the scenario `ref` (a path or a scenario name).

    The source named in messages is `ref` itself when it is a path, else the file found.
    """
    path = resolve_path(ref)
    source = ref if path == Path(ref) else str(path)
    return parse_scenario(_read_text(path, source), source, overrides)


def builtin_scenarios() -> list[tuple[str, str]]:
    """(name, description) of every shipped scenario, sorted by name; each is validated."""
    return [(path.stem, load_scenario(str(path)).description) for path in _builtin_paths()]
