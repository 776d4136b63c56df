"""The navigation task as a Gymnasium environment (the `[gym]` extra): the same robot, sonar ring,
worlds and faults as `vplane-mj run`, driven by a policy instead of a planner.

One `step` is one control tick of `vplane_mj.sim.loop.Run`: the action takes the place of the
planner's decision, then the run senses again (`vplane_mj.envs.task`, which the dm_env
environment shares). Importing this module registers the environment as ENV_ID, so
`gymnasium.make("vplane_mj/Navigation-v0")` builds it. The spaces, the reward and the ending
of an episode are those of docs/environments.md.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError as exc:  # the optional extra
    raise ImportError(
        "vplane_mj.envs.gym_env needs Gymnasium: pip install gymnasium "
        '(or, in a clone of vplane-mj, pip install -e ".[gym]")'
    ) from exc

from vplane_mj.envs.task import Bounds, NavigationTask, Reward
from vplane_mj.scenario import Scenario

ENV_ID = "vplane_mj/Navigation-v0"


class VPlaneNavEnv(gymnasium.Env):
    """Drive the robot to the goal through a world of a family, or through one scenario.

    `task` is the NavigationTask behind the environment (its `run` is the episode's Run).
    """

    def __init__(
        self,
        scenario: Scenario | str | os.PathLike[str] | None = None,
        family: str = "traps",
        overrides: Sequence[str] = (),
        action: str = "force",
        reward: Reward | None = None,
        expose_observation: bool = False,
    ):
        """Build the task and its spaces; the first episode begins with `reset`.

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

        Raises:
            VPlaneError: An invalid scenario, family, override or action.
        """
        self.task = NavigationTask(scenario, family, overrides, action, reward, expose_observation)
        self.observation_space = spaces.Dict(
            {name: _space(name, bounds) for name, bounds in self.task.observation_bounds().items()}
        )
        self.action_space = _space("action", self.task.action_bounds())

    @property
    def reach_m(self) -> float:
        """A sonar's reach from the robot's centre (m): what `ranges` reads where there is no echo."""
        return self.task.reach_m

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode. `seed` (when given, else drawn from the environment's generator)
        picks the family's world, as `vplane-mj generate FAMILY --count 1 --seed SEED` does,
        and is the run's `run.seed` (sensor noise and faults), as `vplane-mj run --seed SEED`."""
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(2**31))
        return self.task.begin(self.task.episode_scenario(episode_seed))

    def step(self, action: np.ndarray) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """One control tick with `action` in place of the planner's decision."""
        step = self.task.advance(action)
        return step.observation, step.reward, step.terminated, step.truncated, step.info

    def close(self) -> None:
        self.task.close()


def _space(name: str, bounds: Bounds) -> spaces.Space:
    """The Gymnasium space of an observation entry (`echo` is 0/1 per sonar) or of the action."""
    if name == "echo":
        return spaces.MultiBinary(bounds.shape[0])
    return spaces.Box(bounds.low, bounds.high, bounds.shape, bounds.dtype)


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="vplane_mj.envs.gym_env:VPlaneNavEnv")
