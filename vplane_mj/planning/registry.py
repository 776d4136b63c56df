"""The planners a scenario can name, with their parameter tables and constructors."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Protocol

from vplane_mj.planning import apf, bug2, dwa, vfh, vobs, vplane, vplane_plus
from vplane_mj.planning.params import PlannerInfo
from vplane_mj.planning.types import Decision, Observation


class Planner(Protocol):
    """A planner: resolved parameters, and one decision per control tick."""

    params: dict[str, float]

    def step(self, obs: Observation) -> Decision: ...


Factory = Callable[[Mapping[str, float], float], Planner]

PLANNERS: dict[str, tuple[PlannerInfo, Factory]] = {
    apf.INFO.name: (apf.INFO, lambda params, _radius: apf.ApfPlanner(params)),
    vplane.INFO.name: (vplane.INFO, vplane.VPlanePlanner),
    vplane_plus.INFO.name: (vplane_plus.INFO, vplane_plus.VPlanePlusPlanner),
    vobs.INFO.name: (vobs.INFO, lambda params, _radius: vobs.VobsPlanner(params)),
    vfh.INFO.name: (vfh.INFO, vfh.VfhPlanner),
    bug2.INFO.name: (bug2.INFO, lambda params, _radius: bug2.Bug2Planner(params)),
    dwa.INFO.name: (dwa.INFO, dwa.DwaPlanner),
}

DEFAULT_PLANNER = vplane.INFO.name


def planner_info(name: str) -> PlannerInfo:
    """The parameter table of planner `name` (KeyError when there is none)."""
    return PLANNERS[name][0]


def make_planner(name: str, params: Mapping[str, float], robot_radius_m: float) -> Planner:
    """A fresh planner `name`, its parameters resolved against the defaults."""
    info, factory = PLANNERS[name]
    return factory(info.resolve(params), robot_radius_m)
