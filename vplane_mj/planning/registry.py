"""The planners a scenario can name, with their parameter tables and constructors.

A planner's module is imported when the planner is first looked up, not before: a run loads
only the planner it uses (some need scipy, whose import costs more than a short run's loop).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator, Mapping
from typing import Protocol

from vplane_mj.planning.params import PlannerInfo
from vplane_mj.planning.types import Decision, Observation


class Planner(Protocol):
    """A planner: resolved parameters, and one decision per control tick."""

    params: dict[str, float]

    def step(self, obs: Observation) -> Decision: ...


Factory = Callable[[Mapping[str, float], float], Planner]

_MODULES = {
    "apf": ("apf", "ApfPlanner", False),
    "vplane": ("vplane", "VPlanePlanner", True),
    "vplane_plus": ("vplane_plus", "VPlanePlusPlanner", True),
    "vobs": ("vobs", "VobsPlanner", False),
    "vfh": ("vfh", "VfhPlanner", True),
    "bug2": ("bug2", "Bug2Planner", False),
    "dwa": ("dwa", "DwaPlanner", True),
}
"""Planner name: (module in vplane_mj.planning, class, whether it takes the robot radius)."""


class _Planners(Mapping[str, tuple[PlannerInfo, Factory]]):
    """Planner name -> (parameter table, constructor), each module imported on first use."""

    def __init__(self) -> None:
        self._loaded: dict[str, tuple[PlannerInfo, Factory]] = {}

    def __getitem__(self, name: str) -> tuple[PlannerInfo, Factory]:
        if name not in self._loaded:
            module_name, class_name, takes_radius = _MODULES[name]
            module = importlib.import_module(f"vplane_mj.planning.{module_name}")
            cls = getattr(module, class_name)
            factory = cls if takes_radius else (lambda params, _radius, cls=cls: cls(params))
            self._loaded[name] = (module.INFO, factory)
        return self._loaded[name]

    def __iter__(self) -> Iterator[str]:
        return iter(_MODULES)

    def __len__(self) -> int:
        return len(_MODULES)


PLANNERS: Mapping[str, tuple[PlannerInfo, Factory]] = _Planners()

DEFAULT_PLANNER = "vplane"


def planner_info(name: str) -> PlannerInfo:
    """The parameter table of planner `name` (KeyError when there is none)."""
    return PLANNERS[name][0]


def make_planner(name: str, params: Mapping[str, float], robot_radius_m: float) -> Planner:
    """A fresh planner `name`, its parameters resolved against the defaults."""
    info, factory = PLANNERS[name]
    return factory(info.resolve(params), robot_radius_m)
