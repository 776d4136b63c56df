"""Scenarios built in Python: the document a TOML file would hold, validated like a file.

`build_scenario` assembles the tables of docs/interface.md section 1 from its arguments and
validates them with the rules and messages of a file (`parse_document`); messages name the
source CODE_SOURCE. The obstacle helpers give `[[world.obstacles]]` tables. Values are
converted to TOML's types first (numpy numbers and arrays included); a value given as None
is left out, so the key's default applies.
"""

from __future__ import annotations

import numbers
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from vplane_mj.errors import ScenarioError
from vplane_mj.scenario.fields import Invalid, join_key
from vplane_mj.scenario.keys import FORMAT
from vplane_mj.scenario.parse import parse_document
from vplane_mj.scenario.spec import Scenario

CODE_SOURCE = "<code>"
"""The source that messages name for a scenario built in code."""

OPTIONAL_SECTIONS = ("planner", "sensors", "run")
"""Tables left out of the document when nothing is given for them."""

Point = Sequence[float]
"""[x, y] in metres (a tuple, a list or a numpy array)."""


def box(center: Point, size: Point, yaw_deg: float | None = None) -> dict[str, Any]:
    """A box obstacle.

    Args:
        center: Its centre [x, y] (m).
        size: Its sides [sx, sy] (m) before it is turned.
        yaw_deg: Its turn about the centre (degrees, counter-clockwise); None: 0.

    Returns:
        The `[[world.obstacles]]` table for `build_scenario`.
    """
    return {"kind": "box", "center": center, "size": size, "yaw_deg": yaw_deg}


def wall(start: Point, end: Point, thickness: float | None = None) -> dict[str, Any]:
    """A straight wall.

    Args:
        start: One end [x, y] (m), the file's `from`.
        end: The other end [x, y] (m), the file's `to`.
        thickness: Its width (m); None: the format's default.

    Returns:
        The `[[world.obstacles]]` table for `build_scenario`.
    """
    return {"kind": "wall", "from": start, "to": end, "thickness": thickness}


def cylinder(center: Point, radius: float) -> dict[str, Any]:
    """A round post.

    Args:
        center: Its axis [x, y] (m).
        radius: Its radius (m).

    Returns:
        The `[[world.obstacles]]` table for `build_scenario`.
    """
    return {"kind": "cylinder", "center": center, "radius": radius}


def cup(
    center: Point, width: float, depth: float, yaw_deg: float | None = None, thickness: float | None = None
) -> dict[str, Any]:
    """A U (C) trap; at yaw 0 its mouth faces -x.

    Args:
        center: Its centre [x, y] (m).
        width: Across its mouth (m).
        depth: From its mouth to its back (m).
        yaw_deg: Its turn about the centre (degrees, counter-clockwise); None: 0.
        thickness: Its walls' width (m); None: the format's default.

    Returns:
        The `[[world.obstacles]]` table (kind "u") for `build_scenario`.
    """
    return {
        "kind": "u",
        "center": center,
        "width": width,
        "depth": depth,
        "yaw_deg": yaw_deg,
        "thickness": thickness,
    }


def h_shape(
    center: Point, length: float, width: float, yaw_deg: float | None = None, thickness: float | None = None
) -> dict[str, Any]:
    """An H: two posts and a crossbar, whose cups open to -x and +x at yaw 0.

    Args:
        center: Its centre [x, y] (m).
        length: Each post's length (m).
        width: The posts' distance apart (m).
        yaw_deg: Its turn about the centre (degrees, counter-clockwise); None: 0.
        thickness: Its walls' width (m); None: the format's default.

    Returns:
        The `[[world.obstacles]]` table (kind "h") for `build_scenario`.
    """
    return {
        "kind": "h",
        "center": center,
        "length": length,
        "width": width,
        "yaw_deg": yaw_deg,
        "thickness": thickness,
    }


def build_scenario(
    name: str,
    *,
    size: Point,
    start: Point,
    goal: Point,
    obstacles: Iterable[Mapping[str, Any]] = (),
    border: bool | None = None,
    description: str | None = None,
    robot: Mapping[str, Any] | None = None,
    planner: str | None = None,
    planner_params: Mapping[str, Any] | None = None,
    sensors: Mapping[str, Any] | None = None,
    run: Mapping[str, Any] | None = None,
    overrides: Sequence[str] = (),
) -> Scenario:
    """A scenario from Python values, validated exactly like a file.

    Tables are given key for key as in a file (docs/scenarios.md); a value of None is left
    out, so the key's default applies. `Scenario.to_toml()` gives the file that loads back
    equal.

    Args:
        name: The scenario's `name`.
        size: The arena `world.size` [W, H] (m).
        start: The robot's start `robot.start` [x, y] (m).
        goal: The goal `robot.goal` [x, y] (m).
        obstacles: `[[world.obstacles]]` tables, as `box`, `wall`, `cylinder`, `cup` and
            `h_shape` give them.
        border: Whether walls surround the arena (`world.border`).
        description: The scenario's `description`.
        robot: Further `[robot]` keys (`start_yaw_deg`, `goal_tolerance`, the faults).
        planner: The planner's name (`planner.name`).
        planner_params: The planner's parameters (the rest of the `[planner]` table).
        sensors: The `[sensors]` table.
        run: The `[run]` table (`seed`, `time_limit_s`, ...).
        overrides: `--set KEY=VALUE` strings applied after.

    Returns:
        The validated scenario; messages name its source `<code>`.

    Raises:
        ScenarioError: A value the format does not allow, naming the key and the reason.
    """
    try:
        document = _to_toml_value(
            {
                "format": FORMAT,
                "name": name,
                "description": description,
                "world": {"size": size, "border": border, "obstacles": list(obstacles) or None},
                "robot": _table("robot", {"start": start, "goal": goal}, robot, "robot"),
                "planner": _table("planner", {"name": planner}, planner_params, "planner_params"),
                "sensors": sensors,
                "run": run,
            },
            "",
        )
    except Invalid as exc:
        raise ScenarioError(CODE_SOURCE, exc.key, exc.reason) from None
    for section in OPTIONAL_SECTIONS:
        if document.get(section) == {}:
            del document[section]  # as a file without the table
    return parse_document(document, CODE_SOURCE, overrides)


def _table(
    path: str, given: dict[str, Any], further: Mapping[str, Any] | None, argument: str
) -> dict[str, Any]:
    """The table `path` of keys given as arguments and further keys (the mapping `argument`),
    none of them given twice."""
    if twice := sorted(given.keys() & dict(further or {}).keys()):
        reason = f"given twice: by its own argument and in {argument}="
        raise Invalid(join_key(path, twice[0]), reason)
    return {**given, **(further or {})}


def _to_toml_value(value: Any, key: str) -> Any:
    """`value` as TOML's parser would give it: tables as dicts without their None values,
    arrays as lists, numbers as int or float; anything else names `key`."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    if isinstance(value, str):
        return value
    if isinstance(value, Mapping):
        table = {}
        for item_key, item in value.items():
            if not isinstance(item_key, str):
                raise Invalid(key, f"table keys must be strings, got {item_key!r}")
            if item is not None:
                table[item_key] = _to_toml_value(item, join_key(key, item_key))
        return table
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, list | tuple):
        return [_to_toml_value(item, f"{key}[{index}]") for index, item in enumerate(value)]
    kind = type(value).__name__
    raise Invalid(key, f"must be a number, a string, a boolean, an array or a table, got {kind}")
