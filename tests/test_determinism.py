"""Same scenario, planner and seed, every fault on: the same summary and trajectory, bit for bit,
in another process and on the Dask engine."""

import json
import os
import subprocess
import sys

import pytest

from vplane_mj.cli import main
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.summary import without_timing

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it

EVERY_FAULT = [
    "sensors.noise_std=0.02",
    "sensors.dropout=0.1",
    "sensors.crosstalk=0.05",
    "sensors.dead=[2, 9]",
    "robot.wheel_friction=0.5",
    "robot.motor_gain=[0.9, 0.7]",
    "robot.motor_bias_nm=[0.01, -0.01]",
    'sensors.pose="odometry"',
    "sensors.odometry_noise=0.01",
]
SETS = [arg for override in EVERY_FAULT for arg in ("--set", override)]


def _run_in_new_process(out_dir, hash_seed: str) -> dict:
    command = [sys.executable, "-m", "vplane_mj", "run", "paper_h_escape", "--seed", "3", *SETS]
    command += ["--no-log", "--no-render", "--out", str(out_dir)]
    env = {**os.environ, "PYTHONHASHSEED": hash_seed}
    finished = subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)
    assert finished.returncode in (0, 1), finished.stderr
    return json.loads((out_dir / "paper_h_escape-vplane-3.json").read_text())


def test_two_processes_and_this_one_give_identical_runs(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    first.mkdir()
    second.mkdir()
    a, b = _run_in_new_process(first, "1"), _run_in_new_process(second, "2")
    here = run_scenario(load_scenario("paper_h_escape", [*EVERY_FAULT, "run.seed=3"])).summary
    here = json.loads(json.dumps(here.to_dict()))  # the JSON form the files hold
    assert without_timing(a) == without_timing(b) == without_timing(here)
    assert a["odometry_error_m"] > 0  # the faults were on


def test_another_seed_gives_another_trajectory():
    def digest(seed):
        scenario = load_scenario("single_box", [*EVERY_FAULT, f"run.seed={seed}", "run.time_limit_s=5"])
        return run_scenario(scenario).summary.trajectory_sha256

    assert digest(0) == digest(0) != digest(1)


def test_dask_and_the_local_pool_give_identical_rows_with_every_fault_on(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    local, remote = tmp_path / "local", tmp_path / "dask"
    local.mkdir()
    remote.mkdir()
    args = ["bench", "paper_c_escape", "single_box", "--planners", "vplane,bug2", "--seeds", "0-1", *SETS]
    assert main([*args, "--jobs", "2", "--out", str(local)]) == 0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        assert main([*args, "--scheduler", cluster.scheduler_address, "--out", str(remote)]) == 0
    capsys.readouterr()

    def rows(directory):
        document = json.loads((directory / "bench.json").read_text())
        return sorted(
            (without_timing(row) for row in document["rows"]),
            key=lambda row: (row["scenario"], row["planner"], row["seed"]),
        )

    local_rows, remote_rows = rows(local), rows(remote)
    assert len(local_rows) == 8
    assert local_rows == remote_rows
    assert len({row["trajectory_sha256"] for row in local_rows}) == 8


BLAS_FREE_RUNS = """
from tests.test_golden import GOLDEN_TIME_LIMIT_S, world_texts
from vplane_mj.kernels import compiled_for_cpu
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.loop import run_scenario

jackal = ['robot.profile="jackal"', 'sensors.pose="ekf"', "run.time_limit_s=8"]
golden = ["planner.name=vplane", f"run.time_limit_s={GOLDEN_TIME_LIMIT_S}"]
runs = [
    parse_scenario(world_texts()["clutter_1_000"], "clutter_1_000", golden),
    load_scenario("paper_c_escape", [*jackal, "planner.name=dwa"]),
    load_scenario("paper_c_escape", [*jackal, "planner.name=vplane_plus"]),
]
print(compiled_for_cpu(), *(run_scenario(scenario).summary.trajectory_sha256 for scenario in runs))
"""


def _blas_free_runs(**env: str) -> list[str]:
    finished = subprocess.run(
        [sys.executable, "-c", BLAS_FREE_RUNS],
        capture_output=True,
        text=True,
        env={**{k: v for k, v in os.environ.items() if k != "NUMBA_CPU_NAME"}, **env},
        timeout=600,
    )
    assert finished.returncode == 0, finished.stderr
    return finished.stdout.split()


def test_trajectories_do_not_depend_on_the_blas_kernels_or_the_cpu_model():
    """OpenBLAS's baseline kernels (no fused multiply-adds) changed two golden trajectories
    while products went through BLAS; the kernels compile for a generic CPU unless asked."""
    usual = _blas_free_runs()
    assert usual[0] == "generic"
    assert _blas_free_runs(OPENBLAS_CORETYPE="Prescott") == usual
