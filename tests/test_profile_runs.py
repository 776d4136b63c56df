"""Real runs of the robot profiles: the laser read at its own rate, the footprint in the summary
and the log, the pioneer's sonars at their places."""

import dataclasses
import math

import numpy as np
import pytest

import vplane_mj
from vplane_mj.logs.reader import iter_messages, read_log
from vplane_mj.robots.profiles import PROFILES, ProfileError
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import Run


@pytest.fixture(scope="module")
def jackal_run(tmp_path_factory):
    """The jackal on the paper's C trap for 3 s, with its log."""
    out = tmp_path_factory.mktemp("jackal")
    scenario = load_scenario("paper_c_escape", ["robot.profile=jackal", "run.time_limit_s=3"])
    return vplane_mj.run(scenario, out, render=False)


def test_a_jackal_summary_names_its_robot_footprint_speed_and_sensor(jackal_run):
    summary = jackal_run.summary
    assert (summary.robot_profile, summary.sensor_kind, summary.top_speed_mps) == ("jackal", "laser", 2.0)
    corners = sorted(map(tuple, summary.footprint_m))
    assert corners == sorted(PROFILES["jackal"].footprint_m)
    assert summary.robot_radius_m == pytest.approx(math.hypot(0.254, 0.215), abs=1e-6)
    # Measured from the outline: the robot starts 0.58 m from the trap's mouth, nearer to nothing else.
    assert 0.0 < summary.min_clearance_m < math.dist(summary.footprint_m[0], (0, 0)) + 1.0


def test_a_jackal_log_holds_its_laser_scan_and_its_outline(jackal_run):
    path = jackal_run.files["log"]
    scans = [message.message for message in iter_messages(path, ("/scan",))]
    assert len(scans) == len(jackal_run.trajectory.times) + 1  # every tick, and the final state
    first = scans[0]
    assert len(first.ranges) == 720 and first.frame_id == "base_link"
    assert first.start_angle == pytest.approx(-math.radians(135)) and first.end_angle == pytest.approx(
        math.radians(135)
    )
    ranges = np.array(first.ranges)
    assert np.isfinite(ranges).any() and np.nanmin(ranges) >= 0.1 and np.nanmax(ranges) <= 30.0
    (world,) = [message.message for message in iter_messages(path, ("/world",))]
    robot = next(entity for entity in world.entities if entity.id == "robot")
    assert not robot.cylinders and len(robot.lines) == 1 and len(robot.triangles) == 1
    outline = sorted((round(p.x, 6), round(p.y, 6)) for p in robot.lines[0].points)
    assert outline == sorted(PROFILES["jackal"].footprint_m)
    metadata = read_log(path).metadata["vplane_mj"]
    assert (metadata["robot_profile"], metadata["sensor_kind"]) == ("jackal", "laser")


def test_a_slow_laser_is_read_only_at_its_rate():
    # The Burger's laser turns at 5 Hz; the planner runs at 20 Hz and sees each scan four times.
    scenario = load_scenario("paper_c_escape", ["robot.profile=turtlebot3_burger", "run.time_limit_s=2"])
    run = Run(scenario)
    scans, stamps = [], []
    while (observation := run.observe()) is not None:
        scans.append((observation.time_s, observation.ranges.copy()))
        stamps.append(observation.scan_time_s)
        run.apply(run.planner.step(observation))
    changes = [
        t
        for (t, now), (_, before) in zip(scans[1:], scans, strict=False)
        if not np.array_equal(now, before, equal_nan=True)
    ]
    assert len(scans) >= 39
    assert changes == pytest.approx([0.2 * k for k in range(1, len(changes) + 1)], abs=1e-6)
    assert sorted(set(stamps)) == pytest.approx([0.0, *changes], abs=1e-6)  # each tick says which scan


def test_the_pioneer_sonars_show_on_a_one_degree_scan(tmp_path):
    scenario = load_scenario("paper_c_escape", ["robot.profile=pioneer3dx", "run.time_limit_s=1"])
    record = vplane_mj.run(scenario, tmp_path, render=False)
    scan = next(message.message for message in iter_messages(record.files["log"], ("/scan",)))
    assert len(scan.ranges) == 360 and scan.start_angle == pytest.approx(-math.pi)
    headings = {round(heading) % 360 for _, _, heading in PROFILES["pioneer3dx"].sonar_mounts}
    slots = {(heading + 180) % 360 for heading in headings}
    echoes = {index for index, value in enumerate(scan.ranges) if math.isfinite(value)}
    assert echoes and echoes <= slots  # readings only where a sonar looks


def test_a_run_of_a_scenario_with_an_unknown_profile_suggests_the_name():
    # A scenario file is checked as it is read; one changed in code is checked when it runs.
    scenario = load_scenario("open_field")
    wrong = dataclasses.replace(scenario, robot=dataclasses.replace(scenario.robot, profile="turtlebot3"))
    with pytest.raises(ProfileError, match="did you mean 'turtlebot3_burger'"):
        Run(wrong)
