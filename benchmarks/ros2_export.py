"""Cost of `vplane-mj export ros2`: the export's wall time and the bag's size per simulated minute.

For each robot (the Jackal: a 720-beam laser at 50 Hz, its planner ticking at 50 Hz; the
default robot: its 16-sonar ring at 20 Hz), `vfh` searches the built-in `walled_goal` for a way to
the goal for `--seconds` of simulated time (it turns and stops all run long), on its EKF's pose
(so that the bag's `map` -> `odom` moves). The run's MCAP log is written, then exported as a
bag `--repeat` times: reported are the ticks, the log's and the bag's size, the bag's size per
simulated minute, and the export's median wall time and median CPU time (reading the log,
converting, writing the bag; in this process, so without Python's start). On a machine that
other work shares, the wall time grows with the others' load; the CPU time is the export's own.

The table is written to `OUT/ros2_export.csv`, `.md` and `.json` (with the command and the date).

    python benchmarks/ros2_export.py [--seconds 100] [--repeat 5] [--out logs/ros2_export]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.logs.reader import read_log
from vplane_mj.logs.ros2 import export_ros2
from vplane_mj.logs.writer import McapLog
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.sensors import scan_bearings

ROBOTS = {
    "jackal, laser 720 beams, 50 Hz": ["robot.profile=jackal", "run.control_hz=50"],
    "default, 16 sonars, 20 Hz": [],
}
"""Each row's robot and the scenario keys that make it."""
CELLS = {
    "robot": "",
    "simulated s": ".0f",
    "ticks": "d",
    "log MB": ".2f",
    "bag MB": ".2f",
    "bag MB per simulated minute": ".2f",
    "export wall s": ".2f",
    "export CPU s": ".2f",
}
"""The table's columns and how each is written."""


def measure(robot: str, seconds: float, repeat: int, work: Path) -> dict:
    """One logged run of `robot` for `seconds` simulated seconds, exported `repeat` times."""
    keys = ["planner.name=vfh", "sensors.pose=ekf", f"run.time_limit_s={seconds}", *ROBOTS[robot]]
    scenario = load_scenario("walled_goal", keys)
    log, bag = work / "run.mcap", work / "run.ros2"
    with McapLog(log, scenario, scan_bearings(scenario), {}) as mcap:
        mcap.close(run_scenario(scenario, (mcap,)).summary.to_dict())
    walls, cpus = [], []
    for _ in range(repeat):
        started, cpu = time.perf_counter(), time.process_time()
        export_ros2(log, bag)
        walls.append(time.perf_counter() - started)
        cpus.append(time.process_time() - cpu)
    simulated = read_log(log).times_ns[-1] / 1e9
    bag_mb = sum(path.stat().st_size for path in bag.iterdir()) / 1e6
    return {
        "robot": robot,
        "simulated s": simulated,
        "ticks": len(read_log(log).times_ns),
        "log MB": log.stat().st_size / 1e6,
        "bag MB": bag_mb,
        "bag MB per simulated minute": bag_mb / (simulated / 60),
        "export wall s": statistics.median(walls),
        "export CPU s": statistics.median(cpus),
    }


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--seconds", type=options.positive, default=100.0, help="simulated seconds of each run"
    )
    parser.add_argument("--repeat", type=options.whole(1), default=5, help="exports of each run's log")
    parser.add_argument("--out", type=Path, default=Path("logs/ros2_export"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    with tempfile.TemporaryDirectory() as work:
        table = [measure(robot, args.seconds, args.repeat, Path(work)) for robot in ROBOTS]
    text = markdown_table(table, list(CELLS), formatted(CELLS))
    print(text)
    print("\n".join(f"wrote {path}" for path in write_table(out, "ros2_export", table, list(CELLS), text)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
