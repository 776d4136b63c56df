"""The dynamic window approach: its window, its arcs, its force through the heading controller, and
closed-loop runs on fixed seeds."""

import math

import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import BEAM, BEARINGS, scan
from vplane_mj.planning.planners import dwa
from vplane_mj.planning.protocol.body import DriveLimits, HeadingGains, RobotBody
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.robots.facts import robot_body, robot_radius_m
from vplane_mj.robots.profiles import DEFAULT, PROFILES
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.control import heading_command
from vplane_mj.sim.loop import Run, run_scenario
from vplane_mj.worlds.barn_protocol import generate_protocol
from vplane_mj.worlds.families import random_barn

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
    return heading_command(*decision.force, yaw, DEFAULT.gains, DEFAULT.limits)


def drive(planner, footprints, speed, ticks, yaw=0.0, start=(0.0, 0.0)):
    """Feed observations of the robot moving straight along `yaw` at `speed` (m/s); the last decision."""
    position = np.asarray(start, float)
    heading = np.array([math.cos(yaw), math.sin(yaw)])
    for tick in range(ticks):
        decision = planner.step(observe(footprints, tick * PERIOD, position, yaw))
        position = position + speed * PERIOD * heading
    return decision, position - speed * PERIOD * heading


def test_the_default_robots_window_is_the_controllers():
    limits = planner().limits
    assert limits == DEFAULT.limits
    assert (limits.max_accel_mps2, limits.max_turn_accel_radps2) == (4.0, 30.0)
    assert planner().lookahead == 1.0


@pytest.mark.parametrize("yaw", [0.0, 2.0, -3.0, 1e6])
def test_the_force_maps_back_to_the_command_through_the_heading_controller(yaw):
    for speed in (0.0, 0.05, 0.3, 0.5):
        for turn in (-2.5, -1.0, 0.0, 0.4, 2.5):
            force = dwa.force_for_command(speed, turn, yaw, HeadingGains())
            v, omega = heading_command(*force, yaw, DEFAULT.gains, DEFAULT.limits)
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


# -- The robot it is given: limits, gains, footprint ---------------------------------------------

JACKAL = robot_body("jackal")
JACKAL_HALF_LENGTH, JACKAL_HALF_WIDTH = 0.254, 0.215


def test_the_limits_and_the_lookahead_are_the_robots_own():
    jackal = dwa.DwaPlanner.build({}, JACKAL)
    assert jackal.limits == DriveLimits(2.0, 4.0, 2.0, 4.0)
    assert jackal.lookahead == pytest.approx(2.0)  # two braking distances from 2 m/s at 2 m/s^2
    reach = jackal.lookahead + jackal.radius + jackal.params.margin_m + jackal.params.map_cell_m
    assert jackal.map.n * jackal.map.cell_m >= 4 * reach  # the arcs stay on the map
    pioneer = dwa.DwaPlanner.build({}, robot_body("pioneer3dx"))
    assert pioneer.limits.max_speed_mps == 1.2
    # 5.236 rad/s would need a heading error beyond 1.4 rad: the controller's cos e nearly 0
    assert pioneer.limits.max_turn_rate_radps == pytest.approx(3.0 * dwa.MAX_HEADING_ERROR)


@pytest.mark.parametrize(
    "overrides, limits, lookahead",
    [
        ({"max_speed": 0.5}, DriveLimits(0.5, 4.0, 2.0, 4.0), 1.0),  # BARN's baseline setting
        ({"max_speed": 3.0, "max_turn_rate": 9.0}, DriveLimits(2.0, 4.0, 2.0, 4.0), 2.0),  # above
        ({"accel_mps2": 1.0, "turn_accel_radps2": 2.0}, DriveLimits(2.0, 4.0, 1.0, 2.0), 4.0),
        ({"max_speed": 1.0, "lookahead_m": 0.7}, DriveLimits(1.0, 4.0, 2.0, 4.0), 0.7),
    ],
)
def test_a_parameter_caps_the_robots_limit_and_never_raises_it(overrides, limits, lookahead):
    planner = dwa.DwaPlanner.build(overrides, JACKAL)
    assert planner.limits == limits and planner.lookahead == pytest.approx(lookahead)


def test_the_list_says_what_a_limit_of_zero_means():
    table = dwa.DwaPlanner.info().params
    for name in ("max_speed", "max_turn_rate", "accel_mps2", "turn_accel_radps2", "lookahead_m"):
        assert table[name].default == 0.0 and table[name].check(0.0) is None
    assert all("robot's" in table[name].doc for name in ("max_speed", "accel_mps2"))
    assert table["max_speed"].check(-0.5) is not None


def test_a_scenario_drives_the_jackal_at_barns_baseline_speed(tmp_path):
    case = generate_protocol(1, 7)[0]
    scenario = parse_scenario(case.toml(), "barn.toml", ["planner.name=dwa", "planner.max_speed=0.5"])
    planner = Run(scenario).planner
    assert isinstance(planner, dwa.DwaPlanner) and planner.robot.profile == "jackal"
    assert planner.limits.max_speed_mps == 0.5 and planner.limits.max_turn_rate_radps == 4.0


@pytest.mark.parametrize("profile", ["jackal", "pioneer3dx", "turtlebot3_burger"])
def test_the_force_maps_back_to_the_command_through_the_robots_own_controller(profile):
    body, robot = robot_body(profile), PROFILES[profile]
    limits = dwa.DwaPlanner.build({}, body).limits
    for yaw in (0.0, 2.0, -3.0):
        for speed in np.linspace(0.0, limits.max_speed_mps, 5):
            for turn in np.linspace(-limits.max_turn_rate_radps, limits.max_turn_rate_radps, 7):
                force = dwa.force_for_command(float(speed), float(turn), yaw, body.gains)
                v, omega = heading_command(*force, yaw, robot.gains, robot.limits)
                assert v == pytest.approx(speed, abs=2 * dwa.CREEP_SPEED)
                assert omega == pytest.approx(turn, abs=1e-9)


def test_a_polygon_robots_window_is_about_its_last_command():
    """The Jackal's drive ramps toward the command: the window follows the commands asked for,
    not the measured turn rate, which on a skid-steer overshoots them."""
    jackal = dwa.DwaPlanner.build({}, JACKAL)
    jackal.step(observe(None, 0.0, (0.0, 0.0), 0.0))
    asked = jackal.command
    assert asked == pytest.approx((0.1, 0.0))  # from rest: a T = 2 m/s^2 x 0.05 s
    speeds, turns = jackal.window(observe(None, PERIOD, (0.0, 0.0), 0.3))  # it spun instead
    assert (speeds[0], speeds[-1]) == pytest.approx((0.0, 0.2))
    assert (turns[0], turns[-1]) == pytest.approx((-0.2, 0.2))  # about 0, not 6 rad/s


def at_rest_on(cells, body=JACKAL, goal=GOAL_FAR, **overrides):
    """A planner for `body` at rest at the origin facing +x, its map holding exactly `cells`
    (world cell centres, m) as obstacles; and its observation."""
    planner = dwa.DwaPlanner.build(overrides, body)
    obs = observe(None, 0.0, (0.0, 0.0), 0.0, goal=goal)
    planner.step(obs)  # no echoes: the map is placed, empty
    cell = planner.map.cell_m
    for x, y in cells:
        world = np.floor(np.array([x, y]) / cell).astype(int)
        assert np.allclose((world + 0.5) * cell, (x, y)), "a cell's centre"
        index = world - planner.map.origin
        planner.map.grid[index[0], index[1]] = planner.map.max_certainty
    return planner, obs


def rectangle_clearance(poses, point):
    """Distance (m) from the Jackal's outline at each pose (N, 3) to a point (exact, outside)."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    dx, dy = point[0] - poses[:, 0], point[1] - poses[:, 1]
    along, across = np.abs(c * dx + s * dy), np.abs(-s * dx + c * dy)
    return np.hypot(np.maximum(along - JACKAL_HALF_LENGTH, 0), np.maximum(across - JACKAL_HALF_WIDTH, 0))


GAP = [(1.05, 0.25), (1.05, -0.25)]
"""Two posts (one map cell each) 0.5 m apart across the way, 1 m ahead: wider than the Jackal
(0.43 m), narrower than its diagonal (0.666 m)."""


def test_the_jackal_drives_through_a_gap_narrower_than_its_diagonal():
    jackal, obs = at_rest_on(GAP, margin_m=0.02)
    speeds, turns = np.array([0.05, 0.1]), np.array([0.0])  # margins 2.5 and 3 cm
    dist = jackal.free_distance(obs, speeds, turns)
    assert np.all(dist == jackal.lookahead)  # 3.5 cm either side
    assert np.all(jackal.stopping_length(speeds, turns) <= dist)
    disc = RobotBody.round(JACKAL.radius_m, limits=JACKAL.limits, gains=JACKAL.gains)
    round_jackal, obs = at_rest_on(GAP, body=disc, margin_m=0.02)
    assert np.all(round_jackal.free_distance(obs, speeds, turns) < 1.05 - JACKAL.radius_m)
    decision = jackal.step(observe(None, PERIOD, (0.0, 0.0), 0.0))
    assert decision.mode == "normal" and command(decision, 0.0)[0] > 0  # on its way through


def test_the_faster_the_wider_the_berth():
    """The margin grows by two control periods' travel: at 0.5 m/s, 2 + 5 cm, more than the
    gap's 3.5 cm either side."""
    jackal, obs = at_rest_on(GAP, margin_m=0.02)
    assert dwa.DRIFT_PERIODS * PERIOD * 0.5 == 0.05
    dist = jackal.free_distance(obs, np.array([0.1, 0.5]), np.array([0.0]))[:, 0]
    ahead = 1.05 - JACKAL_HALF_LENGTH  # where the front reaches the posts' line
    assert dist[0] == jackal.lookahead and ahead - 0.1 < dist[1] < ahead


POST = (0.65, -0.05)
"""A post right of the way, 0.24 m outside the circle of radius 0.9668 m about (0, 0.9668)."""
BEND = 1 / 0.9668
"""The curvature (1/m) of that circle: the centre keeps 0.24 m from the post, more than the
half width and margin, but the front-right corner, which swings out on a left turn, clips it."""


def test_an_arc_whose_corner_would_clip_a_post_is_not_admissible():
    jackal, obs = at_rest_on([POST], margin_m=0.01)
    speeds, turns = np.array([0.05, 2.0]), np.array([0.05, 2.0]) * BEND
    margins = 0.01 + dwa.DRIFT_PERIODS * PERIOD * speeds
    dist = jackal.free_distance(obs, speeds, turns).diagonal()
    travel = np.linspace(0.0, 1.0, 20001)
    points, headings = dwa.arc_poses(obs.position, obs.yaw, travel, BEND * travel)
    centre_gap = np.hypot(*(points - POST).T).min() - JACKAL_HALF_WIDTH
    clearance = rectangle_clearance(np.column_stack((points, headings)), POST)
    assert centre_gap > margins[0] > clearance.min()  # a disc of the half width would pass
    sample = jackal.step_m / (1 + jackal.radius * BEND)  # the centre's travel between two poses
    for margin, free in zip(margins, dist, strict=True):
        clipping = travel[np.argmax(clearance < margin)]  # where the outline comes within it
        assert clipping - sample < free <= clipping
    admissible = jackal.stopping_length(speeds, turns).diagonal() <= dist
    assert list(admissible) == [True, False]  # at 2 m/s the robot cannot stop before it


def test_a_post_inside_the_circumscribed_disc_forbids_a_turn_on_the_spot():
    """Posts 3.5 cm beside the front of each side: turning either way swings a front corner
    into one of them, though the robot stands clear of both."""
    posts = [(0.15, 0.25), (0.15, -0.25)]
    assert all(math.hypot(*post) < JACKAL.radius_m for post in posts)
    jackal, obs = at_rest_on(posts, goal=(0.0, 3.0))
    speeds, turns = jackal.window(observe(None, PERIOD, (0.0, 0.0), 0.0, goal=(0.0, 3.0)))
    dist = jackal.free_distance(obs, speeds, turns)
    spinning = (jackal.stopping_length(speeds, turns) <= dist)[0]
    assert speeds[0] == 0.0 and list(spinning) == list(turns == 0.0)  # only standing still
    round_robot, obs = at_rest_on(posts, body=RobotBody.round(RADIUS), goal=(0.0, 3.0))
    assert np.all(round_robot.free_distance(obs, speeds[:1], turns) == round_robot.lookahead)


def test_a_turn_on_the_spot_is_free_until_a_corner_would_reach_a_post():
    """A post beside the front of the left side, inside the circumscribed disc: turning either
    way is free for the angle the outline turns before it comes within the margin of the post."""
    post = (0.075, 0.275)  # 6 cm beside the side
    assert math.hypot(*post) < JACKAL.radius_m
    jackal, obs = at_rest_on([post], map_cell_m=0.05)
    turns = np.linspace(-4.0, 4.0, 9)
    dist = jackal.free_distance(obs, np.array([0.0]), turns)[0]
    angles = np.linspace(0.0, math.pi, 20001)
    for side in (1.0, -1.0):
        poses = np.column_stack((np.zeros_like(angles), np.zeros_like(angles), side * angles))
        free_angle = angles[np.argmax(rectangle_clearance(poses, post) < jackal.params.margin_m)]
        assert 0.1 < free_angle < 1.2
        length = jackal.radius * free_angle  # what the outermost point travels
        turning = dist[turns * side > 0]
        assert np.all((length - jackal.step_m < turning) & (turning <= length))
    assert dist[turns == 0.0] == jackal.lookahead  # standing still sweeps nothing


# -- Following the map's way ------------------------------------------------------------------

WALL_BUT_ABOVE = [(1.55, y) for y in np.arange(-1.45, 0.6, 0.1)]
"""A wall of cells across the way 1.5 m ahead, from y = -1.45 m to 0.55 m: open above it."""


@pytest.mark.parametrize("body", [JACKAL, RobotBody.round(RADIUS)])
def test_with_follow_way_it_aims_along_the_maps_way_round_a_wall(body):
    fox, obs = at_rest_on(WALL_BUT_ABOVE, body=body, goal=(4.0, 0.0))
    assert np.all(fox.aim(obs) == obs.goal)  # Fox's heading: straight at the wall
    way, obs = at_rest_on(WALL_BUT_ABOVE, body=body, goal=(4.0, 0.0), follow_way=1)
    aim = way.aim(obs)
    # one metre along a way that passes above the wall's end, its centre a passage radius off
    assert np.hypot(*aim) == pytest.approx(1.0, abs=0.15) and aim[1] > 0.5
    decision = way.step(observe(None, PERIOD, (0.0, 0.0), 0.0, goal=(4.0, 0.0)))
    assert command(decision, 0.0)[1] > 0  # it turns toward the opening


def test_with_follow_way_it_aims_at_the_goal_when_the_map_holds_no_way():
    box = [(x, y) for x in np.arange(-1.25, 1.3, 0.1) for y in (-1.25, 1.25)]
    box += [(x, y) for x in (-1.25, 1.25) for y in np.arange(-1.15, 1.2, 0.1)]
    way, obs = at_rest_on(box, goal=(4.0, 0.0), follow_way=1)
    assert np.all(way.aim(obs) == obs.goal)


def laser_scan_with_echo(echo_bearing, echo_range, beams=720):
    """A 270-degree laser's bearings and beam width, one echo at the beam nearest a bearing."""
    bearings = np.linspace(-0.75 * math.pi, 0.75 * math.pi, beams)
    ranges = np.full(beams, np.nan)
    ranges[np.argmin(np.abs(bearings - echo_bearing))] = echo_range
    return bearings, ranges, float(bearings[1] - bearings[0])


def test_a_laser_echo_blocks_the_arcs_before_the_map_is_sure_of_it():
    """One scan leaves the echo's cell below the map's threshold; the polygon check counts the
    scan's own echoes where the map holds no cell (a laser's), a sparse sonar's echo waits for
    the map."""
    for bearings, ranges, beam, blocked in (
        (*laser_scan_with_echo(0.0, 1.05), True),
        (BEARINGS, np.where(np.arange(16) == 0, 1.05, np.nan), BEAM, False),
    ):
        jackal = dwa.DwaPlanner.build({}, JACKAL)
        obs = Observation(0.0, np.zeros(2), 0.0, GOAL_FAR, 0.15, bearings, ranges, beam)
        jackal.step(obs)
        assert not jackal.map.any_cells(jackal.params.map_threshold)  # one scan: not yet sure
        dist = jackal.free_distance(obs, np.array([0.1]), np.array([0.0]))[0, 0]
        assert (dist < 1.05 - JACKAL_HALF_LENGTH) == blocked


# -- The Jackal on BARN protocol worlds ----------------------------------------------------------


def jackal_run(seed, *settings):
    """A run of dwa with the Jackal on the first BARN protocol world of `seed` (start and goal
    10 m apart, the goal's tolerance 1 m)."""
    case = generate_protocol(1, seed)[0]
    return run_scenario(parse_scenario(case.toml(), f"{case.name}.toml", ["planner.name=dwa", *settings]))


def test_the_jackal_crosses_a_barn_protocol_world_at_full_speed_without_collision():
    summary = jackal_run(3).summary
    assert summary.robot_profile == "jackal" and summary.top_speed_mps == 2.0
    assert summary.outcome == "reached" and summary.collisions == 0 and summary.min_clearance_m > 0.02
    assert 9.0 < summary.path_length_m < 10.5
    assert summary.time_to_goal_s < 15.0  # at 0.5 m/s (BARN's baseline) 9 m would take 18 s


def test_following_the_maps_way_it_crosses_a_world_where_the_goals_heading_is_trapped():
    fox = jackal_run(0, "planner.follow_way=0", "planner.clearance_weight=0.2").summary  # Fox's aim
    assert fox.outcome == "stuck" and fox.collisions == 0 and fox.path_length_m < 3.0
    way = jackal_run(0).summary  # the Jackal's own settings: along the map's way
    assert way.planner_params["follow_way"] == 1 and way.planner_params["clearance_weight"] == 0.05
    assert way.outcome == "reached" and way.collisions == 0 and way.min_clearance_m > 0.02
    assert 9.0 < way.path_length_m < 10.5 and way.score == 0.5  # within twice the optimal time
