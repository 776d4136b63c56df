"""Sweeps: scenarios x planners x seeds in a local process pool, resumable, with a results table.

Every finished run is appended at once to `bench.jsonl` in the output directory (one JSON
summary per line), so an interrupted sweep loses nothing finished: the same command run
again skips the runs whose rows exist (same scenario text, planner and seed) and does the
rest. A run that raises, or whose worker process dies, is a row too, with outcome `error`
(see `failures`); the scenario of every run that ended in `error` is saved under
`failed/` for replay. At the end `bench.csv`, `bench.json` (rows and table), `bench.png`,
`bench-scenarios.png` and `bench.html` (see `bench_report`) are written (each atomically)
and the table is printed. An interruption (SIGINT, SIGTERM) stops the
workers at once: the runs they had under way are done again by the next invocation.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import statistics
import sys
from collections.abc import Generator, Iterable
from functools import partial
from pathlib import Path

from vplane_mj.bench.failures import FAILED_DIR, RERUN_KEY, call_or_failure, finished_row
from vplane_mj.bench.job import Job
from vplane_mj.bench.pool import run_in_pool
from vplane_mj.errors import VPlaneError
from vplane_mj.planning.protocol.registry import for_worker
from vplane_mj.scenario import load_scenario
from vplane_mj.scenario.overrides import Override
from vplane_mj.sim.failure import FailureKind, RunFailure, failure_of
from vplane_mj.terminal import Progress

JOURNAL = "bench.jsonl"
TABLE_COLUMNS = (
    "planner",
    "governor",
    "runs",
    "success_rate",
    "mean_score",
    "collision_rate",
    "timeouts",
    "stuck",
    "errors",
    "median_time_to_goal_s",
    "median_path_length_m",
    "median_path_ratio",
    "escapes",
)
"""The bench table's columns, per planner (`summarize`); by scenario, `scenario` first."""
TABLE_BASIS = (
    "success: reached without a collision; medians over the runs that reached the goal; "
    "governor: own (the planner drives its body itself), run (the run's governor) or none"
)
"""What the table's rates and medians count, printed with it."""


MAX_SEEDS = 100_000
"""The most seeds one sweep takes (a typo such as 0-4294967295 would plan billions of runs)."""


def parse_seeds(text: str) -> list[int]:
    """Seeds from "0-19", "7" or "0,2,5-7", each below 2**32; a VPlaneError names the bad part."""
    seeds: set[int] = set()
    for part in text.split(","):
        bounds = part.strip().split("-")
        try:
            low, high = (int(bounds[0]), int(bounds[-1])) if len(bounds) <= 2 else (None, None)
        except ValueError:
            low = high = None
        if low is None or high is None or low < 0 or high < low or high >= 2**32:
            raise VPlaneError(f"--seeds: {part.strip()!r} is not a seed or a range like 0-19 (seeds < 2**32)")
        if len(seeds) + (high - low + 1) > MAX_SEEDS:
            raise VPlaneError(f"--seeds: more than {MAX_SEEDS} seeds in {text.strip()!r}")
        seeds.update(range(low, high + 1))
    return sorted(seeds)


def job_choice(planner: str, seed: int) -> tuple[Override, Override]:
    """The overrides that make a scenario one job's run: its planner and seed (named in
    messages as the sweep's `planners` and `seeds`)."""
    return Override(f"planner.name={planner}", "planners"), Override(f"run.seed={seed}", "seeds")


def plan_jobs(
    scenarios: Iterable[str],
    planners: Iterable[str],
    seeds: Iterable[int],
    overrides: Iterable[str | Override] = (),
) -> list[Job]:
    """Every combination, with `--set` style overrides, each validated as `vplane-mj run` would;
    a planner registered in this process goes with each of its jobs to the worker (`Job`)."""
    jobs = []
    for ref in scenarios:
        for planner in planners:
            for seed in seeds:
                scenario = load_scenario(ref, [*overrides, *job_choice(planner, seed)])
                jobs.append(Job(scenario.name, planner, seed, scenario.to_toml(), for_worker(planner)))
    return jobs


PATH_KEY = "path_xy"
"""The row key of a run's travelled path, [[x, y], ...] (m)."""
PATH_TOLERANCE_M = 0.02
"""A run's path is kept for the report simplified to within this distance (m)."""


def run_job(job: Job) -> dict:
    """Run one job (in a worker process): its summary, the job's key and, under PATH_KEY,
    the travelled path simplified to PATH_TOLERANCE_M (for the report's picture of it); with
    `job.files`, the run's log and ROS 2 bag written into that folder."""
    from vplane_mj.geometry.polyline import PathSimplifier
    from vplane_mj.planning.protocol.registry import register_in_worker
    from vplane_mj.scenario import parse_scenario
    from vplane_mj.sim.loop import run_scenario

    if job.registered_planner is not None:
        register_in_worker(job.registered_planner)
    scenario = parse_scenario(job.toml, f"{job.scenario} (bench)")
    if job.files is None:
        result = run_scenario(scenario)
    else:
        from vplane_mj.bench.run_files import run_with_bag

        result = run_with_bag(scenario, Path(job.files))
    path = PathSimplifier(PATH_TOLERANCE_M)
    for x, y in (*result.positions, result.final_pose[:2]):
        path.add(x, y)
    track = [[round(x, 3), round(y, 3)] for x, y in path.polyline()]
    return {"key": job.key, **result.summary.to_dict(), PATH_KEY: track}


def read_journal(path: Path) -> dict[str, dict]:
    """Finished rows by key; a torn last line (the process was killed mid-write) is ignored."""
    rows: dict[str, dict] = {}
    if not path.exists():
        return rows
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            row = json.loads(line)
        except json.JSONDecodeError:
            continue
        if isinstance(row, dict) and "key" in row:
            rows[row["key"]] = row
    return rows


def run_sweep(
    jobs: list[Job], out_dir: Path, workers: int, scheduler: str | None = None, journal_name: str = JOURNAL
) -> list[dict]:
    """Run the jobs not yet in the journal (`out_dir/journal_name`); return every row of the
    sweep, in job order.

    Locally the jobs go to a pool of `workers` processes; with `scheduler` (an address)
    they go to that Dask distributed cluster instead. Each job is the same pure function
    of its scenario text, so both engines give the same rows. A job that fails (it raises,
    its worker dies) gives a row with outcome `error` and the sweep goes on.
    """
    journal_path = out_dir / journal_name
    finished = read_journal(journal_path)
    pending = [job for job in jobs if job.key not in finished]
    if scheduler and pending:
        results = _dask_results(pending, scheduler)
    else:
        results = run_in_pool(pending, run_job, workers)
    engine = f"on the Dask cluster at {scheduler}" if scheduler else f"with {workers} worker(s)"
    print(
        f"{len(jobs)} runs: {len(jobs) - len(pending)} already done, {len(pending)} to run {engine}",
        file=sys.stderr,
    )
    # Closed explicitly, so that the workers stop however the loop ends (an interruption, an error).
    with contextlib.closing(results):
        if pending:
            progress = Progress("sweep", len(jobs), "runs", done=len(jobs) - len(pending))
            with progress, open(journal_path, "a", encoding="utf-8") as journal:
                if not _ends_with_a_newline(journal_path):
                    journal.write("\n")  # a killed sweep's torn line stays a line apart from the new rows
                for job, result in results:
                    row = finished_row(job, result, out_dir)
                    journal.write(json.dumps(row, allow_nan=False) + "\n")
                    journal.flush()
                    finished[row["key"]] = row
                    progress.advance()
    return [finished[job.key] for job in jobs]


def _ends_with_a_newline(path: Path) -> bool:
    """Whether the file is empty or its last line is complete."""
    with open(path, "rb") as stream:
        if stream.seek(0, os.SEEK_END) == 0:
            return True
        stream.seek(-1, os.SEEK_END)
        return stream.read(1) == b"\n"


SCHEDULER_TIMEOUT_S = 5.0
"""How long a sweep tries to reach its Dask scheduler (s); Dask retries until then, even a
refused connection."""


def _dask_results(jobs: list[Job], scheduler: str) -> Generator[tuple[Job, dict | RunFailure], None, None]:
    """Jobs with their rows or failures as the workers of a Dask distributed cluster finish
    them (the [dask] extra).

    Connects at once, so an unreachable scheduler is reported before anything is written. A
    task that fails in Dask itself (its workers died, `KilledWorker`) is a failure too.
    """
    try:
        from distributed import Client, KilledWorker
        from distributed import as_completed as dask_completed
    except ImportError as exc:
        raise VPlaneError(
            '--scheduler needs Dask: pip install "dask[distributed]" '
            '(or, in a clone of vplane-mj, pip install -e ".[dask]")'
        ) from exc
    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT_S)
    except OSError as exc:
        raise VPlaneError(f"--scheduler: cannot reach a Dask scheduler at {scheduler}: {exc}") from exc

    def results() -> Generator[tuple[Job, dict | RunFailure], None, None]:
        with client:
            futures = client.map(partial(call_or_failure, run_job), jobs, pure=False)
            job_of = dict(zip(futures, jobs, strict=True))
            for future in dask_completed(futures):
                if future.status == "error":
                    exc = future.exception()
                    kind = FailureKind.WORKER_DIED if isinstance(exc, KilledWorker) else FailureKind.EXCEPTION
                    yield job_of[future], failure_of(exc, future.traceback(), kind)
                else:
                    yield job_of[future], future.result()

    return results()


def summarize(rows: list[dict], by_scenario: bool = False) -> list[dict]:
    """The bench table of docs/interface.md: one row per planner, or with `by_scenario` per
    scenario and planner, in first-seen order (columns TABLE_COLUMNS, counted as TABLE_BASIS)."""
    names = ("scenario", "planner") if by_scenario else ("planner",)
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(row[name] for name in names), []).append(row)
    return [{**dict(zip(names, group, strict=True)), **_statistics(mine)} for group, mine in groups.items()]


def _statistics(mine: list[dict]) -> dict:
    """The table's columns after the planner for the runs `mine`."""
    reached = [row for row in mine if row["reached"]]
    return {
        "governor": "/".join(sorted({row.get("governor") or "-" for row in mine})),
        "runs": len(mine),
        "success_rate": sum(row["success"] for row in mine) / len(mine),
        "mean_score": _mean([row["score"] for row in mine if row.get("score") is not None]),
        "collision_rate": sum(row["collisions"] > 0 for row in mine) / len(mine),
        "timeouts": sum(row["outcome"] == "timeout" for row in mine),
        "stuck": sum(row["outcome"] == "stuck" for row in mine),
        "errors": sum(row["outcome"] == "error" for row in mine),
        "median_time_to_goal_s": _median([r["time_to_goal_s"] for r in reached]),
        "median_path_length_m": _median([r["path_length_m"] for r in reached]),
        "median_path_ratio": _median([r["path_ratio"] for r in reached if r.get("path_ratio")]),
        "escapes": sum(row["escapes"] for row in mine),
    }


def _median(values: list[float]) -> float | None:
    return statistics.median(values) if values else None


def _mean(values: list[float]) -> float | None:
    return statistics.fmean(values) if values else None


def format_table(table: list[dict]) -> str:
    """The table as text for the terminal (rich's table, plain characters): one row per
    planner (or scenario and planner), its columns; numbers with two decimals, "-" where none;
    TABLE_BASIS below it."""
    from rich import box
    from rich.console import Console
    from rich.table import Table

    def cell(value) -> str:
        if value is None:
            return "-"
        return f"{value:.2f}" if isinstance(value, float) else str(value)

    columns = list(table[0]) if table else list(TABLE_COLUMNS)
    grid = Table(box=box.SIMPLE_HEAD, pad_edge=False)
    for column in columns:
        text = column in ("scenario", "planner", "governor")
        grid.add_column(column, justify="left" if text else "right", no_wrap=True)
    for row in table:
        grid.add_row(*(cell(row[column]) for column in columns))
    console = Console(file=io.StringIO(), width=400, record=True, color_system=None)
    console.print(grid)
    lines = [line.rstrip() for line in console.export_text().splitlines() if line.strip()]
    return "\n".join([*lines, f"({TABLE_BASIS})"])


MAX_ERRORS_LISTED = 10
"""The most runs in `error` that `bench` lists one by one after its table."""


def error_lines(rows: list[dict], out_dir: Path) -> list[str]:
    """How many runs ended in `error` and where their scenarios are, then the first
    MAX_ERRORS_LISTED of them, each with its message and the command that runs it again;
    nothing when none did."""
    errors = [row for row in rows if row["outcome"] == "error"]
    if not errors:
        return []
    lines = [
        f"{len(errors)} of {len(rows)} runs ended in error; their scenarios are in "
        f"{out_dir / FAILED_DIR}, each run again by the command below it:"
    ]
    for row in errors[:MAX_ERRORS_LISTED]:
        lines.append(f"  {row['scenario']}, {row['planner']}, seed {row['seed']}: {row['message']}")
        if RERUN_KEY in row:
            lines.append(f"    {row[RERUN_KEY]}")
    if len(errors) > MAX_ERRORS_LISTED:
        lines.append(f"  and {len(errors) - MAX_ERRORS_LISTED} more (bench.csv has them all)")
    return lines


def collision_line(collided: list[dict], runs: int) -> str:
    """What `bench --fail-on-collision` says when the runs `collided` (of `runs`) collided: their
    count and the first few, by scenario, planner and seed."""
    named = ", ".join(
        f"{row['scenario']} {row['planner']} seed {row['seed']} ({row['collisions']})" for row in collided[:3]
    )
    more = f" and {len(collided) - 3} more" if len(collided) > 3 else ""
    return f"error: {len(collided)} of {runs} runs collided (--fail-on-collision): {named}{more}"


def family_of(scenario: str) -> str:
    """A generated scenario's family ("traps_1_003" -> "traps"); other names stand alone."""
    parts = scenario.split("_")
    while len(parts) > 1 and parts[-1].isdigit():
        parts.pop()
    return "_".join(parts)
