"""How one run's cost grows with the number of obstacles and of sonar rays, and how a sweep
scales from one worker process to two.

    python benchmarks/scaling.py [--seconds 10]

Obstacles: an arena of 20 x 20 m with N random boxes (seeded), the robot driving with
`apf` for a fixed simulated time; reported as wall time per simulated second and per
physics step. Sonar rays: the same with 16 sonars of 1, 3 and 5 rays, and 32 sonars of 3.
Throughput: the same 12 runs through `bench.run_sweep`'s process pool with 1 and 2 workers.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import tomli_w

from vplane_mj.bench import plan_jobs, run_sweep
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim import run_scenario


def clutter_document(count: int, seconds: float, sensors: dict | None = None) -> str:
    rng = np.random.default_rng(count)
    boxes = []
    while len(boxes) < count:
        x, y = rng.uniform(0.5, 19.5, 2)
        if min(np.hypot(x - 2.0, y - 10.0), np.hypot(x - 18.0, y - 10.0)) < 1.0:
            continue
        boxes.append({"kind": "box", "center": [round(x, 3), round(y, 3)], "size": [0.1, 0.1]})
    return tomli_w.dumps(
        {
            "format": 1,
            "name": f"clutter_{count}",
            "world": {"size": [20.0, 20.0], "obstacles": boxes},
            "robot": {"start": [2.0, 10.0], "goal": [18.0, 10.0]},
            "planner": {"name": "apf", "patience_s": 1000.0},
            "sensors": sensors or {},
            "run": {"time_limit_s": seconds},
        }
    )


def cost(document: str) -> tuple[float, float]:
    """(wall ms per simulated second, wall microseconds per physics step) of one run."""
    summary = run_scenario(parse_scenario(document, "scaling")).summary
    return (
        1e3 * summary["wall_time_s"] / summary["sim_time_s"],
        1e6 * summary["wall_time_s"] / summary["steps"],
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds per run")
    seconds = parser.parse_args().seconds
    print("| boxes | wall ms per simulated s | wall us per physics step |\n|---:|---:|---:|")
    for count in (10, 100, 1000):
        per_second, per_step = cost(clutter_document(count, seconds))
        print(f"| {count} | {per_second:.0f} | {per_step:.1f} |")
    print("\n| sonars x rays | wall ms per simulated s | wall us per physics step |\n|---|---:|---:|")
    for sonars, rays in ((16, 1), (16, 3), (16, 5), (32, 3)):
        sensors = {"count": sonars, "rays_per_sonar": rays}
        per_second, per_step = cost(clutter_document(10, seconds, sensors))
        print(f"| {sonars} x {rays} | {per_second:.0f} | {per_step:.1f} |")
    jobs = plan_jobs(["paper_c_escape", "paper_h_escape", "single_box"], ["apf", "vplane"], [0, 1])
    rates = {}
    for workers in (1, 2):
        with tempfile.TemporaryDirectory() as tmp:
            start = time.perf_counter()
            run_sweep(jobs, Path(tmp), workers)
            rates[workers] = len(jobs) / (time.perf_counter() - start)
    print(
        f"\nsweep of {len(jobs)} runs: {rates[1]:.2f} runs/s with 1 worker, {rates[2]:.2f} runs/s "
        f"with 2 workers: {rates[2] / rates[1]:.2f}x"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
