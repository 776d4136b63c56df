"""Overhead of the run loop over bare physics, measured side by side in one process.

For each scenario: a full run (sonar, planner, controller, metrics; no log, no render)
takes N physics steps in T_full seconds. Then, on a fresh MjData of the same compiled
model, bare physics replays the run's own wheel torques (one `mj_step(nstep=k)` per motor
period, the same N steps, the same motion and contacts) in T_bare. The overhead ratio is
T_full / T_bare; the real-time factor is simulated time over T_full. A second baseline
steps the robot standing still (`mj_step(nstep=N)` in one call). Each measurement is
repeated and the median reported.

With `--log` every full run also writes its MCAP log (to a temporary directory), and the
log's size per simulated minute is reported.

    python benchmarks/overhead.py [SCENARIO ...] [--repeat 3] [--planner apf] [--log]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import mujoco

from vplane_mj.log_mcap import McapLog
from vplane_mj.robot import robot_radius_m
from vplane_mj.scenario import load_scenario
from vplane_mj.sim import run_scenario
from vplane_mj.world import SonarLayout, build_model

DEFAULT_SCENARIOS = ("open_field", "single_box", "paper_c_escape", "paper_h_avoid")


def replay_time(model: mujoco.MjModel, torques, steps: int) -> float:
    """Wall time of bare physics replaying recorded wheel torques over `steps` steps."""
    data = mujoco.MjData(model)
    per_update = steps // len(torques)
    start = time.perf_counter()
    for left, right in torques:
        data.ctrl[0], data.ctrl[1] = left, right
        mujoco.mj_step(model, data, nstep=per_update)
    return time.perf_counter() - start


def full_run(scenario, log_dir: Path | None):
    """One run, with its MCAP log written into `log_dir` when given; (result, log bytes)."""
    if log_dir is None:
        return run_scenario(scenario), 0
    path = log_dir / f"{scenario.name}.mcap"
    bearings = SonarLayout.from_spec(scenario.sensors).bearings
    log = McapLog(path, scenario, robot_radius_m(), bearings, scenario.sensors.range_max, {})
    result = run_scenario(scenario, observers=(log,))
    log.close(result.summary)
    return result, path.stat().st_size


def measure(name: str, planner: str, repeat: int, log_dir: Path | None) -> dict:
    scenario = load_scenario(name, [f"planner.name={planner}"])
    model = build_model(scenario)
    ratios, still_ratios, factors = [], [], []
    for _ in range(repeat):
        result, log_bytes = full_run(scenario, log_dir)
        steps, full = result.summary["steps"], result.summary["wall_time_s"]
        ratios.append(full / replay_time(model, result.torques, steps))
        data = mujoco.MjData(model)
        start = time.perf_counter()
        mujoco.mj_step(model, data, nstep=steps)
        still_ratios.append(full / (time.perf_counter() - start))
        factors.append(result.summary["sim_time_s"] / full)
    return {
        "scenario": name,
        "outcome": result.summary["outcome"],
        "steps": steps,
        "sim_s": result.summary["sim_time_s"],
        "overhead": statistics.median(ratios),
        "overhead_still": statistics.median(still_ratios),
        "realtime": statistics.median(factors),
        "log_mb_per_min": log_bytes / 1e6 / (result.summary["sim_time_s"] / 60.0),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", default=list(DEFAULT_SCENARIOS))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--planner", default="apf")
    parser.add_argument("--log", action="store_true", help="write the MCAP log in every full run")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        report(args, Path(tmp) if args.log else None)
    return 0


def report(args: argparse.Namespace, log_dir: Path | None) -> None:
    logging = "with the MCAP log" if log_dir else "without log"
    print(f"planner {args.planner}, {logging}, median of {args.repeat} runs each")
    print(f"mujoco {mujoco.__version__}\n")
    print(
        "| scenario | outcome | physics steps | simulated s | overhead ratio "
        "| ratio vs robot standing still | real-time factor | log MB per simulated minute |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in args.scenarios:
        row = measure(name, args.planner, args.repeat, log_dir)
        size = f"{row['log_mb_per_min']:.2f}" if log_dir else "-"
        print(
            f"| {row['scenario']} | {row['outcome']} | {row['steps']} | {row['sim_s']:.1f} "
            f"| {row['overhead']:.2f} | {row['overhead_still']:.2f} | {row['realtime']:.0f}x | {size} |"
        )
        sys.stdout.flush()


if __name__ == "__main__":
    sys.exit(main())
