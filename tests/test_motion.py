"""The governor that fits a planner's force to the robot's body (vplane_mj/planning/motion.py),
the dense scan's reduction (scan.py) and the gap sizing by the robot's width, on synthetic
observations; and real runs of the Jackal on a BARN protocol world and of the Pioneer in the
paper's H trap."""

import math

import numpy as np
import pytest

from vplane_mj.planning import motion, scan
from vplane_mj.planning.body import DriveLimits, HeadingGains, RobotBody
from vplane_mj.planning.registry import make_planner
from vplane_mj.planning.types import Observation
from vplane_mj.robots.facts import robot_body

JACKAL = robot_body("jackal")
DEFAULT = robot_body("default")


def test_room_ahead_counts_the_width_and_stops_where_the_robot_can_turn():
    # Posts ahead: one in the way (0.1 m off the axis), one beside it (0.3 m off: the Jackal's
    # half width is 0.215 m), one behind.
    posts = np.array([[1.0, 0.1], [0.6, 0.3], [-0.5, 0.0]])
    room = motion.room_ahead(JACKAL, posts, 0.1, 0.03)
    assert room == pytest.approx(1.0 - JACKAL.radius_m - 0.1)
    assert motion.room_ahead(JACKAL, posts[1:], 0.1, 0.03) == math.inf
    assert motion.room_ahead(JACKAL, np.array([[0.3, 0.0]]), 0.1, 0.03) == 0.0


def test_a_turn_in_place_is_refused_where_a_corner_would_strike_a_post():
    # A post 0.3 m to the left of the centre: clear of the 0.43 m wide Jackal's side (0.085 m),
    # inside the 0.333 m its corners sweep. Turning right swings the front-left corner away
    # from it at first... and the rear-left corner into it: both ways are shut soon.
    post = np.array([[0.0, 0.3]])
    assert motion.outline_distances(JACKAL, post, np.zeros(1))[0, 0] == pytest.approx(0.085)
    left = motion.free_turn(JACKAL, post, 1.0, math.pi / 2, 0.03)
    right = motion.free_turn(JACKAL, post, -1.0, math.pi / 2, 0.03)
    assert 0 < left <= math.radians(30) and 0 < right <= math.radians(30)
    # Nothing within the swept disc: free; a round robot's turn is always free.
    far = np.array([[0.0, 0.5]])
    assert motion.free_turn(JACKAL, far, 1.0, math.pi / 2, 0.03) == pytest.approx(math.pi / 2)
    assert motion.free_turn(DEFAULT, np.array([[0.0, 0.12]]), 1.0, math.pi, 0.03) == math.pi


def test_a_blocked_turn_becomes_a_partial_turn_while_creeping_or_the_other_way_round():
    post = np.array([[0.15, 0.3]])  # ahead-left, inside the swept disc
    wanted = math.radians(120)  # the force points back-left
    turned = motion.turn_direction(JACKAL, post, 0.0, wanted, 0.03, room_m=1.0)
    assert 0.0 <= turned < wanted  # as far as is free, creeping ahead
    # No room ahead and the way left shut at once: as far as is free the other way round.
    boxed = np.array([[0.2, 0.24], [0.6, 0.0]])  # beside the front-left corner, and ahead
    other = motion.turn_direction(JACKAL, boxed, 0.0, wanted, 0.03, room_m=0.0)
    assert other < 0.0


def test_the_speed_policy_brakes_within_the_room_and_bends_and_never_slows_the_default_robot():
    policy = motion.SpeedPolicy(JACKAL)
    assert policy.active and not motion.SpeedPolicy(DEFAULT).active
    assert policy.safe_speed(math.inf) == 2.0
    for room in (0.05, 0.3, 0.8):
        v = policy.safe_speed(room)
        assert v * policy.period_s + v * v / (2 * JACKAL.limits.max_accel_mps2) == pytest.approx(room)
    assert policy.safe_speed(0.0) == 0.0
    # speed_gain converts speed to force: the Jackal's 2 (m/s) per unit.
    force = policy.limit(np.array([3.0, 4.0]), 1.0)
    assert np.hypot(*force) == pytest.approx(0.5) and force[1] / force[0] == pytest.approx(4 / 3)
    # A way that turns a right angle 0.4 m ahead asks for less than one straight ahead.
    straight = np.column_stack((np.linspace(0.1, 3.0, 30), np.zeros(30)))
    corner = np.vstack((straight[:4], np.column_stack((np.full(20, 0.4), np.linspace(0.1, 2.0, 20)))))
    assert policy.bend_speed(np.zeros(2), 0.0, straight) == 2.0
    assert policy.bend_speed(np.zeros(2), 0.0, corner) < 1.5
    # The default robot: the governor leaves every force as it is.
    governor = motion.Governor(DEFAULT, 0.1, 0.03)
    assert governor.idle
    f = np.array([0.3, -0.2])
    assert governor.govern(f, np.zeros(2), 0.0, np.array([[0.15, 0.0]])) is f


def test_the_governor_stops_a_fast_robot_short_of_a_wall_but_lets_it_pass_beside_one():
    governor = motion.Governor(JACKAL, 0.1, 0.03)
    wall = np.column_stack((np.full(40, 1.0), np.linspace(-1.0, 1.0, 40)))
    slowed = governor.govern(np.array([1.0, 0.0]), np.zeros(2), 0.0, wall)
    assert np.hypot(*slowed) * JACKAL.gains.speed_gain == pytest.approx(
        governor.policy.safe_speed(1.0 - JACKAL.radius_m - 0.1)
    )
    beside = np.column_stack((np.linspace(-1.0, 2.0, 40), np.full(40, 0.3)))
    free = governor.govern(np.array([1.0, 0.0]), np.zeros(2), 0.0, beside)
    assert np.allclose(free, [1.0, 0.0])


def test_a_dense_scan_repels_through_its_nearest_echo_per_ring_sector():
    bearings = np.linspace(-3 * math.pi / 4, 3 * math.pi / 4, 720)
    ranges = np.full(720, 2.0)
    ranges[360] = 0.5  # the nearest echo, straight ahead
    obs = Observation(0.0, np.zeros(2), 0.0, np.array([5.0, 0.0]), 0.2, bearings, ranges, math.radians(0.4))
    points = scan.repulsion_points(obs)
    assert scan.is_dense(obs) and len(points) == 13  # 270 degrees of 22.5-degree sectors: 12 and an end
    assert np.min(np.hypot(*points.T)) == pytest.approx(0.5)
    sonar = Observation(0.0, np.zeros(2), 0.0, np.ones(2), 0.2, np.arange(16) * math.pi / 8, ranges[:16], 0.3)
    assert scan.repulsion_points(sonar) is sonar.echo_points()


def test_gaps_are_sized_by_the_robots_width_and_the_default_robot_keeps_its_radius():
    narrow = RobotBody.polygon([[0.4, 0.1], [-0.4, 0.1], [-0.4, -0.1], [0.4, -0.1]])
    assert narrow.half_width_m == pytest.approx(0.1) and narrow.radius_m > 0.4
    assert narrow.inner_radius_m == pytest.approx(0.1) and JACKAL.inner_radius_m == pytest.approx(0.215)
    plus = make_planner("vplane_plus", {}, narrow)
    assert plus._link_m() == pytest.approx(0.2 + plus.params.clearance_m)
    assert plus._lethal_m() == pytest.approx(0.1 + plus.params.path_clearance_m + plus.params.turn_margin_m)
    default = make_planner("vplane_plus", {}, DEFAULT)
    assert default._link_m() == 2 * DEFAULT.radius_m + default.params.clearance_m
    assert default._lethal_m() == DEFAULT.radius_m + default.params.path_clearance_m


def test_a_body_with_other_limits_gets_its_own_reach():
    slow = RobotBody.round(
        0.2, limits=DriveLimits(max_speed_mps=1.0, max_accel_mps2=1.0), gains=HeadingGains(1.0)
    )
    governor = motion.Governor(slow, 0.1, 0.03)
    assert not governor.idle  # brakes in 0.5 m
    assert governor.reach_m == pytest.approx(0.2 + 1.0 * (0.05 + 0.5) + 0.1)


def _run(scenario_text_or_name: str, overrides: list[str]):
    from vplane_mj.scenario import load_scenario
    from vplane_mj.sim.loop import run_scenario

    return run_scenario(load_scenario(scenario_text_or_name, overrides)).summary


def test_a_jackal_crosses_a_barn_protocol_world_fast_and_without_a_collision(tmp_path):
    from vplane_mj.worlds.barn_protocol import generate_protocol

    case = generate_protocol(2, 0)[1]
    path = tmp_path / f"{case.name}.toml"
    path.write_text(case.toml(), encoding="utf-8")
    summary = _run(str(path), ["planner.name=vplane_plus", "run.seed=0"])
    assert summary.outcome == "reached" and summary.collisions == 0
    assert summary.score > 0.4  # measured 0.50: within twice the reference path's time at 2 m/s


def test_the_pioneer_escapes_the_paper_h_trap_without_a_collision():
    summary = _run("paper_h_escape", ["planner.name=vplane", "robot.profile=pioneer3dx", "run.seed=0"])
    assert summary.outcome == "reached" and summary.collisions == 0
