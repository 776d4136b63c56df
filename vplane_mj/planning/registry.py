"""The planners a scenario can name, with their parameter tables."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from vplane_mj.planning import apf
from vplane_mj.planning.params import PlannerInfo
from vplane_mj.planning.types import Decision, Observation

Planner = Callable[[Observation], Decision]

PLANNERS: dict[str, tuple[PlannerInfo, Callable[[Mapping[str, float]], object]]] = {
    apf.INFO.name: (apf.INFO, apf.ApfPlanner),
}

DEFAULT_PLANNER = "vplane"


def planner_info(name: str) -> PlannerInfo:
    """The parameter table of planner `name` (KeyError when there is none)."""
    return PLANNERS[name][0]


def make_planner(name: str, params: Mapping[str, float]):
    """A fresh planner `name` with its parameters resolved against the defaults."""
    info, factory = PLANNERS[name]
    return factory(info.resolve(params))
