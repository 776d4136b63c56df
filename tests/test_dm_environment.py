"""The dm_env environment (docs/environments.md): dm_env's own contract checks, the specs,
determinism and its seeds, the step types and discounts of every ending, and the same trajectory
as `vplane-mj run` under the planner's own decisions."""

import json
import unittest

import dm_env
import numpy as np
import pytest
from dm_env import test_utils

from vplane_mj import ScenarioError, VPlaneError
from vplane_mj.cli import main
from vplane_mj.envs.dm_environment import VPlaneNavDmEnv
from vplane_mj.envs.gym_env import VPlaneNavEnv
from vplane_mj.sim.summary import without_timing


class ForceActionsContract(test_utils.EnvironmentTestMixin, unittest.TestCase):
    """dm_env's checks with force actions; 1.5 s episodes (30 steps), so that the 40 actions of
    the longer sequence cross a LAST step into the next episode's FIRST."""

    def make_object_under_test(self):
        return VPlaneNavDmEnv("single_box", overrides=["run.time_limit_s=1.5"])

    def make_action_sequence(self):
        rng = np.random.default_rng(0)
        for _ in range(40):
            yield rng.uniform(-1.0, 1.0, 2)

    def test_the_longer_sequence_crosses_an_episode_end(self):
        steps = [self.environment.reset()]
        steps += [self.environment.step(action) for action in self.make_action_sequence()]
        kinds = [step.step_type for step in steps]
        assert kinds[30:32] == [dm_env.StepType.LAST, dm_env.StepType.FIRST]
        assert kinds.count(dm_env.StepType.FIRST) == 2 and self.environment.episode_seed == 1


class VelocityActionsContract(test_utils.EnvironmentTestMixin, unittest.TestCase):
    """dm_env's checks with (v, omega) actions on generated corridors."""

    def make_object_under_test(self):
        return VPlaneNavDmEnv(family="corridors", action="velocity", overrides=["run.time_limit_s=1"], seed=4)

    def make_action_sequence(self):
        for _ in range(25):
            yield np.array([0.5, 1.0])


def test_the_specs_name_each_entry_with_its_bounds():
    env = VPlaneNavDmEnv("single_box", overrides=["sensors.count=8", "sensors.range_max=2.5"])
    spec = env.observation_spec()
    assert sorted(spec) == ["echo", "goal", "ranges", "velocity"]
    assert all(spec[name].name == name for name in spec)
    ranges, echo = spec["ranges"], spec["echo"]
    assert (ranges.shape, ranges.dtype, echo.shape, echo.dtype) == ((8,), np.float32, (8,), np.int8)
    assert np.allclose(ranges.maximum, 2.6) and np.all(ranges.minimum == 0) and np.all(echo.maximum == 1)
    assert np.array_equal(spec["goal"].maximum, [300.0, 300.0])
    assert np.array_equal(spec["velocity"].maximum, [2.0, 10.0])
    force = env.action_spec()
    assert (force.name, force.shape, force.dtype) == ("force", (2,), np.float64)
    assert np.array_equal(force.minimum, [-1.0, -1.0]) and np.array_equal(force.maximum, [1.0, 1.0])
    velocity = VPlaneNavDmEnv("single_box", action="velocity").action_spec()
    assert velocity.name == "velocity" and np.array_equal(velocity.maximum, [0.5, 2.5])
    assert env.reward_spec() == dm_env.specs.Array((), np.float64, name="reward")
    assert env.discount_spec().minimum == 0.0 and env.discount_spec().maximum == 1.0


def drive(env, actions):
    """Reset, then step through `actions` (past episode ends): the TimeSteps and, for each
    LAST step, the summary."""
    steps, summaries = [env.reset()], []
    for action in actions:
        steps.append(env.step(action))
        if steps[-1].last():
            summaries.append(without_timing(env.info["summary"]))
    return steps, summaries


def same_time_steps(first, second):
    assert len(first) == len(second)
    for a, b in zip(first, second, strict=True):
        assert (a.step_type, a.reward, a.discount) == (b.step_type, b.reward, b.discount)
        assert all(np.array_equal(a.observation[key], b.observation[key]) for key in a.observation)


OVERRIDES = ["run.time_limit_s=3", "sensors.noise_std=0.02", "sensors.dropout=0.1"]


def test_episodes_are_deterministic_and_episode_k_has_the_seed_plus_k():
    rng = np.random.default_rng(5)
    actions = rng.uniform(-1.0, 1.0, (130, 2))  # two 3 s episodes of 60 steps, and a third begun
    first, first_summaries = drive(VPlaneNavDmEnv(family="clutter", overrides=OVERRIDES, seed=11), actions)
    again, again_summaries = drive(VPlaneNavDmEnv(family="clutter", overrides=OVERRIDES, seed=11), actions)
    same_time_steps(first, again)
    assert first_summaries == again_summaries and len(first_summaries) == 2
    assert [summary["seed"] for summary in first_summaries] == [11, 12]
    assert [step.step_type for step in first].count(dm_env.StepType.FIRST) == 3

    # Episode 1 (seed 12) is Gymnasium's reset(seed=12) under the same actions; its first
    # action is the one the LAST step of episode 0 ignored.
    gym = VPlaneNavEnv(family="clutter", overrides=OVERRIDES)
    observation, _ = gym.reset(seed=12)
    second_episode = first[61:122]
    assert second_episode[0].first() and second_episode[-1].last()
    assert all(np.array_equal(observation[key], second_episode[0].observation[key]) for key in observation)
    for action, step in zip(actions[61:121], second_episode[1:], strict=True):
        observation, reward, terminated, truncated, info = gym.step(action)
        assert all(np.array_equal(observation[key], step.observation[key]) for key in observation)
        assert reward == step.reward and truncated == step.last() and not terminated
    assert without_timing(info["summary"]) == first_summaries[1]

    other, _ = drive(VPlaneNavDmEnv(family="clutter", overrides=OVERRIDES, seed=13), actions[:1])
    assert not np.array_equal(other[0].observation["ranges"], first[0].observation["ranges"])


def test_the_planners_own_decisions_drive_the_trajectory_of_vplane_mj_run(vplane_run):
    name, seed, overrides, expected, planner = vplane_run
    env = VPlaneNavDmEnv(name, overrides=overrides, expose_observation=True, seed=seed)
    time_step = env.reset()
    while not time_step.last():
        time_step = env.step(planner.step(env.info["observation"]).force)
        assert time_step.discount == 1.0 or time_step.last()
    summary = env.info["summary"]
    assert summary["trajectory_sha256"] == expected["trajectory_sha256"]
    assert (summary["steps"], summary["outcome"]) == (expected["steps"], expected["outcome"])
    assert summary["outcome"] == "reached" and time_step.discount == 0.0  # termination
    assert summary["planner"] == "external" and expected["planner"] == "vplane"


def test_reaching_the_goal_is_a_last_step_with_discount_0_and_the_success_bonus(steer_to_goal):
    env = VPlaneNavDmEnv("open_field", action="velocity")
    time_step = env.reset()
    assert time_step.first() and time_step.reward is None and time_step.discount is None
    start_distance, rewards = env.info["distance_to_goal_m"], []
    while True:
        time_step = env.step(steer_to_goal(time_step.observation))
        rewards.append(time_step.reward)
        if time_step.last():
            break
        assert time_step.mid() and time_step.discount == 1.0
    summary = env.info["summary"]
    assert summary["outcome"] == "reached" and env.info["is_success"] and time_step.discount == 0.0
    assert rewards[-1] > 9.0  # the success bonus (10) on the LAST step
    progress = start_distance - env.info["distance_to_goal_m"]
    assert sum(rewards) == pytest.approx(progress + 10.0 - 0.01 * summary["sim_time_s"], abs=1e-9)


def test_the_time_limit_is_a_last_step_with_discount_1_and_the_next_step_begins_the_next_episode(
    walled_off,
):
    env = VPlaneNavDmEnv(walled_off, action="velocity", seed=7)
    steps = [env.reset()]
    while not steps[-1].last():
        steps.append(env.step(np.array([0.3, 0.0])))
    assert len(steps) == 161 and all(step.mid() for step in steps[1:-1])  # 8 s at 20 Hz
    assert steps[-1].discount == 1.0 and env.info["summary"]["outcome"] == "timeout"
    assert env.info["summary"]["collisions"] >= 1 and min(step.reward for step in steps[1:]) < -0.9
    assert env.info["summary"]["seed"] == env.episode_seed == 7
    following = env.step(np.array([np.nan, np.nan]))  # ignored: it begins episode 1
    assert following.first() and env.episode_seed == 8 and env.info["time_s"] == 0.0
    assert all(np.array_equal(following.observation[k], steps[0].observation[k]) for k in ("goal", "echo"))


def test_a_non_finite_action_ends_the_episode_as_an_error_with_discount_0():
    env = VPlaneNavDmEnv("single_box")
    assert env.step(np.zeros(2)).first()  # a new environment: the first step begins an episode
    time_step = env.step(np.array([np.nan, 0.0]))
    assert time_step.last() and time_step.discount == 0.0 and env.info["summary"]["outcome"] == "error"
    env.close()
    assert env.task.run is None and env.step(np.zeros(2)).first()


def test_bad_options_are_clear_errors():
    with pytest.raises(
        VPlaneError, match="family: must be one of barn, clutter, corridors, traps, got 'nope'"
    ):
        VPlaneNavDmEnv(family="nope")
    with pytest.raises(VPlaneError, match="action: must be one of force, velocity, got 'torque'"):
        VPlaneNavDmEnv("single_box", action="torque")
    with pytest.raises(ScenarioError, match=r"sensors\.dropout: must be less than 1, got 2"):
        VPlaneNavDmEnv("single_box", overrides=["sensors.dropout=2"])
    env = VPlaneNavDmEnv("single_box")
    env.reset()
    with pytest.raises(ValueError, match="an action is 2 numbers, got shape"):
        env.step(np.zeros(3))


@pytest.mark.slow
def test_the_documented_examples_run(tmp_path, monkeypatch, doc_examples, capsys):
    monkeypatch.chdir(tmp_path)
    exec(compile(doc_examples("environments.md", "dm_env"), "docs/environments.md", "exec"), {})
    printed_digest = capsys.readouterr().out.splitlines()[-1]
    main(["run", "paper_c_escape", "--seed", "0", "--no-log", "--no-render", "--out", str(tmp_path)])
    summary = json.loads((tmp_path / "paper_c_escape-vplane-0.json").read_text())
    assert printed_digest == summary["trajectory_sha256"]
