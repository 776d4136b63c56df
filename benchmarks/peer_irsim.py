"""Simulated seconds per second beside IR-SIM, the kinematic Python simulator, on the same worlds.

IR-SIM (`pip install ir-sim`, import name `irsim`) is the Python 2D simulator for navigation
research a user would pick instead of this project. Both run `--count` BARN protocol worlds
(`vplane-mj generate barn --protocol`, seed `--seed`: a 4.2 x 14 m arena with its border and
cylinders of radius 0.075 m, 63 to 203 in the first five of seed 0), each with a scan of 16
and of 720 beams over 270 degrees, 0.1-30 m (the Jackal's laser, and the same laser thinned to
16 beams), for at most `--time-limit` simulated seconds:

- IR-SIM: every obstacle piece (`vplane_mj.geometry.shapes` footprints: cylinders as circles,
  the border walls as rectangles) an IR-SIM obstacle, written into its YAML world; the robot a
  diff-drive rectangle of the Jackal's outline (0.508 x 0.43 m) at the scenario's start,
  heading for its goal (tolerance 1 m) with IR-SIM's `dash` behaviour at the Jackal's top speed,
  turn rate and accelerations, a `lidar2d` of the scan above, collision mode `stop`; headless,
  no plotting, stepped at 50 Hz (0.02 s). The run ends at the goal or the time limit: a robot
  that ran into an obstacle stands there, and its lidar keeps scanning every step.
- vplane-mj: the scenario itself (the Jackal profile, `sensors.beams` 16 or 720) with each
  planner of `--planners`, deciding and scanning at 50 Hz as IR-SIM does (`run.control_hz=50`;
  the protocol's default is 20), no log, no render (`vplane_mj.sim.loop.Run`); to the goal,
  the planner giving up or the time limit. Rigid-body physics at 500 Hz with contacts, the
  wheel PI loops at 100 Hz.

Timed: the simulation loop alone (the world is built before the clock starts), in the
process's CPU time (a machine shared with other work delays a run but does not inflate its
CPU time the way it does wall time) and in wall time; best of `--repeat` repeats, interleaved
(each repeat runs every world and every simulator once). Reported per world and overall
(sums over the worlds): simulated seconds per CPU second and per wall second, each row's rate
over IR-SIM's at the same beams (CPU time), and for this project the planner's share of the
loop's wall time (IR-SIM's `dash` points at the goal: next to nothing). Before them, per world,
the largest difference (mm) between the 720-beam scans both simulators cast at the start: the
check that IR-SIM's world is this project's.

BLAS runs one thread for both simulators (`--blas-threads`; 0 leaves OpenBLAS its default, a
thread per core): IR-SIM's lidar multiplies (segments x 2) by (2 x beams) matrices, and
OpenBLAS's threads spent several times the CPU time on them on a 2-core machine shared with
other work. The header says what ran.

The four tables are written to `OUT/peer_irsim_scans.md`, `peer_irsim_worlds.md`,
`peer_irsim_rates.md` (per world, the rates side by side: what the documentation shows) and
`peer_irsim.md` (overall), with their `.csv` and `.json` (the command and the date).

    python benchmarks/peer_irsim.py [--count 2] [--seed 0] [--time-limit 10] [--repeat 3]
        [--planners vplane_plus,dwa] [--blas-threads 1] [--out logs/peer_irsim]

Needs IR-SIM, an optional extra of the benchmarks only: `pip install 'vplane-mj[peers]'`.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import io
import math
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple

import mujoco
import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.geometry import shapes
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario import Scenario, parse_document
from vplane_mj.sim.loop import Run
from vplane_mj.worlds.barn_protocol import generate_protocol
from vplane_mj.worlds.families import Case

BEAMS = (16, 720)
"""Beams of the two scans, both over the Jackal laser's 270 degrees and 0.1-30 m."""
STEP_S = 0.02
"""IR-SIM's step (50 Hz), and this project's control period here."""
IRSIM = "IR-SIM"
SCAN_CELLS = {"world": "", "cylinders": "d", "720-beam scans at the start: largest difference, mm": ".2f"}
RATES = {"sim s per CPU s": ".2f", "sim s per wall s": ".2f", "over IR-SIM (CPU)": ".2f"}
WORLD_CELLS = {
    "world": "",
    "simulator": "",
    "beams": "d",
    "outcome": "",
    "simulated s": ".2f",
    "CPU s": ".3f",
    **RATES,
    "planner share of wall": ".0%",
}
OVERALL_CELLS = {
    "simulator": "",
    "beams": "d",
    "simulated s": ".2f",
    "CPU s": ".3f",
    **RATES,
    "over IR-SIM (wall)": ".2f",
}
"""The three tables' columns (the scans at the start, per world, overall) and how each is written;
the per-world rates side by side take theirs from the configurations (`rates_table`)."""
OVER_IRSIM = " over IR-SIM"
"""Ends the name of a rates-table column that holds a rate over IR-SIM's at the same beams."""
MISSING_PEERS = (
    "peer_irsim.py compares this project with IR-SIM and needs the benchmarks' `peers` extra, "
    "not installed here ({missing}): pip install 'vplane-mj[peers]' (or pip install ir-sim threadpoolctl)"
)


class Peers(NamedTuple):
    """The modules the comparison needs beyond the package: IR-SIM, PyYAML (one of IR-SIM's
    dependencies) to write its worlds, and threadpoolctl to set how many threads BLAS runs."""

    irsim: ModuleType
    yaml: ModuleType
    threadpoolctl: ModuleType


@dataclass
class Timing:
    """One configuration on one world: simulated time (s), best CPU and wall time (s) of its loop
    over the repeats, how the run ended, the planner's share of the loop's wall time."""

    simulated_s: float
    cpu_s: float
    wall_s: float
    outcome: str
    planner_share: float | None = None

    def keep_best(self, other: Timing) -> None:
        self.cpu_s = min(self.cpu_s, other.cpu_s)
        self.wall_s = min(self.wall_s, other.wall_s)


def load_peers() -> Peers | str:
    """The modules of the `peers` extra, or the name of the one missing. IR-SIM prints which
    Matplotlib backends it tried when imported: kept out of the table."""
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            import irsim
            import threadpoolctl
            import yaml
    except ImportError as exc:
        return exc.name or str(exc)
    return Peers(irsim, yaml, threadpoolctl)


def irsim_obstacle(piece: shapes.Piece) -> dict[str, Any]:
    """A footprint piece as an IR-SIM static obstacle: a circle or a rectangle about its centre."""
    if isinstance(piece, shapes.Disc):
        return {"shape": {"name": "circle", "radius": piece.radius}, "state": [*piece.center, 0.0]}
    length, width = 2.0 * piece.half[0], 2.0 * piece.half[1]
    return {
        "shape": {"name": "rectangle", "length": length, "width": width},
        "state": [*piece.center, piece.yaw],
    }


def irsim_world(scenario: Scenario, beams: int) -> dict[str, Any]:
    """The IR-SIM world document of a scenario (see the module docstring) with a `beams` lidar."""
    world, robot, sensors = scenario.world, scenario.robot, scenario.sensors
    profile = robot_profile(robot.profile)
    assert profile.footprint_m is not None, "a robot with an outline"
    xs, ys = [x for x, _ in profile.footprint_m], [y for _, y in profile.footprint_m]
    limits = profile.limits
    wall = shapes.BORDER_THICKNESS_M
    scene = shapes.scene_footprints(world.obstacles, world.size if world.border else None)
    return {
        "world": {
            "width": world.size[0] + 2 * wall,
            "height": world.size[1] + 2 * wall,
            "offset": [-wall, -wall],
            "step_time": STEP_S,
            "collision_mode": "stop",
        },
        "robot": [
            {
                "kinematics": {"name": "diff"},
                "shape": {"name": "rectangle", "length": max(xs) - min(xs), "width": max(ys) - min(ys)},
                "state": [*robot.start, robot.start_yaw],
                "goal": [
                    *robot.goal,
                    math.atan2(robot.goal[1] - robot.start[1], robot.goal[0] - robot.start[0]),
                ],
                "goal_threshold": robot.goal_tolerance,
                "vel_max": [limits.max_speed_mps, limits.max_turn_rate_radps],
                "acce": [limits.max_accel_mps2, limits.max_turn_accel_radps2],
                "behavior": {"name": "dash"},
                "sensors": [
                    {
                        "name": "lidar2d",
                        "number": beams,
                        "angle_range": math.radians(sensors.fov_deg),
                        "range_min": sensors.range_min,
                        "range_max": sensors.range_max,
                    }
                ],
            }
        ],
        "obstacle": [irsim_obstacle(piece) for piece in scene.pieces],
    }


def time_irsim(irsim: ModuleType, world_file: Path, time_limit_s: float) -> Timing:
    """Step an IR-SIM world to its robot's goal or `time_limit_s`; the loop's timing."""
    env = irsim.make(str(world_file), headless=True, log_level="ERROR")
    robot = env.robot
    steps = 0
    cpu, wall = time.process_time(), time.perf_counter()
    while steps * STEP_S < time_limit_s - 1e-9 and not robot.arrive:
        env.step()
        steps += 1
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    outcome = "reached" if robot.arrive else "collided, stopped" if robot.collision else "timeout"
    env.end()
    return Timing(steps * STEP_S, cpu, wall, outcome)


def time_vplane(scenario: Scenario) -> Timing:
    """Run a scenario to its end; the loop's timing."""
    run = Run(scenario)
    cpu, wall = time.process_time(), time.perf_counter()
    result = run.run()
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    summary = result.summary
    share = sum(run.planner_cpu) / run.wall_time_s if run.wall_time_s > 0 else None
    return Timing(summary.sim_time_s, cpu, wall, str(summary.outcome), share)


def irsim_world_file(world_dir: Path, name: str, beams: int) -> Path:
    return world_dir / f"{name}_{beams}.yaml"


def start_scan_difference_mm(case: Case, world_dir: Path, irsim: ModuleType) -> float:
    """The largest difference (mm) between the 720-beam scans both simulators cast at the start of
    a world: how closely IR-SIM's world (its circles are 64-sided polygons) is this project's."""
    beams = BEAMS[-1]
    scenario = parse_document(copy.deepcopy(case.document), case.name, [f"sensors.beams={beams}"])
    env = irsim.make(str(irsim_world_file(world_dir, case.name, beams)), headless=True, log_level="ERROR")
    theirs = np.array(env.robot.sensors[0].range_data, dtype=float)
    env.end()
    ours = Run(scenario).sensor.read(*scenario.robot.start, scenario.robot.start_yaw)
    return 1000.0 * float(np.max(np.abs(ours - theirs)))


def configurations(
    case: Case, planners: list[str], time_limit_s: float, world_dir: Path, peers: Peers
) -> dict[tuple[str, int], Callable[[], Timing]]:
    """(simulator, beams) -> a timed run of that configuration on one world, IR-SIM's first; the
    IR-SIM worlds are written into `world_dir`."""
    document, name = case.document, case.name
    runs: dict[tuple[str, int], Callable[[], Timing]] = {}
    for beams in BEAMS:
        scenario = parse_document(copy.deepcopy(document), name, [f"sensors.beams={beams}"])
        world_file = irsim_world_file(world_dir, name, beams)
        world_file.write_text(peers.yaml.safe_dump(irsim_world(scenario, beams)), encoding="utf-8")
        runs[IRSIM, beams] = lambda file=world_file: time_irsim(peers.irsim, file, time_limit_s)
    for planner in planners:
        for beams in BEAMS:
            overrides = [
                f"planner.name={planner}",
                f"sensors.beams={beams}",
                f"run.control_hz={1.0 / STEP_S:g}",
                f"run.time_limit_s={time_limit_s:g}",
            ]
            scenario = parse_document(copy.deepcopy(document), name, overrides)
            runs[planner, beams] = lambda scenario=scenario: time_vplane(scenario)
            warm_up = parse_document(
                copy.deepcopy(document), name, [*overrides, f"run.time_limit_s={STEP_S}"]
            )
            time_vplane(warm_up)  # imports the planner, loads the numba caches
    return runs


def best_of(
    runs: dict[str, dict[tuple[str, int], Callable[[], Timing]]], repeat: int
) -> dict[str, dict[tuple[str, int], Timing]]:
    """Every run `repeat` times, interleaved (every world and configuration once a repeat); the
    best CPU and wall time of each."""
    worlds: dict[str, dict[tuple[str, int], Timing]] = {name: {} for name in runs}
    for _ in range(repeat):
        for name, configs in runs.items():
            for key, timed_run in configs.items():
                timing = timed_run()
                if key in worlds[name]:
                    worlds[name][key].keep_best(timing)
                else:
                    worlds[name][key] = timing
    return worlds


def rate(simulated_s: float, seconds: float) -> float | None:
    """Simulated seconds per second, None for no time."""
    return simulated_s / seconds if seconds > 0 else None


def label(simulator: str) -> str:
    return IRSIM + " `dash`" if simulator == IRSIM else f"vplane-mj `{simulator}`"


def scan_table(cylinders: dict[str, int], differences: dict[str, float]) -> list[dict]:
    """Per world: its cylinders and how far apart the two 720-beam scans at the start are."""
    return [
        {
            "world": name,
            "cylinders": count,
            "720-beam scans at the start: largest difference, mm": differences[name],
        }
        for name, count in cylinders.items()
    ]


def world_table(worlds: dict[str, dict[tuple[str, int], Timing]]) -> list[dict]:
    """Per world and configuration: how the run ended, its times and its rate over IR-SIM's."""
    table = []
    for name, timings in worlds.items():
        for (simulator, beams), t in timings.items():
            peer = timings[IRSIM, beams]
            over = (t.simulated_s / t.cpu_s) / (peer.simulated_s / peer.cpu_s)
            values = (name, label(simulator), beams, t.outcome, t.simulated_s, t.cpu_s)
            values += (rate(t.simulated_s, t.cpu_s), rate(t.simulated_s, t.wall_s), over, t.planner_share)
            table.append(dict(zip(WORLD_CELLS, values, strict=True)))
    return table


def rate_column(simulator: str, beams: int) -> str:
    """The rates table's column of a configuration: "IR-SIM 16", "`dwa` 720", ..."""
    return f"{IRSIM} {beams}" if simulator == IRSIM else f"`{simulator}` {beams}"


def rates_table(
    worlds: dict[str, dict[tuple[str, int], Timing]], cylinders: dict[str, int]
) -> tuple[list[dict], list[str]]:
    """Per world, its cylinders and each configuration's simulated seconds per CPU second, and
    for this project's, that rate over IR-SIM's at the same beams; the rows and the columns."""
    table, columns = [], ["world", "cylinders"]
    for name, timings in worlds.items():
        row: dict = {"world": name, "cylinders": cylinders[name]}
        for (simulator, beams), t in timings.items():
            peer = timings[IRSIM, beams]
            column = rate_column(simulator, beams)
            row[column] = rate(t.simulated_s, t.cpu_s)
            if simulator != IRSIM:
                row[column + OVER_IRSIM] = (t.simulated_s / t.cpu_s) / (peer.simulated_s / peer.cpu_s)
        columns += [key for key in row if key not in columns]
        table.append(row)
    return table, columns


def rates_markdown(table: list[dict], columns: list[str]) -> str:
    """The rates table as the documentation shows it: a configuration's rate, and in brackets
    its rate over IR-SIM's ("47.41 (7.82x)")."""
    shown = [column for column in columns if not column.endswith(OVER_IRSIM)]

    def cell(row: dict, column: str) -> str:
        value, over = row.get(column), row.get(column + OVER_IRSIM)
        if column in ("world", "cylinders") or value is None:
            return "-" if value is None else str(value)
        return f"{value:.2f}" + ("" if over is None else f" ({over:.2f}x)")

    cells = [{column: cell(row, column) for column in shown} for row in table]
    return markdown_table(cells, shown, lambda _, text: str(text))


def overall_table(worlds: dict[str, dict[tuple[str, int], Timing]]) -> list[dict]:
    """Per configuration, summed over the worlds: times, rates and rates over IR-SIM's."""
    keys = next(iter(worlds.values())).keys()
    totals = {
        key: tuple(
            sum(getattr(w[key], part) for w in worlds.values()) for part in ("simulated_s", "cpu_s", "wall_s")
        )
        for key in keys
    }
    table = []
    for (simulator, beams), (simulated, cpu, wall) in totals.items():
        peer_simulated, peer_cpu, peer_wall = totals[IRSIM, beams]
        over_cpu = (simulated / cpu) / (peer_simulated / peer_cpu)
        over_wall = (simulated / wall) / (peer_simulated / peer_wall)
        values = (label(simulator), beams, simulated, cpu, rate(simulated, cpu), rate(simulated, wall))
        table.append(dict(zip(OVERALL_CELLS, (*values, over_cpu, over_wall), strict=True)))
    return table


def publish(out: Path, stem: str, table: list[dict], cells: dict[str, str]) -> list[Path]:
    """`table` printed and written as `stem` into `out`, each column as `cells` says."""
    text = markdown_table(table, list(cells), formatted(cells))
    print(f"\n{text}")
    return write_table(out, stem, table, list(cells), text)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=options.whole(1), default=2, help="BARN protocol worlds")
    parser.add_argument("--seed", type=options.whole(0), default=0, help="the worlds' generator seed")
    parser.add_argument("--time-limit", type=options.positive, default=10.0, help="simulated seconds at most")
    parser.add_argument(
        "--repeat", type=options.whole(1), default=3, help="interleaved repeats; the best is kept"
    )
    parser.add_argument(
        "--planners", type=options.planners, default="vplane_plus,dwa", help="comma-separated planner names"
    )
    parser.add_argument(
        "--blas-threads",
        type=options.whole(0),
        default=1,
        help="threads BLAS may run (0: its own default, one a core)",
    )
    parser.add_argument("--out", type=Path, default=Path("logs/peer_irsim"))
    args = parser.parse_args(argv)
    peers = load_peers()
    if isinstance(peers, str):
        print(MISSING_PEERS.format(missing=peers), file=sys.stderr)
        return 2
    out = prepare_out_dir(args.out)
    cases = generate_protocol(args.count, args.seed)
    cylinders = {
        case.name: sum(ob["kind"] == "cylinder" for ob in case.document["world"]["obstacles"])
        for case in cases
    }
    limits = peers.threadpoolctl.threadpool_limits(args.blas_threads or None, user_api="blas")
    with limits, tempfile.TemporaryDirectory(prefix="peer_irsim_") as world_dir:
        runs = {
            case.name: configurations(case, args.planners, args.time_limit, Path(world_dir), peers)
            for case in cases
        }
        blas = ", ".join(
            dict.fromkeys(
                f"{pool['internal_api']} with {pool['num_threads']} thread(s)"
                for pool in peers.threadpoolctl.threadpool_info()
                if pool["user_api"] == "blas"
            )
        )
        differences = {
            case.name: start_scan_difference_mm(case, Path(world_dir), peers.irsim) for case in cases
        }
        worlds = best_of(runs, args.repeat)
    print(
        f"best of {args.repeat} interleaved repeats of the simulation loop; at most {args.time_limit:g} s "
        f"simulated; IR-SIM {peers.irsim.__version__} (kinematic, 50 Hz), mujoco {mujoco.__version__} "
        f"(physics 500 Hz, control and scans 50 Hz); BLAS: {blas or 'none found'}"
    )
    written = publish(out, "peer_irsim_scans", scan_table(cylinders, differences), SCAN_CELLS)
    written += publish(out, "peer_irsim_worlds", world_table(worlds), WORLD_CELLS)
    rates, rate_columns = rates_table(worlds, cylinders)
    text = rates_markdown(rates, rate_columns)
    print(f"\n{text}")
    written += write_table(out, "peer_irsim_rates", rates, rate_columns, text)
    written += publish(out, "peer_irsim", overall_table(worlds), OVERALL_CELLS)
    print("\n" + "\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
