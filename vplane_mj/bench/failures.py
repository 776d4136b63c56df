"""Runs of a sweep that end without a summary: what went wrong, as a row with outcome `error`,
and the scenario kept for replay.

A run that raises gives a RunFailure with the exception's type and text and where it was
raised (the innermost frames of its traceback), and the whole traceback; a run whose worker
process died gives one that names the signal or the exit status. Either becomes a row with
every key of a run's summary (outcome `error`, not reached, no collision, nothing travelled,
score 0) and `failure` saying which of the two it was.
"""

from __future__ import annotations

import re
import shlex
import signal
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from vplane_mj.bench.job import Job
from vplane_mj.files import write_atomically
from vplane_mj.planning.protocol.registry import command_line_spec
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.sim.failure import FailureKind, RunFailure, failure_of
from vplane_mj.sim.summary import Outcome, RunSummary
from vplane_mj.version import __version__

FAILURE_KEY = "failure"
"""The row key that says why a run has no summary of its own (a FailureKind)."""
FAILED_SCENARIO_KEY = "failed_scenario"
"""The row key of an `error` run's saved scenario: `vplane-mj run` on it runs it again."""
RERUN_KEY = "rerun"
"""The row key of the command that runs an `error` run again: `vplane-mj run` on its saved
scenario, with `--planner SPEC` for a planner registered in the sweep's process."""
FAILED_DIR = "failed"
"""Where in a sweep's output directory the scenarios of its `error` runs are saved."""

Item = TypeVar("Item")
Result = TypeVar("Result")


def call_or_failure(run: Callable[[Item], Result], item: Item) -> Result | RunFailure:
    """`run(item)`, or the RunFailure of the exception it raised (made where it was raised:
    an exception object may not survive being sent to another process)."""
    try:
        return run(item)
    except Exception as exc:
        trace = exc.__traceback__
        return failure_of(exc, trace.tb_next if trace else None)  # without this frame


def worker_died(exit_code: int) -> RunFailure:
    """The failure of a run whose worker process ended with `exit_code` (-N: killed by signal N)."""
    how = f"killed by {_signal_name(-exit_code)}" if exit_code < 0 else f"it exited with status {exit_code}"
    return RunFailure(FailureKind.WORKER_DIED, f"the worker process running this run died: {how}")


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def error_row(job: Job, failure: RunFailure) -> dict[str, Any]:
    """The sweep's row for a job that ended in `failure`: a summary with outcome `error`, of the
    job's robot and sensor."""
    document = tomllib.loads(job.toml)
    profile = document.get("robot", {}).get("profile", "default")
    summary = RunSummary(
        scenario=job.scenario,
        planner=job.planner,
        seed=job.seed,
        outcome=Outcome.ERROR,
        robot_profile=profile,
        sensor_kind=document.get("sensors", {}).get("kind", robot_profile(profile).sensors["kind"]),
        score=0.0,  # not a success: it counts against the planner's mean score
        message=failure.message,
        version=__version__,
    )
    return {"key": job.key, **summary.to_dict(), FAILURE_KEY: str(failure.kind)}


def save_failed_scenario(out_dir: Path, job: Job, trace: str = "") -> tuple[Path, str]:
    """Write the job's scenario to `out_dir/failed/<scenario>-<planner>-<seed>.toml` (and a
    non-empty traceback beside it as `.traceback.txt`), each atomically; the scenario's path,
    and the command that runs it again, which the file's first lines say too (as comments)."""
    directory = out_dir / FAILED_DIR
    directory.mkdir(exist_ok=True)
    base = re.sub(r"[^\w.-]", "_", f"{job.scenario}-{job.planner}-{job.seed}")
    if trace:
        write_atomically(directory / f"{base}.traceback.txt", lambda tmp: tmp.write_text(trace, "utf-8"))
    target = directory / f"{base}.toml"
    rerun = rerun_command(target, job.planner)
    text = f"# A run of a sweep that ended in error; to run it again:\n# {rerun}\n{job.toml}"
    return write_atomically(target, lambda tmp: tmp.write_text(text, "utf-8")), rerun


def rerun_command(scenario: Path, planner: str) -> str:
    """`vplane-mj run SCENARIO`, and `--planner SPEC` when `planner` was registered in this
    process (a class of a script is named by the script's file; one of an interactive
    session, by nothing: it has to be registered again, in code)."""
    command = f"vplane-mj run {shlex.quote(str(scenario))}"
    spec = command_line_spec(planner)
    return f"{command} --planner {shlex.quote(spec)}" if spec else command


def finished_row(job: Job, result: dict[str, Any] | RunFailure, out_dir: Path) -> dict[str, Any]:
    """A sweep's row for a finished job: its summary row, or the error row of its failure.

    The scenario of every run that ended in `error` (a failure, or a run's own `error`
    outcome, such as its planner raising) is saved for replay and named in the row under
    FAILED_SCENARIO_KEY, with the command that runs it again under RERUN_KEY.
    """
    if isinstance(result, RunFailure):
        row, trace = error_row(job, result), result.traceback
    else:
        row, trace = result, result.get("traceback", "")
    if row["outcome"] == Outcome.ERROR:
        saved, rerun = save_failed_scenario(out_dir, job, trace)
        row[FAILED_SCENARIO_KEY], row[RERUN_KEY] = str(saved), rerun
    return row
