"""Robot profiles and sensor kinds in scenario files: what each resolves to, and every mistake
refused with exit 2, naming the file (or the option), the key and the reason, nothing written."""

import pytest

from vplane_mj.cli import main
from vplane_mj.robots.profiles import PROFILES
from vplane_mj.scenario import parse_scenario

WORLD = """
format = 1
name = "profiled"
[world]
size = [6.0, 4.0]
[[world.obstacles]]
kind = "box"
center = [3.0, 2.0]
size = [0.4, 0.4]
[robot]
profile = "{profile}"
start = [1.0, 2.0]
goal = [5.0, 2.0]
"""


def scenario(profile="default", overrides=()):
    return parse_scenario(WORLD.format(profile=profile), "profiled.toml", list(overrides))


def write(tmp_path, profile="default", extra=""):
    path = tmp_path / "profiled.toml"
    path.write_text(WORLD.format(profile=profile) + extra, encoding="utf-8")
    return path


def refused(capsys, tmp_path, argv):
    """Run the command line: exit 2, one error line, and no file written in the output directory."""
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 2
    assert not out.exists() or not any(out.iterdir())
    error = capsys.readouterr().err
    assert error.startswith("error: ") and error.count("\n") == 1
    return error


@pytest.mark.parametrize("name", list(PROFILES))
def test_each_profile_brings_its_own_sensor_as_the_default(name):
    sensors = scenario(name).sensors
    expected = dict(PROFILES[name].sensors)
    assert sensors.kind == expected["kind"]
    for key, value in expected.items():
        assert getattr(sensors, key) == value, key


def test_a_kind_the_profile_does_not_carry_takes_that_kinds_generic_defaults():
    laser = scenario("default", ["sensors.kind=laser"]).sensors
    assert (laser.kind, laser.fov_deg, laser.beams) == ("laser", 360.0, 360)
    sonar = scenario("jackal", ["sensors.kind=sonar"]).sensors
    assert (sonar.kind, sonar.count, sonar.range_max) == ("sonar", 16, 3.0)
    assert all(getattr(sonar, key) == value for key, value in PROFILES["default"].sensors.items())
    # A key the scenario gives wins over the profile's.
    assert scenario("jackal", ["sensors.beams=16"]).sensors.beams == 16


def test_the_profile_gives_the_tyres_their_friction_unless_the_scenario_does():
    assert scenario("jackal").robot.wheel_friction == PROFILES["jackal"].wheel_friction == 0.5
    assert scenario("jackal", ["robot.wheel_friction=0.8"]).robot.wheel_friction == 0.8
    assert scenario().robot.wheel_friction == 1.0


@pytest.mark.parametrize("key", ["count", "rays_per_sonar", "beam_deg", "crosstalk", "dead"])
def test_a_sonar_key_under_a_laser_is_refused_by_name(capsys, tmp_path, key):
    value = {"dead": "[1]", "crosstalk": "0.1", "beam_deg": "10.0", "count": "16"}.get(key, "3")
    path = write(tmp_path, "jackal", f"[sensors]\n{key} = {value}\n")
    error = refused(capsys, tmp_path, ["run", str(path)])
    assert f"{path}: sensors.{key}: a sonar key, but this sensor is kind = 'laser'" in error


@pytest.mark.parametrize("key", ["fov_deg", "beams", "range_min"])
def test_a_laser_key_under_a_sonar_is_refused_by_name(capsys, tmp_path, key):
    error = refused(capsys, tmp_path, ["run", str(write(tmp_path)), "--set", f"sensors.{key}=90"])
    assert error.startswith(f"error: --set sensors.{key}: a laser key, but this sensor is kind = 'sonar'")


def test_an_unknown_profile_lists_the_known_ones_and_the_closest(capsys, tmp_path):
    error = refused(capsys, tmp_path, ["run", str(write(tmp_path, "jackall"))])
    assert "robot.profile: must be one of 'default', 'jackal', 'pioneer3dx', 'turtlebot3_burger'" in error
    assert "did you mean 'jackal'?" in error


def test_a_start_where_the_footprint_overlaps_an_obstacle_is_refused(capsys, tmp_path):
    # The jackal reaches 0.254 m ahead of its centre: 2.55 m puts its front 0.004 m into the box's face.
    path = write(tmp_path, "jackal")
    error = refused(capsys, tmp_path, ["run", str(path), "--set", "robot.start=[2.55, 2.0]"])
    assert "--set robot.start: the jackal robot's footprint at yaw 0 deg overlaps obstacle " in error
    assert "world.obstacles[0] (by 0.004 m)" in error
    # The round default robot fits there: 0.25 m from the face, more than its 0.11 m radius.
    assert scenario("default", ["robot.start=[2.55, 2.0]"]).robot.start == (2.55, 2.0)


def test_a_goal_the_footprint_fits_in_no_heading_is_refused(capsys, tmp_path):
    # 0.2 m from the box: closer than the jackal's half width (0.215 m), whichever way it faces.
    error = refused(
        capsys, tmp_path, ["run", str(write(tmp_path, "jackal")), "--set", "robot.goal=[3.4, 2.0]"]
    )
    assert "robot.goal: the jackal robot's footprint in every heading overlaps obstacle" in error


def test_the_pioneers_sonars_are_its_own(capsys, tmp_path):
    error = refused(capsys, tmp_path, ["run", str(write(tmp_path, "pioneer3dx")), "--set", "sensors.count=8"])
    assert "sensors.count: the pioneer3dx profile's 16 sonars sit where the robot has them" in error
    assert scenario("pioneer3dx", ["sensors.dead=[15]"]).sensors.dead == (15,)


def test_range_limits_are_checked_per_kind(capsys, tmp_path):
    error = refused(
        capsys, tmp_path, ["run", str(write(tmp_path, "jackal")), "--set", "sensors.range_min=40"]
    )
    assert "sensors.range_min: range_min (40 m) must be less than range_max (30 m)" in error
    error = refused(capsys, tmp_path, ["run", str(write(tmp_path)), "--set", "sensors.range_max=30"])
    assert "sensors.range_max: a sonar reaches at most 20 m, got 30.0" in error
    assert scenario("default", ["sensors.kind=laser", "sensors.range_max=30"]).sensors.range_max == 30.0
