"""The base class of every planner: what it is given once, and what it answers each tick.

A planner is built once per run from its checked parameters and the robot's body (footprint,
limits, controller gains and sensor kind: body.py), then called at the control rate
(`run.control_hz`) with an `Observation` and answers a `Decision` (types.py). It sees only the
pose it believes in, its goal and its range sensor (a sonar ring or a laser), never the
simulator's obstacles.

Planners written when the protocol handed them only the robot's radius,
`__init__(self, params, robot_radius_m)`, keep working: `build` gives them the radius, and
the body as `self.robot` once they are made.
"""

from __future__ import annotations

import inspect
from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import ClassVar, Self

from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.params import PlannerInfo, PlannerParams
from vplane_mj.planning.protocol.types import Decision, Observation


class Planner(ABC):
    """A local planner. Subclasses set the class attributes and implement `step`.

    Attributes:
        name: Names the planner in scenario files (`planner.name`), summaries, output file
            names and the bench table ([a-z0-9_]+).
        summary: One line for `vplane-mj list`.
        citation: Where the method comes from.
        Params: Its frozen `PlannerParams` dataclass (optional: the base class, no
            parameters, by default).
        governs_itself: Whether it drives its body itself: it hands its forces to a governor
            of its own, or checks its motions (the built-in planners). False (the default):
            the run drives its forces through the governor (`vplane_mj.planning.RunGovernor`)
            unless the scenario says `planner.governor = false`.
        params: The instance of `Params` it was built with.
        robot: The robot's body it was built for.
    """

    name: ClassVar[str]
    summary: ClassVar[str]
    citation: ClassVar[str]
    Params: ClassVar[type[PlannerParams]] = PlannerParams
    governs_itself: ClassVar[bool] = False

    def __init__(self, params: PlannerParams, robot: RobotBody | float):
        """Keep the parameters and the robot's body.

        Args:
            params: An instance of `Params`.
            robot: The robot's body, or (as planners written for the first protocol pass it)
                the radius (m) of a round robot.

        Raises:
            TypeError: `params` is not an instance of `Params`.
        """
        if not isinstance(params, self.Params):
            raise TypeError(
                f"planner {self.name!r} takes {self.Params.__name__}, got {type(params).__name__}"
            )
        self.params = params
        self.robot = robot if isinstance(robot, RobotBody) else RobotBody.round(float(robot))
        self.radius = self.robot.radius_m
        """Radius (m) of the disc about the robot's centre that holds all of it."""

    @abstractmethod
    def step(self, obs: Observation) -> Decision:
        """The decision for this control tick.

        Args:
            obs: The pose, goal and range scan of this tick.

        Returns:
            The force to follow (world frame) and what the planner is doing.
        """

    @classmethod
    def build(cls, overrides: Mapping[str, object], robot: RobotBody | float) -> Self:
        """A fresh planner, its parameters the defaults updated with the overrides.

        Args:
            overrides: Parameter values by name (each key and value checked).
            robot: The robot's body, or a round robot's radius (m).

        Returns:
            The planner.

        Raises:
            ParamError: An unknown parameter or a bad value.
        """
        params = cls.Params.resolve(overrides, cls.name)
        body = robot if isinstance(robot, RobotBody) else RobotBody.round(float(robot))
        if not _takes_a_radius(cls):
            return cls(params, body)
        planner = cls(params, body.radius_m)
        planner.robot = body
        return planner

    @classmethod
    def info(cls) -> PlannerInfo:
        """Name, summary, citation and parameter table, as `vplane-mj list` shows them."""
        return PlannerInfo(cls.name, cls.summary, cls.citation, cls.Params.table())


def _takes_a_radius(cls: type[Planner]) -> bool:
    """Whether the class was written for the first protocol: its own `__init__` takes the robot's
    radius as a parameter named `robot_radius_m`."""
    init = cls.__init__
    if init is Planner.__init__:
        return False
    parameters = list(inspect.signature(init).parameters)
    return len(parameters) >= 3 and parameters[2] == "robot_radius_m"
