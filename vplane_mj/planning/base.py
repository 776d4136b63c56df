"""The base class of every planner: what it is given once, and what it answers each tick.

A planner is built once per run from its checked parameters and the robot's radius, then
called at the control rate (`run.control_hz`) with an `Observation` and answers a `Decision`
(types.py). It sees only the pose it believes in, its goal and the sonar ring, never the
simulator's obstacles.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import ClassVar, Self

from vplane_mj.planning.params import PlannerInfo, PlannerParams
from vplane_mj.planning.types import Decision, Observation


class Planner(ABC):
    """A local planner. Subclasses set the class attributes and implement `step`.

    `name` names the planner in scenario files (`planner.name`), summaries, output file names
    and the bench table ([a-z0-9_]+); `summary` is one line for `vplane-mj list`, `citation`
    where the method comes from, `Params` its frozen `PlannerParams` dataclass.
    """

    name: ClassVar[str]
    summary: ClassVar[str]
    citation: ClassVar[str]
    Params: ClassVar[type[PlannerParams]] = PlannerParams

    def __init__(self, params: PlannerParams, robot_radius_m: float):
        """`params`: an instance of `Params`; `robot_radius_m`: the radius (m) of a disc about
        the robot's centre that holds all of it."""
        if not isinstance(params, self.Params):
            raise TypeError(
                f"planner {self.name!r} takes {self.Params.__name__}, got {type(params).__name__}"
            )
        self.params = params
        self.radius = robot_radius_m

    @abstractmethod
    def step(self, obs: Observation) -> Decision:
        """The decision for this control tick: the force to follow (world frame) and what the
        planner is doing."""

    @classmethod
    def build(cls, overrides: Mapping[str, object], robot_radius_m: float) -> Self:
        """A fresh planner, its parameters the defaults updated with `overrides` (each key and
        value checked: `ParamError`)."""
        return cls(cls.Params.resolve(overrides, cls.name), robot_radius_m)

    @classmethod
    def info(cls) -> PlannerInfo:
        """Name, summary, citation and parameter table, as `vplane-mj list` shows them."""
        return PlannerInfo(cls.name, cls.summary, cls.citation, cls.Params.table())
