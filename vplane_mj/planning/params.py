"""Planner parameters as data: each has a default, a unit, bounds and a one-line meaning."""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field

MAX_MAGNITUDE = 1e6
"""No planner parameter may exceed this in absolute value: a larger one is surely a mistake,
and such values overflow the planners' force arithmetic to inf (the run would end in error)."""


@dataclass(frozen=True)
class Param:
    """One numeric planner parameter. Bounds are exclusive (`gt`) or inclusive (`ge`, `le`)."""

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
        if self.integer and not isinstance(value, int):
            return f"must be an integer, got {value!r}"
        if (isinstance(value, int) and abs(value) > sys.float_info.max) or not math.isfinite(value):
            return f"must be finite, got {value!r}"
        if abs(value) > MAX_MAGNITUDE:
            return f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {value!r}"
        if self.gt is not None and not value > self.gt:
            return f"must be greater than {self.gt:g}, got {value!r}"
        if self.ge is not None and not value >= self.ge:
            return f"must be at least {self.ge:g}, got {value!r}"
        if self.le is not None and not value <= self.le:
            return f"must be at most {self.le:g}, got {value!r}"
        return None


@dataclass(frozen=True)
class PlannerInfo:
    """What `vplane-mj list` shows of a planner, and what the scenario validator checks."""

    name: str
    summary: str
    citation: str
    params: Mapping[str, Param] = field(default_factory=dict)

    def resolve(self, overrides: Mapping[str, float]) -> dict[str, float]:
        """Defaults updated with already-validated overrides."""
        values = {key: p.default for key, p in self.params.items()}
        values.update(overrides)
        return values


LOCAL_MAP_PARAMS: dict[str, Param] = {
    "map_cell_m": Param(0.1, "m", "cell size of the local sonar map", ge=0.05, le=1.0),
    "map_size_m": Param(8.0, "m", "side of the square local map that follows the robot", gt=0, le=20.0),
    "map_threshold": Param(4, "", "certainty at which a map cell counts as an obstacle", ge=1, integer=True),
}
"""The sonar certainty grid (localmap.py), shared by the planners that keep one."""

SONAR_MAP_PARAMS: dict[str, Param] = {
    **LOCAL_MAP_PARAMS,
    "sector_deg": Param(5.0, "deg", "polar histogram sector width", ge=0.5, le=45),
    "window_m": Param(2.0, "m", "radius of the histogram's active window", gt=0),
    "histogram_threshold": Param(1.0, "", "sector density above which a sector is blocked", gt=0),
}
"""The sonar certainty grid and polar histogram, shared by the planners that use them.

The bounds keep the grid (at most 400 x 400 cells) and the histogram (at most 720 sectors)
small enough to update at the control rate."""
