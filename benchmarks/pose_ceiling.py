"""How much of the true pose's success an estimated pose can keep on the soak's runs, along the
paths the planners drive.

The soak (`benchmarks/soak.py --poses odometry,ekf,truth`) runs each run that drew an
estimated pose three times: on wheel odometry, on the EKF and on the true pose. This script
reads its plan and journal (`--soak`, its `--out`) and runs each of those runs on the true
pose again with wheel odometry and the EKF following along unseen: the planner drives on the
true pose, as in the journal (its trajectory digest is checked), while both estimates fold in
the same wheels and gyro with the run's own faults and noise. When the run ends, the distance
(m) between each estimate and the robot is what a planner that drove the same path on that
estimate would be off: it stops where the estimate puts it at the goal. Where that exceeds
the goal's tolerance, the success does not survive, unless the error happens to lie along the
way in (the robot then crosses the goal's disc before its estimate arrives).

So, per planner: its successes on the true pose, the share of them whose EKF and whose
odometry ends within the goal tolerance (the ceiling of the soak's ekf / truth and
odometry / truth ratios for a planner that drives these paths, but for that luck; a planner
that turned less would drift less), the median errors, and the ratios the soak measured on
the same runs. Writes `OUT/pose_ceiling.{csv,md,json}` (`--out`, else the soak's
directory) and prints the table.

    python benchmarks/pose_ceiling.py [--soak logs/soak] [--jobs 2]
"""

from __future__ import annotations

import argparse
import statistics
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from soak import JOURNAL, PLAN, pose_fault, read_plan

from vplane_mj.bench import options
from vplane_mj.bench.job import Job
from vplane_mj.bench.sweep import read_journal
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.errors import VPlaneError
from vplane_mj.files import prepare_out_dir
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.drive import Localiser
from vplane_mj.sim.loop import Run

COLUMNS = (
    "planner",
    "truth_successes",
    "ekf_within_tolerance",
    "odometry_within_tolerance",
    "ekf_error_median_m",
    "odometry_error_median_m",
    "soak_ekf_over_truth",
    "soak_odometry_over_truth",
)


def shadowed(toml: str, source: str) -> dict:
    """One run on the true pose with wheel odometry and the EKF following along: its success,
    trajectory digest and both estimates' distance (m) from the robot at its end."""
    truth = parse_scenario(toml, source)
    run = Run(parse_scenario(toml, source, [pose_fault("ekf")]))  # a model that carries the IMU
    ekf = run.localiser
    run.localiser = Localiser(run.drive, truth)  # the planner drives on the true pose
    odometry = Localiser(run.drive, parse_scenario(toml, source, [pose_fault("odometry")]))
    while run.step() is None:
        ekf.pose(run.position, run.yaw)  # both read the wheels (and the gyro) as the run's own would
        odometry.pose(run.position, run.yaw)
    summary = run.summary()
    return {
        "success": summary.success,
        "digest": summary.trajectory_sha256,
        "ekf": ekf.error(run.position),
        "odometry": odometry.error(run.position),
        "tolerance": truth.robot.goal_tolerance,
    }


def _shadowed(job: Job) -> dict:
    return shadowed(job.toml, job.scenario)


def ratio(rows: list[dict], pose: str) -> float | None:
    """Success on `pose` over success on the true pose, over the same runs (`rows`)."""
    truth = sum(row["success"] for row in rows)
    return sum(row[f"success_{pose}"] for row in rows) / truth if truth else None


def table_of(pairs: list[tuple[Job, dict[str, str]]], journal: dict[str, dict], jobs: int) -> list[dict]:
    """The table's rows (module docstring) from the soak's runs on the true pose that drew an
    estimated pose, each with its twins' keys by pose (`paired_runs`), and the journal's rows
    by key."""
    with ProcessPoolExecutor(jobs) as pool:
        results = list(pool.map(_shadowed, [job for job, _ in pairs], chunksize=4))
    per_planner: dict[str, list[dict]] = {}
    for (job, twins), result in zip(pairs, results, strict=True):
        if result["digest"] != journal[job.key]["trajectory_sha256"]:
            raise VPlaneError(f"{job.scenario}: {job.planner} ran another trajectory than the soak's")
        successes = {f"success_{pose}": journal[key]["success"] for pose, key in twins.items()}
        per_planner.setdefault(job.planner, []).append({**result, **successes})
    return [row_of(planner, rows) for planner, rows in sorted(per_planner.items())]


def row_of(planner: str, rows: list[dict]) -> dict:
    """One planner's row of the table from its runs' shadowed results (`table_of`)."""
    reached = [row for row in rows if row["success"]]
    row = {"planner": planner, "truth_successes": len(reached)}
    for pose in ("ekf", "odometry"):
        errors = [run[pose] for run in reached]
        within = sum(error <= run["tolerance"] for error, run in zip(errors, reached, strict=True))
        row[f"{pose}_within_tolerance"] = within / len(reached) if reached else None
        row[f"{pose}_error_median_m"] = statistics.median(errors) if reached else None
        row[f"soak_{pose}_over_truth"] = ratio(rows, pose)
    return row


def paired_runs(runs: list[tuple[Job, list[str]]]) -> list[tuple[Job, dict[str, str]]]:
    """The plan's runs on the true pose that drew an estimated pose, each with the journal keys
    of its twins on odometry and on the EKF, by pose."""
    twins: dict[tuple, dict[str, str]] = {}
    for job, faults in runs:
        for pose in ("odometry", "ekf"):
            if pose_fault(pose) in faults:
                twins.setdefault((job.scenario, job.planner, job.seed), {})[pose] = job.key
    return [
        (job, twins[(job.scenario, job.planner, job.seed)])
        for job, faults in runs
        if pose_fault("truth") in faults
    ]


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--soak", type=Path, default=Path("logs/soak"), help="soak.py's --out")
    parser.add_argument("--jobs", type=options.whole(1), default=2, help="worker processes")
    parser.add_argument("--out", type=Path, help="default: the soak's directory")
    args = parser.parse_args(argv)
    plan_path, journal_path = args.soak / PLAN, args.soak / JOURNAL
    for path in (plan_path, journal_path):
        if not path.is_file():
            raise VPlaneError(f"{path}: missing (run benchmarks/soak.py --poses odometry,ekf,truth first)")
    settings, runs = read_plan(plan_path)
    if set(settings["poses"]) != {"odometry", "ekf", "truth"}:
        raise VPlaneError(f"{plan_path}: poses: the soak must run odometry, ekf and truth")
    out = prepare_out_dir(args.out or args.soak)
    table = table_of(paired_runs(runs), read_journal(journal_path), args.jobs)
    text = markdown_table(table, COLUMNS, cell)
    written = write_table(out, "pose_ceiling", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


def cell(column: str, value) -> str:
    """A table cell: shares as percentages, metres and ratios to two decimals."""
    if value is None:
        return "-"
    if column.endswith("_within_tolerance"):
        return f"{value:.0%}"
    if isinstance(value, float):
        return f"{value:.2f}"
    return f"`{value}`" if column == "planner" else str(value)


if __name__ == "__main__":
    sys.exit(main())
