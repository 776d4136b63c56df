"""The dynamic window approach: its window, its arcs, its force through the heading controller, and
closed-loop runs on fixed seeds."""

import math

import numpy as np
import pytest

from vplane_mj import shapes
from vplane_mj.control import ControllerGains, heading_command
from vplane_mj.families import random_barn
from vplane_mj.planning import dwa
from vplane_mj.planning.body import HeadingGains, RobotBody
from vplane_mj.planning.types import Observation
from vplane_mj.robot import robot_radius_m
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim import run_scenario
from vplane_mj.synthetic import BEAM, BEARINGS, scan

PERIOD = 0.05
RADIUS = robot_radius_m()
GOAL_FAR = np.array([6.0, 0.0])


def planner(**overrides):
    return dwa.DwaPlanner.build(overrides, RADIUS)


def observe(footprints, time_s, position, yaw, goal=GOAL_FAR):
    position = np.asarray(position, float)
    ranges = scan(footprints, position, yaw) if footprints is not None else np.full(16, np.nan)
    return Observation(time_s, position, yaw, np.asarray(goal, float), 0.15, BEARINGS, ranges, BEAM)


def command(decision, yaw):
    """The (v, omega) that the run loop's heading controller makes of a decision's force."""
    return heading_command(*decision.force, yaw, ControllerGains())


def drive(planner, footprints, speed, ticks, yaw=0.0, start=(0.0, 0.0)):
    """Feed observations of the robot moving straight along `yaw` at `speed` (m/s); the last decision."""
    position = np.asarray(start, float)
    heading = np.array([math.cos(yaw), math.sin(yaw)])
    for tick in range(ticks):
        decision = planner.step(observe(footprints, tick * PERIOD, position, yaw))
        position = position + speed * PERIOD * heading
    return decision, position - speed * PERIOD * heading


def test_the_default_robots_window_is_the_controllers():
    gains, limits = ControllerGains(), planner().limits
    assert (limits.max_speed_mps, limits.max_turn_rate_radps) == (gains.max_speed, gains.max_turn_rate)
    assert (limits.max_accel_mps2, limits.max_turn_accel_radps2) == (4.0, 30.0)
    assert planner().lookahead == 1.0


@pytest.mark.parametrize("yaw", [0.0, 2.0, -3.0, 1e6])
def test_the_force_maps_back_to_the_command_through_the_heading_controller(yaw):
    for speed in (0.0, 0.05, 0.3, 0.5):
        for turn in (-2.5, -1.0, 0.0, 0.4, 2.5):
            force = dwa.force_for_command(speed, turn, yaw, HeadingGains())
            v, omega = heading_command(*force, yaw, ControllerGains())
            assert v == pytest.approx(speed, abs=2 * dwa.CREEP_SPEED) and omega == pytest.approx(
                turn, abs=1e-9
            )
    assert np.all(dwa.force_for_command(0.0, 0.0, yaw, HeadingGains()) == 0.0)  # stop: no force at all


@pytest.mark.parametrize(
    "speed, turn, slowest, fastest, leftmost, rightmost",
    [
        (0.3, 0.5, 0.1, 0.5, -1.0, 2.0),  # inside the limits: +-a dt either way
        (0.0, 0.0, 0.0, 0.2, -1.5, 1.5),  # at rest: no reverse
        (0.48, 2.2, 0.28, 0.5, 0.7, 2.5),  # near the top speed and turn rate: clipped
        (-0.1, -3.0, 0.0, 0.1, -2.5, -1.5),  # pushed backwards, spinning past the limit
    ],
)
def test_the_window_holds_the_commands_reachable_in_one_period(
    speed, turn, slowest, fastest, leftmost, rightmost
):
    params = dwa.DwaParams()  # 4 m/s^2 and 30 rad/s^2: +-0.2 m/s and +-1.5 rad/s in 0.05 s
    limits = dwa.window_limits(params, RobotBody.round(RADIUS))
    speeds, turns = dwa.dynamic_window(speed, turn, PERIOD, limits, params.speed_samples, params.turn_samples)
    assert (speeds[0], speeds[-1]) == pytest.approx((slowest, fastest))
    assert (turns[0], turns[-1]) == pytest.approx((leftmost, rightmost))
    assert len(speeds) == params.speed_samples and len(turns) == params.turn_samples


def test_each_command_is_reachable_from_the_velocity_of_the_last_period():
    """From rest the robot may ask for a * dt at most, then a * dt more each tick."""
    dwa_planner = planner()
    position, speeds = np.zeros(2), []
    for tick in range(6):
        decision = dwa_planner.step(observe(None, tick * PERIOD, position, 0.0))
        v, _ = command(decision, 0.0)
        speeds.append(v)
        position = position + np.array([v * PERIOD, 0.0])  # the robot follows its command at once
    assert speeds == pytest.approx([0.2, 0.4, 0.5, 0.5, 0.5, 0.5])


def test_in_open_space_it_drives_straight_at_the_goal_at_top_speed():
    decision, _ = drive(planner(), None, 0.5, ticks=5)
    v, omega = command(decision, 0.0)
    assert v == pytest.approx(0.5) and omega == pytest.approx(0.0, abs=1e-9)
    assert decision.mode == "normal" and decision.force[1] == pytest.approx(0.0, abs=1e-9)


def test_it_turns_toward_a_goal_behind_it_as_fast_as_it_may():
    dwa_planner = planner()
    decision = dwa_planner.step(observe(None, 0.0, (0.0, 0.0), math.pi / 2))  # goal on the right
    _, omega = command(decision, math.pi / 2)
    assert omega == pytest.approx(-1.5)  # the turn-rate acceleration limit from rest


def ground_truth_free_length(footprints, position, yaw, speed, turn, length=1.0):
    """How far (m) the robot's disc travels along the command's circle before touching an obstacle."""
    travel = np.linspace(0.0, length, 2001)
    curvature = turn / speed
    points, _ = dwa.arc_poses(position, yaw, travel, curvature * travel)
    touching = footprints.distance(points) < RADIUS
    return travel[np.argmax(touching)] if touching.any() else math.inf


def test_an_arc_into_a_wall_is_not_chosen():
    """A wall across the way, the goal behind it: the chosen arc bends away in time."""
    wall = shapes.Footprints(shapes.Wall((0.9, -2.0), (0.9, 2.0), 0.1).footprint())
    dwa_planner = planner()
    decision, position = drive(dwa_planner, wall, 0.5, ticks=12)  # the map learns the wall
    straight = ground_truth_free_length(wall, position, 0.0, 0.5, 1e-9)
    assert straight < 0.5  # straight on, the robot would touch the wall within half a metre
    v, omega = command(decision, 0.0)
    assert v > 0.0 and abs(omega) > 1.0
    chosen = ground_truth_free_length(wall, position, 0.0, v, omega)
    assert chosen > straight and v * PERIOD + v * v / (2 * dwa_planner.limits.max_accel_mps2) < chosen


POCKET = shapes.Footprints(
    [
        piece
        for wall in (
            shapes.Wall((0.22, -0.3), (0.22, 0.3), 0.05),
            shapes.Wall((-0.3, 0.22), (0.22, 0.22), 0.05),
            shapes.Wall((-0.3, -0.22), (0.22, -0.22), 0.05),
        )
        for piece in wall.footprint()
    ]
)
"""Walls 0.2 m ahead, left and right of a robot at the origin facing +x: a pocket open behind."""


def test_a_turn_on_the_spot_toward_the_goal_is_always_admissible():
    """Stopped in the pocket: every arc comes closer to a wall, but turning on the spot does not."""
    dwa_planner = planner()
    for tick in range(5):
        decision = dwa_planner.step(observe(POCKET, tick * PERIOD, (0.0, 0.0), 0.0, goal=(0.0, 3.0)))
    v, omega = command(decision, 0.0)
    assert v < 2 * dwa.CREEP_SPEED and omega > 0  # turns left, toward the goal, where it stands
    assert decision.mode == "normal"


def test_with_no_admissible_arc_it_brakes():
    """In the pocket at top speed: the window has no stop and every arc comes closer to a wall."""
    dwa_planner = planner()
    for tick in range(4):  # standing still: the map learns the pocket
        dwa_planner.step(observe(POCKET, tick * PERIOD, (0.0, 0.0), 0.0))
    decision = dwa_planner.step(observe(POCKET, 4 * PERIOD, (0.025, 0.0), 0.0))  # now at 0.5 m/s
    assert decision.mode == "blocked" and [e.text for e in decision.events] == ["no admissible arc: braking"]
    assert command(decision, 0.0) == pytest.approx((0.3, 0.0))  # 0.5 - a dt: as hard as it may


def test_it_reaches_the_goal_past_a_box_without_collision(shipped):
    summary = run_scenario(shipped("single_box", "planner.name=dwa")).summary
    assert summary.success and summary.collisions == 0
    assert summary.path_ratio < 1.15 and summary.min_clearance_m > 0.05


def test_it_crosses_a_barn_world_without_collision():
    case = random_barn("barn_dwa", np.random.default_rng(8))  # 47 boxes; the straight line is blocked
    summary = run_scenario(parse_scenario(case.toml(), "barn_dwa.toml", ["planner.name=dwa"])).summary
    assert summary.success and summary.collisions == 0
    assert 1.05 < summary.path_ratio < 1.6
