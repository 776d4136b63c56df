"""The Gymnasium environment (docs/environments.md): Gymnasium's checks, determinism,
the reward and endings, and the same trajectory as `vplane-mj run` under the planner's own decisions."""

import json
import math

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from vplane_mj import ScenarioError, VPlaneError
from vplane_mj.cli import main
from vplane_mj.envs.gym_env import ENV_ID, VPlaneNavEnv
from vplane_mj.sim.summary import without_timing


def episode(env, actions, seed):
    """Reset with `seed`, then step through `actions` until the episode ends: every step's
    (observation, reward, terminated, truncated, info)."""
    observation, info = env.reset(seed=seed)
    steps = [(observation, 0.0, False, False, info)]
    for action in actions:
        steps.append(env.step(action))
        if steps[-1][2] or steps[-1][3]:
            break
    return steps


@pytest.mark.slow
def test_gymnasium_checks_pass_for_both_kinds_of_action():
    made = gymnasium.make(ENV_ID, scenario="single_box")
    check_env(made.unwrapped)
    check_env(gymnasium.make(ENV_ID, family="corridors", action="velocity").unwrapped)


def test_an_episode_is_the_same_for_the_same_seed_and_actions():
    overrides = ["run.time_limit_s=6", "sensors.noise_std=0.02", "sensors.dropout=0.1"]
    space = VPlaneNavEnv(family="clutter").action_space
    space.seed(5)
    actions = [space.sample() for _ in range(200)]
    first, again = (
        episode(VPlaneNavEnv(family="clutter", overrides=overrides), actions, 11) for _ in range(2)
    )
    assert len(first) == len(again) == 121  # 6 s at 20 Hz, and the reset
    for (obs_a, reward_a, *end_a, _), (obs_b, reward_b, *end_b, _) in zip(first, again, strict=True):
        assert all(np.array_equal(obs_a[key], obs_b[key]) for key in obs_a)
        assert (reward_a, end_a) == (reward_b, end_b)
    assert first[-1][3] and without_timing(first[-1][4]["summary"]) == without_timing(again[-1][4]["summary"])
    other = episode(VPlaneNavEnv(family="clutter", overrides=overrides), actions[:1], 12)
    assert not np.array_equal(other[0][0]["ranges"], first[0][0]["ranges"])  # another world


def test_the_planners_own_decisions_drive_the_trajectory_of_vplane_mj_run(vplane_run):
    name, seed, overrides, expected, planner = vplane_run
    env = VPlaneNavEnv(name, overrides=overrides, expose_observation=True)
    _, info = env.reset(seed=seed)
    while True:
        _, _, terminated, truncated, info = env.step(planner.step(info["observation"]).force)
        if terminated or truncated:
            break
    assert info["summary"]["trajectory_sha256"] == expected["trajectory_sha256"]
    assert (info["summary"]["steps"], info["summary"]["outcome"]) == (expected["steps"], expected["outcome"])
    assert info["summary"]["planner"] == "external" and expected["planner"] == "vplane"


def test_velocity_actions_reach_the_goal_and_the_rewards_add_up(steer_to_goal):
    env = VPlaneNavEnv("open_field", action="velocity")
    observation, info = env.reset(seed=0)
    assert observation["goal"] == pytest.approx([math.dist((1, 1), (5, 5)), 0.0], abs=1e-5)
    assert np.array_equal(observation["echo"] == 1, observation["ranges"] < env.reach_m)
    start_distance, rewards = info["distance_to_goal_m"], []
    while True:
        observation, reward, terminated, truncated, info = env.step(steer_to_goal(observation))
        rewards.append(reward)
        if terminated or truncated:
            break
    summary = info["summary"]
    assert terminated and not truncated and info["is_success"] and summary["outcome"] == "reached"
    assert info["distance_to_goal_m"] <= 0.15 and summary["sim_time_s"] < 14.0
    progress = start_distance - info["distance_to_goal_m"]
    assert sum(rewards) == pytest.approx(progress + 10.0 - 0.01 * summary["sim_time_s"], abs=1e-9)


def test_collisions_cost_and_the_time_limit_truncates(walled_off):
    env = VPlaneNavEnv(walled_off, action="velocity")
    steps = episode(env, [np.array([0.3, 0.0])] * 1000, seed=0)
    collided = [i for i in range(1, len(steps)) if steps[i][4]["collisions"] > steps[i - 1][4]["collisions"]]
    assert collided and all(steps[i][1] < -0.9 for i in collided)
    *_, terminated, truncated, info = steps[-1]
    assert truncated and not terminated and info["summary"]["outcome"] == "timeout"
    assert info["summary"]["collisions"] == info["collisions"] == len(collided)


def test_a_non_finite_action_ends_the_episode_as_an_error():
    env = VPlaneNavEnv("single_box")
    env.reset(seed=0)
    _, _, terminated, truncated, info = env.step(np.array([np.nan, 0.0]))
    assert terminated and not truncated and info["summary"]["outcome"] == "error"
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(np.zeros(2))


def test_bad_options_are_clear_errors():
    with pytest.raises(
        VPlaneError, match="family: must be one of barn, clutter, corridors, traps, got 'nope'"
    ):
        VPlaneNavEnv(family="nope")
    with pytest.raises(VPlaneError, match="action: must be one of force, velocity, got 'torque'"):
        VPlaneNavEnv("single_box", action="torque")
    with pytest.raises(ScenarioError, match=r"sensors\.dropout: must be less than 1, got 2"):
        VPlaneNavEnv("single_box", overrides=["sensors.dropout=2"])


@pytest.mark.slow
def test_the_documented_examples_run(tmp_path, monkeypatch, doc_examples, capsys):
    monkeypatch.chdir(tmp_path)
    exec(compile(doc_examples("environments.md", "Gymnasium"), "docs/environments.md", "exec"), {})
    printed_digest = capsys.readouterr().out.splitlines()[-1]
    main(["run", "paper_c_escape", "--seed", "0", "--no-log", "--no-render", "--out", str(tmp_path)])
    summary = json.loads((tmp_path / "paper_c_escape-vplane-0.json").read_text())
    assert printed_digest == summary["trajectory_sha256"]
