"""The Python API (docs/python-api.md): scenarios loaded and built in code, `run`, `sweep`, and
the command line as a thin layer over them."""

import importlib
import json
import math
import signal
import subprocess
import sys

import numpy as np
import pytest

import vplane_mj
from vplane_mj import (
    EventKind,
    Outcome,
    ScenarioError,
    VPlaneError,
    box,
    build_scenario,
    cup,
    cylinder,
    h_shape,
    load_scenario,
    run,
    sweep,
    wall,
)
from vplane_mj.cli import main
from vplane_mj.logs.reader import read_log
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.metrics import trajectory_digest
from vplane_mj.sim.summary import without_timing
from vplane_mj.terminal import Interrupted

TRAP = """
format = 1
name = "built_trap"
description = "a cup between start and goal"

[world]
size = [8.0, 6.0]

[[world.obstacles]]
kind = "u"
center = [4.0, 3.0]
width = 1.6
depth = 1.2
thickness = 0.1

[[world.obstacles]]
kind = "cylinder"
center = [2.0, 5.0]
radius = 0.3

[[world.obstacles]]
kind = "box"
center = [6.5, 1.0]
size = [0.4, 0.6]
yaw_deg = 30.0

[[world.obstacles]]
kind = "wall"
from = [1.0, 0.5]
to = [3.0, 0.5]

[[world.obstacles]]
kind = "h"
center = [6.5, 5.0]
length = 1.0
width = 1.0

[robot]
start = [1.0, 3.0]
goal = [7.0, 3.0]
goal_tolerance = 0.2

[planner]
name = "vplane"
plane_gain = 2.0

[sensors]
noise_std = 0.01

[run]
seed = 4
time_limit_s = 120.0
"""


def built_trap(**changes):
    """The scenario of TRAP, built in code; `changes` replace arguments of build_scenario."""
    arguments = {
        "size": (8.0, 6.0),
        "start": (1.0, 3.0),
        "goal": (7.0, 3.0),
        "description": "a cup between start and goal",
        "obstacles": [
            cup((4.0, 3.0), width=1.6, depth=1.2, thickness=0.1),
            cylinder((2.0, 5.0), 0.3),
            box((6.5, 1.0), (0.4, 0.6), yaw_deg=30.0),
            wall((1.0, 0.5), (3.0, 0.5)),
            h_shape((6.5, 5.0), length=1.0, width=1.0),
        ],
        "robot": {"goal_tolerance": 0.2},
        "planner": "vplane",
        "planner_params": {"plane_gain": 2.0},
        "sensors": {"noise_std": 0.01},
        "run": {"seed": 4, "time_limit_s": 120.0},
    }
    return build_scenario("built_trap", **{**arguments, **changes})


def test_importing_the_package_loads_no_simulator_plotting_or_opengl():
    script = (
        "import sys, vplane_mj\n"
        "heavy = ('mujoco', 'matplotlib', 'OpenGL', 'scipy', 'gymnasium', 'dm_control', 'dm_env')\n"
        "print(sorted(name for name in heavy if name in sys.modules))\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def test_every_public_name_resolves_and_is_listed():
    assert sorted(vplane_mj.__all__) == sorted(vplane_mj._MODULE_OF)
    for name, module in vplane_mj._MODULE_OF.items():
        assert getattr(vplane_mj, name) is getattr(importlib.import_module(module), name), name
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        vplane_mj.nonsense  # noqa: B018
    # dir() lists the public names before their first use, which imports them (a fresh process).
    script = "import vplane_mj\nprint(sorted(set(vplane_mj.__all__) - set(dir(vplane_mj))))\n"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def test_a_scenario_built_in_code_equals_the_same_file():
    built = built_trap()
    from_file = parse_scenario(TRAP, "trap.toml")
    assert built == from_file
    assert built.to_toml() == from_file.to_toml()
    assert (built.source, from_file.source) == ("<code>", "trap.toml")
    assert built.world.obstacles[2].yaw == pytest.approx(math.radians(30.0))
    assert dict(built.planner_params) == {"plane_gain": 2.0}


def test_a_built_scenario_saves_to_a_file_that_loads_back_equal_and_runs(tmp_path, capsys):
    built = built_trap(run={"seed": 4, "time_limit_s": 5.0})
    path = built.save(tmp_path / "trap.toml")
    loaded = load_scenario(str(path))
    assert loaded == built and loaded.source == str(path)
    assert main(["run", str(path), "--no-render", "--no-log", "--out", str(tmp_path)]) == 1  # 5 s: timeout
    assert "built_trap [vplane, seed 4]: timeout after 5.00 s simulated" in capsys.readouterr().out


def test_numpy_values_are_accepted_like_numbers(tmp_path):
    built = build_scenario(
        "np_values",
        size=np.array([6.0, 4.0]),
        start=(np.float32(0.75), np.int64(2)),
        goal=[5.25, 2.0],
        obstacles=[box(np.array([3.0, 2.0]), (0.5, 0.5))],
        run={"seed": np.uint8(3)},
    )
    assert built.robot.start == (0.75, 2.0) and built.run.seed == 3
    # Plain Python numbers (a numpy scalar compares equal to one, but is not TOML).
    assert [type(v) for v in (*built.robot.start, *built.world.size)] == [float] * 4
    assert type(built.run.seed) is int
    assert load_scenario(str(built.save(tmp_path / "np.toml"))) == built


INVALID = [
    (
        {"obstacles": [cup((4.0, 3.0), width=0.15, depth=1.2, thickness=0.1)]},
        ("width = 1.6", "width = 0.15"),
        "world.obstacles[0].width",
    ),
    (
        {"planner_params": {"plane_gain": 2.0, "bogus": 1.0}},
        ("plane_gain = 2.0", "plane_gain = 2.0\nbogus = 1.0"),
        "planner.bogus",
    ),
    ({"planner": "nope"}, ('name = "vplane"', 'name = "nope"'), "planner.name"),
    (
        {"sensors": {"noise_std": 0.01, "dropout": 1.0}},
        ("noise_std = 0.01", "noise_std = 0.01\ndropout = 1.0"),
        "sensors.dropout",
    ),
    ({"start": (4.0, 2.35)}, ("start = [1.0, 3.0]", "start = [4.0, 2.35]"), "robot.start"),
    ({"run": {"seed": -1}}, ("seed = 4\ntime_limit_s = 120.0", "seed = -1"), "run.seed"),
    (
        {"robot": {"goal_tolerance": 0.2, "wheels": 3}},
        ("goal_tolerance = 0.2", "goal_tolerance = 0.2\nwheels = 3"),
        "robot.wheels",
    ),
    ({"size": (8.0, "six")}, ("size = [8.0, 6.0]", 'size = [8.0, "six"]'), "world.size"),
]


@pytest.mark.parametrize("changes, edit, key", INVALID)
def test_an_invalid_built_scenario_fails_with_the_message_of_the_same_file(changes, edit, key):
    old, new = edit
    assert old in TRAP
    with pytest.raises(ScenarioError) as from_file:
        parse_scenario(TRAP.replace(old, new), "trap.toml")
    with pytest.raises(ScenarioError) as built:
        built_trap(**changes)
    assert (built.value.key, built.value.reason) == (from_file.value.key, from_file.value.reason)
    assert built.value.key == key
    assert str(built.value) == str(from_file.value).replace("trap.toml", "<code>", 1)


def test_what_no_file_can_hold_is_an_error_naming_the_key():
    with pytest.raises(ScenarioError, match=r"^<code>: sensors.noise_std: must be a number, a string"):
        built_trap(sensors={"noise_std": object()})
    with pytest.raises(ScenarioError, match=r"^<code>: robot.start: given twice"):
        built_trap(robot={"start": (1.0, 1.0)})
    with pytest.raises(ScenarioError, match=r"^<code>: planner.name: given twice"):
        built_trap(planner_params={"name": "apf"})


def test_overrides_apply_to_built_and_loaded_scenarios_alike():
    built = built_trap(overrides=["run.seed=9", "world.obstacles[0].yaw_deg=45"])
    loaded = parse_scenario(TRAP, "trap.toml", ["run.seed=9", "world.obstacles[0].yaw_deg=45"])
    assert built == loaded and built.run.seed == 9
    assert built.world.obstacles[0].yaw == pytest.approx(math.radians(45.0))


def test_run_reaches_the_goal_and_returns_its_summary_trajectory_events_and_files(tmp_path):
    record = run(load_scenario("single_box"), tmp_path, render=False)
    summary, trajectory = record.summary, record.trajectory
    assert record.reached and summary.outcome is Outcome.REACHED and summary.collisions == 0
    assert list(record.files) == ["log", "summary"]
    assert record.files["summary"] == tmp_path / "single_box-vplane-0.json"
    assert json.loads(record.files["summary"].read_text()) == summary.to_dict()
    n = len(trajectory.times)
    assert n > 100 and trajectory.positions.shape == (n, 2) and trajectory.yaws.shape == (n,)
    assert len(trajectory.modes) == n and set(trajectory.modes) <= {"normal", "avoiding", "escaping"}
    assert trajectory_digest(list(trajectory.positions), trajectory.final_pose, trajectory.final_pose[2]) == (
        summary.trajectory_sha256
    )
    x, y, _ = trajectory.final_pose
    assert math.hypot(5.2 - x, 2.0 - y) <= 0.15
    kinds = [event.kind for event in record.events]
    assert kinds[0] is EventKind.RUN_STARTED and kinds[-1] is EventKind.GOAL_REACHED
    assert record.events[-1].time_s == pytest.approx(summary.time_to_goal_s)
    logged = read_log(record.files["log"]).events
    assert [(e.kind, e.text, dict(e.data)) for e in record.events] == [
        (e.kind, e.text, e.data) for e in logged
    ]


def test_run_without_an_output_directory_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    record = run("single_box", out=None)
    assert list(tmp_path.iterdir()) == [] and dict(record.files) == {}
    written = run("single_box", tmp_path / "out", log=False, render=False)
    assert record.summary.without_timing() == written.summary.without_timing()


def test_run_rejects_a_video_without_a_log_before_writing(tmp_path):
    with pytest.raises(VPlaneError, match="the video is made from the log"):
        run("single_box", tmp_path / "out", log=False, video=True)
    assert not (tmp_path / "out").exists()


def test_the_command_line_prints_what_the_api_returns(tmp_path, capsys):
    assert main(["run", "single_box", "--no-render", "--out", str(tmp_path / "cli")]) == 0
    lines = capsys.readouterr().out.splitlines()
    record = run("single_box", tmp_path / "api", render=False)
    s = record.summary
    cli_summary = json.loads((tmp_path / "cli" / "single_box-vplane-0.json").read_text())
    assert lines == [
        f"single_box [vplane, seed 0]: reached after {s.sim_time_s:.2f} s simulated, path "
        f"{s.path_length_m:.2f} m, collisions 0, min clearance {s.min_clearance_m:.3f} m, local minima 0, "
        f"escapes 0, wall {cli_summary['wall_time_s']:.2f} s",
        f"wrote {tmp_path / 'cli' / 'single_box-vplane-0.mcap'}",
        f"wrote {tmp_path / 'cli' / 'single_box-vplane-0.json'}",
    ]
    assert without_timing(cli_summary) == s.without_timing()


def test_an_interruption_while_writing_keeps_the_whole_files_and_says_so(tmp_path, capsys, monkeypatch):
    def interrupted(image, path):
        raise Interrupted(signal.SIGINT)

    monkeypatch.setattr("vplane_mj.viz.render.write_png", interrupted)
    assert main(["run", "single_box", "--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "interrupted by SIGINT: the run's outputs were being written",
        f"wrote {tmp_path / 'single_box-vplane-0.mcap'}",
        f"wrote {tmp_path / 'single_box-vplane-0.json'}",
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "single_box-vplane-0.json",
        "single_box-vplane-0.mcap",
    ]


def test_sweep_gives_the_rows_and_table_of_bench(tmp_path, capsys):
    args = ["open_field", "--planners", "apf,vplane", "--seeds", "0-1", "--jobs", "2"]
    assert main(["bench", *args, "--set", "sensors.noise_std=0.01", "--out", str(tmp_path / "cli")]) == 0
    printed = capsys.readouterr().out
    bench = json.loads((tmp_path / "cli" / "bench.json").read_text())
    result = sweep(
        ["open_field"], ["apf", "vplane"], "0-1", ["sensors.noise_std=0.01"], 2, out=tmp_path / "api"
    )
    assert printed.startswith(result.table_text() + "\n")
    assert result.table == bench["table"]
    untimed = [[without_timing(row) for row in rows] for rows in (result.rows, bench["rows"])]
    assert untimed[0] == untimed[1]
    assert [p.name for p in result.files] == [
        "bench.csv",
        "bench.json",
        "bench.png",
        "bench-scenarios.png",
        "bench.html",
    ]
    assert [(s.planner, s.seed, s.reached) for s in result.summaries()] == [
        ("apf", 0, True),
        ("apf", 1, True),
        ("vplane", 0, True),
        ("vplane", 1, True),
    ]


def test_sweep_runs_scenarios_built_in_code_and_can_keep_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    quick = build_scenario(
        "quick", size=(4.0, 3.0), start=(0.8, 1.5), goal=(3.2, 1.5), obstacles=[box((2.0, 2.6), (0.4, 0.4))]
    )
    result = sweep([quick, "open_field"], ["apf"], [0, 7], jobs=1, out=None)
    assert list(tmp_path.iterdir()) == []
    assert [(row["scenario"], row["seed"]) for row in result.rows] == [
        ("quick", 0),
        ("quick", 7),
        ("open_field", 0),
        ("open_field", 7),
    ]
    assert all(row["reached"] for row in result.rows) and result.files == ()
    assert result.table[0]["runs"] == 4 and result.table[0]["success_rate"] == 1.0


def test_sweep_rejects_invalid_input_before_any_run_and_leaves_no_directory(tmp_path):
    with pytest.raises(VPlaneError, match=r"^planners: unknown planner 'nope'"):
        sweep(["open_field"], ["nope"], out=tmp_path / "new" / "dir")
    with pytest.raises(VPlaneError, match="jobs: must be at least 1, got 0"):
        sweep(["open_field"], ["apf"], jobs=0, out=tmp_path / "new" / "dir")
    assert not (tmp_path / "new").exists()


@pytest.mark.slow
def test_the_documented_examples_run(tmp_path, monkeypatch, doc_examples, capsys):
    monkeypatch.chdir(tmp_path)
    script = doc_examples("python-api.md", "Run a scenario", "Build a scenario in code", "Sweep")
    exec(compile(script, "docs/python-api.md", "exec"), {})
    assert load_scenario("my_trap.toml").name == "my_trap"
    assert (tmp_path / "logs" / "paper_c_escape-vplane-3.json").exists()
    assert json.loads((tmp_path / "results" / "bench.json").read_text())["table"][0]["runs"] == 6
    assert "paper_c_escape vplane 2 reached" in capsys.readouterr().out


def test_the_drawing_helpers_draw_the_world_and_a_path_by_mode():
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.colors import to_rgba

    from vplane_mj.viz.palette import MODE_RGBA, OTHER_MODE_RGBA
    from vplane_mj.viz.plots import draw_path, draw_world, label_modes

    scenario = load_scenario("paper_c_escape")
    figure, axes = plt.subplots()
    draw_world(axes, scenario, margin_m=0.5)
    pieces = sum(len(obstacle.footprint()) for obstacle in scenario.world.obstacles)
    assert len(axes.patches) == pieces + 4 + 1  # the cup's three walls, the border, the goal
    width, height = scenario.world.size
    assert axes.get_xlim() == (-0.5, width + 0.5) and axes.get_ylim() == (-0.5, height + 0.5)
    assert axes.get_legend_handles_labels()[1] == ["start", "goal"]
    positions = np.array([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [3.0, 2.0]])
    modes = ("normal", "escaping", "mine", "normal")
    draw_path(axes, positions, modes)
    (path,) = [c for c in axes.collections if isinstance(c, LineCollection)]
    assert [tuple(c) for c in path.get_colors()] == [
        MODE_RGBA["normal"],
        MODE_RGBA["escaping"],
        OTHER_MODE_RGBA,
    ]
    assert [segment.tolist() for segment in path.get_segments()][1] == [[2.0, 1.0], [2.0, 2.0]]
    label_modes(axes, modes)
    handles, labels = axes.get_legend_handles_labels()
    assert labels == ["start", "goal", "path: normal", "path: escaping"]
    assert to_rgba(handles[3].get_color()) == MODE_RGBA["escaping"]
    plt.close(figure)
