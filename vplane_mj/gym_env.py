"""The navigation task as a Gymnasium environment (the `[gym]` extra): the same robot, sonar ring,
worlds and faults as `vplane-mj run`, driven by a policy instead of a planner.

One `step` is one control tick of `vplane_mj.sim.Run`: the action takes the place of the
planner's decision, then the run senses again. Importing this module registers the
environment as ENV_ID, so `gymnasium.make("vplane_mj/Navigation-v0")` builds it. The spaces,
the reward and the ending of an episode are those of the README's "Gymnasium environment".
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError as exc:  # the optional extra
    raise ImportError("vplane_mj.gym_env needs Gymnasium: pip install 'vplane-mj[gym]'") from exc

from vplane_mj.control import ControllerGains
from vplane_mj.errors import VPlaneError
from vplane_mj.families import FAMILIES, generate
from vplane_mj.planning.types import Decision, Observation
from vplane_mj.reference import shortest_path_length
from vplane_mj.robot import robot_radius_m
from vplane_mj.scenario import MAX_ARENA_M, Scenario, load_scenario, parse_scenario
from vplane_mj.sim import Run
from vplane_mj.sonar import SONAR_MOUNT_RADIUS_M
from vplane_mj.summary import Outcome

ENV_ID = "vplane_mj/Navigation-v0"
ACTIONS = ("force", "velocity")
"""What an action is: a planner's force (world frame), or a body speed and turn rate."""
FORCE_BOUND = 1.0
"""Each force component of the action space lies in [-FORCE_BOUND, FORCE_BOUND] (units of
force): a force of magnitude 1 along the heading already commands the top speed."""
GOAL_BOUND_M = 2 * MAX_ARENA_M
"""The goal's coordinates in the robot frame are clipped to +-GOAL_BOUND_M (m)."""
VELOCITY_BOUND = (2.0, 10.0)
"""The observed speed (m/s) and turn rate (rad/s) are clipped to +- these."""
AGENT_MODE = "agent"
"""The planner mode that the run records for a tick driven by the environment's action."""


@dataclass(frozen=True)
class Reward:
    """The reward of one step: `progress` per metre that the distance to the goal shrinks,
    minus `collision` per new contact episode, minus `time_per_s` per simulated second, plus
    `success` when the goal is reached."""

    progress: float = 1.0
    collision: float = 1.0
    time_per_s: float = 0.01
    success: float = 10.0


class VPlaneNavEnv(gymnasium.Env):
    """Drive the robot to the goal through a world of a family, or through one scenario.

    `scenario` (a Scenario, or a file or built-in scenario's name) is run in every episode;
    without it each `reset` draws a world of `family` (traps, clutter, corridors or barn, as
    `vplane-mj generate` makes them). `overrides` are `--set` strings applied to every
    world (faults, sensor noise, the time limit). `action` is "force" or "velocity".
    `reward` weighs the terms of the reward. With `expose_observation` every `info` holds
    the planner's Observation of the tick under "observation" (None once the episode is over).
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
        if action not in ACTIONS:
            raise VPlaneError(f"action: must be one of {', '.join(ACTIONS)}, got {action!r}")
        if scenario is None and family not in FAMILIES:
            raise VPlaneError(f"family: must be one of {', '.join(sorted(FAMILIES))}, got {family!r}")
        if scenario is not None and not isinstance(scenario, Scenario):
            scenario = load_scenario(os.fspath(scenario))
        self.scenario = scenario
        self.family = family
        self.overrides = tuple(overrides)
        self.action = action
        self.reward_weights = reward or Reward()
        self.expose_observation = expose_observation
        self.gains = ControllerGains()
        sensors = self._scenario(0).sensors  # the overrides checked now; the ring is every episode's
        self.reach_m = sensors.range_max + SONAR_MOUNT_RADIUS_M
        self.observation_space = _observation_space(sensors.count, self.reach_m)
        self.action_space = _action_space(action, self.gains)
        self.run: Run | None = None
        self._distance = 0.0
        self._collisions = 0
        self._observation: Observation | None = None

    # -- the Gymnasium API -------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode. `seed` (when given, else drawn from the environment's generator)
        picks the family's world, as `vplane-mj generate FAMILY --count 1 --seed SEED` does,
        and is the run's `run.seed` (sensor noise and faults), as `vplane-mj run --seed SEED`."""
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(2**31))
        scenario = self._scenario(episode_seed)
        self.run = Run(scenario, external=True)
        self._distance = self._true_distance()
        self._collisions = 0
        self._observation = self.run.observe()
        if self._observation is None:
            raise VPlaneError(f"{scenario.source}: the run is over before its first control tick")
        return self._gym_observation(), self._info()

    def step(self, action: np.ndarray) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """One control tick with `action` in place of the planner's decision."""
        run = self.run
        if run is None or self._observation is None:
            raise RuntimeError("step: the episode is over (or never began): call reset")
        decision, command = self._decision(np.asarray(action, dtype=float))
        ending = run.apply(decision, command)
        self._observation = None if ending is not None else run.observe()
        reward = self._reward()
        info = self._info()
        terminated = truncated = False
        if run.ending is not None:
            summary = run.summary()
            reached = run.ending.outcome is Outcome.REACHED
            reward += self.reward_weights.success if reached else 0.0
            truncated = run.ending.outcome is Outcome.TIMEOUT
            terminated = not truncated
            info["summary"] = summary.to_dict()
            info["is_success"] = summary.success
        return self._gym_observation(), reward, terminated, truncated, info

    # -- an episode's world ------------------------------------------------------------------
    def _scenario(self, episode_seed: int) -> Scenario:
        """The scenario of an episode, with the overrides and `run.seed` set to the episode's seed."""
        overrides = [*self.overrides, f"run.seed={episode_seed}"]
        if self.scenario is not None:
            return parse_scenario(self.scenario.to_toml(), self.scenario.source, overrides)
        case = _family_case(self.family, episode_seed)
        return parse_scenario(case.toml(), case.name, overrides)

    # -- from an action to a decision --------------------------------------------------------
    def _decision(self, action: np.ndarray) -> tuple[Decision, tuple[float, float] | None]:
        """The tick's decision, and the command that replaces the heading controller's."""
        if action.shape != (2,):
            raise ValueError(f"step: an action is 2 numbers, got shape {action.shape}")
        if self.action == "force":
            return Decision(force=action.copy(), mode=AGENT_MODE), None
        gains, yaw = self.gains, self._observation.yaw
        speed = float(np.clip(action[0], -gains.max_speed, gains.max_speed))
        turn = float(np.clip(action[1], -gains.max_turn_rate, gains.max_turn_rate))
        if not (math.isfinite(speed) and math.isfinite(turn)):
            return Decision(force=np.full(2, np.nan), mode=AGENT_MODE), None
        # The decision's force is one the heading controller would answer with this speed.
        force = np.array([math.cos(yaw), math.sin(yaw)]) * speed / gains.speed_gain
        return Decision(force=force, mode=AGENT_MODE), (speed, turn)

    # -- what the agent sees and earns -------------------------------------------------------
    def _gym_observation(self) -> dict[str, np.ndarray]:
        """Sonar ranges and echoes, the goal in the robot frame and the body velocity.

        Within an episode the pose is the planner's (truth or odometry, as `sensors.pose`
        says); once the run is over, the simulator's.
        """
        run = self.run
        if self._observation is not None:
            position, yaw = self._observation.position, self._observation.yaw
        else:
            position, yaw = run.position, run.drive.yaw()
        echo = np.isfinite(run.ranges)
        ranges = np.clip(np.where(echo, run.ranges, self.reach_m), 0.0, self.reach_m)
        dx, dy = run.goal[0] - position[0], run.goal[1] - position[1]
        goal = (math.cos(yaw) * dx + math.sin(yaw) * dy, -math.sin(yaw) * dx + math.cos(yaw) * dy)
        return {
            "ranges": ranges.astype(np.float32),
            "echo": echo.astype(np.int8),
            "goal": np.clip(goal, -GOAL_BOUND_M, GOAL_BOUND_M).astype(np.float32),
            "velocity": np.clip(run.drive.body_velocity(), *_velocity_bounds()).astype(np.float32),
        }

    def _reward(self) -> float:
        """Progress toward the goal, less new collisions and the time of the tick (no success bonus)."""
        run, weights = self.run, self.reward_weights
        distance = self._true_distance()
        collisions = len(run.collisions.points)
        reward = (
            weights.progress * (self._distance - distance)
            - weights.collision * (collisions - self._collisions)
            - weights.time_per_s / run.scenario.run.control_hz
        )
        self._distance, self._collisions = distance, collisions
        return float(reward)

    def _true_distance(self) -> float:
        position, goal = self.run.position, self.run.goal
        return math.hypot(goal[0] - position[0], goal[1] - position[1])

    def _info(self) -> dict[str, Any]:
        run = self.run
        info: dict[str, Any] = {
            "time_s": float(run.data.time),
            "distance_to_goal_m": self._distance,
            "collisions": self._collisions,
        }
        if self.expose_observation:
            info["observation"] = self._observation
        return info


def _family_case(family: str, seed: int):
    """World `seed` of a family: the first case `vplane-mj generate FAMILY --seed SEED` writes."""
    radius = robot_radius_m()

    def has_path(scenario: Scenario, clearance_m: float) -> bool:
        return shortest_path_length(scenario, radius, clearance_m) is not None

    return generate(family, 1, seed, has_path)[0]


def _velocity_bounds() -> tuple[np.ndarray, np.ndarray]:
    high = np.array(VELOCITY_BOUND)
    return -high, high


def _observation_space(count: int, reach_m: float) -> spaces.Dict:
    """The observation: see `VPlaneNavEnv._gym_observation` and the README."""
    low, high = _velocity_bounds()
    return spaces.Dict(
        {
            "ranges": spaces.Box(0.0, reach_m, (count,), np.float32),
            "echo": spaces.MultiBinary(count),
            "goal": spaces.Box(-GOAL_BOUND_M, GOAL_BOUND_M, (2,), np.float32),
            "velocity": spaces.Box(low.astype(np.float32), high.astype(np.float32), (2,), np.float32),
        }
    )


def _action_space(action: str, gains: ControllerGains) -> spaces.Box:
    """A world-frame force, or a body speed (m/s) and turn rate (rad/s) within the controller's
    limits; float64, so that a planner's force passes unchanged."""
    if action == "force":
        return spaces.Box(-FORCE_BOUND, FORCE_BOUND, (2,), np.float64)
    high = np.array([gains.max_speed, gains.max_turn_rate])
    return spaces.Box(-high, high, (2,), np.float64)


if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="vplane_mj.gym_env:VPlaneNavEnv")
