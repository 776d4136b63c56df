"""Many runs from Python (`vplane_mj.sweep`): scenarios x planners x seeds, as `vplane-mj bench`
runs them (`vplane_mj.bench.sweep`: the jobs, the resumable journal, the process pool or a Dask
cluster, the table and the report); the command line's `bench` is this call with its flags.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from vplane_mj.bench.job import Job
from vplane_mj.bench.sweep import (
    format_table,
    job_choice,
    parse_seeds,
    plan_jobs,
    run_sweep,
    summarize,
)
from vplane_mj.errors import VPlaneError, readable
from vplane_mj.files import DEFAULT_OUT, exclusive, output_directory
from vplane_mj.planning.protocol import registry
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.plugins import PlannerError, is_import_spec
from vplane_mj.planning.protocol.registry import for_worker, load_planner, register_planner, unknown_planner
from vplane_mj.scenario import Scenario, parse_scenario
from vplane_mj.scenario.overrides import Override
from vplane_mj.sim.summary import Outcome, RunSummary


class SweepErrorWarning(UserWarning):
    """Some runs of a sweep ended in `error` (a planner raised, a worker died, ...): `sweep`
    returns their rows all the same (`SweepResult.errors`) and warns once with their count."""


@dataclass(frozen=True, eq=False)
class SweepResult:
    """What a sweep gave.

    Attributes:
        rows: One per run, in the order scenario, planner, seed: the run's summary as a dict,
            its journal `key` and its simplified path `path_xy` (m).
        table: One row per planner, the columns of `vplane_mj.bench.sweep.TABLE_COLUMNS`.
        files: The report files written (none with `report=False` or `out=None`).
    """

    rows: list[dict]
    table: list[dict]
    files: tuple[Path, ...]

    @property
    def errors(self) -> list[dict]:
        """The rows of the runs that ended in `error` (each with its `message`; in a kept output
        directory also its `failed_scenario` and `rerun`), in row order."""
        return [row for row in self.rows if row["outcome"] == Outcome.ERROR]

    def summaries(self) -> list[RunSummary]:
        """The rows as run summaries."""
        return [RunSummary.from_dict(row) for row in self.rows]

    def scenario_table(self) -> list[dict]:
        """The table with one row per scenario and planner (`vplane-mj bench --by-scenario`)."""
        return summarize(self.rows, by_scenario=True)

    def table_text(self, by_scenario: bool = False) -> str:
        """The table as `vplane-mj bench` prints it (`by_scenario`: the table per scenario and
        planner, as `--by-scenario` prints it after)."""
        return format_table(self.scenario_table() if by_scenario else self.table)


def sweep(
    scenarios: Iterable[Scenario | str | os.PathLike[str]],
    planners: Iterable[str | type[Planner]] | None = None,
    seeds: Iterable[int] | str = (0,),
    overrides: Sequence[str | Override] = (),
    jobs: int | None = None,
    scheduler: str | None = None,
    out: str | os.PathLike[str] | None = DEFAULT_OUT,
    *,
    report: bool = True,
    wait: bool = False,
    ros2: bool = False,
) -> SweepResult:
    """Run every scenario with every planner and seed, as `vplane-mj bench` does.

    Every run is validated before any starts, progress is shown on stderr, finished runs are
    appended to `bench.jsonl` in `out` and the same sweep again runs only what is missing.
    One sweep at a time writes into a folder (its lock file `.bench.lock`). Runs that end in
    `error` are returned as rows all the same, with one SweepErrorWarning.

    Args:
        scenarios: Each a Scenario, or the path or built-in name of a scenario file.
        planners: Planner names, import specs (`module:Class`, `file.py:Class`) or `Planner`
            classes (the last two registered here and imported by the workers); None: all.
        seeds: The seeds, as integers or as text like "0-19".
        overrides: `--set KEY=VALUE` strings applied to every run.
        jobs: Worker processes; None: one per core.
        scheduler: The address of a Dask scheduler to run on instead of local workers.
        out: The folder of the journal and the report (default ./logs); None keeps nothing (the journal goes
            to a temporary folder, no report is written).
        report: Write the table and figures (bench.csv, bench.json, bench.png,
            bench-scenarios.png, bench.html).
        wait: While another sweep holds `out`, wait for it to end and then run only the jobs
            it left, instead of raising OutputBusy.
        ros2: Each run the sweep runs also writes its log and its ROS 2 bag into `out`
            (`<name>-<planner>-<seed>.mcap` and `.ros2`); with local workers only.

    Returns:
        One row per run (scenario, planner, seed order), the table per planner and the
        report files written.

    Raises:
        VPlaneError: Invalid input (a scenario, planner, seed or override; `jobs` below 1),
            naming the scenario and key, before any run starts.
        OutputBusy: Another sweep holds `out` and `wait` is False.
    """
    workers = (os.cpu_count() or 1) if jobs is None else jobs
    if workers < 1:
        raise VPlaneError(f"jobs: must be at least 1, got {workers}")
    chosen = sorted(registry.PLANNERS) if planners is None else [planner_name(p) for p in planners]
    seed_list = parse_seeds(seeds) if isinstance(seeds, str) else list(seeds)
    if ros2 and (scheduler or out is None):
        raise VPlaneError("ros2: local workers write the bags into `out`: give `out`, no `scheduler`")

    def sweep_into(out_dir: Path, report: bool) -> SweepResult:
        planned = _plan(scenarios, chosen, seed_list, overrides)
        if ros2:
            planned = [dataclasses.replace(job, files=str(out_dir)) for job in planned]
        rows = run_sweep(planned, out_dir, workers, scheduler)
        table = summarize(rows)
        files: tuple[Path, ...] = ()
        if report:
            from vplane_mj.bench.report import write_outputs  # matplotlib: only when a report is written

            files = tuple(write_outputs(rows, table, out_dir, planned))
        return SweepResult(rows, table, files)

    if out is None:
        with tempfile.TemporaryDirectory(prefix="vplane-mj-sweep-") as scratch:
            result = sweep_into(Path(scratch), report=False)
    else:
        with output_directory(Path(out)) as out_dir:
            what = f"{readable(out_dir)}: the folder of a sweep"
            remedy = "wait for it (--wait) or choose another --out"
            with exclusive(out_dir / ".bench.lock", what, remedy, wait, _say):
                result = sweep_into(out_dir, report)
    if result.errors:
        warnings.warn(_errors_warning(result), SweepErrorWarning, stacklevel=2)
    return result


def _say(line: str) -> None:
    """Tell the user (on stderr) what the sweep waits for."""
    print(line, file=sys.stderr)


def _errors_warning(result: SweepResult) -> str:
    """The warning of a sweep some of whose runs ended in `error`: how many, and the first."""
    first = result.errors[0]
    return (
        f"{len(result.errors)} of {len(result.rows)} runs ended in error (SweepResult.errors); "
        f"the first, {first['scenario']} with {first['planner']} and seed {first['seed']}: {first['message']}"
    )


def planner_name(planner: str | type[Planner], option: str = "planners") -> str:
    """The name a sweep's rows give `planner`: a known name as it is; an import spec or a
    class registered here first (a VPlaneError naming `option` when it is no valid planner)."""
    try:
        if isinstance(planner, type):
            return register_planner(planner).name
        if is_import_spec(planner):
            return load_planner(planner).name
    except PlannerError as exc:
        raise VPlaneError(f"{option}: {exc}") from None
    if planner not in registry.PLANNERS:
        raise VPlaneError(f"{option}: {unknown_planner(planner)}")
    return planner


def _plan(
    scenarios: Iterable[Scenario | str | os.PathLike[str]],
    planners: list[str],
    seeds: list[int],
    overrides: Sequence[str | Override],
) -> list[Job]:
    """The jobs of every scenario in turn: files and names as `bench` plans them, scenarios
    built in code from their TOML text, each validated with the planner, seed and overrides."""
    jobs: list[Job] = []
    for scenario in scenarios:
        if isinstance(scenario, Scenario):
            jobs += _jobs_of(scenario, planners, seeds, overrides)
        else:
            jobs += plan_jobs([os.fspath(scenario)], planners, seeds, overrides)
    return jobs


def _jobs_of(
    scenario: Scenario, planners: list[str], seeds: list[int], overrides: Sequence[str | Override]
) -> list[Job]:
    """The jobs of one Scenario object, validated as `plan_jobs` validates a file's."""
    text, jobs = scenario.to_toml(), []
    for planner in planners:
        for seed in seeds:
            resolved = parse_scenario(text, scenario.source, [*overrides, *job_choice(planner, seed)])
            jobs.append(Job(resolved.name, planner, seed, resolved.to_toml(), for_worker(planner)))
    return jobs
