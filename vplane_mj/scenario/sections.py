"""Each table of a scenario file read into its dataclass (docs/interface.md section 1).

Besides each key's own rule (`keys.py`), a section checks what spans keys: the format
and name, an obstacle's shape (and a moving one's motion, `motion.py`), the planner's
parameters against its table, a motor bias within the torque limit of the profile's model,
the sensor's keys against its kind and its defaults from the robot's profile, dead sonars
within the ring, a laser's range limits in order, a control period of at least one physics
step, a sensor that reads at least a tenth as often as the planner decides.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from vplane_mj.errors import did_you_mean
from vplane_mj.geometry.motion import Moving
from vplane_mj.geometry.shapes import Box, Cylinder, Obstacle
from vplane_mj.planning.protocol import registry
from vplane_mj.planning.protocol.params import ParamError
from vplane_mj.planning.protocol.plugins import is_import_spec
from vplane_mj.robots.facts import robot_facts
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario.fields import (
    Invalid,
    checked,
    join_key,
    read_fields,
    sub_table,
    type_name,
)
from vplane_mj.scenario.keys import (
    FORMAT,
    GENERIC_SENSORS,
    GOVERNOR,
    KIND_KEYS,
    MAX_NAME_LENGTH,
    MAX_OBSTACLE_M,
    MAX_SONAR_RANGE_M,
    MAX_TICKS_PER_SCAN,
    NAME_PATTERN,
    OBSTACLE_KINDS,
    PLANNER_KEYS,
    ROBOT_FIELDS,
    RUN_FIELDS,
    SECTIONS,
    SENSOR_FIELDS,
    STRING,
    TOP_FIELDS,
    WORLD_FIELDS,
)
from vplane_mj.scenario.motion import MOVING_KINDS, read_motion
from vplane_mj.scenario.spec import RobotSpec, RunSpec, SensorSpec, WorldSpec


def _check_format(doc: Mapping[str, Any]) -> None:
    """`format` is present and exactly the integer 1."""
    if "format" not in doc:
        raise Invalid("format", f"missing required key (this version reads format = {FORMAT})")
    value = doc["format"]
    if type(value) is not int or value != FORMAT:
        raise Invalid("format", f"must be {FORMAT}, got {value!r}")


def read_top(doc: Mapping[str, Any]) -> dict[str, Any]:
    """format, name and description, and no unknown top-level key."""
    _check_format(doc)
    top = read_fields(doc, "", TOP_FIELDS, extra=SECTIONS)
    if not NAME_PATTERN.fullmatch(top["name"]):
        raise Invalid("name", f"must match [a-z0-9_]+ (it names output files), got {top['name']!r}")
    if len(top["name"]) > MAX_NAME_LENGTH:
        length = len(top["name"])
        raise Invalid("name", f"must be at most {MAX_NAME_LENGTH} characters (it names files), got {length}")
    return top


def _read_obstacle(item: Any, path: str, seed: int, index: int) -> Obstacle | Moving:
    """One `[[world.obstacles]]` table as a shapes dataclass, or a `Moving` one when it has a
    `motion` table (its shape then stands where the motion puts it at the run's start)."""
    if not isinstance(item, dict):
        raise Invalid(path, f"must be a table, got {type_name(item)}")
    if "kind" not in item:
        raise Invalid(join_key(path, "kind"), "missing required key")
    kind_name = checked(item["kind"], STRING, join_key(path, "kind"))
    kind = OBSTACLE_KINDS.get(kind_name)
    if kind is None:
        hint = did_you_mean(kind_name, OBSTACLE_KINDS)
        reason = f"unknown obstacle kind {kind_name!r} (known: {', '.join(OBSTACLE_KINDS)}){hint}"
        raise Invalid(join_key(path, "kind"), reason)
    if "motion" not in item:
        shape = kind.shape(**read_fields(item, path, kind.fields, extra=("kind",)))
        if kind.check:
            kind.check(shape, path)
        return shape
    if kind_name not in MOVING_KINDS:
        reason = f"only a {' or a '.join(MOVING_KINDS)} can move, not a {kind_name!r}"
        raise Invalid(join_key(path, "motion"), reason)
    if "center" in item:
        reason = "a moving obstacle has no center: its motion's keyframes place it (give one or the other)"
        raise Invalid(join_key(path, "center"), reason)
    fields = {key: field for key, field in kind.fields.items() if key != "center"}
    values = read_fields(item, path, fields, extra=("kind", "motion"))
    motion = read_motion(item["motion"], join_key(path, "motion"), seed, index, MAX_OBSTACLE_M)
    start = motion.position(0.0)
    shape = kind.shape(center=(float(start[0]), float(start[1])), **values)
    assert isinstance(shape, Cylinder | Box), "MOVING_KINDS build cylinders and boxes"
    return Moving(shape, motion, index)


def _read_obstacles(world: Mapping[str, Any], seed: int) -> tuple[list[Obstacle], list[Moving]]:
    """All `[[world.obstacles]]`, in order: the static ones and the moving ones."""
    items = world.get("obstacles", [])
    if not isinstance(items, list):
        raise Invalid("world.obstacles", f"must be an array of tables, got {type_name(items)}")
    static: list[Obstacle] = []
    moving: list[Moving] = []
    for index, item in enumerate(items):
        obstacle = _read_obstacle(item, f"world.obstacles[{index}]", seed, index)
        if isinstance(obstacle, Moving):
            moving.append(obstacle)
        else:
            static.append(obstacle)
    return static, moving


def read_world(doc: Mapping[str, Any], seed: int = 0) -> WorldSpec:
    """The `[world]` table; the random phases of moving obstacles drawn from the run's `seed`."""
    table = sub_table(doc, "world", required=True)
    values = read_fields(table, "world", WORLD_FIELDS, extra=("obstacles",))
    static, moving = _read_obstacles(table, seed)
    return WorldSpec(**values, obstacles=tuple(static), moving=tuple(moving))


def _facing(start: tuple[float, float], goal: tuple[float, float]) -> float:
    """The yaw (rad) that faces from `start` toward `goal`."""
    return math.atan2(goal[1] - start[1], goal[0] - start[0])


def read_robot(doc: Mapping[str, Any]) -> RobotSpec:
    """The `[robot]` table, profile, start_yaw and wheel friction resolved; a motor bias within
    the torque limit of the profile's model."""
    values = read_fields(sub_table(doc, "robot", required=True), "robot", ROBOT_FIELDS)
    values.setdefault("profile", "default")
    values.setdefault("start_yaw", _facing(values["start"], values["goal"]))
    values.setdefault("wheel_friction", robot_profile(values["profile"]).wheel_friction)
    limit = robot_facts(values["profile"]).torque_limit_nm
    for index, bias in enumerate(values.get("motor_bias_nm", ())):
        if abs(bias) > limit:
            reason = f"item {index}: must be within the motor's torque limit +-{limit:g} N m, got {bias!r}"
            raise Invalid("robot.motor_bias_nm", reason)
    return RobotSpec(**values)


def read_planner(
    doc: Mapping[str, Any], recorded: bool = False, profile: str = "default"
) -> tuple[str, Mapping[str, float], bool]:
    """The planner's name, the parameters the file gives (checked against its dataclass), over
    those the robot's `profile` sets for that planner (`RobotProfile.planner_settings`), and
    `governor` (true unless the file says false).

    `recorded`: the scenario of a finished run (a log's metadata), whose planner was checked
    when it ran and need not be registered in this process; its parameters are kept as given.
    """
    table = sub_table(doc, "planner")
    given = "name" in table
    name = checked(table.get("name", registry.DEFAULT_PLANNER), STRING, "planner.name")
    governor = checked(table.get("governor", True), GOVERNOR, "planner.governor")
    given_params = {key: value for key, value in table.items() if key not in PLANNER_KEYS}
    if recorded and name not in registry.PLANNERS and NAME_PATTERN.fullmatch(name):
        return name, MappingProxyType(given_params), governor
    if name not in registry.PLANNERS:
        default = "" if given else " (the default)"
        reason = registry.unknown_planner(name, default)
        if is_import_spec(name):
            reason += (
                "; a scenario names a planner only by name: a planner class is imported only when "
                "named on the command line (--planner module:Class) or registered in code"
            )
        raise Invalid("planner.name", reason)
    overrides = {**robot_profile(profile).planner_settings.get(name, {})}
    overrides.update(given_params)
    try:
        params = registry.PLANNERS[name].Params.checked(overrides, name)
    except ParamError as exc:
        raise Invalid(join_key("planner", exc.key), exc.reason) from None
    return name, MappingProxyType(params), governor


def read_sensors(doc: Mapping[str, Any], profile: str = "default") -> SensorSpec:
    """The optional `[sensors]` table over the defaults of the robot's profile (of another kind
    than the profile's sensor: that kind's generic defaults). Keys of the other kind are refused;
    a profile whose sonars sit at fixed places refuses `count`; dead sonars must exist in the
    ring; a laser's shortest range lies below its longest; a sonar reaches at most
    MAX_SONAR_RANGE_M."""
    table = sub_table(doc, "sensors")
    given = read_fields(table, "sensors", SENSOR_FIELDS)
    robot = robot_profile(profile)
    kind = given.get("kind", robot.sensors["kind"])
    other = next(k for k in KIND_KEYS if k != kind)
    for key in table:
        if key in KIND_KEYS[other]:
            own = ", ".join(KIND_KEYS[kind])
            reason = f"a {other} key, but this sensor is kind = {kind!r} (its own keys: {own})"
            raise Invalid(f"sensors.{key}", reason)
    if "count" in table and robot.sonar_mounts is not None:
        reason = f"the {profile} profile's {len(robot.sonar_mounts)} sonars sit where the robot has them"
        raise Invalid("sensors.count", reason)
    defaults = robot.sensors if kind == robot.sensors["kind"] else GENERIC_SENSORS[kind]
    resolved = {key: SENSOR_FIELDS[key].to_python(value) for key, value in defaults.items()}
    sensors = SensorSpec(**{**resolved, **given})
    for index, sonar in enumerate(table.get("dead", [])):
        if sonar >= sensors.count:
            ring = f"a ring of count = {sensors.count} (0 to {sensors.count - 1})"
            raise Invalid("sensors.dead", f"item {index}: no sonar {sonar} in {ring}")
    if kind == "sonar" and sensors.range_max > MAX_SONAR_RANGE_M:
        reason = f"a sonar reaches at most {MAX_SONAR_RANGE_M:g} m, got {sensors.range_max!r}"
        raise Invalid("sensors.range_max", reason)
    if kind == "laser" and not sensors.range_min < sensors.range_max:
        key = "sensors.range_min" if "range_min" in table else "sensors.range_max"
        reason = f"range_min ({sensors.range_min:g} m) must be less than range_max ({sensors.range_max:g} m)"
        raise Invalid(key, reason)
    return sensors


def read_run(doc: Mapping[str, Any]) -> RunSpec:
    """The optional `[run]` table; the control period must span at least one physics step."""
    run = RunSpec(**read_fields(sub_table(doc, "run"), "run", RUN_FIELDS))
    if 1.0 / run.control_hz < run.physics_dt_s:
        reason = (
            f"the control period 1/control_hz ({1.0 / run.control_hz:g} s) must be at least "
            f"physics_dt_s ({run.physics_dt_s:g} s)"
        )
        raise Invalid("run.control_hz", reason)
    return run


def check_sensor_rate(doc: Mapping[str, Any], sensors: SensorSpec, run: RunSpec) -> None:
    """The planner decides at most MAX_TICKS_PER_SCAN times per sensor reading. The error names
    `sensors.rate_hz` when the file gives it, else `run.control_hz` (the rate is then the robot
    profile's)."""
    if run.control_hz <= MAX_TICKS_PER_SCAN * sensors.rate_hz:
        return
    if "rate_hz" in sub_table(doc, "sensors"):
        least = run.control_hz / MAX_TICKS_PER_SCAN
        reason = (
            f"must be at least run.control_hz / {MAX_TICKS_PER_SCAN} ({run.control_hz:g} Hz / "
            f"{MAX_TICKS_PER_SCAN}), that is {least:g} Hz, got {sensors.rate_hz!r}"
        )
        raise Invalid("sensors.rate_hz", reason)
    most = MAX_TICKS_PER_SCAN * sensors.rate_hz
    reason = (
        f"must be at most {MAX_TICKS_PER_SCAN} x the sensor's rate_hz ({sensors.rate_hz:g} Hz, "
        f"its default for this robot), that is {most:g} Hz, got {run.control_hz!r}"
    )
    raise Invalid("run.control_hz", reason)
