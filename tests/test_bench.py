"""`vplane-mj bench`: the sweep, its outputs, resuming, interruptions, and invalid input."""

import contextlib
import csv
import dataclasses
import json
import os
import shlex
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from vplane_mj.bench import sweep as sweep_module
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
from vplane_mj.planning.protocol.plugins import FILE_MODULE_PREFIX
from vplane_mj.planning.protocol.registry import load_planner
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
        (["--set", "sensors.dropout=2"], "sensors.dropout"),
    ],
)
def test_invalid_input_exits_2_and_writes_nothing(tmp_path, capsys, extra, fragment):
    assert main(["bench", "open_field", *extra, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and fragment in err
    assert list(tmp_path.iterdir()) == []


def test_an_unreachable_scheduler_exits_2_and_writes_nothing(tmp_path, capsys, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(sweep_module, "SCHEDULER_TIMEOUT_S", 0.5)  # Dask retries until then
    with socket.socket() as refusing:
        refusing.bind(("127.0.0.1", 0))  # bound and not listening: a connection is refused at once
        address = f"tcp://127.0.0.1:{refusing.getsockname()[1]}"
        assert main(["bench", "open_field", "--scheduler", address, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: --scheduler: cannot reach a Dask scheduler at {address}: "), err
    assert list(tmp_path.iterdir()) == []


def test_parse_seeds():
    assert parse_seeds("0-3") == [0, 1, 2, 3]
    assert parse_seeds("7") == [7]
    assert parse_seeds("5,0-1,5") == [0, 1, 5]
    for bad in ("0-4294967296", "0-4294967295", "-1", "3-1", "a"):
        with pytest.raises(VPlaneError, match="--seeds"):
            parse_seeds(bad)


@pytest.mark.slow
def test_a_dask_cluster_gives_the_same_rows_as_the_local_pool(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    local, remote = tmp_path / "local", tmp_path / "dask"
    local.mkdir()
    remote.mkdir()
    args = ["bench", "open_field", "paper_c_escape", "--planners", "apf,vplane", "--seeds", "0"]
    assert main([*args, "--jobs", "2", "--out", str(local)]) == 0
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
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


# A sweep in its own process, interrupted as a user or a service manager would. Its runs are
# open_field and single_box, each by apf and by `gated`, an apf held mid-run until the test
# opens a gate (GATED_PLANNER): with two workers, the two apf runs of open_field finish, then
# both workers hold a gated run, so the test acts at a known point of the sweep, whatever the
# speed of the machine, and a sweep that waited for its runs rather than stop would never end.
SEEDS = (0, 1)
SWEEP_KEYS = {(s, p, seed) for s in ("open_field", "single_box") for p in ("apf", "gated") for seed in SEEDS}
TIME_LIMIT = "run.time_limit_s=8"

GATED_PLANNER = """
import time
import uuid
from pathlib import Path

from vplane_mj.planning.planners.apf import ApfPlanner

GATE = Path(__file__).parent
HOLD_AT_S = 0.5
WAIT_AT_MOST_S = 300.0  # a run whose gate a failed test never opened ends by itself


class Gated(ApfPlanner):
    name = "gated"
    summary = "apf, held mid-run (once) until its gate opens"
    citation = "none"
    held = False

    def step(self, obs):
        if not self.held and obs.time_s >= HOLD_AT_S:
            self.held = True
            (GATE / f"held-{uuid.uuid4().hex}").touch()
            deadline = time.monotonic() + WAIT_AT_MOST_S
            while not (GATE / "open").exists():
                if time.monotonic() > deadline:
                    raise TimeoutError("the gate never opened")
                time.sleep(0.01)
        return super().step(obs)
"""


@dataclasses.dataclass
class Gate:
    """The gated planner's file, and its gate: a `held-*` file per run that reached it, and
    the file `open`, which lets every held run go on (and the later ones pass)."""

    directory: Path

    @property
    def spec(self) -> str:
        return f"{self.directory.resolve() / 'gated_planner.py'}:Gated"

    def held(self) -> int:
        return len(list(self.directory.glob("held-*")))

    def open(self) -> None:
        (self.directory / "open").touch()


@pytest.fixture
def gate(tmp_path, own_registry):
    """A closed gate, its planner registered in this process too (to plan its jobs here)."""
    directory = tmp_path / "gate"
    directory.mkdir()
    (directory / "gated_planner.py").write_text(GATED_PLANNER)
    found = Gate(directory)
    load_planner(found.spec)
    yield found
    found.open()  # nothing stays held
    sys.modules.pop(f"{FILE_MODULE_PREFIX}gated_planner", None)  # the next test's file is another


def bench_arguments(out_dir, gate):
    return [
        *["bench", "open_field", "single_box", "--planners", f"apf,{gate.spec}", "--seeds", "0-1"],
        *["--jobs", "2", "--set", TIME_LIMIT, "--out", str(out_dir)],
    ]


def bench_command(out_dir, gate):
    return [sys.executable, "-m", "vplane_mj", *bench_arguments(out_dir, gate)]


PATIENT_SWEEP = """
import sys
from vplane_mj.bench import pool
from vplane_mj.cli import main

pool.JOIN_TIMEOUT_S = 600.0
sys.exit(main(sys.argv[1:]))
"""
"""`vplane-mj` whose sweep would wait 600 s, not 5, for a worker to end by itself before it
terminates it: a sweep that stopped its workers other than at once would outlast the test."""


def start_bench(out_dir, gate):
    """The sweep (PATIENT_SWEEP) as the leader of its own process group, like a command started
    from a shell."""
    return subprocess.Popen(
        [sys.executable, "-c", PATIENT_SWEEP, *bench_arguments(out_dir, gate)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def wait_until(condition, process, what, seconds=60.0):
    """Wait until `condition()` holds; fail when the sweep ends first or it takes `seconds`."""
    deadline = time.monotonic() + seconds
    while not condition():
        if process.poll() is not None or time.monotonic() > deadline:
            raise AssertionError(f"{what} did not happen (sweep status {process.poll()})")
        time.sleep(0.02)


def journal_lines(out_dir) -> int:
    """The complete lines of the sweep's journal."""
    journal = out_dir / JOURNAL
    return journal.read_bytes().count(b"\n") if journal.exists() else 0


def hold_both_workers(out_dir, gate, process):
    """Wait until the sweep has written its two apf rows of open_field and both workers hold
    a gated run; the pids of its workers."""
    wait_until(lambda: journal_lines(out_dir) == 2 and gate.held() == 2, process, "two rows, two held runs")
    workers = descendants(process.pid)
    assert len(workers) == 2, "the sweep does not have its two worker processes"
    return workers


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


def assert_the_rerun_completes_the_sweep(out_dir, gate, done):
    """With the gate open, the same command again runs only what the journal lacks and writes
    one row per run."""
    gate.open()
    finished = subprocess.run(bench_command(out_dir, gate), capture_output=True, text=True, timeout=120)
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
@pytest.mark.slow
def test_an_interrupted_sweep_keeps_its_finished_runs_stops_its_workers_and_resumes(
    tmp_path, gate, signum, whole_group
):
    out_dir = tmp_path / "out"
    process = start_bench(out_dir, gate)
    try:
        workers = hold_both_workers(out_dir, gate, process)
        # Ctrl-C in a terminal signals the whole foreground process group, workers included.
        (os.killpg if whole_group else os.kill)(process.pid, signum)
        try:
            _, err = process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            raise AssertionError("the sweep waited for its workers, held at the gate, to end") from None
        assert process.returncode == 128 + signum, err
        assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
        messages = [line for line in err.splitlines() if "interrupted" in line]
        assert messages == [
            f"interrupted by {signal.Signals(signum).name}: finished runs are kept in {out_dir / JOURNAL}; "
            "run the same command again to complete the sweep"
        ]
        # Held at the closed gate, a worker would run on for minutes: gone means stopped.
        assert not wait_until_gone(workers, seconds=30.0), "worker processes outlived the sweep"
    finally:
        end_session(process)
    assert gate.held() == 2  # no run started after the interruption
    assert len(assert_only_complete_files(out_dir)) == 2
    assert_the_rerun_completes_the_sweep(out_dir, gate, done=2)


@pytest.mark.slow
def test_a_killed_sweep_leaves_a_journal_the_rerun_resumes_from(tmp_path, gate):
    out_dir = tmp_path / "out"
    process = start_bench(out_dir, gate)
    try:
        workers = hold_both_workers(out_dir, gate, process)
        process.kill()
        process.communicate(timeout=30)
        # Orphaned workers notice that the sweep is gone and exit rather than run on (held at
        # the closed gate, they would run on for minutes).
        assert not wait_until_gone(workers, seconds=30.0), "worker processes outlived the killed sweep"
    finally:
        end_session(process)
    assert len(read_journal(out_dir / JOURNAL)) == 2
    # The killed sweep's lock file stays, stale (the kernel dropped its lock): the rerun takes it.
    assert {path.name for path in out_dir.iterdir()} == {JOURNAL, ".bench.lock"}
    assert_the_rerun_completes_the_sweep(out_dir, gate, done=2)
    assert not (out_dir / ".bench.lock").exists()


# ----------------------------------------------------------------- runs that fail, workers that die


def gated_jobs():
    """The jobs of the gated sweep, planned in this process."""
    return plan_jobs(["open_field", "single_box"], ["apf", "gated"], SEEDS, [TIME_LIMIT])


def broken(job):
    """The job with a scenario that no longer validates: its run raises in the worker."""
    return dataclasses.replace(job, seed=7, toml=job.toml.replace('name = "apf"', 'name = "nope"'))


def saved_text(saved: Path, job, planner_spec: str = "") -> str:
    """A failed run's saved scenario: the command that runs it again (with `--planner SPEC` for a
    planner registered in the sweep's process), then the job's scenario."""
    rerun = f"vplane-mj run {saved}" + (f" --planner {planner_spec}" if planner_spec else "")
    return f"# A run of a sweep that ended in error; to run it again:\n# {rerun}\n{job.toml}"


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


@pytest.mark.slow
def test_a_worker_killed_mid_sweep_is_an_error_row_and_every_other_run_finishes(tmp_path, gate):
    out_dir = tmp_path / "out"
    process = start_bench(out_dir, gate)
    try:
        killed = min(hold_both_workers(out_dir, gate, process))
        os.kill(killed, signal.SIGKILL)
        assert not wait_until_gone({killed}, seconds=30.0)
        gate.open()  # the other held run, and those to come, go on
        out, err = process.communicate(timeout=120)
    finally:
        end_session(process)
    assert process.returncode == 0, err
    rows = [json.loads(line) for line in (out_dir / JOURNAL).read_text().splitlines()]
    assert sorted((r["scenario"], r["planner"], r["seed"]) for r in rows) == sorted(SWEEP_KEYS)
    [error] = [row for row in rows if row["outcome"] == "error"]
    assert error["failure"] == "worker_died" and not error["success"] and error["collisions"] == 0
    assert error["message"] == "the worker process running this run died: killed by SIGKILL"
    assert all(row["steps"] > 0 for row in rows if row is not error)  # the queued runs were not lost
    job = next(j for j in gated_jobs() if j.key == error["key"])
    assert (job.scenario, job.planner) == ("open_field", "gated")  # the run the worker held
    saved = out_dir / "failed" / f"open_field-gated-{job.seed}.toml"
    assert error["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, job, gate.spec)
    assert [path.name for path in (out_dir / "failed").iterdir()] == [saved.name]
    assert f"1 of 8 runs ended in error; their scenarios are in {out_dir / 'failed'}" in out
    died = f"open_field, gated, seed {job.seed}: the worker process running this run died: killed by SIGKILL"
    assert f"\n  {died}\n    vplane-mj run {saved} --planner {gate.spec}\n" in out
    table = {line["planner"]: line for line in json.loads((out_dir / "bench.json").read_text())["table"]}
    assert (table["apf"]["errors"], table["gated"]["errors"]) == (0, 1)
    with open(out_dir / "bench.csv", newline="") as stream:
        csv_rows = list(csv.DictReader(stream))
    assert sorted(row["outcome"] == "error" for row in csv_rows) == [False] * 7 + [True]

    # Resuming runs nothing again.
    again = subprocess.run(bench_command(out_dir, gate), capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "8 runs: 8 already done, 0 to run" in again.stderr
    assert len((out_dir / JOURNAL).read_text().splitlines()) == 8


@pytest.mark.slow
def test_a_failed_dask_task_is_the_same_error_row_as_in_the_local_pool(tmp_path):
    distributed = pytest.importorskip("distributed")
    good = plan_jobs(["open_field"], ["apf"], [0])[0]
    failing = broken(good)
    (tmp_path / "local").mkdir()
    local = run_sweep([failing], tmp_path / "local", workers=1)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        rows = run_sweep([good, failing], tmp_path, 1, cluster.scheduler_address)
    assert [row["outcome"] for row in rows] == ["reached", "error"]
    saved = tmp_path / "failed" / "open_field-apf-7.toml"
    assert rows[1]["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, failing)
    elsewhere = {"failed_scenario": "", "rerun": ""}  # the two sweeps' output directories differ
    assert {**rows[1], **elsewhere} == {**local[0], **elsewhere}


@pytest.mark.slow
def test_a_dask_worker_that_dies_mid_run_is_an_error_row(tmp_path, gate):
    distributed = pytest.importorskip("distributed")
    import dask

    job = next(j for j in gated_jobs() if j.planner == "gated")
    (tmp_path / "out").mkdir()
    # No second attempt for a task whose worker died: the first death fails it (KilledWorker).
    with (
        dask.config.set({"distributed.scheduler.allowed-failures": 0}),
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        [worker_pid] = client.run(os.getpid).values()
        killed = []

        def kill_the_worker_mid_run():
            deadline = time.monotonic() + 60
            while gate.held() == 0 and time.monotonic() < deadline:
                time.sleep(0.02)
            if gate.held():
                os.kill(worker_pid, signal.SIGKILL)
                killed.append(worker_pid)
            else:
                gate.open()  # the run never got to the gate: let it end, and fail below

        killer = threading.Thread(target=kill_the_worker_mid_run)
        killer.start()
        [row] = run_sweep([job], tmp_path / "out", 1, cluster.scheduler_address)
        killer.join()
    assert killed, "the run never reached the gate"
    assert row["outcome"] == "error" and row["failure"] == "worker_died", row
    assert row["message"].startswith("distributed.scheduler.KilledWorker: ")
    assert "all those workers died while running it" in row["message"]
    saved = tmp_path / "out" / "failed" / f"{job.scenario}-gated-{job.seed}.toml"
    assert row["failed_scenario"] == str(saved) and saved.read_text() == saved_text(saved, job, gate.spec)


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
