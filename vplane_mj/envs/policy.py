"""A planner as a dm_env policy: a callable from a TimeStep to the action, for `dm_control.viewer`
or any loop over `VPlaneNavDmEnv`.

The planner sees what it sees in a run (the task's Observation of the tick: pose, goal, ranges),
not the agent's observation, and its decision becomes the environment's action: the force
itself for `action="force"`; for `action="velocity"`, the body speed and turn rate the run
would drive (the decision's own command, else the heading controller's answer to its force).
Either way the robot moves as in `vplane-mj run` with that planner, with one difference: an
environment cannot give up, so when the planner does (a run would end as `stuck`), the episode
goes on with the planner's decisions, to its time limit or to another ending.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import dm_env
import numpy as np

from vplane_mj.errors import VPlaneError
from vplane_mj.planning.planners.run_governor import RunGovernor
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.plugins import PlannerError, planner_problem
from vplane_mj.planning.protocol.registry import PLANNERS, unknown_planner
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.robots.facts import robot_body
from vplane_mj.sim.control import heading_command, within_limits
from vplane_mj.sim.loop import Run

if TYPE_CHECKING:
    from vplane_mj.envs.dm_environment import VPlaneNavDmEnv


class PlannerPolicy:
    """Drives `environment` with a planner; every episode gets a fresh planner for its robot
    (profile, footprint, limits, sensor kind), whose forces are driven through the run's
    governor as `vplane-mj run` drives them (a planner of your own, unless the scenario says
    `planner.governor = false`).

    Args:
        environment: A VPlaneNavDmEnv, or a wrapper of one.
        planner: A registered planner's name or a Planner class; None: each episode's
            scenario's own planner.
        params: The planner's parameters (default: its defaults; with `planner=None`, the
            scenario's).
    """

    def __init__(
        self,
        environment: VPlaneNavDmEnv,
        planner: str | type[Planner] | None = None,
        params: Mapping[str, object] | None = None,
    ):
        if isinstance(planner, str) and planner not in PLANNERS:
            raise VPlaneError(unknown_planner(planner))
        if planner is not None and not isinstance(planner, str) and (problem := planner_problem(planner)):
            raise PlannerError(f"{planner!r}: {problem}")
        self.task = environment.task
        self.planner = planner
        self.params = params
        self._run: Run | None = None
        self._planner: Planner | None = None
        self._governor: RunGovernor | None = None

    def __call__(self, time_step: dm_env.TimeStep) -> np.ndarray:
        """The action for the tick that `time_step` begins. On a LAST step (no episode goes on)
        it is zeros, which the environment ignores: its next step begins the next episode."""
        observation, run = self.task.observation, self.task.run
        if observation is None or run is None or time_step.last():
            return np.zeros(2)
        if run is not self._run:  # a new episode
            self._run, self._planner = run, self._planner_for(run)
            self._governor = RunGovernor.offered(self._planner, run.scenario.planner_governor)
        assert self._planner is not None, "made for this episode above"
        decision = self._planner.step(observation)
        if self._governor is not None:  # as a run drives it (`vplane_mj.planning.RunGovernor`)
            self._governor.drive(decision, observation)
        return self._action(decision, observation, run)

    def reset(self) -> None:
        """Forget the episode's planner (dm_control.viewer calls this when it restarts)."""
        self._run = self._planner = self._governor = None

    def _planner_for(self, run: Run) -> Planner:
        """A fresh planner for the robot of the run's scenario."""
        scenario = run.scenario
        body = robot_body(scenario.robot.profile, scenario.sensors.kind)
        if self.planner is None:
            params = self.params if self.params is not None else scenario.planner_params
            return PLANNERS[scenario.planner].build(params, body)
        cls = PLANNERS[self.planner] if isinstance(self.planner, str) else self.planner
        return cls.build(self.params or {}, body)

    def _planner_name(self, run: Run) -> str:
        if self.planner is None:
            return run.scenario.planner
        return self.planner if isinstance(self.planner, str) else self.planner.name

    def _action(self, decision: Decision, observation: Observation, run: Run) -> np.ndarray:
        """The environment's action that drives the robot as `decision` would in a run."""
        if self.task.action == "force":
            if decision.command is not None:
                raise VPlaneError(
                    f"planner {self._planner_name(run)!r} commands a body speed and turn rate, "
                    "which a force cannot carry: make the environment with action='velocity'"
                )
            return np.array(decision.force, dtype=float)
        if decision.command is not None:
            return np.array(within_limits(decision.command, run.drive.limits))
        fx, fy = float(decision.force[0]), float(decision.force[1])
        if not (math.isfinite(fx) and math.isfinite(fy)):  # the run ends as `error`; so does the episode
            return np.full(2, np.nan)
        return np.array(heading_command(fx, fy, observation.yaw, run.drive.gains, run.drive.limits))
