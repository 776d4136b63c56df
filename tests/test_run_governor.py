"""The run's governor: a planner that does not drive its body itself (one of your own) has its
forces driven on the robot's body, on by default, off with `planner.governor = false`; the
summary, the run's line and the bench table say which."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import vplane_mj
from vplane_mj.planning import Decision, MotionParams, Planner, RunGovernor, register_planner
from vplane_mj.planning.protocol.plugins import import_planner
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import ScenarioError, load_scenario
from vplane_mj.sim.loop import Run
from vplane_mj.worlds.barn_import import import_world

ROOT = Path(__file__).parents[1]
GO_TO_GOAL = import_planner(str(ROOT / "examples" / "go_to_goal_planner.py") + ":GoToGoalPlanner")
"""The example planner, imported (each test that names it registers it in a registry of its own)."""


@pytest.fixture(scope="module")
def barn_world_1(tmp_path_factory) -> Path:
    """BARN's world 1 (the Jackal with its laser) as a scenario file."""
    case = import_world(ROOT / "tests" / "data" / "barn" / "world_1.world").case
    path = tmp_path_factory.mktemp("barn") / f"{case.name}.toml"
    path.write_text(case.toml())
    return path


@pytest.mark.slow
def test_the_example_planner_on_barn_world_1_is_governed_by_default_and_collides_without(
    barn_world_1, own_registry
):
    register_planner(GO_TO_GOAL)
    governed = vplane_mj.run(load_scenario(str(barn_world_1), ["planner.name=go_to_goal"]), out=None)
    assert governed.summary.governor == "run"
    assert governed.summary.success and governed.summary.collisions == 0
    assert governed.summary.min_clearance_m > 0.02

    scenario = load_scenario(str(barn_world_1), ["planner.name=go_to_goal", "planner.governor=false"])
    free = vplane_mj.run(scenario, out=None)
    assert free.summary.governor == "none"
    assert free.summary.reached and free.summary.collisions >= 10 and not free.summary.success
    assert f"REACHED WITH {free.summary.collisions} COLLISIONS (not a success)" in free.line()


def test_built_in_planners_drive_their_bodies_themselves():
    body = robot_body("jackal", "laser")
    for name in ("apf", "vplane", "vplane_plus", "vobs", "vfh", "bug2", "dwa"):
        planner = make_planner(name, {}, body)
        assert planner.governs_itself and RunGovernor.offered(planner) is None, name
    mine = GO_TO_GOAL.build({}, body)
    assert RunGovernor.offered(mine) is not None and RunGovernor.offered(mine, wanted=False) is None


def test_the_run_s_governor_takes_the_planner_s_own_margins():
    @dataclass(frozen=True)
    class WideParams(MotionParams):
        pass

    class Wide(Planner):
        name = "wide"
        summary = "its own margins"
        citation = ""
        Params = WideParams

        def step(self, obs):
            return Decision(force=obs.goal - obs.position, mode="normal")

    body = robot_body("jackal", "laser")
    wide = Wide.build({"turn_margin_m": 0.2}, body)
    governor = RunGovernor.offered(wide)
    assert governor is not None and governor.governor.turn_margin_m == 0.2
    plain = GO_TO_GOAL.build({}, body)
    assert RunGovernor.offered(plain).governor.turn_margin_m == MotionParams().turn_margin_m


def test_a_decision_with_a_command_or_a_non_finite_force_is_left_as_it_is(barn_world_1, own_registry):
    register_planner(GO_TO_GOAL)
    run = Run(load_scenario(str(barn_world_1), ["planner.name=go_to_goal"]))
    observation = run.observe()
    governor = run.run_governor
    assert governor is not None
    commanded = Decision(force=np.array([1.0, 0.0]), mode="normal", command=(0.3, 0.1))
    governor.drive(commanded, observation)
    assert commanded.command == (0.3, 0.1)
    broken = Decision(force=np.array([np.nan, 0.0]), mode="normal")
    governor.drive(broken, observation)
    assert broken.command is None and np.isnan(broken.force[0])
    forced = Decision(force=np.array([1.0, 0.0]), mode="normal")
    governor.drive(forced, observation)
    assert forced.command is not None


def test_planner_governor_is_a_bool_and_named_in_errors(tmp_path):
    with pytest.raises(ScenarioError, match=r"^overrides planner\.governor: must be true or false"):
        load_scenario("open_field", ['planner.governor="off"'])
    path = tmp_path / "mine.toml"
    path.write_text(load_scenario("open_field").to_toml() + "\n[planner]\ngovernor = 1\n")
    with pytest.raises(ScenarioError, match=r"mine\.toml: planner\.governor: must be true or false"):
        load_scenario(str(path))
    assert load_scenario("open_field", ["planner.governor=false"]).planner_governor is False
    assert load_scenario("open_field").planner_governor is True
