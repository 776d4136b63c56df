"""Planner parameters as frozen dataclasses: each field a number with a default, a unit, bounds
and a one-line meaning.

A planner declares its parameters as a subclass of `PlannerParams`, each field made by
`param(...)`; groups that several planners share (`groups.py`) are reused by inheritance.
`PlannerParams.resolve` turns a mapping of overrides (a scenario's `[planner]` table, `--set
planner.KEY=VALUE`, a dict in code) into the dataclass, checking every key and value first.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Self

from vplane_mj.errors import VPlaneError, did_you_mean

MAX_MAGNITUDE = 1e6
"""No planner parameter may exceed this in absolute value: a larger one is surely a mistake,
and such values overflow the planners' force arithmetic to inf (the run would end in error)."""

PARAM = "vplane_mj.param"
"""The key of a dataclass field's metadata that holds its `Param`."""


@dataclass(frozen=True)
class Param:
    """One numeric planner parameter, as `param` declares it.

    Attributes:
        default: The value when none is given.
        unit: Its unit as `vplane-mj list` shows it ("m", "rad", "s", ...; "" for none).
        doc: Its meaning, one line.
        gt: Exclusive lower bound; None: none.
        ge: Inclusive lower bound; None: none.
        le: Inclusive upper bound; None: none.
        integer: Whether it is a count (an int).
    """

    default: float
    unit: str
    doc: str
    gt: float | None = None
    ge: float | None = None
    le: float | None = None
    integer: bool = False

    def check(self, value: object) -> str | None:
        """Return why `value` is unacceptable, or None when it is fine."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            return f"must be a number, got {type(value).__name__}"
        if abs(value) > sys.float_info.max or not math.isfinite(value):
            return f"must be finite, got {value!r}"
        if self.integer and not isinstance(value, int):
            return f"must be an integer, got {value!r}"
        if abs(value) > MAX_MAGNITUDE:
            return f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {value!r}"
        if self.gt is not None and not value > self.gt:
            return f"must be greater than {self.gt:g}, got {value!r}"
        if self.ge is not None and not value >= self.ge:
            return f"must be at least {self.ge:g}, got {value!r}"
        if self.le is not None and not value <= self.le:
            return f"must be at most {self.le:g}, got {value!r}"
        return None


def param(
    default: float,
    unit: str,
    doc: str,
    gt: float | None = None,
    ge: float | None = None,
    le: float | None = None,
    integer: bool = False,
) -> Any:
    """A field of a `PlannerParams` dataclass, its value checked when the planner is built.

    Args:
        default: The value when none is given.
        unit: Its unit as `vplane-mj list` shows it ("m", "rad", "s", ...; "" for none).
        doc: Its meaning, one line.
        gt: Exclusive lower bound.
        ge: Inclusive lower bound.
        le: Inclusive upper bound.
        integer: Whether it is a count (an int).

    Returns:
        The dataclass field, its `Param` in the metadata.
    """
    spec = Param(default, unit, doc, gt=gt, ge=ge, le=le, integer=integer)
    return field(default=default, metadata={PARAM: spec})


def with_default(params: type[PlannerParams], name: str, default: float) -> Any:
    """A group's parameter with another default (unit, meaning and bounds kept), for a subclass
    that shares the parameter but not its default.

    Args:
        params: The group (a `PlannerParams` subclass) that declares the parameter.
        name: The parameter's name.
        default: Its new default.

    Returns:
        The dataclass field.
    """
    spec = params.table()[name]
    return field(default=default, metadata={PARAM: dataclasses.replace(spec, default=default)})


class ParamError(VPlaneError):
    """A planner parameter that is unknown or has a bad value.

    Args:
        key: The parameter's name (the message says `planner.KEY`).
        reason: Why it is refused.
    """

    def __init__(self, key: str, reason: str):
        self.key = key
        self.reason = reason
        super().__init__(f"planner.{key}: {reason}")

    def __reduce__(self):
        """Rebuilt from its arguments, so that it crosses a process boundary (a sweep's worker)."""
        return type(self), (self.key, self.reason)


@dataclass(frozen=True)
class PlannerParams:
    """The base of every planner's parameters (a frozen dataclass of `param` fields).

    Groups combine by inheritance; a dataclass lists the fields of its bases in reverse
    order of the bases (`class P(B, A)` holds A's fields, then B's, then its own). A
    subclass is built with its fields as keyword arguments, each defaulting to its `param`'s
    default; `resolve` builds it from overrides with every key and value checked.
    """

    @classmethod
    def table(cls) -> dict[str, Param]:
        """Every parameter by name, in declaration order (what `vplane-mj list` shows)."""
        return {f.name: f.metadata[PARAM] for f in dataclasses.fields(cls)}

    @classmethod
    def checked(cls, overrides: Mapping[str, object], planner: str) -> dict[str, float]:
        """The overrides with every key and value checked (ParamError for the first bad one),
        each number as the dataclass holds it: an int for an integer parameter, else a float."""
        table = cls.table()
        values: dict[str, float] = {}
        for key, value in overrides.items():
            spec = table.get(key)
            if spec is None:
                known = ", ".join(table)
                raise ParamError(
                    key, f"not a parameter of planner {planner!r} ({known}){did_you_mean(key, table)}"
                )
            reason = spec.check(value)
            if reason:
                raise ParamError(key, reason)
            assert isinstance(value, int | float), "check accepts numbers only"
            values[key] = value if spec.integer else float(value)
        return values

    @classmethod
    def resolve(cls, overrides: Mapping[str, object], planner: str) -> Self:
        """The defaults updated with the overrides, checked.

        Args:
            overrides: Parameter values by name.
            planner: The planner's name, for messages.

        Returns:
            The parameters.

        Raises:
            ParamError: An unknown key or a bad value (the first found).
        """
        return cls(**cls.checked(overrides, planner))

    def as_dict(self) -> dict[str, float]:
        """Every value by name, in declaration order (the run summary's `planner_params`)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}


@dataclass(frozen=True)
class PlannerInfo:
    """What `vplane-mj list` shows of a planner: derived from its class and its parameters."""

    name: str
    summary: str
    citation: str
    params: Mapping[str, Param] = field(default_factory=dict)
