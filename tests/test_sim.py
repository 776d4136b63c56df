"""Closed-loop runs in MuJoCo: controller behaviour, APF outcomes, metrics and determinism."""

import math

import numpy as np
import pytest

from vplane_mj.planning import Decision, Observation, Planner, register_planner
from vplane_mj.robots.profiles import DEFAULT, PROFILES
from vplane_mj.sim.control import within_limits
from vplane_mj.sim.loop import Run, run_scenario
from vplane_mj.sim.metrics import barn_score
from vplane_mj.sim.summary import TIMING_KEYS

OPEN = """
format = 1
name = "open"
[world]
size = [6.0, 3.0]
[robot]
start = [1.0, 1.5]
start_yaw_deg = {yaw}
goal = [5.0, 1.5]
[planner]
name = "apf"
"""

SUMMARY_KEYS = {
    "format",
    "score",
    "scenario",
    "planner",
    "seed",
    "outcome",
    "reached",
    "success",
    "time_to_goal_s",
    "sim_time_s",
    "steps",
    "physics_dt_s",
    "control_hz",
    "wall_time_s",
    "path_length_m",
    "collisions",
    "min_clearance_m",
    "local_minima",
    "escapes",
    "robot_radius_m",
}


class Recorder:
    def __init__(self):
        self.ticks, self.events = [], []

    def on_tick(self, tick):
        self.ticks.append(tick)

    def on_event(self, time_s, text):
        self.events.append((time_s, text))


def test_robot_drives_straight_along_an_aligned_force(scenario_from):
    result = run_scenario(scenario_from(OPEN.format(yaw=0.0)))
    assert result.summary.reached
    assert np.max(np.abs(result.positions[:, 1] - 1.5)) < 0.01
    # cruise speed is the controller's 0.5 m/s limit: 4 m in well under 12 s
    assert result.summary.time_to_goal_s < 12.0


def test_robot_turns_in_place_toward_a_force_behind_it(scenario_from):
    recorder = Recorder()
    result = run_scenario(scenario_from(OPEN.format(yaw=180.0)), observers=(recorder,))
    # While the goal is more than 90 degrees off the heading the command is a pure turn.
    turned = next(t for t in recorder.ticks if abs(t.yaw) <= math.radians(90))
    assert 0.3 < turned.time_s < 1.5  # 90 degrees at up to 2.5 rad/s
    assert np.hypot(*(turned.position - [1.0, 1.5])) < 0.03  # it turned on the spot
    assert result.summary.reached


@pytest.mark.parametrize("name", ["open_field", "single_box"])
def test_apf_reaches_the_goal_without_collision(shipped, name):
    scenario = shipped(name, "planner.name=apf")
    summary = run_scenario(scenario).summary
    straight = math.dist(scenario.robot.start, scenario.robot.goal) - scenario.robot.goal_tolerance
    assert summary.outcome == "reached" and summary.success
    assert summary.collisions == 0
    assert straight - 0.01 <= summary.path_length_m <= 1.2 * straight
    assert summary.min_clearance_m > 0.0
    assert summary.to_dict().keys() >= SUMMARY_KEYS


@pytest.mark.parametrize("name", ["paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape"])
def test_apf_is_trapped_in_the_paper_scenarios(shipped, name):
    summary = run_scenario(shipped(name, "planner.name=apf")).summary
    assert not summary.reached
    assert summary.outcome == "stuck"
    assert summary.local_minima >= 1
    assert summary.final_distance_to_goal_m > 3.0


def test_collisions_are_counted_as_separate_episodes(shipped):
    # Without repulsion APF drives straight into the box and pushes against it.
    summary = run_scenario(
        shipped("single_box", "planner.name=apf", "planner.repulse_gain=0", "run.time_limit_s=20")
    ).summary
    assert summary.collisions >= 1
    assert not summary.success
    assert summary.min_clearance_m < 0.0


def test_clearance_is_measured_against_the_contract_geometry(scenario_from):
    summary = run_scenario(scenario_from(OPEN.format(yaw=0.0))).summary
    # Driving along y = 1.5 in a 3 m high arena: the borders are 1.5 m from the centre.
    # The start is 1 m from the west border; the robot never gets closer than that.
    assert summary.min_clearance_m == pytest.approx(1.0 - summary.robot_radius_m, abs=1e-6)


def test_same_seed_gives_identical_summaries(shipped):
    scenario = shipped("paper_c_escape", "sensors.noise_std=0.02", "sensors.dropout=0.1")
    first = run_scenario(scenario)
    second = run_scenario(scenario)
    assert first.summary.without_timing() == second.summary.without_timing()
    assert TIMING_KEYS[0] in first.summary.to_dict()
    np.testing.assert_array_equal(first.positions, second.positions)


def test_time_limit_ends_the_run(shipped):
    summary = run_scenario(shipped("open_field", "run.time_limit_s=2")).summary
    assert summary.outcome == "timeout" and not summary.reached
    assert summary.sim_time_s == pytest.approx(2.0, abs=0.06)
    assert summary.time_to_goal_s is None


def test_motion_quality_metrics(shipped):
    straight = run_scenario(shipped("open_field", "planner.name=apf")).summary
    detour = run_scenario(shipped("paper_c_escape")).summary
    assert straight.smoothness_rad_per_m < 0.05 and straight.oscillation_per_m < 1.0
    assert detour.smoothness_rad_per_m > 5 * straight.smoothness_rad_per_m
    assert detour.mean_clearance_m > detour.min_clearance_m > 0
    assert 0 < detour.planner_cpu_ms_mean <= detour.planner_cpu_ms_max


def test_barn_score_clips_the_time_between_two_and_eight_optimal_times():
    # 5 m at 0.5 m/s: OT = 10 s.
    assert barn_score(True, 5.0, 25.0, 0.5) == pytest.approx(10 / 25)
    assert barn_score(True, 5.0, 12.0, 0.5) == pytest.approx(0.5)  # faster than 2 OT counts as 2 OT
    assert barn_score(True, 5.0, 300.0, 0.5) == pytest.approx(1 / 8)  # slower than 8 OT counts as 8 OT
    assert barn_score(False, 5.0, 25.0, 0.5) == 0.0
    assert barn_score(True, None, 25.0, 0.5) is None


def test_the_summary_scores_a_run_against_its_reference_path(shipped):
    reached = run_scenario(shipped("paper_c_escape")).summary
    optimal_time = reached.reference_length_m / 0.5  # BARN's OT runs to the goal point
    assert reached.optimal_length_m == pytest.approx(reached.reference_length_m - 0.15)
    assert reached.success
    expected = optimal_time / min(max(reached.time_to_goal_s, 2 * optimal_time), 8 * optimal_time)
    assert reached.score == pytest.approx(expected)
    assert 0.125 <= reached.score <= 0.5
    trapped = run_scenario(shipped("paper_c_escape", "planner.name=apf")).summary
    assert trapped.score == 0.0


class _Reverser(Planner):
    """Backs off at 0.3 m/s for its first second, then lets the force drive to the goal."""

    name = "reverser"
    summary = "backs off, then heads for the goal"
    citation = ""

    def step(self, obs: Observation) -> Decision:
        self.seen = [*getattr(self, "seen", []), (obs.time_s, obs.velocity)]
        decision = Decision(force=obs.goal - obs.position, mode="normal")
        if obs.time_s < 1.0:
            decision.command = (-0.3, 0.0)
        return decision


def test_a_planner_can_command_a_reverse_and_reads_the_wheels_speeds(scenario_from, own_registry):
    register_planner(_Reverser)
    run = Run(scenario_from(OPEN.format(yaw=0.0), ["planner.name=reverser"]))
    while run.step() is None:
        pass
    result = run.result()
    assert result.summary.reached
    # Heading +x, backing off: x decreases below the start's 1.0 m during the first second.
    backed = result.positions[result.times <= 1.0]
    assert backed[:, 0].min() < 1.0 - 0.15 and np.max(np.abs(backed[:, 1] - 1.5)) < 0.02
    # The wheels report the speed driven: -0.3 m/s once the motors have caught up, then forward.
    _, (speed, turn) = min(run.planner.seen, key=lambda seen: abs(seen[0] - 0.5))
    assert speed == pytest.approx(-0.3, abs=0.03) and abs(turn) < 0.05
    assert max(v for t, (v, _) in run.planner.seen if t > 3.0) > 0.4


class _Overdriver(Planner):
    """Commands far beyond any robot's top speed and turn rate on its first tick, then pulls
    along the heading with a force far beyond the top speed's."""

    name = "overdriver"
    summary = "asks for more than the robot can do"
    citation = ""

    def step(self, obs: Observation) -> Decision:
        decision = Decision(force=1e3 * np.array([math.cos(obs.yaw), math.sin(obs.yaw)]), mode="normal")
        if obs.time_s == 0.0:
            decision.command = (9.0, -9.0)
        return decision


@pytest.mark.parametrize("profile", list(PROFILES))
def test_a_run_holds_its_commands_within_its_robots_limits(scenario_from, own_registry, profile):
    register_planner(_Overdriver)
    run = Run(scenario_from(OPEN.format(yaw=0.0), ["planner.name=overdriver", f"robot.profile={profile}"]))
    limits = PROFILES[profile].limits
    run.step()  # the command, clamped
    assert run.command == (limits.max_speed_mps, -limits.max_turn_rate_radps)
    run.step()  # the heading controller's answer to the force
    assert run.command[0] == limits.max_speed_mps and abs(run.command[1]) < limits.max_turn_rate_radps


def test_a_commanded_speed_and_turn_rate_are_held_within_the_robot_limits():
    limits = DEFAULT.limits
    assert within_limits((-9.0, 9.0), limits) == (-limits.max_speed_mps, limits.max_turn_rate_radps)
    assert within_limits((0.2, -0.1), limits) == (0.2, -0.1)
    assert within_limits((math.nan, 1.0), limits) == (0.0, 0.0)
