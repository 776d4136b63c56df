"""Overhead of whole runs over the physics floor, measured side by side in one process.

For each scenario and planner: a full run (sensor, planner, controller, metrics; no log, no
render) takes N physics steps. The floor is MuJoCo alone on the same world with the sensor
stage disabled (no rays), replaying the run's own wheel torques (one `mj_step` of k steps per
motor period: the same N steps, the same motion and contacts; moving obstacles placed before
every step, as the run places them). The same replay on the world as
exported, whose rangefinders cast every sonar ray at every physics step, is the physics "as
built" before the sonar cast its rays only when it pings. Reported: run over floor, run
writing its MCAP log (into a temporary directory) over floor, as built over floor, and run
over as built. Times are the process's CPU time, which other processes on a shared machine do
not inflate; from a run's is subtracted that of a run of one control tick of the same scenario
(building its models: what the loop's wall time in the summary leaves out too). Run over floor
in wall-clock time (the summary's `wall_time_s`) is shown beside, and for a robot with a
laser, the CPU time of its scans over the floor. Each measurement is repeated, interleaved,
and the median kept. `--profile` prints, for the first scenario and planner, where a run's
time goes; `--plot PNG` draws the ratios. Last, the run loop's own share: a run of
`open_field` whose planner costs next to nothing (`straight_to_goal`, a unit force toward the
goal), over its floor.

The table is written to `OUT/overhead.csv`, `.md` and `.json` (with the command and the date).

    python benchmarks/overhead.py [SCENARIO ...] [--planners vplane,apf] [--repeat 3] [--no-log] [--profile]
        [--plot overhead.png] [--out logs/overhead]

SCENARIO is a built-in name or a scenario file (e.g. one of `vplane-mj generate`).
"""

from __future__ import annotations

import argparse
import cProfile
import math
import pstats
import statistics
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.logs.writer import McapLog
from vplane_mj.planning import Decision, Observation, Planner, PlannerParams
from vplane_mj.planning.protocol.registry import register_planner
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.laser import LaserScanner
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.moving import MovingObstacles
from vplane_mj.sim.sensors import scan_bearings
from vplane_mj.sim.world import build_model

DEFAULT_SCENARIOS = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
HARNESS_SCENARIO = "open_field"
"""Where `straight_to_goal` reaches its goal: no obstacle between the start and the goal."""
CELLS = {
    "scenario": "",
    "planner": "",
    "outcome": "",
    "physics steps": "d",
    "floor us/step": ".1f",
    "run / floor": ".2f",
    "run with log / floor": ".2f",
    "as built / floor": ".2f",
    "run / as built": ".2f",
    "run / floor, wall clock": ".2f",
    "laser / floor": ".2f",
    "planner ms/tick": ".3f",
    "log MB/min": ".2f",
}
"""The table's columns and how each is written ("-" where not measured)."""


class StraightToGoal(Planner):
    """A unit force toward the goal: a planner that costs next to nothing, so that a run of it
    measures the run loop itself (sonar, wheel PI loops, bookkeeping)."""

    name = "straight_to_goal"
    summary = "a unit force toward the goal (the run loop's own cost, for this benchmark)"
    citation = "-"
    Params = PlannerParams

    def step(self, obs: Observation) -> Decision:
        dx, dy = obs.goal[0] - obs.position[0], obs.goal[1] - obs.position[1]
        distance = max(math.hypot(dx, dy), 1e-9)
        return Decision(force=np.array([dx / distance, dy / distance]), mode="normal")


class LaserClock:
    """The CPU time (s) a run's laser scans take (`LaserScanner.read`: cast, noise, dropout),
    added up while the clock is installed."""

    def __init__(self):
        self.seconds = 0.0
        self._read = LaserScanner.read

    def __enter__(self) -> LaserClock:
        read = self._read

        def timed_read(scanner, x, y, yaw):
            start = time.process_time()
            ranges = read(scanner, x, y, yaw)
            self.seconds += time.process_time() - start
            return ranges

        LaserScanner.read = timed_read
        return self

    def __exit__(self, *exc) -> None:
        LaserScanner.read = self._read


def replay_time(model: mujoco.MjModel, torques, steps: int, clock=time.process_time, world=None) -> float:
    """Time (s, by `clock`) of bare physics replaying recorded wheel torques over `steps` steps;
    a `world` with moving obstacles has them placed before every step, as the run does."""
    data = mujoco.MjData(model)
    moving = MovingObstacles(model, data, world) if world is not None and world.moving else None
    per_update = steps // len(torques)
    start = clock()
    for left, right in torques:
        data.ctrl[0], data.ctrl[1] = left, right
        if moving is None:
            mujoco.mj_step(model, data, per_update)
            continue
        for _ in range(per_update):
            moving.place(data.time)
            mujoco.mj_step(model, data)
    return clock() - start


def logged_run(scenario, log_dir: Path) -> tuple[float, int]:
    """CPU time (s) of one run that writes its MCAP log into `log_dir`, and the log's bytes."""
    path = log_dir / f"{scenario.name}-{scenario.planner}.mcap"
    bearings = scan_bearings(scenario)
    start = time.process_time()
    log = McapLog(path, scenario, bearings, {})
    result = run_scenario(scenario, observers=(log,))
    log.close(result.summary.to_dict())
    return time.process_time() - start, path.stat().st_size


def measure(ref: str, planner: str, repeat: int, log_dir: Path | None) -> dict:
    scenario = load_scenario(ref, [f"planner.name={planner}"])
    built = build_model(scenario)
    floor = build_model(scenario)
    floor.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_SENSOR
    run_scenario(scenario)  # warm up: imports, caches
    times: dict[str, list[float]] = {
        key: [] for key in ("run", "floor", "built", "log", "run wall", "floor wall", "laser")
    }
    one_tick = load_scenario(
        ref, [f"planner.name={planner}", f"run.time_limit_s={1 / scenario.run.control_hz}"]
    )
    log_bytes = 0
    for _ in range(repeat):
        start = time.process_time()
        run_scenario(one_tick)
        setup = time.process_time() - start
        start = time.process_time()
        with LaserClock() as laser:
            result = run_scenario(scenario)
        times["run"].append(time.process_time() - start - setup)
        times["laser"].append(laser.seconds)
        summary = result.summary
        times["run wall"].append(summary.wall_time_s)
        world = scenario.world
        times["floor"].append(replay_time(floor, result.torques, summary.steps, world=world))
        times["floor wall"].append(
            replay_time(floor, result.torques, summary.steps, time.perf_counter, world=world)
        )
        times["built"].append(replay_time(built, result.torques, summary.steps, world=world))
        if log_dir is not None:
            cpu, log_bytes = logged_run(scenario, log_dir)
            times["log"].append(cpu - setup)
    median = {key: statistics.median(values) for key, values in times.items() if values}
    return {
        "scenario": scenario.name,
        "planner": planner,
        "outcome": summary.outcome,
        "steps": summary.steps,
        "run": median["run"] / median["floor"],
        "log": median["log"] / median["floor"] if "log" in median else None,
        "built": median["built"] / median["floor"],
        "run_vs_built": median["run"] / median["built"],
        "laser": median["laser"] / median["floor"] if scenario.sensors.kind == "laser" else None,
        "run_wall": median["run wall"] / median["floor wall"],
        "floor_us": 1e6 * median["floor"] / summary.steps,
        "planner_ms": summary.planner_cpu_ms_mean,
        "log_mb_per_min": log_bytes / 1e6 / (summary.sim_time_s / 60.0),
    }


def profile(ref: str, planner: str, top: int = 18) -> None:
    """Print the functions where one full run spends most of its own time."""
    scenario = load_scenario(ref, [f"planner.name={planner}"])
    run_scenario(scenario)
    profiler = cProfile.Profile()
    profiler.enable()
    run_scenario(scenario)
    profiler.disable()
    print(f"\nprofile of one {planner} run of {scenario.name} (cProfile, by own time):\n")
    pstats.Stats(profiler, stream=sys.stdout).strip_dirs().sort_stats("tottime").print_stats(top)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=options.scenario, default=list(DEFAULT_SCENARIOS))
    parser.add_argument(
        "--planners", type=options.planners, default="vplane", help="comma-separated planner names"
    )
    parser.add_argument("--repeat", type=options.whole(1), default=3)
    parser.add_argument("--no-log", action="store_true", help="do not time runs that write their log")
    parser.add_argument("--profile", action="store_true", help="profile one run of the first combination")
    parser.add_argument("--plot", type=Path, help="also draw the ratios into this PNG")
    parser.add_argument("--out", type=Path, default=Path("logs/overhead"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    with tempfile.TemporaryDirectory() as tmp:
        rows = report(args.scenarios, args.planners, args.repeat, None if args.no_log else Path(tmp))
    table = [table_row(row) for row in rows]
    text = markdown(table)
    print(f"median of {args.repeat} interleaved repeats, CPU time; mujoco {mujoco.__version__}\n\n{text}")
    written = write_table(out, "overhead", table, list(CELLS), text)
    if args.plot:
        plot(rows, args.plot)
        print(f"wrote {args.plot}")
    if args.profile:
        profile(args.scenarios[0], args.planners[0])
    register_planner(StraightToGoal)
    harness = measure(HARNESS_SCENARIO, StraightToGoal.name, args.repeat, None)
    print(
        f"\nThe run loop alone: `{StraightToGoal.name}` ({harness['planner_ms']:.3f} ms a tick) "
        f"{harness['outcome']} on {HARNESS_SCENARIO} at {harness['run']:.2f} times the floor."
    )
    print("\n".join(f"wrote {path}" for path in written))
    return 0


def plot(rows: list[dict], path: Path) -> None:
    """Each row's run over floor, without and with its log, as bars."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.arange(len(rows))
    figure, ax = plt.subplots(figsize=(2 + 0.9 * len(rows), 3.8), layout="constrained")
    ax.bar(x - 0.2, [row["run"] for row in rows], 0.4, label="run / floor", color="tab:blue")
    logged = [row["log"] if row["log"] is not None else 0.0 for row in rows]
    ax.bar(x + 0.2, logged, 0.4, label="run with its log / floor", color="tab:orange")
    ax.axhline(1.0, color="black", linewidth=0.8)
    ax.set_xticks(x, [f"{row['planner']}\n{row['scenario']}" for row in rows], fontsize=7)
    ax.set_ylabel("CPU time over the physics floor")
    ax.set_title("A run against MuJoCo's bare physics of the same world and steps", fontsize=10)
    ax.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=100)
    plt.close(figure)


def report(scenarios: list[str], planners: list[str], repeat: int, log_dir: Path | None) -> list[dict]:
    """Every planner on every scenario, measured (see `measure`)."""
    return [measure(ref, planner, repeat, log_dir) for planner in planners for ref in scenarios]


def table_row(row: dict) -> dict:
    """A measurement as the table's row; what was not measured is None."""
    values = (
        row["scenario"],
        row["planner"],
        row["outcome"],
        row["steps"],
        row["floor_us"],
        row["run"],
        row["log"],
        row["built"],
        row["run_vs_built"],
        row["run_wall"],
        row["laser"],
        row["planner_ms"],
        None if row["log"] is None else row["log_mb_per_min"],
    )
    return dict(zip(CELLS, values, strict=True))


def markdown(table: list[dict]) -> str:
    """The table as Markdown, planner names as code."""
    number = formatted(CELLS)
    return markdown_table(
        table, list(CELLS), lambda key, value: f"`{value}`" if key == "planner" else number(key, value)
    )


if __name__ == "__main__":
    sys.exit(main())
