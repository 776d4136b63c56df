"""A planner as a dm_env policy (docs/environments.md): it drives the environment along the
trajectory of `vplane-mj run` with that planner, by name, by class or as the scenario says, with
either kind of action; it refuses what it cannot do; and dm_control's viewer runs it (its
runtime, the part of the viewer that steps the environment, here without a window)."""

import warnings
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from vplane_mj import VPlaneError
from vplane_mj.envs import PlannerPolicy, VPlaneNavDmEnv
from vplane_mj.planning.planners.bug2 import Bug2Planner
from vplane_mj.planning.planners.vplane import VPlanePlanner
from vplane_mj.planning.protocol.plugins import PlannerError, import_planner
from vplane_mj.planning.protocol.registry import PLANNERS, register_planner
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario

EXAMPLES = Path(__file__).parents[1] / "examples"


def drive(env, policy):
    """One episode of `env` under `policy`: its TimeSteps."""
    steps = [env.reset()]
    while not steps[-1].last():
        steps.append(env.step(policy(steps[-1])))
    return steps


def run_digest(name, *overrides):
    """The trajectory digest and outcome of `vplane-mj run NAME --seed 0 --set OVERRIDE...`."""
    summary = run_scenario(load_scenario(name, ["run.seed=0", *overrides])).summary
    return summary.trajectory_sha256, summary.outcome.value


@pytest.mark.parametrize(
    ("action", "planner", "overrides"),
    [
        ("force", "vplane", ()),
        ("velocity", "vplane", ()),
        ("velocity", PLANNERS["bug2"], ()),  # a class rather than a name
        ("force", None, ("planner.name=vfh",)),  # the scenario's own planner
    ],
    ids=["vplane-force", "vplane-velocity", "bug2-class", "scenario-planner"],
)
def test_a_planner_drives_the_robot_to_the_goal_along_its_run(action, planner, overrides):
    with VPlaneNavDmEnv("paper_c_escape", action=action, overrides=overrides) as env:
        drive(env, PlannerPolicy(env, planner))
        summary = env.info["summary"]
    name = planner if isinstance(planner, str) else getattr(planner, "name", None)
    expected = run_digest("paper_c_escape", *overrides, *([f"planner.name={name}"] if name else []))
    assert (summary["trajectory_sha256"], summary["outcome"]) == expected
    assert summary["outcome"] == "reached" and summary["planner"] == "external"


class Counted(VPlanePlanner):
    """vplane, keeping every planner made."""

    name = "counted"
    made: ClassVar[list[VPlanePlanner]] = []

    def __init__(self, params, robot):
        super().__init__(params, robot)
        self.made.append(self)


def test_each_episode_gets_a_fresh_planner_for_its_world():
    with VPlaneNavDmEnv(family="traps", overrides=["run.time_limit_s=60"], seed=2) as env:
        policy = PlannerPolicy(env, Counted, {"influence": 0.8})
        outcomes = []
        for _ in range(2):
            drive(env, policy)
            outcomes.append(env.info["summary"]["outcome"])
    assert len(Counted.made) == 2 and Counted.made[1].params.influence == 0.8
    assert outcomes == ["reached", "reached"]


class Commanding(Bug2Planner):
    """Bug2 that commands a speed and a turn rate beyond the robot's (2.5 rad/s)."""

    name = "commanding"

    def step(self, obs):
        decision = super().step(obs)
        decision.command = (0.3, 9.0)
        return decision


def test_the_policy_refuses_what_it_cannot_do():
    with VPlaneNavDmEnv("single_box") as env:
        with pytest.raises(VPlaneError, match=r"unknown planner 'nope'; available: apf, .*vplane"):
            PlannerPolicy(env, "nope")
        with pytest.raises(PlannerError, match=r"is not a subclass of vplane_mj\.planning\.Planner"):
            PlannerPolicy(env, dict)
        with pytest.raises(VPlaneError, match=r"planner 'commanding' commands a body speed.*'velocity'"):
            PlannerPolicy(env, Commanding)(env.reset())
    with VPlaneNavDmEnv("single_box", action="velocity", overrides=["run.time_limit_s=0.1"]) as env:
        policy = PlannerPolicy(env, Commanding)
        first = env.reset()
        assert np.array_equal(policy(first), [0.3, 2.5])  # within the robot's limits
        steps = [first, env.step(policy(first)), env.step(np.zeros(2))]
        assert steps[-1].last() and np.array_equal(policy(steps[-1]), [0.0, 0.0])  # ignored anyway


def test_dm_controls_viewer_runs_the_policy_and_restarts_with_the_next_episode():
    with warnings.catch_warnings():  # importing the viewer loads GLFW, which finds no display
        warnings.simplefilter("ignore")
        from dm_control.viewer import runtime

    with VPlaneNavDmEnv("paper_c_escape", overrides=["sensors.noise_std=0.01"]) as env:
        assert not callable(env)  # so dm_control.viewer.launch(env, ...) takes it as its loader's result
        policy = PlannerPolicy(env, "vplane")
        viewer = runtime.Runtime(env, policy)
        viewer.simulation_time_budget = 5.0  # simulated seconds a frame, to run quickly
        physics_changes = []
        viewer.on_physics_changed += lambda: physics_changes.append(env.physics)
        first_physics = env.physics
        viewer.tick(5.0, paused=False)  # begins the episode (the physics made for it) and steps it
        stepped_to = viewer.get_time()
        viewer.tick(5.0, paused=True)  # paused: recomputes the state, the time stands still
        assert viewer.state is runtime.State.RUNNING and viewer.get_time() == stepped_to
        assert 5.0 <= stepped_to < 5.1  # the ticks of 50 ms that fill the frame's 5 s
        while viewer.state is not runtime.State.STOPPED:
            viewer.tick(5.0, paused=False)
        assert env.info["summary"]["outcome"] == "reached" and not physics_changes
        assert env.physics is first_physics

        viewer.restart()  # the viewer's Backspace: the application also resets the policy
        policy.reset()
        viewer.tick(1.0, paused=False)
        assert physics_changes == [env.physics] and env.physics is not first_physics
        assert env.episode_seed == 1 and 1.0 <= viewer.get_time() < 1.1
        while viewer.state is not runtime.State.STOPPED:
            viewer.tick(5.0, paused=False)
        assert env.info["summary"]["outcome"] == "reached" and env.info["summary"]["seed"] == 1


def test_an_own_planner_is_governed_as_in_a_run(own_registry):
    """go_to_goal on the Jackal: the policy's episode is the run's trajectory, governed."""
    planner = import_planner(str(EXAMPLES / "go_to_goal_planner.py") + ":GoToGoalPlanner")
    register_planner(planner)
    overrides = ("robot.profile=jackal", "run.time_limit_s=8")
    with VPlaneNavDmEnv("paper_c_escape", action="velocity", overrides=overrides) as env:
        drive(env, PlannerPolicy(env, planner))
        summary = env.info["summary"]
    governed = run_digest("paper_c_escape", *overrides, "planner.name=go_to_goal")
    free = run_digest("paper_c_escape", *overrides, "planner.name=go_to_goal", "planner.governor=false")
    assert governed != free
    assert (summary["trajectory_sha256"], summary["outcome"]) == governed
