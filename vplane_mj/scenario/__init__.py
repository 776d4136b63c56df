"""Scenario files: TOML text -> validated, frozen dataclasses (docs/interface.md section 1).

Every rule of the contract is checked before anything runs; any failure is a
ScenarioError naming the source, the key path (`world.obstacles[2].width`) and the
reason. The parts, one job each:

- `spec.py`: the frozen dataclasses (Scenario, WorldSpec, RobotSpec, SensorSpec, RunSpec);
- `fields.py`: the rule engine (one key's type and bounds, one table's allowed keys);
- `keys.py`: every allowed key as data, and the format's limits;
- `sections.py`: each table read into its dataclass, with the rules that span keys;
- `placement.py`: start and goal inside the arena and clear of walls and obstacles;
- `overrides.py`: `--set KEY=VALUE` applied to the parsed document;
- `parse.py`: text and overrides -> Scenario;
- `build.py`: a scenario from Python values, as the document a file would hold.

This module finds the files: a path, a name in ./scenarios/, or a built-in scenario.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from vplane_mj.errors import ScenarioError, did_you_mean, readable
from vplane_mj.files import data_dir
from vplane_mj.scenario.build import CODE_SOURCE, box, build_scenario, cup, cylinder, h_shape, wall
from vplane_mj.scenario.fields import Field
from vplane_mj.scenario.keys import (
    FORMAT,
    MAX_ARENA_M,
    MAX_NAME_LENGTH,
    MAX_NOISE_STD_M,
    MAX_OBSTACLE_M,
    MIN_OBSTACLE_M,
    NAME_PATTERN,
)
from vplane_mj.scenario.overrides import Override
from vplane_mj.scenario.parse import parse_document, parse_scenario
from vplane_mj.scenario.spec import RobotSpec, RunSpec, Scenario, SensorSpec, WorldSpec

__all__ = [
    "CODE_SOURCE",
    "FORMAT",
    "MAX_ARENA_M",
    "MAX_NAME_LENGTH",
    "MAX_NOISE_STD_M",
    "MAX_OBSTACLE_M",
    "MIN_OBSTACLE_M",
    "NAME_PATTERN",
    "Field",
    "RobotSpec",
    "RunSpec",
    "Scenario",
    "ScenarioError",
    "SensorSpec",
    "WorldSpec",
    "box",
    "build_scenario",
    "builtin_scenarios",
    "cup",
    "cylinder",
    "h_shape",
    "load_scenario",
    "parse_document",
    "parse_scenario",
    "resolve_path",
    "wall",
]


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
        raise ScenarioError(readable(ref), "", "is a directory, not a scenario file")
    builtin = [builtin.stem for builtin in _builtin_paths()]
    reason = f"no such file or built-in scenario (built-in: {', '.join(builtin) or 'none'})"
    raise ScenarioError(readable(ref), "", reason + _closest_scenario(ref, builtin))


def _closest_scenario(ref: str, builtin: list[str]) -> str:
    """The "did you mean" of a scenario that does not exist: for a name, the closest name in
    ./scenarios/ or among the built-in ones; for a path, the closest file beside it."""
    path = Path(ref)
    if NAME_PATTERN.fullmatch(ref):
        return did_you_mean(ref, [*(found.stem for found in Path("scenarios").glob("*.toml")), *builtin])
    if not path.parent.is_dir():
        return ""
    return did_you_mean(ref, [str(found) for found in path.parent.glob("*.toml")])


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


def load_scenario(ref: str, overrides: Sequence[str | Override] = ()) -> Scenario:
    """Read, parse, override and validate a scenario file.

    The source named in messages and logs is `ref` itself when it is a path, else the file
    found, as `readable` shows it.

    Args:
        ref: A path, else a name in ./scenarios/, else a built-in scenario's name.
        overrides: `--set KEY=VALUE` strings (or parsed overrides) applied before validation.

    Returns:
        The validated scenario.

    Raises:
        ScenarioError: No such file or scenario, unreadable text, or an invalid key, naming
            the source, the key path and the reason.
    """
    path = resolve_path(ref)
    source = readable(ref if path == Path(ref) else path)
    return parse_scenario(_read_text(path, source), source, overrides)


def builtin_scenarios() -> list[tuple[str, str]]:
    """(name, description) of every shipped scenario, sorted by name; each is validated."""
    return [(path.stem, load_scenario(str(path)).description) for path in _builtin_paths()]
