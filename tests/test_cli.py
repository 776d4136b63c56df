"""The command line (docs/interface.md section 2): outputs, exit codes, and nothing written on bad input."""

import json
import os
import signal
import subprocess
import sys
import time

import matplotlib.image
import mujoco
import numpy as np
import pytest

import vplane_mj
from vplane_mj.cli import main
from vplane_mj.geometry.cache import CACHE_ENV
from vplane_mj.logs.reader import read_log
from vplane_mj.viz import palette

BAD_SCENARIO = """
format = 1
name = "bad"
[world]
size = [4.0, 4.0]
[[world.obstacles]]
kind = "u"
center = [2.0, 2.0]
width = 0.08
depth = 1.0
[robot]
start = [0.5, 0.5]
goal = [3.5, 3.5]
"""


def run_cli(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_run_writes_summary_and_render_and_exits_0_on_reach(tmp_path, capsys):
    code, out, _ = run_cli(capsys, "run", "open_field", "--planner", "apf", "--out", str(tmp_path))
    assert code == 0
    summary = json.loads((tmp_path / "open_field-apf-0.json").read_text())
    assert summary["format"] == 1 and summary["reached"] and summary["outcome"] == "reached"
    image = matplotlib.image.imread(tmp_path / "open_field-apf-0.png")
    assert image.shape[0] >= 500 and image.shape[1] >= 500
    assert "reached" in out and str(tmp_path / "open_field-apf-0.json") in out
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "open_field-apf-0.json",
        "open_field-apf-0.mcap",
        "open_field-apf-0.png",
    ]
    log = read_log(tmp_path / "open_field-apf-0.mcap")
    assert log.complete and log.summary["path_length_m"] == summary["path_length_m"]


def test_render_shows_the_path_in_its_colour(tmp_path, capsys):
    run_cli(capsys, "run", "open_field", "--planner", "apf", "--out", str(tmp_path))
    image = matplotlib.image.imread(tmp_path / "open_field-apf-0.png")[..., :3]
    normal = (np.abs(image - palette.MODE_RGBA["normal"][:3]) < 0.02).all(axis=-1)
    # The diagonal path from (1, 1) to (5, 5) in a 6 x 6 arena: pixels of `normal` on the diagonal.
    rows, cols = np.nonzero(normal)
    assert len(rows) > 200
    h, w = normal.shape
    assert np.corrcoef(cols / w, 1 - rows / h)[0, 1] > 0.95


def test_run_exits_1_when_the_goal_is_not_reached(tmp_path, capsys):
    code, _, _ = run_cli(
        capsys, "run", "paper_c_escape", "--planner", "apf", "--no-render", "--out", str(tmp_path)
    )
    assert code == 1
    summary = json.loads((tmp_path / "paper_c_escape-apf-0.json").read_text())
    assert summary["outcome"] == "stuck" and not summary["reached"]
    assert not (tmp_path / "paper_c_escape-apf-0.png").exists()


def test_seed_and_set_name_the_outputs(tmp_path, capsys):
    code, _, _ = run_cli(
        capsys,
        "run",
        "open_field",
        "--seed",
        "7",
        "--set",
        "run.time_limit_s=1",
        "--no-render",
        "--out",
        str(tmp_path),
    )
    assert code == 1
    summary = json.loads((tmp_path / "open_field-vplane-7.json").read_text())
    assert summary["seed"] == 7 and summary["outcome"] == "timeout"


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["run", "no_such_scenario"], "no_such_scenario"),
        (["run", "open_field", "--set", "run.time_limit_s=-1"], "run.time_limit_s"),
        (["run", "open_field", "--set", "planner.no_such_param=1"], "planner.no_such_param"),
        (["run", "open_field", "--planner", "nope"], "--planner: unknown planner 'nope'"),
        (["run", "open_field", "--set", "novalue"], "--set"),
        (["run", "open_field", "--set", "sensors.dropout=1.0"], "sensors.dropout"),
        (["run", "open_field", "--set", "sensors.noise_std=-0.1"], "sensors.noise_std"),
        (["run", "open_field", "--set", "robot.goal=[7.0, 3.0]"], "robot.goal"),
        (["run", "open_field", "--set", "robot.start=[1.0]"], "robot.start"),
        (["run", "open_field", "--set", "run.seed=true"], "run.seed"),
        (["run", "open_field", "--set", "run.physics_dt_s=nan"], "run.physics_dt_s"),
        (["run", "open_field", "--set", "world.size=[0, 4]"], "world.size"),
        (["run", "open_field", "--set", "world.colour=1"], "world.colour"),
        (["run", "open_field", "--set", "format=2"], "format"),
        (["run", "open_field", "--set", "name=Bad-Name"], "name"),
        (["run", "paper_c_escape", "--set", "world.obstacles[0].kind=spiral"], "world.obstacles[0].kind"),
        (["run", "paper_c_escape", "--set", "world.obstacles[0].width=0.15"], "world.obstacles[0].width"),
        (["run", "paper_c_escape", "--set", "robot.start=[5.45, 5.2]"], "robot.start"),
        (["run", "paper_h_avoid", "--set", "world.obstacles.0.length=0.05"], "world.obstacles[0].length"),
        (["run", "open_field", "--set", "planner.max_escapes=1.5"], "planner.max_escapes"),
        (["run", "open_field", "--planner", "apf", "--set", "planner.plane_gain=1"], "planner.plane_gain"),
    ],
)
def test_invalid_input_exits_2_and_writes_nothing(tmp_path, capsys, argv, fragment):
    code, _, err = run_cli(capsys, *argv, "--out", str(tmp_path))
    assert code == 2
    assert err.startswith("error: ") and fragment in err
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_invalid_scenario_file_is_named_with_key_and_reason(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(BAD_SCENARIO)
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    code, _, err = run_cli(capsys, "run", str(bad), "--out", str(out_dir))
    assert code == 2
    assert f"{bad}: world.obstacles[0].width: must be greater than 2*thickness" in err
    assert list(out_dir.iterdir()) == []


ABSURD_SCENARIO = """
format = 1
name = "absurd"
[world]
size = [4.0, 4.0]
[robot]
start = [0.5, 0.5]
goal = [3.5, 3.5]
{robot}
[sensors]
{sensors}
[run]
{run}
"""


@pytest.mark.parametrize(
    "keys, key, fragment",
    [
        ({"sensors": 'kind = "laser"\nrate_hz = 0.001'}, "sensors.rate_hz", "at least run.control_hz / 10"),
        (
            {"robot": 'profile = "turtlebot3_burger"', "run": "control_hz = 100"},
            "run.control_hz",
            "that is 50 Hz",
        ),
        ({"run": "time_limit_s = 1e6"}, "run.time_limit_s", "at most 86400"),
        ({"robot": "goal_tolerance = 1e6"}, "robot.goal_tolerance", "at most 5"),
        ({"robot": "start_yaw_deg = 1e300"}, "robot.start_yaw_deg", "at most 360"),
    ],
)
def test_an_absurd_rate_or_limit_is_exit_2_naming_file_and_key(tmp_path, capsys, keys, key, fragment):
    """Values that would run but mean nothing (one laser scan in 1,000 s, say) are refused."""
    path = tmp_path / "absurd.toml"
    path.write_text(ABSURD_SCENARIO.format(**{"robot": "", "sensors": "", "run": "", **keys}))
    out_dir = tmp_path / "out"
    code, _, err = run_cli(capsys, "run", str(path), "--planner", "vplane_plus", "--out", str(out_dir))
    assert code == 2
    assert err.startswith(f"error: {path}: {key}: ") and fragment in err, err
    assert not out_dir.exists()


def test_a_missing_output_directory_is_created_with_its_parents(tmp_path, capsys):
    out_dir = tmp_path / "results" / "today"
    code, out, _ = run_cli(capsys, "run", "open_field", "--planner", "apf", "--no-log", "--out", str(out_dir))
    assert code == 0 and str(out_dir / "open_field-apf-0.json") in out
    assert sorted(p.name for p in out_dir.iterdir()) == ["open_field-apf-0.json", "open_field-apf-0.png"]


def test_generate_creates_its_output_directory_too(tmp_path, capsys):
    out_dir = tmp_path / "scenarios" / "traps"
    code, out, _ = run_cli(capsys, "generate", "traps", "--count", "1", "--seed", "3", "--out", str(out_dir))
    assert code == 0 and [p.suffix for p in out_dir.iterdir()] == [".toml"] and str(out_dir) in out


def test_an_output_directory_is_not_created_for_rejected_input(tmp_path, capsys):
    out_dir = tmp_path / "results" / "today"
    code, _, err = run_cli(capsys, "bench", "open_field", "--planners", "nope", "--out", str(out_dir))
    assert code == 2 and "nope" in err
    assert list(tmp_path.iterdir()) == []


def test_check_exit_codes(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(BAD_SCENARIO)
    assert run_cli(capsys, "check", "open_field", "paper_h_escape")[0] == 0
    code, out, err = run_cli(capsys, "check", "open_field", str(bad))
    assert code == 2 and "ok: open_field" in out and "world.obstacles[0].width" in err


def test_mjcf_writes_a_loadable_world(tmp_path, capsys):
    target = tmp_path / "world.xml"
    code, _, _ = run_cli(capsys, "mjcf", "paper_c_avoid", "-o", str(target))
    assert code == 0
    model = mujoco.MjModel.from_xml_path(str(target))
    assert model.nu == 2 and model.nsensor == 49


def test_list_shows_scenarios_and_planner_parameters(capsys):
    code, out, _ = run_cli(capsys, "list")
    assert code == 0
    for expected in ("paper_c_escape", "open_field", "apf", "vplane", "repulse_gain", "plane_gain"):
        assert expected in out


def test_usage_error_exits_2(capsys):
    assert run_cli(capsys, "run")[0] == 2
    assert run_cli(capsys, "frobnicate")[0] == 2


@pytest.mark.parametrize("launcher", ["script", "module"])
def test_installed_entry_points(launcher, console_script):
    command = [console_script("vplane-mj")] if launcher == "script" else [sys.executable, "-m", "vplane_mj"]
    done = subprocess.run([*command, "check", "single_box"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "ok: single_box" in done.stdout


LOADED = """
import sys
from vplane_mj.cli import main
status = main(sys.argv[1:])
heavy = ("OpenGL", "matplotlib", "scipy.sparse", "dm_control", "dm_env", "numba")
print(status, sorted(name for name in heavy if name in sys.modules))
"""


def test_a_run_without_render_or_log_loads_only_what_it_uses(tmp_path):
    args = ["run", "single_box", "--no-render", "--no-log", "--out", str(tmp_path)]
    env = {key: value for key, value in os.environ.items() if key not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    env[CACHE_ENV] = str(tmp_path / "cache")  # empty: the first run computes the reference path
    first = subprocess.run([sys.executable, "-c", LOADED, *args], capture_output=True, text=True, env=env)
    assert first.returncode == 0, first.stderr
    again = subprocess.run([sys.executable, "-c", LOADED, *args], capture_output=True, text=True, env=env)
    # The planner's compiled kernels need numba; no renderer, no plots; the reference path
    # came from the cache the second time: no graph search (numba itself imports scipy's root).
    assert again.stdout.split("\n")[-2] == "0 ['numba']"
    assert first.stdout.split("\n")[-2] == "0 ['numba', 'scipy.sparse']"  # the first run computed it


@pytest.mark.parametrize("command", [["check", "single_box"], ["list"]])
def test_commands_that_only_read_scenarios_do_not_load_numba(command):
    done = subprocess.run([sys.executable, "-c", LOADED, *command], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    status, loaded = done.stdout.split("\n")[-2].split(" ", 1)
    assert status == "0" and "numba" not in loaded


def start_long_run(tmp_path):
    """A vplane-mj run in its own process that lasts a while: apf trapped for up to 600 s."""
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "vplane_mj",
            "run",
            "paper_c_escape",
            "--planner",
            "apf",
            "--set",
            "planner.patience_s=1000",
            "--set",
            "run.time_limit_s=600",
            "--out",
            str(tmp_path),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def wait_for_partial_log(tmp_path, process, seconds=60.0):
    """Wait until the run has flushed a few simulated seconds of log (`.NAME.mcap.PID-RANDOM.partial`)."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and process.poll() is None:
        for partial in tmp_path.glob(f".paper_c_escape-apf-0.mcap.{process.pid}-*.partial"):
            if partial.stat().st_size > 20_000:
                return partial
        time.sleep(0.05)
    raise AssertionError("the run did not start writing its log")


@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupted_run_closes_its_log_and_writes_nothing_else(tmp_path, capsys, signum, status):
    process = start_long_run(tmp_path)
    wait_for_partial_log(tmp_path, process)
    process.send_signal(signum)
    _, err = process.communicate(timeout=60)
    assert process.returncode == status
    assert "interrupted by" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper_c_escape-apf-0.mcap"]
    log = read_log(tmp_path / "paper_c_escape-apf-0.mcap")
    assert log.complete and len(log.times_ns) > 20
    assert np.all(np.diff(log.times_ns) > 0)
    assert main(["summary", str(tmp_path / "paper_c_escape-apf-0.mcap")]) == 0
    out = capsys.readouterr().out
    assert json.loads(out[: out.index("\nevents:")])["outcome"] == "interrupted"
    assert "the log holds no stored summary" in out


def test_killed_run_leaves_a_recoverable_partial_log(tmp_path):
    process = start_long_run(tmp_path)
    partial = wait_for_partial_log(tmp_path, process)
    process.kill()
    process.communicate(timeout=60)
    assert not (tmp_path / "paper_c_escape-apf-0.mcap").exists()
    assert not (tmp_path / "paper_c_escape-apf-0.json").exists()
    log = read_log(partial)
    assert not log.complete and len(log.times_ns) > 20
    assert np.all(np.diff(log.times_ns) > 0)


@pytest.mark.parametrize("command", [["run", "open_field", "--no-log", "--no-render"], ["list"]])
def test_a_reader_that_goes_away_does_not_turn_into_a_traceback(tmp_path, command):
    """`vplane-mj ... | head -1`: the command finishes, writes its files, keeps its exit status."""
    out = ["--out", str(tmp_path)] if command[0] == "run" else []
    process = subprocess.Popen(
        [sys.executable, "-m", "vplane_mj", *command, *out],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    process.stdout.close()  # the reader is gone before anything is printed
    stderr = process.stderr.read()
    assert process.wait(timeout=120) == 0
    assert "Traceback" not in stderr and "BrokenPipe" not in stderr, stderr
    if command[0] == "run":
        assert json.loads((tmp_path / "open_field-vplane-0.json").read_text())["reached"]


def test_a_run_with_its_render_and_log_loads_no_plotting_library(tmp_path):
    args = ["run", "single_box", "--out", str(tmp_path)]
    env = {**os.environ, CACHE_ENV: str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", LOADED, *args], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[-2] == "0 ['OpenGL', 'numba', 'scipy.sparse']"  # the render: OpenGL only
    assert (tmp_path / "single_box-vplane-0.png").stat().st_size > 0


def test_version_names_the_package_and_the_contract(capsys):
    assert main(["--version"]) == 0
    out = capsys.readouterr().out
    assert out.strip() == f"vplane-mj {vplane_mj.__version__} (contract v{vplane_mj.CONTRACT_VERSION})"
    assert vplane_mj.CONTRACT_VERSION == "1.3"
