"""TOML text -> a validated Scenario, or a ScenarioError naming the source, key and reason.

The document is parsed, the `--set` overrides are applied, then every section is read
(`sections.py`) and the start and goal placed (`placement.py`): the rules of
docs/interface.md section 1, all checked before anything runs.
"""

from __future__ import annotations

import tomllib
from collections.abc import Sequence
from types import MappingProxyType
from typing import Any

from vplane_mj.errors import ScenarioError
from vplane_mj.scenario.fields import Invalid
from vplane_mj.scenario.overrides import Override, apply_override
from vplane_mj.scenario.placement import check_placement
from vplane_mj.scenario.sections import (
    check_sensor_rate,
    read_planner,
    read_robot,
    read_run,
    read_sensors,
    read_top,
    read_world,
)
from vplane_mj.scenario.spec import Scenario


def _freeze(value: Any) -> Any:
    """A read-only deep copy of a parsed TOML value: tables as mappingproxies, arrays as tuples."""
    if isinstance(value, dict):
        return MappingProxyType({key: _freeze(item) for key, item in value.items()})
    if isinstance(value, list):
        return tuple(_freeze(item) for item in value)
    return value


def _build_scenario(doc: dict[str, Any], source: str, recorded: bool) -> Scenario:
    """Validate a parsed document section by section, the sensor's rate against the control
    rate, then the start and goal placement."""
    top = read_top(doc)
    run = read_run(doc)
    world = read_world(doc, run.seed)
    robot = read_robot(doc)
    planner, params, governor = read_planner(doc, recorded, robot.profile)
    sensors = read_sensors(doc, robot.profile)
    check_sensor_rate(doc, sensors, run)
    scenario = Scenario(
        name=top["name"],
        description=top.get("description", ""),
        source=source,
        world=world,
        robot=robot,
        planner=planner,
        planner_params=params,
        planner_governor=governor,
        sensors=sensors,
        run=run,
        raw=_freeze(doc),
    )
    check_placement(world, robot)
    return scenario


def _origin(key: str, applied: list[tuple[str, Override]]) -> str:
    """How an error at `key` names the last override that set it, a table or array that holds
    it, or a key inside it (the override made the table at `key`); "" when none did."""
    for path, override in reversed(applied):
        if key == path or _inside(key, path):
            return override.origin(key)
        if _inside(path, key):
            return override.origin(path)
    return ""


def _inside(key: str, path: str) -> bool:
    """Whether `key` lies inside the table or array at `path`."""
    return key.startswith((f"{path}.", f"{path}["))


def _parse_toml(text: str, source: str) -> dict[str, Any]:
    """The TOML document, or a ScenarioError quoting tomllib (line and column)."""
    try:
        return tomllib.loads(text)
    except (ValueError, RecursionError) as exc:  # TOMLDecodeError, huge integers, deep nesting
        raise ScenarioError(source, "", f"invalid TOML: {exc}") from None


def parse_scenario(
    text: str, source: str, overrides: Sequence[str | Override] = (), recorded: bool = False
) -> Scenario:
    """Parse TOML text, apply `--set KEY=VALUE` overrides, validate: a Scenario or ScenarioError.

    `recorded`: the text is a finished run's scenario (from its log), whose planner need not be
    registered in this process (nothing is imported either way)."""
    return parse_document(_parse_toml(text, source), source, overrides, recorded)


def parse_document(
    doc: dict[str, Any], source: str, overrides: Sequence[str | Override] = (), recorded: bool = False
) -> Scenario:
    """Validate a document as TOML parses it (tables as dicts, arrays as lists), after the
    `--set KEY=VALUE` overrides (applied to `doc` in place): a Scenario or ScenarioError.

    An error at a key an override set (or inside it) names that override, not `source`."""
    applied: list[tuple[str, Override]] = []  # the key path each override set, in order
    culprit: Override | None = None
    try:
        for override in map(Override.of, overrides):
            culprit = override
            applied.append((apply_override(doc, override.text), override))
        culprit = None
        return _build_scenario(doc, source, recorded)
    except Invalid as exc:
        origin = culprit.origin(exc.key) if culprit else _origin(exc.key, applied)
        raise ScenarioError(source, exc.key, exc.reason, origin) from None
    except Exception as exc:  # promised: no input ever escapes as anything but ScenarioError
        reason = f"cannot be validated (internal error, please report it: {exc!r})"
        raise ScenarioError(source, "", reason) from exc
