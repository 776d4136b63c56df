"""The rule engine of scenario files: one key's type and bounds, one table's allowed keys.

A `Field` describes an allowed key; `read_fields` checks a parsed TOML table against a
table of them, so an unknown key anywhere is an error. A broken rule raises `Invalid`
with the key path (`world.obstacles[2].width`) and the reason; `parse_scenario` turns it
into the ScenarioError the user sees (docs/interface.md section 1, "Validation").
"""

from __future__ import annotations

import json
import operator
import re
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeGuard

from vplane_mj.errors import did_you_mean


class Invalid(Exception):
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


def type_name(value: object) -> str:
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


def is_number(value: object) -> TypeGuard[int | float]:
    """An int or a float, but not a bool (TOML booleans are not numbers)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def is_finite(value: float) -> bool:
    """Finite as a float: false for inf, nan and integers too large for a float."""
    return abs(value) <= sys.float_info.max


def _check_number(value: object, field: Field) -> str | None:
    """A finite number within bounds; integers are accepted."""
    if not is_number(value):
        return f"must be a number, got {type_name(value)}"
    if not is_finite(value):
        return f"must be finite, got {value!r}"
    return _bounds_reason(value, field)


def _check_int(value: object, field: Field) -> str | None:
    """An integer within bounds."""
    if not isinstance(value, int) or isinstance(value, bool):
        return f"must be an integer, got {type_name(value)}"
    return _bounds_reason(value, field)


def _check_bool(value: object, field: Field) -> str | None:
    """true or false."""
    return None if isinstance(value, bool) else f"must be true or false, got {type_name(value)}"


def _check_str(value: object, field: Field) -> str | None:
    """A string, one of the field's choices when it has any."""
    if not isinstance(value, str):
        return f"must be a string, got {type_name(value)}"
    if field.choices and value not in field.choices:
        choices = ", ".join(map(repr, field.choices))
        return f"must be one of {choices}, got {value!r}{did_you_mean(value, field.choices)}"
    return None


def _check_two_numbers(value: object, field: Field, shape: str) -> str | None:
    """An array of exactly 2 finite numbers, each within bounds; `shape` shows their meaning."""
    if not isinstance(value, list):
        return f"must be an array of 2 numbers {shape}, got {type_name(value)}"
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
        return f"must be an array of integers, got {type_name(value)}"
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

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def join_key(path: str, key: str) -> str:
    """The key path of `key` inside the table at `path` ("" is the top level).

    A key that is not a bare TOML key (empty, spaces, dots, ...) is shown quoted.
    """
    part = key if _BARE_KEY.fullmatch(key) else json.dumps(key)
    return f"{path}.{part}" if path else part


def _reject_unknown(table: Mapping[str, Any], path: str, allowed: Sequence[str]) -> None:
    """Fail on the first key of `table` that is not in `allowed`."""
    for key in table:
        if key not in allowed:
            reason = f"unknown key (allowed here: {', '.join(allowed)}){did_you_mean(key, allowed)}"
            raise Invalid(join_key(path, key), reason)


def checked(value: Any, field: Field, key: str) -> Any:
    """The value of `key` converted for the dataclasses, or an error naming `key`."""
    reason = field.check(value)
    if reason:
        raise Invalid(key, reason)
    return field.to_python(value)


def read_fields(
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
            values[field.attr or key] = checked(table[key], field, join_key(path, key))
        elif field.required:
            raise Invalid(join_key(path, key), "missing required key")
    return values


def sub_table(
    parent: Mapping[str, Any], key: str, path: str = "", required: bool = False
) -> Mapping[str, Any]:
    """The table `parent[key]`: {} when absent and optional, an error when not a table."""
    full = join_key(path, key)
    if key not in parent:
        if required:
            raise Invalid(full, "missing required table")
        return {}
    table = parent[key]
    if not isinstance(table, dict):
        raise Invalid(full, f"must be a table, got {type_name(table)}")
    return table
