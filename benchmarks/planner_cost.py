"""Planner cost per control tick: every planner on the same observations, side by side.

For each scenario, one run driven by `--driver` records what its planner observed at every
control tick (pose, goal, sonar scan). Every planner then steps through that same sequence
from a fresh state, `--repeat` times, in turn (a, b, c, a, b, c, ...). The time is the
process's CPU time, which a busy machine delays but does not inflate the way it does wall
time; the median over the repeats of each planner's mean per tick is reported, and its
ratio to `vfh`'s. The sonar map that vfh, vplane and dwa keep is the same code; its update
alone is reported as `map`. Last, what one numpy operation costs on this machine (CPU time
of `a * b` on arrays of 16 and of 400 floats, the size of a sonar scan and of a map update's
candidate cells), the unit in which the planners' ticks are spent. The default scenarios
are a generated BARN-like world (the one of tests/test_dwa.py), paper_c_escape and
single_box.

The table is written to `OUT/planner_cost.csv` (a row per scenario and planner), `.md` and
`.json` (with the command and the date).

    python benchmarks/planner_cost.py [SCENARIO ...] [--driver dwa] [--repeat 5] [--out logs/planner_cost]
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.planning.planners.groups import LocalMapParams
from vplane_mj.planning.protocol.registry import PLANNERS, make_planner
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.world import SonarLayout
from vplane_mj.worlds.families import random_barn

BARN_SEED = 8
"""The generated BARN-like world of the default set (47 boxes; tests/test_dwa.py drives it)."""
COLUMNS = ("scenario", "ticks", "planner", "ms_per_tick", "over_vfh")
"""The CSV's: a row per scenario and planner (`map`, the sonar map's update alone, among them)."""


class _Recorder:
    """Rebuilds each tick's Observation (the planner sees the true pose by default)."""

    def __init__(self, scenario):
        self.scenario = scenario
        self.bearings = SonarLayout.from_spec(scenario.sensors).bearings
        self.observations: list[Observation] = []

    def on_tick(self, tick) -> None:
        if tick.decision.mode == "finished":
            return
        robot, sensors = self.scenario.robot, self.scenario.sensors
        self.observations.append(
            Observation(
                tick.time_s,
                np.array(tick.position),
                tick.yaw,
                np.asarray(robot.goal, float),
                robot.goal_tolerance,
                self.bearings,
                np.array(tick.ranges),
                math.radians(sensors.beam_deg),
            )
        )

    def on_event(self, time_s: float, text: str) -> None:
        pass


def scenarios(names: list[str], driver: str):
    if names:
        return [load_scenario(name, [f"planner.name={driver}"]) for name in names]
    barn = random_barn(f"barn_seed{BARN_SEED}", np.random.default_rng(BARN_SEED))
    return [
        parse_scenario(barn.toml(), f"{barn.name}.toml", [f"planner.name={driver}"]),
        load_scenario("paper_c_escape", [f"planner.name={driver}"]),
        load_scenario("single_box", [f"planner.name={driver}"]),
    ]


def map_only(params: LocalMapParams) -> Callable[[Observation], None]:
    """One tick of the sonar map alone, as vfh, vplane and dwa update it."""
    grid = params.local_map()
    return lambda obs: grid.update(obs.position, obs.yaw, obs.bearings, obs.ranges, obs.beam_width)


def per_tick_ms(planners: list[str], observations: list[Observation], repeat: int) -> dict[str, float]:
    """Median over `repeat` rounds of each planner's (and the map's) mean CPU time per tick (ms)."""
    times: dict[str, list[float]] = {name: [] for name in [*planners, "map"]}
    for _ in range(repeat):
        for name in times:
            if name == "map":
                step = map_only(LocalMapParams())
            else:
                step = make_planner(name, {}, robot_radius_m()).step
            start = time.process_time()
            for obs in observations:
                step(obs)
            times[name].append(1e3 * (time.process_time() - start) / len(observations))
    return {name: statistics.median(values) for name, values in times.items()}


def numpy_call_us(size: int, calls: int = 200_000) -> float:
    """CPU time (us) of one numpy multiplication of two arrays of `size` floats."""
    a, b = np.ones(size), np.full(size, 0.5)
    start = time.process_time()
    for _ in range(calls):
        a * b
    return 1e6 * (time.process_time() - start) / calls


def cost_rows(name: str, ticks: int, cost: dict[str, float]) -> list[dict]:
    """A scenario's rows: each planner's (and the map's) ms per tick and its ratio to vfh's."""
    return [
        {
            "scenario": name,
            "ticks": ticks,
            "planner": planner,
            "ms_per_tick": ms,
            "over_vfh": ms / cost["vfh"],
        }
        for planner, ms in cost.items()
    ]


def markdown(table: list[dict]) -> str:
    """One line per scenario: its ticks and each planner's ms per tick (its ratio to vfh's)."""
    lines: dict[str, dict] = {}
    for row in table:
        line = lines.setdefault(row["scenario"], {"scenario": row["scenario"], "ticks": str(row["ticks"])})
        line[f"`{row['planner']}` ms (x vfh)"] = f"{row['ms_per_tick']:.3f} ({row['over_vfh']:.2f})"
    return markdown_table(list(lines.values()), list(next(iter(lines.values()))), lambda _, value: value)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=options.scenario)
    parser.add_argument("--driver", type=options.planner, default="dwa")
    parser.add_argument("--repeat", type=options.whole(1), default=5)
    parser.add_argument("--out", type=Path, default=Path("logs/planner_cost"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    table = []
    for scenario in scenarios(args.scenarios, args.driver):
        recorder = _Recorder(scenario)
        run_scenario(scenario, observers=(recorder,))
        cost = per_tick_ms(sorted(PLANNERS), recorder.observations, args.repeat)
        table += cost_rows(scenario.name, len(recorder.observations), cost)
    text = markdown(table)
    print(text)
    small, large = numpy_call_us(16), numpy_call_us(400)
    print(f"\nOne numpy operation: {small:.2f} us on 16 floats, {large:.2f} us on 400 floats (CPU time).")
    print("\n".join(f"wrote {path}" for path in write_table(out, "planner_cost", table, COLUMNS, text)))

    return 0


if __name__ == "__main__":
    sys.exit(main())
