"""The planners a scenario can name, by name, each a `Planner` class.

A planner's module is imported when the planner is first looked up, not before: a run loads
only the planner it uses (some need scipy, whose import costs more than a short run's loop).
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, Mapping

from vplane_mj.planning.base import Planner
from vplane_mj.planning.params import PlannerInfo

BUILT_IN: dict[str, tuple[str, str]] = {
    "apf": ("apf", "ApfPlanner"),
    "vplane": ("vplane", "VPlanePlanner"),
    "vplane_plus": ("vplane_plus", "VPlanePlusPlanner"),
    "vobs": ("vobs", "VobsPlanner"),
    "vfh": ("vfh", "VfhPlanner"),
    "bug2": ("bug2", "Bug2Planner"),
    "dwa": ("dwa", "DwaPlanner"),
}
"""Planner name: (its module in vplane_mj.planning, its class)."""


class _Planners(Mapping[str, type[Planner]]):
    """Planner name -> class, each module imported on first use."""

    def __init__(self) -> None:
        self._loaded: dict[str, type[Planner]] = {}

    def __getitem__(self, name: str) -> type[Planner]:
        if name not in self._loaded:
            module_name, class_name = BUILT_IN[name]
            module = importlib.import_module(f"vplane_mj.planning.{module_name}")
            self._loaded[name] = getattr(module, class_name)
        return self._loaded[name]

    def __contains__(self, name: object) -> bool:
        return name in BUILT_IN

    def __iter__(self) -> Iterator[str]:
        return iter(BUILT_IN)

    def __len__(self) -> int:
        return len(BUILT_IN)


PLANNERS: Mapping[str, type[Planner]] = _Planners()

DEFAULT_PLANNER = "vplane"


def planner_info(name: str) -> PlannerInfo:
    """Name, summary, citation and parameter table of planner `name` (KeyError when there is none)."""
    return PLANNERS[name].info()


def make_planner(name: str, params: Mapping[str, object], robot_radius_m: float) -> Planner:
    """A fresh planner `name`, its parameters resolved against the defaults (each checked)."""
    return PLANNERS[name].build(params, robot_radius_m)
