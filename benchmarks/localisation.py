"""The pose a planner is handed against the true pose: wheel odometry and the EKF on BARN worlds.

Runs `--planner` (default vplane_plus) with the Jackal on each scenario (files given, else
`--count` worlds generated as `vplane-mj generate barn --protocol` does, seed `--world-seed`,
written to `OUT/cases/`) for each seed of `--seeds` and each pose source of `--poses`
(`sensors.pose`: `truth`, `odometry`, `ekf`), with laser noise `--noise` (m). At every control
tick it compares the pose the planner used with the simulator's.

Prints per pose source: the runs, the success rate (reached without a collision), the share
with a collision, and, over the runs, the median and 95th percentile of the final position
error (m) and heading error (degrees) and the median of each run's largest position error;
writes `OUT/localisation.csv` and `.md`.

    python benchmarks/localisation.py [--count 20] [--seeds 0] [--poses odometry,ekf] [--out DIR]
    python benchmarks/localisation.py barn-train/*.toml --poses truth,odometry,ekf
"""

from __future__ import annotations

import argparse
import math
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import Run
from vplane_mj.worlds.barn_protocol import generate_protocol

POSES = ("truth", "odometry", "ekf")
COLUMNS = (
    "pose",
    "runs",
    "success_rate",
    "collision_rate",
    "final_error_median_m",
    "final_error_p95_m",
    "largest_error_median_m",
    "heading_error_median_deg",
    "heading_error_p95_deg",
)


def run_one(job: tuple[str, str, str, int, float]) -> dict:
    """One run: its success, collision and the errors of the pose its planner used."""
    path, planner, pose, seed, noise = job
    overrides = [f"planner.name={planner}", f"sensors.pose={pose}", f"run.seed={seed}"]
    scenario = load_scenario(path, [*overrides, *([f"sensors.noise_std={noise}"] if noise > 0 else [])])
    run = Run(scenario)
    while run.step() is None:
        pass
    summary = run.summary()
    belief = run.localiser.odometry
    true_yaw = run.drive.yaw()
    heading = 0.0 if belief is None else math.degrees(abs(math.remainder(belief.yaw - true_yaw, math.tau)))
    return {
        "pose": pose,
        "success": bool(summary.success),
        "collided": summary.collisions > 0,
        "final_error_m": summary.odometry_error_m or 0.0,
        "largest_error_m": summary.odometry_error_max_m or 0.0,
        "heading_error_deg": heading,
    }


def pose_table(rows: list[dict], poses: list[str]) -> list[dict]:
    """Per pose source, a row of the table."""
    table = []
    for pose in poses:
        mine = [r for r in rows if r["pose"] == pose]
        final = np.array([r["final_error_m"] for r in mine])
        heading = np.array([r["heading_error_deg"] for r in mine])
        table.append(
            {
                "pose": pose,
                "runs": len(mine),
                "success_rate": sum(r["success"] for r in mine) / len(mine),
                "collision_rate": sum(r["collided"] for r in mine) / len(mine),
                "final_error_median_m": float(np.median(final)),
                "final_error_p95_m": float(np.percentile(final, 95)),
                "largest_error_median_m": float(np.median([r["largest_error_m"] for r in mine])),
                "heading_error_median_deg": float(np.median(heading)),
                "heading_error_p95_deg": float(np.percentile(heading, 95)),
            }
        )
    return table


def markdown(table: list[dict]) -> str:
    """The table as Markdown."""

    def cell(key: str, value) -> str:
        if key.endswith("_rate"):
            return f"{100 * value:.1f}%"
        if key.endswith("_deg"):
            return f"{value:.2f}"
        return f"{value:.3f}" if isinstance(value, float) else str(value)

    return markdown_table(table, COLUMNS, cell)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "scenarios",
        nargs="*",
        type=options.scenario,
        help="scenario files (default: generated protocol worlds)",
    )
    parser.add_argument("--planner", type=options.planner, default="vplane_plus")
    parser.add_argument(
        "--poses", type=options.names(POSES, "pose"), default="odometry,ekf", help="sensors.pose values"
    )
    options.add_world_sweep(parser, (20, "protocol worlds, without scenario files"), "0", "localisation")
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    scenarios = args.scenarios
    if not scenarios:
        (out / "cases").mkdir(exist_ok=True)
        scenarios = []
        for case in generate_protocol(args.count, args.world_seed):
            path = out / "cases" / f"{case.name}.toml"
            path.write_text(case.toml(), encoding="utf-8")
            scenarios.append(str(path))
    jobs = [
        (path, args.planner, pose, seed, args.noise)
        for pose in args.poses
        for path in scenarios
        for seed in args.seeds
    ]
    with ProcessPoolExecutor(args.jobs) as pool:
        rows = list(pool.map(run_one, jobs))
    table = pose_table(rows, args.poses)
    text = markdown(table)
    written = write_table(out, "localisation", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
