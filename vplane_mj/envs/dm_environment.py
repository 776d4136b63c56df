"""The navigation task as a `dm_env.Environment`, the interface of DeepMind's control suite: the
same robot, sonar ring, worlds, faults, observation, actions, reward and endings as the
Gymnasium environment (both wrap `vplane_mj.envs.task`).

One `step` is one control tick of `vplane_mj.sim.loop.Run`. The first TimeStep of an episode is
FIRST (no reward, no discount), the last is LAST: discount 0 when the run ends in a state of
its own (reached, stuck, error), 1 when the time limit cuts it short (dm_env's truncation).
dm_env's `reset` takes no seed: episode k of an environment built with `seed` has the seed
`seed + k`. The specs, the reward and the endings are those of docs/environments.md.

`physics` is dm_control's Physics of the episode (`vplane_mj.envs.physics`): the run steps its
model and data, so dm_control's tools see the state the run is in: the suite's wrappers
(`dm_control.suite.wrappers.pixels` renders it as an observation) and `dm_control.viewer`.
docs/environments.md shows them.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import dm_env
import numpy as np
from dm_env import specs

from vplane_mj.envs.physics import NavigationPhysics, episode_physics
from vplane_mj.envs.task import Bounds, NavigationTask, Reward
from vplane_mj.scenario import Scenario


class VPlaneNavDmEnv(dm_env.Environment):
    """Drive the robot to the goal through a world of a family, or through one scenario.

    The options are those of `vplane_mj.envs.gym_env.VPlaneNavEnv`, and `seed`. `info` is the
    latest TimeStep's info (the keys of the Gymnasium environment's `info`); `task` is the
    NavigationTask behind the environment (its `run` is the episode's Run).

    `physics` (dm_control's Physics) is made with the episode's world before the episode
    begins, so that it can be rendered at once (dm_control's pixel wrapper does, when it is
    made); `close` frees it, and with it the rendering contexts it made.
    """

    def __init__(
        self,
        scenario: Scenario | str | os.PathLike[str] | None = None,
        family: str = "traps",
        overrides: Sequence[str] = (),
        action: str = "force",
        reward: Reward | None = None,
        expose_observation: bool = False,
        seed: int = 0,
    ):
        """Build the task and its specs; the first episode begins with `reset` or `step`.

        Args:
            scenario: The scenario run in every episode (a Scenario, or the path or built-in
                name of a scenario file); None: each `reset` draws a world of `family`.
            family: The world family drawn from without a scenario: "traps", "clutter",
                "corridors" or "barn", as `vplane-mj generate` makes them.
            overrides: `--set KEY=VALUE` strings applied to every world (faults, sensor
                noise, the time limit).
            action: "force": a force (world frame) as a planner's decision; "velocity": the
                body speed (m/s) and turn rate (rad/s).
            reward: The weights of the reward's terms; None: the defaults.
            expose_observation: Put the planner's Observation of each tick in `info` under
                "observation" (None once the episode is over).
            seed: Episode k (counting from 0 every episode this environment begins, by
                `reset` or by a `step` after a LAST step) is world `seed + k` of the family,
                with `run.seed = seed + k`.

        Raises:
            VPlaneError: An invalid scenario, family, override or action.
        """
        self.task = NavigationTask(scenario, family, overrides, action, reward, expose_observation)
        self.seed = seed
        self.episodes = 0
        """How many episodes this environment has begun."""
        self.info: dict[str, Any] = {}
        self._observation_spec = {
            name: _spec(name, bounds) for name, bounds in self.task.observation_bounds().items()
        }
        self._action_spec = _spec(action, self.task.action_bounds())
        self._physics: NavigationPhysics | None = None
        self._waiting: Scenario | None = None
        """The scenario of `_physics` while its episode has not begun yet."""

    @property
    def episode_seed(self) -> int | None:
        """The seed of the latest episode begun (None before the first)."""
        return self.seed + self.episodes - 1 if self.episodes else None

    @property
    def physics(self) -> NavigationPhysics:
        """dm_control's Physics of the latest episode begun, which goes on or has ended (its run
        steps the Physics' model and data); before the first episode and after `close`, that of
        the episode that begins next. A new one each episode."""
        if self._physics is None:
            self._prepare_next_episode()
        assert self._physics is not None, "prepared above"
        return self._physics

    def reset(self) -> dm_env.TimeStep:
        """Begin the next episode (seed `seed + episodes`); its FIRST TimeStep."""
        if self._waiting is None:
            self._prepare_next_episode()
        physics, scenario = self.physics, self._waiting
        assert scenario is not None, "prepared above"
        self._waiting = None
        observation, self.info = self.task.begin(scenario, (physics.model.ptr, physics.data.ptr))
        self.episodes += 1
        return dm_env.restart(observation)

    def _prepare_next_episode(self) -> None:
        """Make the Physics of the episode that begins next (the one before it freed)."""
        scenario = self.task.episode_scenario(self.seed + self.episodes)
        self._free_physics()
        self._physics, self._waiting = episode_physics(scenario), scenario

    def step(self, action: np.ndarray) -> dm_env.TimeStep:
        """One control tick with `action` in place of the planner's decision: a MID TimeStep, or
        the LAST one when the run ends. With no episode going on (a new environment, or after a
        LAST step), the next episode begins instead and the action is ignored (dm_env's rule)."""
        if self.task.over:
            return self.reset()
        step = self.task.advance(action)
        self.info = step.info
        if step.outcome is None:
            return dm_env.transition(step.reward, step.observation)
        if step.truncated:
            return dm_env.truncation(step.reward, step.observation)
        return dm_env.termination(step.reward, step.observation)

    def observation_spec(self) -> dict[str, specs.BoundedArray]:
        """`ranges` (count,) float32 m, `echo` (count,) int8 0/1, `goal` (2,) float32 m in the
        robot frame, `velocity` (2,) float32 m/s and rad/s: see docs/environments.md."""
        return self._observation_spec

    def action_spec(self) -> specs.BoundedArray:
        """(2,) float64, named after the action kind: `force` (world frame, units of force,
        [-1, 1] each) or `velocity` (v m/s, omega rad/s, within the robot's limits)."""
        return self._action_spec

    def reward_spec(self) -> specs.Array:
        """A float64 scalar: the reward of docs/environments.md (progress in m, collisions, time, success)."""
        return specs.Array((), np.float64, name="reward")

    def close(self) -> None:
        """Let go of the episode's run and free its Physics; a later `reset` or `step` begins the
        next episode (and `physics` makes that episode's)."""
        self.task.close()
        self._free_physics()

    def _free_physics(self) -> None:
        if self._physics is not None:
            self._physics.free()
        self._physics = self._waiting = None


def _spec(name: str, bounds: Bounds) -> specs.BoundedArray:
    """The dm_env spec of an observation entry or of the action, named `name`."""
    return specs.BoundedArray(bounds.shape, bounds.dtype, bounds.low, bounds.high, name=name)
