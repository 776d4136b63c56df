"""The benchmark scripts run: each, with the smallest arguments it takes, exits 0 and prints or
writes its results (their numbers are the docs' business, not the tests')."""

from __future__ import annotations

import csv
import importlib.util
import json
import math
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.test_benchmark_options import benchmark_module
from tests.test_moving import CROSSING, scenario_text
from vplane_mj.bench.sweep import job_choice
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it

BENCHMARKS = Path(__file__).parents[1] / "benchmarks"
SCRIPT_ENVIRONMENT = {**os.environ, "PYTHONPATH": str(BENCHMARKS.parent)}
"""The scripts import this checkout's package, whichever the environment has installed."""


def run_benchmark(script: str, *arguments: str, cwd: Path) -> str:
    """The standard output of `python benchmarks/SCRIPT ARGUMENTS`, which must exit 0."""
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), *arguments],
        cwd=cwd,
        env=SCRIPT_ENVIRONMENT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def refused_benchmark(script: str, *arguments: str) -> str:
    """The standard error of `python benchmarks/SCRIPT ARGUMENTS`, which must exit 2 (bad input)."""
    refused = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), *arguments],
        env=SCRIPT_ENVIRONMENT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert refused.returncode == 2, refused.stderr[-2000:]
    return refused.stderr


def table_rows(text: str, first_cell: str) -> list[list[str]]:
    """The cells of the Markdown table rows of `text` whose first cell is `first_cell`."""
    rows = [[cell.strip() for cell in line.strip().strip("|").split("|")] for line in text.splitlines()]
    return [row for row in rows if row and row[0] == first_cell]


@pytest.mark.parametrize(
    ("script", "arguments", "first_cell", "number_column"),
    [
        ("planner_cost.py", ("open_field", "--driver", "apf", "--repeat", "1"), "open_field", 2),
        ("video.py", ("open_field", "--repeat", "1"), "open_field", 3),
        ("map_update.py", ("--repeat", "1", "--poses", "2"), "jackal_laser", 2),
        ("dm_control_env.py", ("single_box", "--steps", "2", "--repeat", "1"), "pixels top 84 x 84", 1),
    ],
)
def test_timing_benchmarks_print_their_table_and_write_it_with_its_command(
    tmp_path, script, arguments, first_cell, number_column
):
    (row,) = table_rows(run_benchmark(script, *arguments, cwd=tmp_path), first_cell)
    number = row[number_column].split()[0]
    assert float(number) > 0, row
    stem = script.removesuffix(".py")
    sidecar = json.loads((tmp_path / "logs" / stem / f"{stem}.json").read_text(encoding="utf-8"))
    assert sidecar["command"] == shlex.join(["python", f"benchmarks/{script}", *arguments])
    assert first_cell in (tmp_path / "logs" / stem / f"{stem}.md").read_text(encoding="utf-8")


def number(cell: str) -> float:
    """A table cell's number, which must be finite."""
    value = float(cell.split()[0])
    assert math.isfinite(value), cell
    return value


# The timings of one repeat on a shared machine vary too much to compare one with another:
# the tests check the tables' structure, their counts and that each ratio is within generous
# bounds (a timer that is broken, say zero or the wrong run, gives a ratio far outside them).
RATIO_BOUNDS = (0.2, 50.0)


def test_overhead_times_runs_and_the_run_loop_alone_against_the_floor(tmp_path):
    arguments = ("open_field", "--planners", "apf", "--repeat", "1", "--plot", "ratios.png")
    text = run_benchmark("overhead.py", *arguments, cwd=tmp_path)
    assert (tmp_path / "ratios.png").stat().st_size > 1000
    (row,) = table_rows(text, "open_field")
    assert row[1:3] == ["`apf`", "reached"]
    steps = run_scenario(load_scenario("open_field", ["planner.name=apf"])).summary.steps
    assert int(row[3]) == steps  # the physics steps of the run it timed
    assert number(row[4]) > 0  # floor us/step
    for ratio in row[5:10]:  # run, run with log, as built, run / as built, wall clock
        assert RATIO_BOUNDS[0] < number(ratio) < RATIO_BOUNDS[1], row
    assert row[10] == "-"  # the laser's share: the default robot has sonars
    assert number(row[11]) > 0 and number(row[12]) > 0  # planner ms/tick, log MB/min
    loop_alone = re.search(r"The run loop alone: .* reached on open_field at ([0-9.]+) times the floor", text)
    assert loop_alone is not None, text
    assert RATIO_BOUNDS[0] < float(loop_alone.group(1)) < RATIO_BOUNDS[1]


def test_overhead_reports_the_lasers_share_of_the_floor_on_a_protocol_world(tmp_path):
    from vplane_mj.worlds.barn_protocol import generate_protocol

    (case,) = generate_protocol(1, 0)
    (tmp_path / "world.toml").write_text(case.toml(), encoding="utf-8")
    arguments = ("world.toml", "--planners", "apf", "--repeat", "1", "--no-log")
    text = run_benchmark("overhead.py", *arguments, cwd=tmp_path)
    (row,) = table_rows(text, case.name)
    assert 0 < number(row[10]) < number(row[5])  # the laser's scans: a part of the run


def test_startup_times_runs_against_their_loop_and_the_main_job_with_its_log_and_render(tmp_path):
    text = run_benchmark("startup.py", "open_field", "--repeat", "1", cwd=tmp_path)
    (row,) = table_rows(text, "open_field")
    process_s, loop_s, ratio = map(number, row[1:4])
    assert process_s > loop_s > 0  # the loop is timed inside the process
    assert ratio == pytest.approx(process_s / loop_s, rel=0.02, abs=0.01)  # of the rounded cells
    for name in ("log and render", "log, --no-render", "--no-render --no-log"):
        (job,) = table_rows(text, name)
        assert number(job[1]) > 0
    for command in ("`python -c 'import numpy'`", "`vplane-mj check open_field`", "`vplane-mj list`"):
        (line,) = table_rows(text, command)
        assert number(line[1]) > 0 and RATIO_BOUNDS[0] < number(line[2]) < RATIO_BOUNDS[1]


def test_footprint_clearance_times_the_kernel_against_numpy_on_the_same_poses(tmp_path):
    text = run_benchmark("footprint_clearance.py", "--points", "1", "--repeat", "1", cwd=tmp_path)
    (line,) = [line for line in text.splitlines() if re.match(r"\| [0-9]", line)]
    poses, kernel_ms, numpy_ms, _, difference = map(float, line.strip("| ").split("|"))
    assert poses > 1000 and kernel_ms > 0 and numpy_ms > 0 and difference < 1e-9


def test_laser_cast_times_both_casters_on_both_worlds_and_the_first_calls(tmp_path):
    text = run_benchmark("laser_cast.py", "--origins", "2", "--repeat", "1", cwd=tmp_path)
    for world in ("BARN-size", "paper-size"):
        rows = table_rows(text, world)
        assert len(rows) == 2, text  # the Jackal's scan and the Burger's
        for row in rows:
            ours_us, theirs_us, _, diff_mm = map(float, row[3:7])
            assert ours_us > 0 and theirs_us > 0 and diff_mm <= 1.0
    first = re.search(r"First cast in a new process: ([0-9.]+) s .* cache \(compile\), ([0-9.]+) s", text)
    assert first is not None, text
    assert float(first.group(1)) > 0 and float(first.group(2)) > 0


def test_sweep_benchmarks_write_their_results(tmp_path):
    run_benchmark(
        "clutter.py", "--barn", "1", "--count", "1", "--planners", "apf", "--out", "clutter", cwd=tmp_path
    )
    table = (tmp_path / "clutter" / "clutter.csv").read_text(encoding="utf-8").splitlines()
    families = {row["family"]: row for row in csv.DictReader(table)}
    assert {"paper", "suite", "traps", "clutter", "corridors", "barn", "barn_noisy"} <= set(families)
    assert int(families["suite"]["runs"]) == 34 and families["paper"]["success_rate"] == "0.0"  # apf
    for script, arguments in (
        ("degradation.py", ("--cases", "2", "--noise", "0", "--dropout", "0.1", "--planners", "apf")),
        ("soak.py", ("--count", "3", "--pose", "ekf")),
    ):
        name = script.removesuffix(".py")
        out = run_benchmark(script, *arguments, "--time-limit", "5", "--out", name, cwd=tmp_path)
        assert f"wrote {name}/{name}.png" in out
        assert (tmp_path / name / f"{name}.png").stat().st_size > 1000
    header = (tmp_path / "soak" / "soak_planners.csv").read_text(encoding="utf-8").splitlines()[0]
    assert header.endswith("success_true_pose,success_ekf")


def test_pose_ceiling_shadows_the_soaks_true_pose_runs(tmp_path):
    run_benchmark(
        "soak.py",
        *("--count", "16", "--poses", "odometry,ekf,truth", "--time-limit", "20", "--out", "soak"),
        cwd=tmp_path,
    )
    journal = [json.loads(line) for line in (tmp_path / "soak" / "soak.jsonl").read_text().splitlines()]
    plan = json.loads((tmp_path / "soak" / "plan.json").read_text())
    on_truth = [run["job"]["planner"] for run in plan["runs"] if 'sensors.pose="truth"' in run["faults"]]
    assert on_truth  # some runs drew the estimated pose
    out = run_benchmark("pose_ceiling.py", "--soak", "soak", cwd=tmp_path)
    assert "wrote soak/pose_ceiling.md" in out
    rows = list(csv.DictReader((tmp_path / "soak" / "pose_ceiling.csv").open()))
    assert sorted(row["planner"] for row in rows) == sorted(set(on_truth))
    assert any(row["truth_successes"] != "0" for row in rows)  # a success to shadow
    for row in rows:
        for column in ("ekf_within_tolerance", "odometry_within_tolerance"):
            assert row[column] == "" if row["truth_successes"] == "0" else 0.0 <= float(row[column]) <= 1.0
    assert len(journal) == len(plan["runs"])
    assert "error: " in refused_benchmark("pose_ceiling.py", "--soak", str(tmp_path / "none"))


def test_barn_protocol_sweeps_the_planners_beside_barns_published_figures(tmp_path):
    out = run_benchmark(
        "barn_protocol.py",
        *("--count", "1", "--seeds", "0", "--planners", "vplane_plus,apf", "--out", "barn"),
        cwd=tmp_path,
    )
    rows = {row["planner"]: row for row in csv.DictReader((tmp_path / "barn" / "barn_protocol.csv").open())}
    assert set(rows) == {"vplane_plus", "apf"} and all(row["runs"] == "1" for row in rows.values())
    assert table_rows(out, "BARN: DWA baseline") and table_rows(out, "BARN: best entries")
    assert (tmp_path / "barn" / "barn_protocol.png").stat().st_size > 1000


def test_dynabarn_sweeps_each_third_beside_the_published_rates(tmp_path):
    out = run_benchmark(
        "dynabarn.py",
        *("--count", "3", "--seeds", "0", "--planners", "apf", "--out", "dyn"),
        cwd=tmp_path,
    )
    rows = list(csv.DictReader((tmp_path / "dyn" / "dynabarn.csv").open()))
    assert [(row["third"], row["runs"]) for row in rows] == [
        ("easy", "1"),
        ("medium", "1"),
        ("hard", "1"),
        ("all", "3"),
    ]
    assert table_rows(out, "DynaBARN: DWA") and (tmp_path / "dyn" / "dynabarn.md").is_file()
    assert (tmp_path / "dyn" / "dynabarn.png").stat().st_size > 1000


def test_dynabarn_collisions_are_classified_from_the_sweeps_journal(tmp_path):
    # dwa meets a cylinder in most hard worlds: every collided run of the sweep is run again
    # (its digest checked) and its first contact counted in exactly one class.
    run_benchmark(
        "dynabarn.py",
        *("--count", "2", "--seeds", "0-1", "--planners", "dwa", "--out", "dyn"),
        cwd=tmp_path,
    )
    journal = [json.loads(line) for line in (tmp_path / "dyn" / "bench.jsonl").read_text().splitlines()]
    collided = sum(row["collisions"] > 0 for row in journal)
    assert collided > 0
    run_benchmark("dynabarn_collisions.py", "--sweep", "dyn", "--planners", "dwa", cwd=tmp_path)
    (row,) = csv.DictReader((tmp_path / "dyn" / "dynabarn_collisions.csv").open())
    assert int(row["runs"]) == 4 and int(row["collided"]) == collided
    assert sum(int(row[kind]) for kind in ("landed", "appeared", "unseen", "in_view")) == collided
    # Another laser noise runs other trajectories than the journal's: refused, naming the world.
    refused = refused_benchmark(
        "dynabarn_collisions.py", "--sweep", str(tmp_path / "dyn"), "--planners", "dwa", "--noise", "0"
    )
    assert "dynabarn_0_" in refused and "another trajectory" in refused
    assert "error: " in refused_benchmark("dynabarn_collisions.py", "--sweep", str(tmp_path / "none"))


LANDING = """
[[world.obstacles]]
kind = "cylinder"
radius = 0.4
[world.obstacles.motion]
keyframes = [[0.0, 1.9, 3.0], [1.0, 1.9, 5.5]]
interpolation = "linear"
phase_s = 0.7
"""
"""A cylinder whose loop lands it in front of a robot at (1.5, 3.0) 0.3 s into the run."""


def test_a_cylinder_whose_loop_lands_it_on_the_robot_between_two_ticks_is_a_landing(tmp_path):
    # The cylinder's loop wraps 0.3 s into the run: it jumps from 1.75 m north of the robot back
    # to its first keyframe, over the robot's front, and touches it before the next control
    # tick. The contact is classified from the tick after it (the tick before still has the
    # cylinder far off, where it was never seen to jump).
    collisions = benchmark_module("dynabarn_collisions")
    case = tmp_path / "landing.toml"
    case.write_text(scenario_text(LANDING, "start = [1.5, 3.0]\ngoal = [8.0, 3.0]"))
    digest = run_scenario(load_scenario(str(case), job_choice("apf", 0))).summary.trajectory_sha256
    assert collisions.classify(case, "apf", 0, 0.0, digest) == {"kind": "landed"}


class _Scans:
    """A tracker's stand-in that counts the scans it is given and tracks nothing."""

    moving_beams = np.zeros(0, dtype=bool)

    def __init__(self):
        self.scans = 0

    def update(self, *scan) -> tuple:
        self.scans += 1
        return ()


def _crossing_scenario(tmp_path):
    """CROSSING with the Jackal and its laser: the cylinder crosses north at 1.25 m/s 4 m east of
    a robot at (1, 3), ahead of it facing east, behind it (outside 270 degrees) facing west."""
    case = tmp_path / "crossing.toml"
    case.write_text(scenario_text(CROSSING, 'profile = "jackal"\nstart = [1.0, 3.0]\ngoal = [9.0, 3.0]'))
    return load_scenario(str(case))


def _scan_of(centre, radius, here, beams):
    """`beams` beams of a robot at `here` facing east toward a disc, and their ranges (m)."""
    offset = np.asarray(centre) - here
    toward = math.atan2(offset[1], offset[0])
    bearings = toward + np.linspace(-0.02, 0.02, beams)
    along = np.hypot(*offset) * np.cos(bearings - toward)
    across = np.hypot(*offset) * np.sin(bearings - toward)
    return bearings, along - np.sqrt(radius**2 - across**2)


def test_true_tracks_hand_over_what_the_laser_could_see_late_and_coast_out_of_view(tmp_path):
    scenario = _crossing_scenario(tmp_path)
    ceiling, scans = benchmark_module("dynabarn_ceiling"), _Scans()
    truth = ceiling.TrueTracks(scans, scenario, ceiling.Handover(echoes=0, latency_s=0.1))
    here, nothing = np.array([1.0, 3.0]), (np.zeros(0), np.zeros(0))
    assert truth.update(0.0, here, 0.0, *nothing) == ()  # in view, not yet for 0.1 s
    (track,) = truth.update(0.1, here, 0.0, *nothing)
    np.testing.assert_allclose(track.position, scenario.world.moving[0].motion.position(0.1))
    np.testing.assert_allclose(track.velocity, (0.0, 1.25))
    assert track.radius_m == 0.4 and track.moving and track.position_std_m == 0.0
    (coasting,) = truth.update(1.0, here, math.pi, *nothing)  # behind: it coasts at its velocity
    np.testing.assert_allclose(coasting.position, track.position + 0.9 * track.velocity)
    assert coasting.last_seen_s == 0.1 and coasting.stamp_s == 1.0
    assert truth.update(2.2, here, math.pi, *nothing) == ()  # unseen for longer than coast_s (2 s)
    assert truth.update(2.3, here, 0.0, *nothing) == ()  # back in view: late again
    assert scans.scans == 5


def test_true_tracks_of_what_the_scan_shows_need_echoes_on_the_obstacle(tmp_path):
    scenario = _crossing_scenario(tmp_path)
    ceiling = benchmark_module("dynabarn_ceiling")
    truth = ceiling.TrueTracks(_Scans(), scenario, ceiling.Handover(echoes=3))
    here, centre = np.array([1.0, 3.0]), scenario.world.moving[0].motion.position(0.5)
    assert truth.update(0.5, here, 0.0, np.zeros(0), np.zeros(0)) == ()  # in view, no echo on it
    assert truth.update(0.55, here, 0.0, *_scan_of(centre, 0.4, here, 2)) == ()  # two echoes: too few
    (track,) = truth.update(0.5, here, 0.0, *_scan_of(centre, 0.4, here, 3))
    np.testing.assert_allclose(track.position, centre)


def test_dynabarn_ceiling_runs_each_mode_on_the_same_worlds(tmp_path):
    out = run_benchmark(
        "dynabarn_ceiling.py",
        *("--count", "3", "--seeds", "0", "--modes", "tracker,seen", "--out", "c"),
        cwd=tmp_path,
    )
    for mode in ("`tracker`", "`seen`"):
        (row,) = table_rows(out, mode)
        assert row[1] == "3" and 0 <= int(row[2]) <= 3 and int(row[2]) + int(row[4]) <= 3
    assert (tmp_path / "c" / "dynabarn_ceiling.csv").is_file()


def test_tracker_accuracy_scores_the_tracks_against_the_simulator(tmp_path):
    out = run_benchmark(
        "tracker_accuracy.py", "--count", "3", "--planner", "apf", "--out", "acc", cwd=tmp_path
    )
    (row,) = table_rows(out, "all")
    assert int(row[1]) > 0  # obstacle-ticks scored
    assert 0.5 < number(row[2].rstrip("%")) / 100 <= 1.0  # found
    assert 0.0 <= number(row[4]) < 0.1  # median position error (m)


def test_localisation_sets_the_ekf_beside_wheel_odometry(tmp_path):
    out = run_benchmark(
        "localisation.py", *("--count", "2", "--poses", "odometry,ekf", "--out", "loc"), cwd=tmp_path
    )
    (odometry,) = table_rows(out, "odometry")
    (ekf,) = table_rows(out, "ekf")
    assert odometry[1] == ekf[1] == "2"  # runs
    assert 0.0 < number(ekf[4]) < number(odometry[4])  # median final position error (m)
    assert (tmp_path / "loc" / "localisation.csv").is_file()


def test_log_growth_reports_the_size_per_simulated_minute(tmp_path):
    out = run_benchmark("log_growth.py", *("--minutes", "0.5,2", "--out", "growth"), cwd=tmp_path)
    (half,) = table_rows(out, "0.5")
    (two,) = table_rows(out, "2")
    assert number(half[4]) == 1.0 and 0.8 < number(two[4]) < 1.1  # MB per minute over the shortest's
    assert number(half[5]) < number(two[5])  # the path's vertices
    assert (tmp_path / "growth" / "log_growth.csv").is_file()


def test_sweep_rate_counts_runs_per_core_minute_of_each_planners_sweep(tmp_path):
    out = run_benchmark(
        "sweep_rate.py", *("--worlds", "2", "--planners", "apf,vplane", "--out", "rate"), cwd=tmp_path
    )
    rows = {row["planner"]: row for row in csv.DictReader((tmp_path / "rate" / "sweep_rate.csv").open())}
    assert set(rows) == {"apf", "vplane"} and all(row["runs"] == "2" for row in rows.values())
    assert all(float(row["cpu_s"]) > 0 and float(row["runs_per_core_minute"]) > 0 for row in rows.values())
    assert len(table_rows(out, "barn, default robot")) == 2
    assert (tmp_path / "rate" / "sweep_rate.png").stat().st_size > 1000


def run_peer_irsim(cwd: Path) -> subprocess.CompletedProcess:
    """benchmarks/peer_irsim.py with its smallest arguments."""
    arguments = ("--count", "1", "--time-limit", "0.1", "--repeat", "1", "--planners", "dwa")
    return subprocess.run(
        [sys.executable, str(BENCHMARKS / "peer_irsim.py"), *arguments],
        cwd=cwd,
        env=SCRIPT_ENVIRONMENT,
        capture_output=True,
        text=True,
        timeout=600,
    )


# Looked up, not imported: importing IR-SIM sets Matplotlib's backend for the whole test process.
@pytest.mark.skipif(
    importlib.util.find_spec("irsim") is None, reason="IR-SIM (the `peers` extra) not installed"
)
def test_peer_irsim_times_both_simulators_on_the_same_world(tmp_path):
    done = run_peer_irsim(tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    rows = table_rows(done.stdout, "barn_protocol_0_000")
    ((_, cylinders, difference_mm),) = [row for row in rows if len(row) == 3]
    assert int(cylinders) > 100 and float(difference_mm) < 2.0  # IR-SIM's world scans as this project's
    timings = {(row[1], row[2]): row for row in rows if len(row) == 10}
    simulators = ("IR-SIM `dash`", "vplane-mj `dwa`")
    assert set(timings) == {(simulator, beams) for simulator in simulators for beams in ("16", "720")}
    for row in timings.values():
        assert float(row[4]) == pytest.approx(0.1) and float(row[6]) > 0  # simulated s, sim s per CPU s
    overall = [table_rows(done.stdout, simulator) for simulator in simulators]
    assert [[row[1] for row in rows] for rows in overall] == [["16", "720"], ["16", "720"]]


def test_peer_irsim_without_irsim_says_what_to_install(tmp_path):
    script = str(BENCHMARKS / "peer_irsim.py")
    hide_irsim = (
        "import runpy, sys; sys.modules['irsim'] = None; sys.argv = [sys.argv[1]]; "
        "runpy.run_path(sys.argv[0], run_name='__main__')"
    )
    done = subprocess.run(
        [sys.executable, "-c", hide_irsim, script],
        cwd=tmp_path,
        env=SCRIPT_ENVIRONMENT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "pip install 'vplane-mj[peers]'" in done.stderr and "(irsim)" in done.stderr


def test_ros2_export_reports_its_time_and_the_bag_s_size_per_minute(tmp_path):
    out = run_benchmark("ros2_export.py", *("--seconds", "2", "--repeat", "1", "--out", "bags"), cwd=tmp_path)
    (jackal,) = table_rows(out, "jackal, laser 720 beams, 50 Hz")
    (default,) = table_rows(out, "default, 16 sonars, 20 Hz")
    assert number(jackal[2]) == 101 and number(default[2]) == 41  # ticks: 2 s at 50 and 20 Hz
    assert number(jackal[5]) > number(default[5]) > 0  # MB per minute: 720 beams at 50 Hz weigh more
    assert number(jackal[6]) > 0 and number(default[6]) > 0  # the export's seconds
    assert (tmp_path / "bags" / "ros2_export.csv").is_file()


def test_a_prediction_misses_by_what_the_obstacle_changed_after_it():
    predict = benchmark_module("motion_prediction").prediction_errors
    # 1 m/s east until 10 s, then 2 m/s: predicted from 8.0 s (its last half second at 1 m/s),
    # 3 s ahead it is 1 m farther along than the constant velocity puts it, and not aside.
    times = np.arange(150, 221) * 0.05
    east = np.where(times < 10.0, times, 10.0 + 2.0 * (times - 10.0))
    ((speeding,),) = predict(np.stack([east, np.zeros_like(east)], 1), 0.05, 0.5, 0.25, (3.0,))
    assert speeding == pytest.approx([1.0, 1.0, 0.0, 1.0], abs=1e-9)
    # A straight line at a steady speed is predicted exactly, both ways.
    steady = predict(np.outer(times, [1.2, -0.5]), 0.05, 0.5, 0.25, (0.5, 3.0))
    assert len(steady) > 0 and np.abs(steady).max() < 1e-9
    # On a circle (2 m radius, 0.5 rad/s) the constant velocity strays to the left, the
    # constant turn rate follows it.
    times = np.arange(200) * 0.05
    circle = predict(np.stack([2 * np.cos(0.5 * times), 2 * np.sin(0.5 * times)], 1), 0.05, 0.5, 0.25, (1.0,))
    assert circle[:, 0, 2].min() > 0.2 and circle[:, 0, 3].max() < 0.02
    # A window over a loop's jump back to its start is left out.
    jumped = np.outer(times, [1.0, 0.0])
    jumped[100:] -= 5.0
    kept = predict(jumped, 0.05, 0.5, 0.25, (1.0,))
    assert len(kept) == len(predict(np.outer(times, [1.0, 0.0]), 0.05, 0.5, 0.25, (1.0,))) - 6


def test_motion_prediction_scores_generated_worlds(tmp_path):
    out = run_benchmark(
        "motion_prediction.py", *("--count", "3", "--span", "20", "--out", "mp"), cwd=tmp_path
    )
    one, three = table_rows(out, "all")[1], table_rows(out, "all")[3]
    assert one[1] == "1.0" and three[1] == "3.0"
    assert int(one[2]) > 0 and 0.0 < number(one[4]) < number(three[4])  # the error grows ahead
    assert (tmp_path / "mp" / "motion_prediction.csv").is_file()
