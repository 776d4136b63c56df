"""`vplane-mj bench`: the sweep, its outputs, resuming, interruptions, and invalid input."""

import contextlib
import csv
import dataclasses
import json
import os
import shlex
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from vplane_mj.bench.failures import FAILED_SCENARIO_KEY
from vplane_mj.bench.sweep import (
    JOURNAL,
    PATH_KEY,
    error_lines,
    family_of,
    parse_seeds,
    plan_jobs,
    read_journal,
    run_sweep,
    summarize,
)
from vplane_mj.cli import main
from vplane_mj.errors import VPlaneError
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.summary import without_timing

OUTPUTS = ("bench.csv", "bench.json", "bench.png", "bench-scenarios.png", "bench.html")
ARGS = ["bench", "open_field", "paper_c_escape", "--planners", "apf,vplane", "--seeds", "0-1", "--jobs", "2"]


def test_a_sweep_writes_rows_table_and_plot_and_resumes(tmp_path, capsys):
    assert main([*ARGS, "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "8 runs: 0 already done, 8 to run" in captured.err
    document = json.loads((tmp_path / "bench.json").read_text())
    rows, table = document["rows"], document["table"]
    assert len(rows) == 8 and {(r["scenario"], r["planner"], r["seed"]) for r in rows} == {
        (s, p, seed) for s in ("open_field", "paper_c_escape") for p in ("apf", "vplane") for seed in (0, 1)
    }
    by_planner = {row["planner"]: row for row in table}
    assert by_planner["vplane"]["success_rate"] == 1.0
    assert by_planner["apf"]["success_rate"] == 0.5  # trapped in the C obstacle
    assert by_planner["apf"]["stuck"] == 2
    assert 1.0 <= by_planner["vplane"]["median_path_ratio"] < 1.6
    assert "success_rate" in captured.out and "vplane" in captured.out
    assert len((tmp_path / "bench.csv").read_text().splitlines()) == 9
    assert (tmp_path / "bench.png").stat().st_size > 10_000
    assert (tmp_path / "bench-scenarios.png").stat().st_size > 5_000
    assert "path_xy" not in (tmp_path / "bench.csv").read_text().splitlines()[0]
    for r in rows:  # the travelled path, simplified, from the start to where the run ended
        path = r["path_xy"]
        assert 2 <= len(path) < 200
        assert path[0] == pytest.approx(list(load_scenario(r["scenario"]).robot.start), abs=0.01)
        assert r["final_distance_to_goal_m"] == pytest.approx(
            np.hypot(*(np.array(path[-1]) - load_scenario(r["scenario"]).robot.goal)), abs=0.01
        )
    page = (tmp_path / "bench.html").read_text()
    assert page.count("<details") == 8 and page.count("<polyline") == 8
    assert "http://" not in page and "https://" not in page and "<script" not in page

    # Rerunning the same command runs nothing again and gives the same rows.
    assert main([*ARGS, "--out", str(tmp_path)]) == 0
    assert "8 already done, 0 to run" in capsys.readouterr().err
    again = json.loads((tmp_path / "bench.json").read_text())["rows"]
    assert [r["key"] for r in again] == [r["key"] for r in rows]

    # An interrupted sweep (journal with 5 rows, the last one torn) completes the rest.
    lines = (tmp_path / "bench.jsonl").read_text().splitlines()
    (tmp_path / "bench.jsonl").write_text("\n".join(lines[:5]) + "\n" + lines[5][:40])
    assert main([*ARGS, "--out", str(tmp_path)]) == 0
    assert "5 already done, 3 to run" in capsys.readouterr().err
    assert len(read_journal(tmp_path / "bench.jsonl")) == 8  # the torn line did not swallow a new row
    resumed = json.loads((tmp_path / "bench.json").read_text())["rows"]

    assert [without_timing(r) for r in resumed] == [without_timing(r) for r in rows]


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--seeds", "5-2"], "--seeds"),
        (["--seeds", "x"], "--seeds"),
        (["--planners", "apf,nope"], "--planners: unknown planner 'nope'"),
        (["--jobs", "0"], "--jobs"),
        (["--scheduler", "tcp://127.0.0.1:8786"], "--scheduler"),
        (["--set", "sensors.dropout=2"], "sensors.dropout"),
    ],
)
def test_invalid_input_exits_2_and_writes_nothing(tmp_path, capsys, extra, fragment):
    assert main(["bench", "open_field", *extra, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and fragment in err
    assert list(tmp_path.iterdir()) == []


def test_parse_seeds():
    assert parse_seeds("0-3") == [0, 1, 2, 3]
    assert parse_seeds("7") == [7]
    assert parse_seeds("5,0-1,5") == [0, 1, 5]
    for bad in ("0-4294967296", "0-4294967295", "-1", "3-1", "a"):
        with pytest.raises(VPlaneError, match="--seeds"):
            parse_seeds(bad)


def test_a_dask_cluster_gives_the_same_rows_as_the_local_pool(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    local, remote = tmp_path / "local", tmp_path / "dask"
    local.mkdir()
    remote.mkdir()
    args = ["bench", "open_field", "paper_c_escape", "--planners", "apf,vplane", "--seeds", "0"]
    assert main([*args, "--jobs", "2", "--out", str(local)]) == 0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        assert main([*args, "--scheduler", cluster.scheduler_address, "--out", str(remote)]) == 0
    assert "on the Dask cluster at" in capsys.readouterr().err

    def rows(directory):
        document = json.loads((directory / "bench.json").read_text())
        return [without_timing(r) for r in document["rows"]]

    assert rows(remote) == rows(local)


def test_family_of_a_generated_scenario():
    assert family_of("traps_1_003") == "traps"
    assert family_of("clutter_12_000") == "clutter"
    assert family_of("paper_c_avoid") == "paper_c_avoid"


# A sweep in its own process, interrupted as a user or a service manager would. A finer physics
# step makes each run (8 simulated seconds) last about a second, so that a signal lands mid-sweep
# and a sweep that waited for its remaining runs (three rounds of two) rather than stop would show.
SWEEP = ["open_field", "single_box", "--planners", "apf", "--seeds", "0-3", "--jobs", "2"]
SWEEP_KEYS = {(s, "apf", seed) for s in ("open_field", "single_box") for seed in range(4)}
SLOW_RUNS = ["--set", "run.physics_dt_s=0.0005", "--set", "run.time_limit_s=8"]


def bench_command(out_dir):
    return [sys.executable, "-m", "vplane_mj", "bench", *SWEEP, *SLOW_RUNS, "--out", str(out_dir)]


def start_bench(out_dir):
    """The sweep as the leader of its own process group, like a command started from a shell."""
    return subprocess.Popen(
        bench_command(out_dir),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def wait_for_a_finished_run(out_dir, process, seconds=60.0):
    """Wait until the journal holds a complete line: the sweep is under way."""
    journal = out_dir / JOURNAL
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and process.poll() is None:
        if journal.exists() and b"\n" in journal.read_bytes():
            return
        time.sleep(0.02)
    raise AssertionError(f"the sweep finished no run (status {process.poll()})")


def proc_stat(pid):
    """(parent pid, state letter) of a live process from /proc, or None once it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    state, ppid = text[text.rindex(")") + 2 :].split()[:2]
    return int(ppid), state


def descendants(pid):
    """The pids of every process below `pid`."""
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and (stat := proc_stat(entry.name)):
            parents[int(entry.name)] = stat[0]
    found, frontier = set(), {pid}
    while frontier:
        frontier = {child for child, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def wait_until_gone(pids, seconds):
    """The pids still running (zombies count as gone) after waiting up to `seconds`."""
    deadline = time.monotonic() + seconds
    while True:
        alive = {pid for pid in pids if (stat := proc_stat(pid)) and stat[1] != "Z"}
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.05)


def end_session(process):
    """Kill whatever is left of the sweep's process group (a failed test leaves nothing behind)."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)
    if process.returncode is None:
        process.communicate(timeout=30)


def assert_only_complete_files(out_dir):
    """The journal's lines are whole rows; the other outputs are complete or absent."""
    names = {path.name for path in out_dir.iterdir()}
    assert names <= {JOURNAL, *OUTPUTS}, names
    text = (out_dir / JOURNAL).read_text(encoding="utf-8")
    assert text.endswith("\n")
    rows = [json.loads(line) for line in text.splitlines()]
    keys = [(row["scenario"], row["planner"], row["seed"]) for row in rows]
    assert len(keys) == len(set(keys)) and set(keys) <= SWEEP_KEYS
    if "bench.json" in names:
        assert len(json.loads((out_dir / "bench.json").read_text())["rows"]) == len(SWEEP_KEYS)
    if "bench.csv" in names:
        with open(out_dir / "bench.csv", newline="") as stream:
            table = list(csv.reader(stream))
        assert "scenario" in table[0] and all(len(row) == len(table[0]) for row in table[1:])
    for name in ("bench.png", "bench-scenarios.png"):
        if name in names:
            data = (out_dir / name).read_bytes()
            assert data.startswith(b"\x89PNG\r\n\x1a\n") and data.endswith(b"IEND\xaeB`\x82")
    if "bench.html" in names:
        assert (out_dir / "bench.html").read_text().rstrip().endswith("</html>")
    return rows


def assert_the_rerun_completes_the_sweep(out_dir, done):
    """The same command again runs only what the journal lacks and writes one row per run."""
    finished = subprocess.run(bench_command(out_dir), capture_output=True, text=True, timeout=120)
    assert finished.returncode == 0, finished.stderr
    assert f"{len(SWEEP_KEYS)} runs: {done} already done, {len(SWEEP_KEYS) - done} to run" in finished.stderr
    assert len(assert_only_complete_files(out_dir)) == len(SWEEP_KEYS)
    assert set(OUTPUTS) <= {path.name for path in out_dir.iterdir()}
    with open(out_dir / "bench.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == len(SWEEP_KEYS)
    assert {(row["scenario"], row["planner"], int(row["seed"])) for row in rows} == SWEEP_KEYS


@pytest.mark.parametrize(
    "signum, whole_group",
    [(signal.SIGINT, False), (signal.SIGINT, True), (signal.SIGTERM, False), (signal.SIGTERM, True)],
    ids=["SIGINT-process", "SIGINT-group", "SIGTERM-process", "SIGTERM-group"],
)
def test_an_interrupted_sweep_keeps_its_finished_runs_stops_its_workers_and_resumes(
    tmp_path, signum, whole_group
):
    process = start_bench(tmp_path)
    try:
        wait_for_a_finished_run(tmp_path, process)
        workers = descendants(process.pid)
        assert workers, "the sweep has no worker processes"
        # Ctrl-C in a terminal signals the whole foreground process group, workers included.
        signalled = time.monotonic()
        (os.killpg if whole_group else os.kill)(process.pid, signum)
        _, err = process.communicate(timeout=30)
        assert time.monotonic() - signalled < 2.0, "the sweep waited for its remaining runs"
        assert process.returncode == 128 + signum, err
        assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
        messages = [line for line in err.splitlines() if "interrupted" in line]
        assert messages == [
            f"interrupted by {signal.Signals(signum).name}: finished runs are kept in {tmp_path / JOURNAL}; "
            "run the same command again to complete the sweep"
        ]
        assert not wait_until_gone(workers, seconds=2.0), "worker processes outlived the sweep"
    finally:
        end_session(process)
    done = len(assert_only_complete_files(tmp_path))
    assert 1 <= done < len(SWEEP_KEYS)
    assert_the_rerun_completes_the_sweep(tmp_path, done)


def test_a_killed_sweep_leaves_a_journal_the_rerun_resumes_from(tmp_path):
    process = start_bench(tmp_path)
    try:
        wait_for_a_finished_run(tmp_path, process)
        workers = descendants(process.pid)
        process.kill()
        process.communicate(timeout=30)
        # Orphaned workers notice that the sweep is gone and exit rather than run on.
        assert not wait_until_gone(workers, seconds=5.0), "worker processes outlived the killed sweep"
    finally:
        end_session(process)
    done = len(read_journal(tmp_path / JOURNAL))
    assert 1 <= done < len(SWEEP_KEYS)
    assert {path.name for path in tmp_path.iterdir()} == {JOURNAL}
    assert_the_rerun_completes_the_sweep(tmp_path, done)


# ----------------------------------------------------------------- runs that fail, workers that die


def planned_jobs(*overrides):
    return plan_jobs(["open_field", "single_box"], ["apf"], range(4), overrides)


def broken(job):
    """The job with a scenario that no longer validates: its run raises in the worker."""
    return dataclasses.replace(job, seed=7, toml=job.toml.replace('name = "apf"', 'name = "nope"'))


def saved_text(saved: Path, job) -> str:
    """A failed run's saved scenario: the command that runs it again, then the job's scenario."""
    return f"# A run of a sweep that ended in error; to run it again:\n# vplane-mj run {saved}\n{job.toml}"


def test_a_run_that_raises_is_an_error_row_with_its_scenario_saved_and_the_sweep_goes_on(tmp_path, capsys):
    good = plan_jobs(["open_field"], ["apf"], [0, 1])
    failing = broken(good[0])
    jobs = [good[0], failing, good[1]]
    rows = run_sweep(jobs, tmp_path, workers=2)
    assert [row["key"] for row in rows] == [job.key for job in jobs]
    assert [row["outcome"] for row in rows] == ["reached", "error", "reached"]
    error = rows[1]
    assert error["failure"] == "exception" and not error["success"] and not error["reached"]
    assert error["collisions"] == 0 and error["path_length_m"] == 0 and error["score"] == 0
    assert error["time_to_goal_s"] is None and (error["scenario"], error["seed"]) == ("open_field", 7)
    assert set(rows[0]) - {PATH_KEY, FAILED_SCENARIO_KEY} <= set(error)  # every key of a summary row
    # The exception's type and text, and where it was raised.
    assert error["message"].startswith("vplane_mj.errors.ScenarioError: open_field (bench): planner.name: ")
    assert "unknown planner 'nope'" in error["message"]
    assert "(at vplane_mj/scenario/parse.py:" in error["message"] and "in run_job" in error["message"]
    saved = tmp_path / "failed" / "open_field-apf-7.toml"
    assert error["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, failing)
    assert error["rerun"] == f"vplane-mj run {saved}"
    trace = (tmp_path / "failed" / "open_field-apf-7.traceback.txt").read_text()
    assert trace.startswith("Traceback (most recent call last):") and "ScenarioError" in trace
    assert sorted(path.name for path in (tmp_path / "failed").iterdir()) == [
        "open_field-apf-7.toml",
        "open_field-apf-7.traceback.txt",
    ]
    [line] = summarize(rows)
    assert (line["runs"], line["errors"], line["success_rate"]) == (3, 1, pytest.approx(2 / 3))
    assert error_lines(rows, tmp_path) == [
        f"1 of 3 runs ended in error; their scenarios are in {tmp_path / 'failed'}, "
        "each run again by the command below it:",
        f"  open_field, apf, seed 7: {error['message']}",
        f"    vplane-mj run {saved}",
    ]
    capsys.readouterr()

    # The error row is a finished run: resuming runs nothing again.
    assert run_sweep(jobs, tmp_path, workers=2) == rows
    assert "3 runs: 3 already done, 0 to run" in capsys.readouterr().err
    assert len((tmp_path / JOURNAL).read_text().splitlines()) == 3


def test_a_worker_killed_mid_sweep_is_an_error_row_and_every_other_run_finishes(tmp_path):
    process = start_bench(tmp_path)
    try:
        wait_for_a_finished_run(tmp_path, process)
        workers = descendants(process.pid)
        assert len(workers) == 2, "the sweep does not have its two worker processes"
        os.kill(min(workers), signal.SIGKILL)
        out, err = process.communicate(timeout=120)
    finally:
        end_session(process)
    assert process.returncode == 0, err
    rows = [json.loads(line) for line in (tmp_path / JOURNAL).read_text().splitlines()]
    assert sorted((r["scenario"], r["planner"], r["seed"]) for r in rows) == sorted(SWEEP_KEYS)
    [error] = [row for row in rows if row["outcome"] == "error"]
    assert error["failure"] == "worker_died" and not error["success"] and error["collisions"] == 0
    assert error["message"] == "the worker process running this run died: killed by SIGKILL"
    assert all(row["steps"] > 0 for row in rows if row is not error)  # the queued runs were not lost
    job = next(j for j in planned_jobs(*SLOW_RUNS[1::2]) if j.key == error["key"])
    saved = tmp_path / "failed" / f"{job.scenario}-apf-{job.seed}.toml"
    assert error["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, job)
    assert [path.name for path in (tmp_path / "failed").iterdir()] == [saved.name]
    assert f"1 of 8 runs ended in error; their scenarios are in {tmp_path / 'failed'}" in out
    died = (
        f"  {job.scenario}, apf, seed {job.seed}: the worker process running this run died: killed by SIGKILL"
    )
    assert f"{died}\n    vplane-mj run {saved}\n" in out
    assert json.loads((tmp_path / "bench.json").read_text())["table"][0]["errors"] == 1
    with open(tmp_path / "bench.csv", newline="") as stream:
        table = list(csv.DictReader(stream))
    assert sorted(row["outcome"] == "error" for row in table) == [False] * 7 + [True]

    # Resuming runs nothing again.
    again = subprocess.run(bench_command(tmp_path), capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "8 runs: 8 already done, 0 to run" in again.stderr
    assert len((tmp_path / JOURNAL).read_text().splitlines()) == 8


def test_a_failed_dask_task_is_the_same_error_row_as_in_the_local_pool(tmp_path):
    distributed = pytest.importorskip("distributed")
    good = plan_jobs(["open_field"], ["apf"], [0])[0]
    failing = broken(good)
    (tmp_path / "local").mkdir()
    local = run_sweep([failing], tmp_path / "local", workers=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True) as cluster:
        rows = run_sweep([good, failing], tmp_path, 1, cluster.scheduler_address)
    assert [row["outcome"] for row in rows] == ["reached", "error"]
    saved = tmp_path / "failed" / "open_field-apf-7.toml"
    assert rows[1]["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, failing)
    elsewhere = {"failed_scenario": "", "rerun": ""}  # the two sweeps' output directories differ
    assert {**rows[1], **elsewhere} == {**local[0], **elsewhere}


def test_a_dask_worker_that_dies_mid_run_is_an_error_row(tmp_path):
    distributed = pytest.importorskip("distributed")
    import dask

    [job] = planned_jobs(*SLOW_RUNS[1::2])[:1]
    # No second attempt for a task whose worker died: the first death fails it (KilledWorker).
    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True) as cluster,
        distributed.Client(cluster) as client,
    ):
        [worker_pid] = client.run(os.getpid).values()

        def kill_the_worker_mid_run():
            deadline = time.monotonic() + 60
            while not any(client.processing().values()) and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(0.3)
            os.kill(worker_pid, signal.SIGKILL)

        killer = threading.Thread(target=kill_the_worker_mid_run)
        killer.start()
        [row] = run_sweep([job], tmp_path, 1, cluster.scheduler_address)
        killer.join()
    assert row["outcome"] == "error" and row["failure"] == "worker_died"
    assert row["message"].startswith("distributed.scheduler.KilledWorker: ")
    assert "all those workers died while running it" in row["message"]
    saved = tmp_path / "failed" / f"{job.scenario}-apf-{job.seed}.toml"
    assert row["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, job)


FAILING_PLANNER = """
from vplane_mj.planning import Decision, Planner, PlannerParams


class Faulty(Planner):
    name = "faulty"
    summary = "toward the goal, and a bug after half a second"
    citation = "none"
    Params = PlannerParams

    def step(self, obs):
        if obs.time_s >= 0.5:
            raise KeyError("no such thing")
        return Decision(force=obs.goal - obs.position, mode="normal")
"""


def test_the_command_printed_for_a_run_in_error_runs_it_again(
    tmp_path, capsys, monkeypatch, recwarn, own_registry
):
    """`bench --planners apf,file.py:Class` whose planner raises: the rows are in error, and the
    command `bench` prints for each (also the first lines of its saved scenario) runs it again."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "faulty_bench_planner.py").write_text(FAILING_PLANNER)
    argv = ["bench", "open_field", "--planners", "apf,faulty_bench_planner.py:Faulty", "--jobs", "1"]
    assert main([*argv, "--out", "out"]) == 0
    assert not recwarn.list  # the command line lists the runs in error instead of warning
    out = capsys.readouterr().out
    saved = Path("out") / "failed" / "open_field-faulty-0.toml"
    rerun = f"vplane-mj run {saved} --planner {tmp_path / 'faulty_bench_planner.py'}:Faulty"
    error = "planner 'faulty' raised at t = 0.500 s: KeyError: 'no such thing' (at "
    assert f"1 of 2 runs ended in error; their scenarios are in {saved.parent}, each run again" in out
    assert f"\n  open_field, faulty, seed 0: {error}" in out and f"\n    {rerun}\n" in out
    assert saved.read_text().splitlines()[1] == f"# {rerun}"
    assert main([*shlex.split(rerun)[1:], "--out", "again", "--no-render"]) == 3  # not "unknown planner"
    assert error in capsys.readouterr().err
    assert json.loads(Path("again/open_field-faulty-0.json").read_text())["outcome"] == "error"
