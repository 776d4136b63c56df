"""Soak test: generated scenarios with random sensor and actuation faults, all planners, no crash.

`--count` scenarios (default 1000) are generated in turn from the families traps, clutter and
corridors (`vplane_mj.worlds.families.generate`, seed `--seed`, only cases with a reference path),
the planners are assigned round-robin, and each run gets its own random faults, each fault
turned on independently with probability 1/2 (the estimated pose 1/4), drawn from the same
seed so the soak is reproducible:

| fault | key | range |
|---|---|---|
| sonar range noise | sensors.noise_std | 0-0.05 m |
| dropout | sensors.dropout | 0-0.3 |
| crosstalk (spurious short echoes) | sensors.crosstalk | 0-0.1 |
| dead sonars | sensors.dead | 1-3 of the 16 |
| wheel slip | robot.wheel_friction | 0.2-1.0 |
| motor gain, per wheel | robot.motor_gain | 0.5-1.0 |
| motor bias, per wheel | robot.motor_bias_nm | -0.05-0.05 N m |
| estimated pose | sensors.pose = the first of `--poses`, sensors.odometry_noise | 0-0.02 per tick |

With several `--poses` (`odometry`, `ekf`, and `truth`: the simulator's), each run that drew the
estimated pose is also run with each of the others, all else the same: their success columns
compare the planners on the same runs. The outcomes and the success per family count the runs
as drawn, with the first pose. Each run has the simulated time limit `--time-limit` (s). The
runs go through the sweep of `vplane-mj bench` (`vplane_mj.bench.sweep.run_sweep`) with `--jobs`
worker processes. A run that raises is a crash: its row has outcome `error` and the exception
with where it was raised, its traceback goes to
`OUT/failed/<scenario>-<planner>-<seed>.traceback.txt`, and the soak goes on. A worker process
that dies (segfault, out of memory) fails only the run it had under way, which is recorded as
ended without a summary; a new worker takes its place. The scenario of every crash, run without
a summary or `error` outcome is written beside it as `<...>.toml` (run it again with
`vplane-mj run FILE`). The planned runs (scenario texts and faults; planning 1000 takes a few
minutes) are saved in `OUT/plan.json` and the finished ones journaled in `OUT/soak.jsonl`, so
the same command run again (after Ctrl-C, say) only does what is missing (delete both to start
afresh, e.g. after a change to the scenario generators).

Prints and writes `OUT/soak.json` (runs, crashes, runs without a summary, outcomes per
planner, success rate per planner and family, the `error` outcomes with their messages,
wall times), the planners' table (runs, outcomes, success per family, on the true pose and on
each of `--poses`) as `OUT/soak_planners.md`, `.csv` and `.json` (with the command and the
date), and `OUT/soak.png` (outcomes per planner). Exit status 1 if any run crashed or
ended without a summary, else 0.

    python benchmarks/soak.py [--count 1000] [--seed 0] [--jobs 2] [--time-limit 60] [--poses odometry]
        [--out logs/soak]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.failures import FAILURE_KEY, FailureKind
from vplane_mj.bench.job import Job
from vplane_mj.bench.sweep import family_of, run_sweep
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir, write_atomically, write_json
from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.scenario import SensorSpec, parse_scenario
from vplane_mj.terminal import Interrupted, signals_raise_interrupted
from vplane_mj.worlds.families import generate

JOURNAL = "soak.jsonl"
PLAN = "plan.json"
TABLE = "soak_planners"
"""The planners' table: `soak_planners.md`, `.csv` and `.json` (`soak.json` has every figure)."""
OUTCOMES = ("reached", "timeout", "stuck", "error")
POSES = ("odometry", "ekf", "truth")
"""The poses `--poses` lists from."""


def pose_fault(pose: str) -> str:
    """The override that has the planner use `pose` (one of POSES)."""
    return f'sensors.pose="{pose}"'


def draw_faults(rng: np.random.Generator, pose: str) -> list[str]:
    """`--set` overrides for one run's faults (see the table above), `pose` the estimated one."""

    def on(probability: float = 0.5) -> bool:
        return rng.random() < probability

    def draw(low: float, high: float, size: int | None = None):
        return np.round(rng.uniform(low, high, size), 4).tolist()

    faults = []
    if on():
        faults.append(f"sensors.noise_std={draw(0.0, 0.05)}")
    if on():
        faults.append(f"sensors.dropout={draw(0.0, 0.3)}")
    if on():
        faults.append(f"sensors.crosstalk={draw(0.0, 0.1)}")
    if on():
        dead = rng.choice(SensorSpec.count, size=int(rng.integers(1, 4)), replace=False)
        faults.append(f"sensors.dead={sorted(dead.tolist())}")
    if on():
        faults.append(f"robot.wheel_friction={draw(0.2, 1.0)}")
    if on():
        faults.append(f"robot.motor_gain={draw(0.5, 1.0, 2)}")
    if on():
        faults.append(f"robot.motor_bias_nm={draw(-0.05, 0.05, 2)}")
    if on(0.25):
        faults += [pose_fault(pose), f"sensors.odometry_noise={draw(0.0, 0.02)}"]
    return faults


def plan_soak(
    count: int, seed: int, time_limit: float, poses: tuple[str, ...]
) -> list[tuple[Job, list[str]]]:
    """The runs, each with its fault overrides: families in turn, planners round-robin; a run
    that drew the estimated pose (the first of `poses`) again with each of the others."""
    families = ["traps", "clutter", "corridors"]
    cases = {
        family: generate(family, len(range(k, count, len(families))), seed)
        for k, family in enumerate(families)
    }
    fault_rng = np.random.default_rng([seed, 1])  # a stream apart from the generators'
    planners = sorted(PLANNERS)
    runs = []
    for index in range(count):
        case = cases[families[index % len(families)]][index // len(families)]
        planner = planners[index % len(planners)]
        drawn = draw_faults(fault_rng, poses[0])
        estimated = pose_fault(poses[0]) in drawn
        for pose in poses if estimated else poses[:1]:
            faults = [pose_fault(pose) if fault == pose_fault(poses[0]) else fault for fault in drawn]
            overrides = [
                *faults,
                f"planner.name={planner}",
                f"run.seed={index}",
                f"run.time_limit_s={time_limit}",
            ]
            scenario = parse_scenario(case.toml(), case.name, overrides)
            runs.append((Job(case.name, planner, index, scenario.to_toml()), faults))
    return runs


def load_or_plan(
    path: Path, count: int, seed: int, time_limit: float, poses: tuple[str, ...]
) -> list[tuple[Job, list[str]]]:
    """The runs as planned before in `path` with the same arguments, else planned and saved there."""
    settings = {"count": count, "seed": seed, "time_limit_s": time_limit, "poses": list(poses)}
    if path.exists():
        planned, runs = read_plan(path)
        if planned == settings:
            return runs
    runs = plan_soak(count, seed, time_limit, poses)
    write_json(path, {"settings": settings, "runs": [{"job": asdict(j), "faults": f} for j, f in runs]})
    return runs


def read_plan(path: Path) -> tuple[dict, list[tuple[Job, list[str]]]]:
    """A saved plan's settings and its runs, each with its fault overrides."""
    plan = json.loads(path.read_text(encoding="utf-8"))
    return plan["settings"], [(Job(**run["job"]), run["faults"]) for run in plan["runs"]]


def base_name(job: Job) -> str:
    return f"{job.scenario}-{job.planner}-{job.seed}"


def success_rate(rows: list[dict]) -> float | None:
    """The share of `rows` that succeeded; None for no rows."""
    return sum(row["success"] for row in rows) / len(rows) if rows else None


def report(
    runs: list[tuple[Job, list[str]]], rows: dict[str, dict], wall_s: float, poses: tuple[str, ...]
) -> dict:
    """The soak's figures from the journal rows of its runs (by key), run with `poses`."""
    planners = sorted({job.planner for job, _ in runs})
    families = list(dict.fromkeys(family_of(job.scenario) for job, _ in runs))
    finished = [(job, rows[job.key]) for job, _ in runs]
    summaries = [(job, row) for job, row in finished if FAILURE_KEY not in row]
    crashes = [(job, row) for job, row in finished if row.get(FAILURE_KEY) == FailureKind.EXCEPTION]
    died = [(job, row) for job, row in finished if row.get(FAILURE_KEY) == FailureKind.WORKER_DIED]
    on_pose = {pose: {job.key for job, faults in runs if pose_fault(pose) in faults} for pose in poses}
    drawn = {job.key for job, _ in runs} - set().union(*(on_pose[pose] for pose in poses[1:]))
    outcomes = {planner: dict.fromkeys(OUTCOMES, 0) for planner in planners}
    success: dict[str, dict] = {planner: {} for planner in planners}
    for planner in planners:
        for family in families:
            mine = [
                r
                for j, r in summaries
                if j.key in drawn and j.planner == planner and family_of(j.scenario) == family
            ]
            success[planner][family] = success_rate(mine)
            for row in mine:
                outcomes[planner][row["outcome"]] += 1
    true_pose = drawn - on_pose[poses[0]]
    by_pose: dict[str, dict] = {planner: {} for planner in planners}
    for planner in planners:
        mine = [r for j, r in summaries if j.planner == planner]
        by_pose[planner]["true pose"] = success_rate([r for r in mine if r["key"] in true_pose])
        for pose in poses:
            by_pose[planner][pose] = success_rate([r for r in mine if r["key"] in on_pose[pose]])
    estimates = {
        pose: [r["odometry_error_m"] for j, r in summaries if j.key in on_pose[pose]]
        for pose in poses
        if pose != "truth"
    }
    pose_errors = {pose: statistics.median(errors) for pose, errors in estimates.items() if errors}
    run_wall = [row["wall_time_s"] for _, row in summaries]
    return {
        "format": 1,
        "runs": len(drawn),
        "runs_per_planner": {
            planner: sum(j.key in drawn and j.planner == planner for j, _ in runs) for planner in planners
        },
        "runs_on_the_other_poses": len(runs) - len(drawn),
        "crashes": [
            {"run": base_name(j), "planner": j.planner, "exception": r["message"]} for j, r in crashes
        ],
        "without_summary": [
            {"run": base_name(j), "planner": j.planner, "reason": r["message"]} for j, r in died
        ],
        "outcomes_per_planner": outcomes,
        "success_rate_per_planner_and_family": success,
        "success_rate_per_planner_and_pose": by_pose,
        "position_error_m_median_per_pose": pose_errors,
        "errors": [
            {"run": base_name(j), "message": r["message"]} for j, r in summaries if r["outcome"] == "error"
        ],
        "faults_per_run_mean": sum(len(faults) for job, faults in runs if job.key in drawn) / len(drawn),
        "wall_time_s": wall_s,
        "run_wall_time_s_total": sum(run_wall),
        "run_wall_time_s_mean": sum(run_wall) / len(run_wall) if run_wall else None,
        "run_wall_time_s_max": max(run_wall, default=None),
    }


def planner_table(figures: dict) -> list[dict]:
    """One row per planner: its runs as drawn, their outcomes, and its success per family and
    per pose (`success_traps`, ..., `success_true_pose`, then `success_odometry` and so on for
    each of `--poses`, on the same runs)."""
    table = []
    for planner, counts in figures["outcomes_per_planner"].items():
        rates = {
            **figures["success_rate_per_planner_and_family"][planner],
            **figures["success_rate_per_planner_and_pose"][planner],
        }
        runs = figures["runs_per_planner"][planner]
        success = {f"success_{name.replace(' ', '_')}": rate for name, rate in rates.items()}
        table.append({"planner": planner, "runs": runs, **counts, **success})
    return table


def markdown(table: list[dict]) -> str:
    """The planners' table as Markdown, the success rates in %."""

    def cell(key: str, value) -> str:
        if key.startswith("success_"):
            return "-" if value is None else f"{100 * value:.0f}%"
        return f"`{value}`" if key == "planner" else str(value)

    return markdown_table(table, list(table[0]), cell)


def print_report(figures: dict, text: str) -> None:
    """The soak's counts, the planners' table (`text`), what failed and the times."""
    crashes, missing = figures["crashes"], figures["without_summary"]
    print(f"runs: {figures['runs']}, crashes: {len(crashes)}, without a summary: {len(missing)}\n")
    print(text)
    for title, entries, field in (
        ("crashes", crashes, "exception"),
        ("without a summary", missing, "reason"),
        ("error outcomes", figures["errors"], "message"),
    ):
        if entries:
            print(f"\n{title}:")
            for entry in entries:
                print(f"  {entry['run']}: {entry[field]}")
    total, mean, longest = (figures[f"run_wall_time_s_{k}"] for k in ("total", "mean", "max"))
    print(f"\nwall time {figures['wall_time_s']:.0f} s; simulation loops {total:.0f} s in all", end="")
    print(f", {mean:.2f} s mean, {longest:.1f} s max per run" if mean is not None else "")
    for pose, error in figures["position_error_m_median_per_pose"].items():
        print(f"the {pose} pose's position error at the end: {error:.2f} m median")


def plot(figures: dict, path: Path) -> Path:
    """Outcomes per planner as stacked bars, crashes and runs without a summary on top."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outcomes = figures["outcomes_per_planner"]
    planners = list(outcomes)
    stacks = {outcome: [outcomes[p][outcome] for p in planners] for outcome in OUTCOMES}
    for label, entries in (("crash", figures["crashes"]), ("no summary", figures["without_summary"])):
        stacks[label] = [sum(entry["planner"] == p for entry in entries) for p in planners]
    colours = ("C2", "C1", "C0", "C3", "k", "C7")
    figure, ax = plt.subplots(figsize=(7, 4))
    bottom = np.zeros(len(planners))
    for (label, counts), colour in zip(stacks.items(), colours, strict=True):
        ax.bar(planners, counts, bottom=bottom, color=colour, label=label)
        bottom += counts
    ax.set(ylabel="runs", title=f"soak: {figures['runs']} runs with random faults")
    ax.tick_params(axis="x", labelrotation=30)  # long planner names stay apart
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    figure.tight_layout()
    return write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=options.whole(1), default=1000, help="number of runs")
    parser.add_argument(
        "--seed", type=options.whole(0), default=0, help="master seed of scenarios and faults"
    )
    parser.add_argument("--time-limit", type=options.positive, default=60.0, help="simulated seconds per run")
    parser.add_argument("--jobs", type=options.whole(1), default=2, help="worker processes")
    parser.add_argument(
        "--poses",
        type=options.names(POSES, "pose"),
        default="odometry",
        help="the estimated pose of a quarter of the runs, then others to compare",
    )
    parser.add_argument("--out", type=Path, default=Path("logs/soak"))
    args = parser.parse_args(argv)
    poses = tuple(args.poses)
    if poses[0] == "truth":
        parser.error("argument --poses: the first pose is the estimate the runs drive on, not truth")

    started = time.monotonic()
    prepare_out_dir(args.out)
    runs = load_or_plan(args.out / PLAN, args.count, args.seed, args.time_limit, poses)
    try:
        with signals_raise_interrupted():
            rows = run_sweep([job for job, _ in runs], args.out, args.jobs, journal_name=JOURNAL)
    except Interrupted as exc:
        print(f"\ninterrupted by {exc}: the same command goes on from here", file=sys.stderr)
        return exc.exit_status

    figures = report(runs, {row["key"]: row for row in rows}, time.monotonic() - started, poses)
    table = planner_table(figures)
    text = markdown(table)
    print_report(figures, text)
    written = [
        *write_table(args.out, TABLE, table, list(table[0]), text),
        write_json(args.out / "soak.json", figures),
        plot(figures, args.out / "soak.png"),
    ]
    print("\n" + "\n".join(f"wrote {path}" for path in written))
    return 1 if figures["crashes"] or figures["without_summary"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
