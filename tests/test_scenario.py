"""Scenario files: the contract's format, every validation rule, overrides, round trips."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vplane_mj import scenario as scenario_module
from vplane_mj.errors import ScenarioError
from vplane_mj.geometry.shapes import Box, Cup, Cylinder, HShape, Wall
from vplane_mj.planning.protocol import registry
from vplane_mj.scenario import (
    RunSpec,
    Scenario,
    SensorSpec,
    builtin_scenarios,
    load_scenario,
    parse_scenario,
    resolve_path,
)

HEAD = 'format = 1\nname = "t"\n'
WORLD = "[world]\nsize = [10.0, 10.0]\n"
ROBOT = "[robot]\nstart = [1.0, 1.0]\ngoal = [9.0, 9.0]\n"
PLANNER = '[planner]\nname = "apf"\n'
MINIMAL = HEAD + WORLD + ROBOT + PLANNER

FULL = """
format = 1
name = "full_example"
description = "every obstacle kind and every optional key"

[world]
size = [10.0, 8]
border = true

[[world.obstacles]]
kind = "box"
center = [2.0, 2.0]
size = [0.5, 1.0]
yaw_deg = 90

[[world.obstacles]]
kind = "wall"
from = [4.0, 1.0]
to = [4.0, 3.0]
thickness = 0.1

[[world.obstacles]]
kind = "cylinder"
center = [7.0, 2.0]
radius = 0.3

[[world.obstacles]]
kind = "u"
center = [5.0, 6.0]
yaw_deg = 180
width = 1.6
depth = 1.2
thickness = 0.05

[[world.obstacles]]
kind = "c"
center = [8.0, 6.0]
width = 1.0
depth = 0.8

[[world.obstacles]]
kind = "h"
center = [2.0, 6.0]
length = 1.0
width = 1.2
yaw_deg = -45
thickness = 0.08

[robot]
start = [1.0, 4.0]
start_yaw_deg = 30
goal = [9.0, 4.0]
goal_tolerance = 0.2
wheel_friction = 0.5
motor_gain = [0.9, 1]
motor_bias_nm = [0, -0.02]

[planner]
name = "apf"
attract_gain = 0.7
influence = 1

[sensors]
noise_std = 0.01
dropout = 0.05
crosstalk = 0.02
dead = [23, 4]
pose = "odometry"
odometry_noise = 0.01
count = 24
rays_per_sonar = 5
beam_deg = 25
range_max = 4.0
rate_hz = 10

[run]
seed = 7
time_limit_s = 120
physics_dt_s = 0.004
control_hz = 25
"""


def obstacle(body: str) -> str:
    """MINIMAL with one obstacle table whose lines are `body`."""
    return MINIMAL + "[[world.obstacles]]\n" + body


def errors_of(text: str, overrides=()) -> ScenarioError:
    """The ScenarioError that parsing `text` with `overrides` raises."""
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, "scenarios/x.toml", overrides)
    return info.value


# --------------------------------------------------------------------------- valid input


def test_full_example_loads_with_every_value():
    s = parse_scenario(FULL, "full.toml")
    assert (s.name, s.source) == ("full_example", "full.toml")
    assert s.description == "every obstacle kind and every optional key"
    assert s.world.size == (10.0, 8.0) and s.world.border is True
    box, wall, cylinder, cup, c_cup, h = s.world.obstacles
    assert box == Box(center=(2.0, 2.0), size=(0.5, 1.0), yaw=math.pi / 2)
    assert wall == Wall(start=(4.0, 1.0), end=(4.0, 3.0), thickness=0.1)
    assert cylinder == Cylinder(center=(7.0, 2.0), radius=0.3)
    assert cup == Cup(center=(5.0, 6.0), width=1.6, depth=1.2, yaw=math.pi, thickness=0.05)
    assert c_cup == Cup(center=(8.0, 6.0), width=1.0, depth=0.8)
    assert h == HShape(center=(2.0, 6.0), length=1.0, width=1.2, yaw=-math.pi / 4, thickness=0.08)
    assert s.robot.start == (1.0, 4.0) and s.robot.goal == (9.0, 4.0)
    assert s.robot.start_yaw == pytest.approx(math.radians(30))
    assert s.robot.goal_tolerance == 0.2
    assert (s.robot.wheel_friction, s.robot.motor_gain, s.robot.motor_bias_nm) == (
        0.5,
        (0.9, 1.0),
        (0, -0.02),
    )
    assert s.planner == "apf"
    assert dict(s.planner_params) == {"attract_gain": 0.7, "influence": 1.0}
    assert s.sensors == SensorSpec(0.01, 0.05, 0.02, (4, 23), "odometry", 0.01, 24, 5, 25.0, 4.0, 10.0)
    assert s.run == RunSpec(seed=7, time_limit_s=120.0, physics_dt_s=0.004, control_hz=25.0)
    assert isinstance(s.run.seed, int) and isinstance(s.run.time_limit_s, float)


def test_minimal_example_takes_the_defaults():
    s = parse_scenario(MINIMAL, "min.toml")
    assert s.description == ""
    assert s.world.border is True and s.world.obstacles == ()
    assert s.robot.goal_tolerance == 0.15
    assert (s.robot.wheel_friction, s.robot.motor_gain, s.robot.motor_bias_nm) == (
        1.0,
        (1.0, 1.0),
        (0.0, 0.0),
    )
    assert dict(s.planner_params) == {}
    assert s.sensors == SensorSpec()
    assert s.run == RunSpec()
    assert (s.sensors.count, s.run.seed, s.run.time_limit_s) == (16, 0, 300.0)


@pytest.mark.parametrize(
    ("start", "goal", "yaw"),
    [
        ("[1, 1]", "[9, 9]", math.pi / 4),
        ("[5, 8]", "[5, 2]", -math.pi / 2),
        ("[9, 5]", "[1, 5]", math.pi),
    ],
)
def test_start_yaw_faces_the_goal_by_default(start, goal, yaw):
    robot = f"[robot]\nstart = {start}\ngoal = {goal}\n"
    s = parse_scenario(HEAD + WORLD + robot + PLANNER, "yaw.toml")
    assert s.robot.start_yaw == pytest.approx(yaw)


def test_border_false_allows_points_on_the_arena_edge():
    s = parse_scenario(MINIMAL, "x", ["world.border=false", "robot.start=[0, 0]"])
    assert s.robot.start == (0.0, 0.0)


def test_resolved_scenario_is_read_only():
    s = parse_scenario(FULL, "full.toml")
    with pytest.raises(TypeError):
        s.raw["name"] = "other"  # type: ignore[index]
    with pytest.raises(TypeError):
        s.planner_params["influence"] = 2.0  # type: ignore[index]


def test_default_planner_is_used_when_absent(monkeypatch):
    monkeypatch.setattr(registry, "DEFAULT_PLANNER", "apf")
    assert parse_scenario(HEAD + WORLD + ROBOT, "x").planner == "apf"
    assert parse_scenario(HEAD + WORLD + ROBOT + "[planner]\n", "x").planner == "apf"


def test_unregistered_default_planner_fails_cleanly(monkeypatch):
    monkeypatch.setattr(registry, "DEFAULT_PLANNER", "not_registered")
    err = errors_of(HEAD + WORLD + ROBOT)
    assert err.key == "planner.name"
    assert "not_registered" in err.reason and "default" in err.reason and "apf" in err.reason


def test_message_names_source_key_and_reason():
    err = errors_of(obstacle('kind = "u"\ncenter = [5, 5]\nwidth = 0.08\ndepth = 1\n'))
    assert str(err) == (
        "scenarios/x.toml: world.obstacles[0].width: must be greater than 2*thickness (0.1), got 0.08"
    )
    assert err.source == "scenarios/x.toml"


# --------------------------------------------------------------------------- invalid input

BAD_CASES = [
    # top level
    ("no_format", HEAD.replace("format = 1\n", "") + WORLD + ROBOT, (), "format", "missing"),
    ("format_2", MINIMAL, ["format=2"], "format", "must be 1"),
    ("format_float", MINIMAL, ["format=1.0"], "format", "must be 1"),
    ("format_bool", MINIMAL, ["format=true"], "format", "must be 1"),
    ("no_name", "format = 1\n" + WORLD + ROBOT + PLANNER, (), "name", "missing"),
    ("bad_name", MINIMAL, ['name="Bad Name"'], "name", "[a-z0-9_]+"),
    ("description_number", MINIMAL, ["description=3"], "description", "must be a string"),
    ("unknown_top_key", MINIMAL, ["colour=1"], "colour", "unknown key"),
    ("unknown_quoted_key", HEAD + '"a b" = 1\n' + WORLD + ROBOT, (), '"a b"', "unknown key"),
    ("unknown_empty_key", HEAD + '"" = 1\n' + WORLD + ROBOT, (), '""', "unknown key"),
    # world
    ("no_world", HEAD + ROBOT + PLANNER, (), "world", "missing"),
    ("world_not_table", HEAD + "world = 3\n" + ROBOT + PLANNER, (), "world", "must be a table"),
    ("unknown_world_key", MINIMAL, ["world.gravity=9.8"], "world.gravity", "unknown key"),
    ("unknown_world_table", MINIMAL + "[world.extra]\na = 1\n", (), "world.extra", "unknown key"),
    ("no_size", HEAD + "[world]\nborder = true\n" + ROBOT, (), "world.size", "missing"),
    ("size_one_number", MINIMAL, ["world.size=[10]"], "world.size", "exactly 2"),
    ("size_not_array", MINIMAL, ["world.size=10"], "world.size", "array of 2 numbers"),
    ("size_negative", MINIMAL, ["world.size=[10, -1]"], "world.size", "greater than 0"),
    ("size_inf", MINIMAL, ["world.size=[10, inf]"], "world.size", "finite"),
    ("size_nan", MINIMAL, ["world.size=[nan, 10]"], "world.size", "finite"),
    ("size_bool", MINIMAL, ["world.size=[10, true]"], "world.size", "must be a number"),
    ("border_int", MINIMAL, ["world.border=1"], "world.border", "true or false"),
    ("obstacles_not_array", MINIMAL, ["world.obstacles=3"], "world.obstacles", "array"),
    ("obstacle_not_table", MINIMAL, ["world.obstacles=[1]"], "world.obstacles[0]", "table"),
    # obstacles
    (
        "no_kind",
        obstacle("center = [5, 5]\nradius = 1\n"),
        (),
        "world.obstacles[0].kind",
        "missing",
    ),
    ("kind_number", obstacle("kind = 3\n"), (), "world.obstacles[0].kind", "must be a string"),
    (
        "unknown_kind",
        obstacle('kind = "star"\n'),
        (),
        "world.obstacles[0].kind",
        "unknown obstacle",
    ),
    (
        "box_unknown_key",
        obstacle('kind = "box"\ncenter = [5, 5]\nsize = [1, 1]\nradius = 1\n'),
        (),
        "world.obstacles[0].radius",
        "unknown key",
    ),
    (
        "box_zero_size",
        obstacle('kind = "box"\ncenter = [5, 5]\nsize = [0, 1]\n'),
        (),
        "world.obstacles[0].size",
        "greater than 0",
    ),
    (
        "box_no_size",
        obstacle('kind = "box"\ncenter = [5, 5]\n'),
        (),
        "world.obstacles[0].size",
        "missing",
    ),
    (
        "wall_no_length",
        obstacle('kind = "wall"\nfrom = [3, 3]\nto = [3, 3]\n'),
        (),
        "world.obstacles[0].to",
        "differ",
    ),
    (
        "wall_zero_thickness",
        obstacle('kind = "wall"\nfrom = [3, 3]\nto = [3, 5]\nthickness = 0\n'),
        (),
        "world.obstacles[0].thickness",
        "greater than 0",
    ),
    (
        "wall_yaw",
        obstacle('kind = "wall"\nfrom = [3, 3]\nto = [3, 5]\nyaw_deg = 10\n'),
        (),
        "world.obstacles[0].yaw_deg",
        "unknown key",
    ),
    (
        "cylinder_negative_radius",
        obstacle('kind = "cylinder"\ncenter = [5, 5]\nradius = -0.1\n'),
        (),
        "world.obstacles[0].radius",
        "greater than 0",
    ),
    (
        "cylinder_center_3d",
        obstacle('kind = "cylinder"\ncenter = [5, 5, 0]\nradius = 1\n'),
        (),
        "world.obstacles[0].center",
        "exactly 2",
    ),
    (
        "u_narrow",
        obstacle('kind = "u"\ncenter = [5, 5]\nwidth = 0.08\ndepth = 1\n'),
        (),
        "world.obstacles[0].width",
        "must be greater than 2*thickness (0.1), got 0.08",
    ),
    (
        "u_shallow",
        obstacle('kind = "u"\ncenter = [5, 5]\nwidth = 1\ndepth = 0.05\n'),
        (),
        "world.obstacles[0].depth",
        "greater than thickness (0.05)",
    ),
    (
        "c_width_equals_2t",
        obstacle('kind = "c"\ncenter = [5, 5]\nwidth = 0.2\ndepth = 1\nthickness = 0.1\n'),
        (),
        "world.obstacles[0].width",
        "2*thickness (0.2)",
    ),
    (
        "h_short",
        obstacle('kind = "h"\ncenter = [5, 5]\nlength = 0.05\nwidth = 1\n'),
        (),
        "world.obstacles[0].length",
        "greater than thickness",
    ),
    (
        "h_narrow",
        obstacle('kind = "h"\ncenter = [5, 5]\nlength = 1\nwidth = 0.1\n'),
        (),
        "world.obstacles[0].width",
        "2*thickness",
    ),
    (
        "h_yaw_nan",
        obstacle('kind = "h"\ncenter = [5, 5]\nlength = 1\nwidth = 1\nyaw_deg = nan\n'),
        (),
        "world.obstacles[0].yaw_deg",
        "finite",
    ),
    (
        "h_depth_key",
        obstacle('kind = "h"\ncenter = [5, 5]\nlength = 1\nwidth = 1\ndepth = 1\n'),
        (),
        "world.obstacles[0].depth",
        "unknown key",
    ),
    (
        "second_obstacle",
        obstacle('kind = "cylinder"\ncenter = [5, 5]\nradius = 1\n')
        + '[[world.obstacles]]\nkind = "cylinder"\ncenter = [5, 5]\nradius = 0\n',
        (),
        "world.obstacles[1].radius",
        "greater than 0",
    ),
    # robot
    ("no_robot", HEAD + WORLD + PLANNER, (), "robot", "missing"),
    ("no_start", HEAD + WORLD + "[robot]\ngoal = [9, 9]\n", (), "robot.start", "missing"),
    ("no_goal", HEAD + WORLD + "[robot]\nstart = [1, 1]\n", (), "robot.goal", "missing"),
    ("start_string_item", MINIMAL, ['robot.start=[1, "a"]'], "robot.start", "item 1"),
    ("start_three_numbers", MINIMAL, ["robot.start=[1, 1, 1]"], "robot.start", "exactly 2"),
    ("goal_outside", MINIMAL, ["robot.goal=[11, 5]"], "robot.goal", "inside the arena"),
    ("start_negative", MINIMAL, ["robot.start=[-1, 5]"], "robot.start", "inside the arena"),
    (
        "goal_outside_no_border",
        MINIMAL,
        ["world.border=false", "robot.goal=[5, 10.5]"],
        "robot.goal",
        "inside the arena",
    ),
    ("start_at_border", MINIMAL, ["robot.start=[0.05, 5]"], "robot.start", "border wall"),
    (
        "start_inside_obstacle",
        obstacle('kind = "box"\ncenter = [1, 1]\nsize = [1, 1]\n'),
        (),
        "robot.start",
        "inside obstacle world.obstacles[0]",
    ),
    (
        "goal_near_obstacle",
        obstacle('kind = "cylinder"\ncenter = [9, 9.5]\nradius = 0.45\n'),
        (),
        "robot.goal",
        "robot radius",
    ),
    ("start_yaw_inf", MINIMAL, ["robot.start_yaw_deg=inf"], "robot.start_yaw_deg", "finite"),
    ("start_yaw_string", MINIMAL, ["robot.start_yaw_deg=north"], "robot.start_yaw_deg", "number"),
    ("start_yaw_turns", MINIMAL, ["robot.start_yaw_deg=720"], "robot.start_yaw_deg", "at most 360"),
    ("start_yaw_huge", MINIMAL, ["robot.start_yaw_deg=-1e300"], "robot.start_yaw_deg", "at least -360"),
    ("goal_tolerance_zero", MINIMAL, ["robot.goal_tolerance=0"], "robot.goal_tolerance", "than 0"),
    (
        "goal_tolerance_bool",
        MINIMAL,
        ["robot.goal_tolerance=true"],
        "robot.goal_tolerance",
        "number",
    ),
    ("goal_tolerance_wide", MINIMAL, ["robot.goal_tolerance=100"], "robot.goal_tolerance", "at most 5"),
    ("robot_unknown_key", MINIMAL, ["robot.speed=1"], "robot.speed", "unknown key"),
    # planner
    ("planner_not_table", HEAD + 'planner = "apf"\n' + WORLD + ROBOT, (), "planner", "table"),
    ("unknown_planner", MINIMAL, ["planner.name=nope"], "planner.name", "available: apf"),
    ("planner_name_number", MINIMAL, ["planner.name=3"], "planner.name", "must be a string"),
    ("unknown_planner_param", MINIMAL, ["planner.eta=2.0"], "planner.eta", "not a parameter"),
    ("param_range", MINIMAL, ["planner.attract_gain=-1"], "planner.attract_gain", "greater than 0"),
    ("param_bool", MINIMAL, ["planner.attract_gain=true"], "planner.attract_gain", "number"),
    ("param_inf", MINIMAL, ["planner.influence=inf"], "planner.influence", "finite"),
    ("param_huge_int", MINIMAL, ["planner.influence=" + "9" * 400], "planner.influence", "finite"),
    # sensors
    ("sensors_not_table", MINIMAL, ["sensors=3"], "sensors", "must be a table"),
    ("dropout_one", MINIMAL, ["sensors.dropout=1"], "sensors.dropout", "less than 1"),
    ("dropout_negative", MINIMAL, ["sensors.dropout=-0.1"], "sensors.dropout", "at least 0"),
    ("noise_negative", MINIMAL, ["sensors.noise_std=-0.01"], "sensors.noise_std", "at least 0"),
    ("count_float", MINIMAL, ["sensors.count=16.0"], "sensors.count", "integer"),
    ("count_large", MINIMAL, ["sensors.count=129"], "sensors.count", "at most 128"),
    ("count_small", MINIMAL, ["sensors.count=3"], "sensors.count", "at least 4"),
    ("rays_zero", MINIMAL, ["sensors.rays_per_sonar=0"], "sensors.rays_per_sonar", "at least 1"),
    ("beam_wide", MINIMAL, ["sensors.beam_deg=61"], "sensors.beam_deg", "at most 60"),
    ("range_short", MINIMAL, ["sensors.range_max=0.2"], "sensors.range_max", "greater than 0.2"),
    ("rate_zero", MINIMAL, ["sensors.rate_hz=0"], "sensors.rate_hz", "greater than 0"),
    ("rate_slow", MINIMAL, ["sensors.rate_hz=0.001"], "sensors.rate_hz", "at least run.control_hz / 10"),
    (
        "rate_slow_for_control",
        MINIMAL,
        ["sensors.rate_hz=4", "run.control_hz=50"],
        "sensors.rate_hz",
        "that is 5 Hz, got 4.0",
    ),
    (
        "control_fast_for_profile_rate",
        MINIMAL,
        ["robot.profile=turtlebot3_burger", "run.control_hz=60"],
        "run.control_hz",
        "rate_hz (5 Hz, its default for this robot), that is 50 Hz",
    ),
    ("sensors_unknown_key", MINIMAL, ["sensors.fov=1"], "sensors.fov", "unknown key"),
    # run
    ("seed_negative", MINIMAL, ["run.seed=-1"], "run.seed", "at least 0"),
    ("seed_large", MINIMAL, ["run.seed=4294967296"], "run.seed", "less than 4294967296"),
    ("seed_float", MINIMAL, ["run.seed=1.5"], "run.seed", "integer"),
    ("time_limit_negative", MINIMAL, ["run.time_limit_s=-1"], "run.time_limit_s", "than 0"),
    ("time_limit_long", MINIMAL, ["run.time_limit_s=86401"], "run.time_limit_s", "at most 86400"),
    ("time_limit_date", MINIMAL, ["run.time_limit_s=1979-05-27"], "run.time_limit_s", "date"),
    ("dt_large", MINIMAL, ["run.physics_dt_s=0.1"], "run.physics_dt_s", "at most 0.01"),
    ("control_fast", MINIMAL, ["run.control_hz=1000"], "run.control_hz", "at most 200"),
    (
        "control_below_dt",
        MINIMAL,
        ["run.physics_dt_s=0.01", "run.control_hz=200"],
        "run.control_hz",
        "physics_dt_s",
    ),
    ("run_unknown_key", MINIMAL, ["run.steps=10"], "run.steps", "unknown key"),
]


@pytest.mark.parametrize(
    ("text", "overrides", "key", "fragment"),
    [pytest.param(*case[1:], id=case[0]) for case in BAD_CASES],
)
def test_invalid_scenario_names_key_and_reason(text, overrides, key, fragment):
    err = errors_of(text, overrides)
    assert err.key == key
    assert fragment in err.reason
    set_keys = [override.partition("=")[0] for override in overrides]
    if any(key == set_key or key.startswith((f"{set_key}.", f"{set_key}[")) for set_key in set_keys):
        # A key an override set: the message names the override, not the file.
        assert str(err) == f"overrides {key}: {err.reason} (applied to scenarios/x.toml)"
    else:
        assert str(err) == f"scenarios/x.toml: {key}: {err.reason}"


# --------------------------------------------------------------------------- files and names


def test_missing_file(tmp_path):
    ref = str(tmp_path / "nope.toml")
    with pytest.raises(ScenarioError, match="no such file or built-in scenario") as info:
        load_scenario(ref)
    assert (info.value.source, info.value.key) == (ref, "")


def test_unknown_scenario_name():
    with pytest.raises(ScenarioError, match="no such file or built-in scenario"):
        load_scenario("no_scenario_has_this_name")


def test_directory_is_rejected(tmp_path):
    with pytest.raises(ScenarioError, match="is a directory"):
        load_scenario(str(tmp_path))


def test_non_utf8_file_is_rejected(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(MINIMAL.replace('"t"', '"caf\xe9"').encode("latin-1"))
    with pytest.raises(ScenarioError, match="UTF-8") as info:
        load_scenario(str(path))
    assert info.value.source == str(path)


def test_toml_syntax_error_quotes_line_and_column(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("format = 1\nname = \n", encoding="utf-8")
    with pytest.raises(ScenarioError, match="invalid TOML") as info:
        load_scenario(str(path))
    assert "line 2" in info.value.reason and "column" in info.value.reason


def test_load_from_path_keeps_the_path_as_source(tmp_path):
    path = tmp_path / "ok.toml"
    path.write_text(MINIMAL, encoding="utf-8")
    s = load_scenario(str(path), ["run.seed=3"])
    assert (s.source, s.run.seed) == (str(path), 3)
    path.write_text(MINIMAL.replace("10.0, 10.0", "10.0, -1"), encoding="utf-8")
    with pytest.raises(ScenarioError) as info:
        load_scenario(str(path))
    assert str(info.value).startswith(f"{path}: world.size: ")


def _with_description(name: str) -> str:
    """MINIMAL named `name`, with a description."""
    return MINIMAL.replace('name = "t"', f'name = "{name}"\ndescription = "about {name}"')


@pytest.fixture
def builtin_dir(tmp_path, monkeypatch) -> Path:
    """A fake built-in scenario folder holding two scenarios; the working folder is tmp_path."""
    folder = tmp_path / "builtin"
    folder.mkdir()
    for name in ("zeta_two", "alpha_one"):
        (folder / f"{name}.toml").write_text(_with_description(name), "utf-8")
    monkeypatch.setattr(scenario_module, "data_dir", lambda kind: folder)
    monkeypatch.chdir(tmp_path)
    return folder


def test_builtin_scenarios_are_listed_sorted(builtin_dir):
    assert builtin_scenarios() == [("alpha_one", "about alpha_one"), ("zeta_two", "about zeta_two")]


def test_name_resolves_to_builtin(builtin_dir):
    assert resolve_path("alpha_one") == builtin_dir / "alpha_one.toml"
    s = load_scenario("alpha_one")
    assert s.name == "alpha_one" and s.source == str(builtin_dir / "alpha_one.toml")


def test_local_scenarios_folder_comes_first(builtin_dir):
    local = Path("scenarios")
    local.mkdir()
    (local / "alpha_one.toml").write_text(_with_description("local_copy"), "utf-8")
    assert resolve_path("alpha_one") == local / "alpha_one.toml"
    assert load_scenario("alpha_one").name == "local_copy"


SHIPPED = [
    "corridor",
    "open_field",
    "paper_c_avoid",
    "paper_c_escape",
    "paper_h_avoid",
    "paper_h_escape",
    "single_box",
    "walled_goal",
]
"""The scenarios the package ships (docs/scenarios.md), sorted by name."""


def test_shipped_scenarios_all_validate():
    listed = builtin_scenarios()
    assert [name for name, _ in listed] == SHIPPED
    assert all(description for _, description in listed)
    assert [load_scenario(name).name for name in SHIPPED] == SHIPPED  # each validated, as any file


# --------------------------------------------------------------------------- overrides


def test_override_float_list_and_strings():
    s = parse_scenario(
        MINIMAL,
        "x",
        ["planner.attract_gain=2.5", "robot.goal=[8, 7]", "description=just some words"],
    )
    assert dict(s.planner_params) == {"attract_gain": 2.5}
    assert s.robot.goal == (8.0, 7.0)
    assert s.description == "just some words"
    assert parse_scenario(MINIMAL, "x", ['description="quoted"']).description == "quoted"


def test_override_bare_word_creates_missing_table():
    s = parse_scenario(HEAD + WORLD + ROBOT, "x", ["planner.name=apf", "sensors.count=32"])
    assert (s.planner, s.sensors.count) == ("apf", 32)
    assert s.raw["planner"] == {"name": "apf"}


@pytest.mark.parametrize("key", ["world.obstacles.1.radius", "world.obstacles[1].radius"])
def test_override_obstacle_field_by_index(key):
    text = obstacle('kind = "cylinder"\ncenter = [5, 5]\nradius = 1\n') + (
        '[[world.obstacles]]\nkind = "cylinder"\ncenter = [3, 7]\nradius = 0.5\n'
    )
    s = parse_scenario(text, "x", [f"{key}=0.25"])
    assert s.world.obstacles[1] == Cylinder(center=(3.0, 7.0), radius=0.25)
    assert s.world.obstacles[0].radius == 1.0


@pytest.mark.parametrize("key", ["robot.goal.0", "robot.goal[0]"])
def test_override_array_item(key):
    assert parse_scenario(MINIMAL, "x", [f"{key}=8"]).robot.goal == (8.0, 9.0)


@pytest.mark.parametrize(
    ("override", "key", "fragment"),
    [
        ("robot.goal", "robot.goal", "KEY=VALUE"),
        ("=3", "", "key before '=' is empty"),
        ("world.obstacles[5].radius=1", "world.obstacles[5].radius", "out of range"),
        ("world.obstacles.5.radius=1", "world.obstacles.5.radius", "out of range"),
        ("robot.goal[2]=1", "robot.goal[2]", "out of range"),
        ("world.obstacles.radius=1", "world.obstacles.radius", "index it like"),
        ("world[0]=1", "world[0]", "table, it cannot be indexed"),
        ("name[0]=1", "name[0]", "string, it cannot be indexed"),
        ("name.first=1", "name.first", "string, it cannot be indexed"),
        ("robot..goal=1", "robot..goal", "malformed key"),
        ("robot.goal[x]=1", "robot.goal[x]", "malformed key"),
    ],
)
def test_malformed_override(override, key, fragment):
    text = obstacle('kind = "cylinder"\ncenter = [5, 5]\nradius = 1\n')
    err = errors_of(text, [override])
    assert err.key == key
    assert fragment in err.reason and str(err).startswith(f"overrides {key}".rstrip() + ": ")


def test_override_is_validated_like_the_file():
    err = errors_of(MINIMAL, ["run.time_limit_s=-1"])
    assert (err.key, err.source) == ("run.time_limit_s", "scenarios/x.toml")


# --------------------------------------------------------------------------- round trip


@pytest.mark.parametrize(
    ("text", "overrides"),
    [
        (FULL, ()),
        (MINIMAL, ()),
        (FULL, ["world.obstacles[3].width=2", "planner.influence=1.5", "description=changed"]),
    ],
)
def test_to_toml_round_trips(text, overrides):
    s = parse_scenario(text, "rt.toml", overrides)
    again = parse_scenario(s.to_toml(), "rt.toml")
    assert again == s
    assert tomllib.loads(s.to_toml()) == tomllib.loads(again.to_toml())


def test_to_toml_holds_the_overrides():
    s = parse_scenario(FULL, "x", ["run.seed=11"])
    assert tomllib.loads(s.to_toml())["run"]["seed"] == 11


def test_scenario_is_a_frozen_dataclass():
    s = parse_scenario(MINIMAL, "x")
    assert isinstance(s, Scenario)
    with pytest.raises(AttributeError):
        s.name = "other"  # type: ignore[misc]


# --------------------------------------------------------------------------- robustness

FULL_DOC = tomllib.loads(FULL)

_texts = st.text(st.characters(codec="utf-8"), max_size=12)
_scalars = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.floats(),
    _texts,
    st.dates(),
    st.datetimes(),
    st.times(),
)
_values = st.recursive(
    _scalars,
    lambda inner: (
        st.lists(inner, max_size=3)
        | st.dictionaries(st.text(st.characters(codec="utf-8"), min_size=1, max_size=8), inner, max_size=3)
    ),
    max_leaves=6,
)


def _paths(node, prefix=()):
    """Every key path (tuple of keys and indices) inside a parsed document."""
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for key, value in items:
        yield (*prefix, key)
        if isinstance(value, dict | list):
            yield from _paths(value, (*prefix, key))


def _get(doc, path):
    """The value at `path`."""
    for key in path:
        doc = doc[key]
    return doc


PATHS = list(_paths(FULL_DOC))
TABLE_PATHS = [(), *(p for p in PATHS if isinstance(_get(FULL_DOC, p), dict))]

_mutations = st.one_of(
    st.tuples(st.just("delete"), st.sampled_from(PATHS), st.none()),
    st.tuples(st.just("replace"), st.sampled_from(PATHS), _values),
    st.tuples(st.just("add"), st.sampled_from(TABLE_PATHS), st.tuples(_texts, _values)),
)


def _mutate(doc, operation, path, payload):
    """Apply one mutation in place; a path an earlier mutation removed is skipped."""
    try:
        if operation == "add":
            key, value = payload
            _get(doc, path)[key] = value
            return
        parent, key = _get(doc, path[:-1]), path[-1]
        if operation == "delete":
            del parent[key]
        elif type(parent[key]) is not type(payload):
            parent[key] = payload
    except (KeyError, IndexError, TypeError):
        pass


def _assert_clean(err: ScenarioError):
    """A ScenarioError that reports the input, not a bug of the validator."""
    assert "internal error" not in err.reason


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(_mutations, min_size=1, max_size=3))
def test_mutated_documents_parse_or_raise_scenario_error(mutations):
    doc = copy.deepcopy(FULL_DOC)
    for mutation in mutations:
        _mutate(doc, *mutation)
    try:
        parse_scenario(tomli_w.dumps(doc), "mutant.toml")
    except ScenarioError as err:
        _assert_clean(err)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=60), st.lists(st.text(max_size=30), max_size=2))
def test_arbitrary_text_and_overrides_raise_scenario_error(text, overrides):
    for document in (text, MINIMAL):
        try:
            parse_scenario(document, "random.toml", overrides)
        except ScenarioError as err:
            _assert_clean(err)
