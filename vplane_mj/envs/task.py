"""The navigation task that the reinforcement-learning environments share: Gymnasium's
(`vplane_mj.envs.gym_env`) and dm_env's (`vplane_mj.envs.dm_environment`).

An episode is one `vplane_mj.sim.loop.Run` of a scenario, or of a generated family's world, driven
one control tick per step by an action in place of the planner's decision. This module
decides everything the two environments have in common: the episode's world from its seed,
the action kinds and their meaning, the observation and its bounds, the reward, how the
run's ending maps to terminated or truncated, and the per-step info with the summary. It
imports neither Gymnasium nor dm_env; each environment only wraps it in its own API.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from vplane_mj.errors import VPlaneError
from vplane_mj.planning.protocol.body import DriveLimits
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.robots.facts import SONAR_MOUNT_RADIUS_M
from vplane_mj.robots.profiles import ControllerGains, robot_profile
from vplane_mj.scenario import MAX_ARENA_M, Scenario, load_scenario, parse_scenario
from vplane_mj.sim.loop import Run
from vplane_mj.sim.summary import Outcome
from vplane_mj.worlds.families import FAMILIES, Case, generate

if TYPE_CHECKING:
    import mujoco

ACTIONS = ("force", "velocity")
"""What an action is: a planner's force (world frame), or a body speed and turn rate."""
FORCE_BOUND = 1.0
"""Each force component of the action lies in [-FORCE_BOUND, FORCE_BOUND] (units of force):
a force of magnitude 1 along the heading already commands the top speed."""
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
    `success` when the goal is reached.

    Attributes:
        progress: Reward per metre the distance to the goal shrinks (1/m).
        collision: Penalty per new contact episode.
        time_per_s: Penalty per simulated second (1/s).
        success: Reward for reaching the goal.
    """

    progress: float = 1.0
    collision: float = 1.0
    time_per_s: float = 0.01
    success: float = 10.0


@dataclass(frozen=True)
class Bounds:
    """An observation entry or the action: its shape, dtype and element-wise limits."""

    shape: tuple[int, ...]
    dtype: type[np.generic]
    low: np.ndarray
    high: np.ndarray

    @classmethod
    def box(cls, shape: tuple[int, ...], dtype: type[np.generic], low: Any, high: Any) -> Bounds:
        """Bounds with `low` and `high` (scalars or arrays) broadcast to `shape` in `dtype`."""
        return cls(
            shape,
            dtype,
            np.broadcast_to(np.asarray(low, dtype), shape).copy(),
            np.broadcast_to(np.asarray(high, dtype), shape).copy(),
        )


@dataclass(frozen=True)
class TaskStep:
    """What one step of the task gives: the observation, the reward, the run's outcome once it
    is over (None while it goes on) and the info."""

    observation: dict[str, np.ndarray]
    reward: float
    outcome: Outcome | None
    info: dict[str, Any]

    @property
    def truncated(self) -> bool:
        """The episode was cut short by the time limit: the state it stopped in is no end state."""
        return self.outcome is Outcome.TIMEOUT

    @property
    def terminated(self) -> bool:
        """The episode reached an end state: the goal, `stuck` or `error`."""
        return self.outcome is not None and not self.truncated


class NavigationTask:
    """Episodes of driving the robot to the goal (the options as the environments take them).

    `scenario` (a Scenario, or a file or built-in scenario's name) is run in every episode;
    without it each episode is a world of `family` (traps, clutter, corridors or barn, as
    `vplane-mj generate` makes them). `overrides` are `--set` strings applied to every
    world. `action` is "force" or "velocity". `reward` weighs the terms of the reward. With
    `expose_observation` every info holds the planner's Observation of the tick under
    "observation" (None once the episode is over).
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
        first = self.episode_scenario(0)  # the overrides checked now; robot and ring are every episode's
        robot = robot_profile(first.robot.profile)
        self.gains: ControllerGains = robot.gains
        """The robot's controller gains, whose heading law a `velocity` action's force follows."""
        self.limits: DriveLimits = robot.limits
        """The robot's top speed (m/s) and turn rate (rad/s), which bound a `velocity` action."""
        sensors = first.sensors
        self.sonar_count = sensors.count
        self.reach_m = sensors.range_max + SONAR_MOUNT_RADIUS_M
        """A sonar's reach from the robot's centre (m): what `ranges` reads where there is no echo."""
        self.run: Run | None = None
        self._distance = 0.0
        self._collisions = 0
        self._observation: Observation | None = None

    @property
    def over(self) -> bool:
        """No episode goes on: none has begun, the last one has ended, or the task was closed."""
        return self._observation is None

    @property
    def observation(self) -> Observation | None:
        """What the scenario's planner would see on the tick that goes on (None when no episode
        goes on): the Observation a policy made of a planner decides on."""
        return self._observation

    @property
    def _episode_run(self) -> Run:
        """The run of the episode that goes on or has just ended (RuntimeError when no episode
        has begun since the task was made or closed)."""
        if self.run is None:
            raise RuntimeError("no episode has begun (or the task was closed): call reset")
        return self.run

    # -- the episode -------------------------------------------------------------------------
    def episode_scenario(self, episode_seed: int) -> Scenario:
        """The scenario of an episode, with the overrides and `run.seed` set to the episode's seed:
        the task's scenario, or world `episode_seed` of its family."""
        overrides = [*self.overrides, f"run.seed={episode_seed}"]
        if self.scenario is not None:
            return parse_scenario(self.scenario.to_toml(), self.scenario.source, overrides)
        case = family_case(self.family, episode_seed)
        return parse_scenario(case.toml(), case.name, overrides)

    def begin(
        self, scenario: Scenario, physics: tuple[mujoco.MjModel, mujoco.MjData] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode of `scenario` (one that `episode_scenario` made); its first observation
        and info. `physics`: the fresh model and data of its world to step (see `Run`), when
        another owner holds them (dm_control's Physics); by default the run builds its own."""
        self.run = Run(scenario, external=True, physics=physics)
        self._distance = self._true_distance()
        self._collisions = 0
        self._observation = self.run.observe()
        if self._observation is None:
            raise VPlaneError(f"{scenario.source}: the run is over before its first control tick")
        return self._agent_observation(), self._info()

    def advance(self, action: np.ndarray) -> TaskStep:
        """One control tick with `action` in place of the planner's decision."""
        observation = self._observation
        if observation is None:  # the task is `over`
            raise RuntimeError("step: the episode is over (or never began): call reset")
        run = self._episode_run
        decision, command = self._decision(np.asarray(action, dtype=float), observation.yaw)
        ending = run.apply(decision, command)
        self._observation = None if ending is not None else run.observe()
        reward = self._reward()
        info = self._info()
        outcome = None if run.ending is None else run.ending.outcome
        if outcome is not None:
            summary = run.summary()
            reward += self.reward_weights.success if outcome is Outcome.REACHED else 0.0
            info["summary"] = summary.to_dict()
            info["is_success"] = summary.success
        return TaskStep(self._agent_observation(), reward, outcome, info)

    def close(self) -> None:
        """Let go of the episode's run (a new episode can begin afterwards)."""
        self.run = None
        self._observation = None

    # -- the bounds of observations and actions ----------------------------------------------
    def observation_bounds(self) -> dict[str, Bounds]:
        """Each entry of the observation (see `_agent_observation`; units in docs/environments.md)."""
        count, speed_turn = self.sonar_count, np.array(VELOCITY_BOUND)
        return {
            "ranges": Bounds.box((count,), np.float32, 0.0, self.reach_m),
            "echo": Bounds.box((count,), np.int8, 0, 1),
            "goal": Bounds.box((2,), np.float32, -GOAL_BOUND_M, GOAL_BOUND_M),
            "velocity": Bounds.box((2,), np.float32, -speed_turn, speed_turn),
        }

    def action_bounds(self) -> Bounds:
        """A world-frame force, or a body speed (m/s) and turn rate (rad/s) within the robot's
        top ones (its profile's limits); float64, so that a planner's force passes unchanged."""
        if self.action == "force":
            return Bounds.box((2,), np.float64, -FORCE_BOUND, FORCE_BOUND)
        high = np.array([self.limits.max_speed_mps, self.limits.max_turn_rate_radps])
        return Bounds.box((2,), np.float64, -high, high)

    # -- from an action to a decision --------------------------------------------------------
    def _decision(self, action: np.ndarray, yaw: float) -> tuple[Decision, tuple[float, float] | None]:
        """The tick's decision, and the command that replaces the heading controller's, with the
        robot at `yaw` (rad) as the planner sees it."""
        if action.shape != (2,):
            raise ValueError(f"step: an action is 2 numbers, got shape {action.shape}")
        if self.action == "force":
            return Decision(force=action.copy(), mode=AGENT_MODE), None
        top_speed, top_turn = self.limits.max_speed_mps, self.limits.max_turn_rate_radps
        speed = float(np.clip(action[0], -top_speed, top_speed))
        turn = float(np.clip(action[1], -top_turn, top_turn))
        if not (math.isfinite(speed) and math.isfinite(turn)):
            return Decision(force=np.full(2, np.nan), mode=AGENT_MODE), None
        # The decision's force is one the heading controller would answer with this speed.
        force = np.array([math.cos(yaw), math.sin(yaw)]) * speed / self.gains.speed_gain
        return Decision(force=force, mode=AGENT_MODE), (speed, turn)

    # -- what the agent sees and earns -------------------------------------------------------
    def _agent_observation(self) -> dict[str, np.ndarray]:
        """Sonar ranges and echoes, the goal in the robot frame and the body velocity.

        Within an episode the pose is the planner's (truth, odometry or an EKF's, as `sensors.pose`
        says); once the run is over, the simulator's.
        """
        run = self._episode_run
        if self._observation is not None:
            position, yaw = self._observation.position, self._observation.yaw
        else:
            position, yaw = run.position, run.drive.yaw()
        echo = np.isfinite(run.ranges)
        ranges = np.clip(np.where(echo, run.ranges, self.reach_m), 0.0, self.reach_m)
        dx, dy = run.goal[0] - position[0], run.goal[1] - position[1]
        goal = (math.cos(yaw) * dx + math.sin(yaw) * dy, -math.sin(yaw) * dx + math.cos(yaw) * dy)
        high = np.array(VELOCITY_BOUND)
        return {
            "ranges": ranges.astype(np.float32),
            "echo": echo.astype(np.int8),
            "goal": np.clip(goal, -GOAL_BOUND_M, GOAL_BOUND_M).astype(np.float32),
            "velocity": np.clip(run.drive.body_velocity(), -high, high).astype(np.float32),
        }

    def _reward(self) -> float:
        """Progress toward the goal, less new collisions and the time of the tick (no success bonus)."""
        run, weights = self._episode_run, self.reward_weights
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
        run = self._episode_run
        position, goal = run.position, run.goal
        return math.hypot(goal[0] - position[0], goal[1] - position[1])

    def _info(self) -> dict[str, Any]:
        run = self._episode_run
        info: dict[str, Any] = {
            "time_s": float(run.data.time),
            "distance_to_goal_m": self._distance,
            "collisions": self._collisions,
        }
        if self.expose_observation:
            info["observation"] = self._observation
        return info


def family_case(family: str, seed: int) -> Case:
    """World `seed` of a family: the first case `vplane-mj generate FAMILY --seed SEED` writes."""
    return generate(family, 1, seed)[0]
