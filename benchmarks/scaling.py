"""How a run's cost grows with obstacles and sonar rays, and how sweeps scale with workers.

    python benchmarks/scaling.py [--seconds 10] [--sweep 1000] [--out logs/scaling]

Obstacles: a 20 x 20 m arena with N random 0.1 m boxes (seeded), the robot driving with
`apf` for a fixed simulated time; CPU time per physics step of the whole run, of the
physics floor (the same world with MuJoCo's sensor stage off, replaying the run's
torques) and of the world as exported, whose rangefinders cast every ray at every step.
Sonar rays: the same with 16 sonars of 1, 3 and 5 rays, and 32 sonars of 3. Throughput:
the same 40 runs (paper scenarios, every planner, two seeds with 2 cm sonar noise) through
`bench.run_sweep`'s process pool with 1 and 2 workers, side by side (wall clock).
`--sweep N`: the wall time of a sweep of N runs (the paper scenarios and generated traps
and clutter, every planner, seeds with 2 cm sonar noise, 60 simulated seconds at most),
from an empty reference-path cache. The two tables are written to `OUT/scaling.md` (boxes)
and `OUT/scaling_rays.md`, with their `.csv` and `.json` (the command and the date).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np
import tomli_w

from vplane_mj.bench import options
from vplane_mj.bench.sweep import plan_jobs, run_sweep
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.geometry.cache import CACHE_ENV
from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.world import build_model
from vplane_mj.worlds.families import generate

PAPER = ["paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape"]
COST_COLUMNS = ("CPU us per physics step: run", "floor (sensors off)", "as exported (rays every step)")


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


def replay_us(model: mujoco.MjModel, torques: np.ndarray, steps: int) -> float:
    """CPU microseconds per step of bare physics replaying a run's wheel torques."""
    data = mujoco.MjData(model)
    per_update = steps // len(torques)
    start = time.process_time()
    for left, right in torques:
        data.ctrl[0], data.ctrl[1] = left, right
        mujoco.mj_step(model, data, per_update)
    return 1e6 * (time.process_time() - start) / steps


def cost(document: str) -> tuple[float, float, float]:
    """CPU microseconds per physics step: the run, the floor (sensors off), the world as exported."""
    scenario = parse_scenario(document, "scaling")
    run_scenario(scenario)  # warm up
    start = time.process_time()
    result = run_scenario(scenario)
    run = time.process_time() - start
    steps = result.summary.steps
    floor, built = build_model(scenario), build_model(scenario)
    floor.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_SENSOR
    return (
        1e6 * run / steps,
        replay_us(floor, result.torques, steps),
        replay_us(built, result.torques, steps),
    )


def _any_world(scenario, clearance_m: float) -> bool:
    """Keep every generated world: the sweep times runs, solvable or not."""
    return True


def sweep_documents(count: int) -> list[str]:
    """Scenario files for a sweep of `count` runs: paper scenarios, then generated worlds."""
    worlds = count // (len(PLANNERS) * 10)
    cases = generate("traps", worlds, 0, _any_world) + generate("clutter", worlds, 1, _any_world)
    return PAPER + [case.toml() for case in cases][: max(0, worlds - len(PAPER))]


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=options.positive, default=10.0, help="simulated seconds per run")
    parser.add_argument(
        "--sweep", type=options.whole(0), default=0, help="also time a sweep of this many runs"
    )
    parser.add_argument("--out", type=Path, default=Path("logs/scaling"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    boxes = [(count, cost(clutter_document(count, args.seconds))) for count in (10, 100, 1000)]
    written = publish(out, "scaling", "boxes", boxes)
    rings = [
        (f"{sonars} x {rays}", {"count": sonars, "rays_per_sonar": rays})
        for sonars, rays in ((16, 1), (16, 3), (16, 5), (32, 3))
    ]
    rays = [(name, cost(clutter_document(10, args.seconds, ring))) for name, ring in rings]
    written += publish(out, "scaling_rays", "sonars x rays", rays)
    jobs = plan_jobs(PAPER, sorted(PLANNERS), [0, 1], ["sensors.noise_std=0.02"])
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
    if args.sweep:
        time_sweep(args.sweep)
    print("\n" + "\n".join(f"wrote {path}" for path in written))
    return 0


def publish(out: Path, stem: str, first: str, costs: list[tuple]) -> list[Path]:
    """The costs per physics step (`first`: what each row varies) printed and written as `stem`."""
    table = [{first: value, **dict(zip(COST_COLUMNS, cost, strict=True))} for value, cost in costs]
    columns = [first, *COST_COLUMNS]
    text = markdown_table(table, columns, formatted(dict.fromkeys(COST_COLUMNS, ".1f")))
    print(f"\n{text}")
    return write_table(out, stem, table, columns, text)


def time_sweep(count: int) -> None:
    """Wall time of a sweep of about `count` runs on 2 workers, from an empty cache."""
    with tempfile.TemporaryDirectory() as tmp:
        os.environ[CACHE_ENV] = str(Path(tmp) / "cache")
        paths = []
        for index, text in enumerate(sweep_documents(count)):
            if text in PAPER:
                paths.append(text)
                continue
            path = Path(tmp) / f"world_{index:03d}.toml"
            path.write_text(text)
            paths.append(str(path))
        overrides = ["sensors.noise_std=0.02", "run.time_limit_s=60"]
        jobs = plan_jobs(paths, sorted(PLANNERS), range(10), overrides)
        start = time.perf_counter()
        rows = run_sweep(jobs, Path(tmp), 2)
        wall = time.perf_counter() - start
        loops = sum(row["wall_time_s"] for row in rows)
    print(
        f"\nsweep of {len(jobs)} runs on 2 workers: {wall:.0f} s wall ({len(jobs) / wall:.2f} runs/s), "
        f"{loops:.0f} s of simulation loops"
    )


if __name__ == "__main__":
    raise SystemExit(main())
