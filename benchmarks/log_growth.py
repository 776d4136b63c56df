"""How a run's MCAP log grows with the run's length: size per simulated minute.

Runs `vfh` in the built-in `walled_goal` (it searches for a way to the goal as long as the run
lasts, about 28 m of turns a minute) for each length of `--minutes`, writes the log, and
reports its size, its size per simulated minute, that over the shortest run's, and the
vertices of the last `/path` message; writes `OUT/log_growth.csv` and `.md`.

    python benchmarks/log_growth.py [--minutes 1,10,30] [--set KEY=VALUE]... [--out DIR]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from vplane_mj.bench import options
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.logs.reader import iter_messages
from vplane_mj.logs.writer import McapLog
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.sensors import scan_bearings

COLUMNS = ("minutes", "path_m", "log_mb", "mb_per_minute", "ratio_to_shortest", "path_vertices")


def measure(minutes: float, overrides: list[str], out: Path) -> dict:
    """One run of `minutes` simulated minutes with `overrides`, logged into `out`: its log's size
    and path."""
    overrides = ["planner.name=vfh", f"run.time_limit_s={60.0 * minutes}", *overrides]
    scenario = load_scenario("walled_goal", overrides)
    path = out / f"walled_goal-{minutes:g}min.mcap"
    with McapLog(path, scenario, scan_bearings(scenario), {}) as log:
        summary = run_scenario(scenario, (log,)).summary
        log.close(summary.to_dict())
    *_, last = iter_messages(path, ("/path",))
    size_mb = path.stat().st_size / 1e6
    return {
        "minutes": minutes,
        "path_m": round(summary.path_length_m, 1),
        "log_mb": round(size_mb, 3),
        "mb_per_minute": round(size_mb / minutes, 3),
        "path_vertices": len(last.message.entities[0].lines[0].points),
    }


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--minutes",
        type=options.positives,
        default="1,10,30",
        help="run lengths (simulated minutes)",
    )
    parser.add_argument(
        "--set", action="append", default=[], metavar="KEY=VALUE", help="a scenario key: robot.profile=jackal"
    )
    parser.add_argument("--out", type=Path, default=Path("logs/log_growth"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    table = [measure(minutes, args.set, out) for minutes in sorted(args.minutes)]
    for row in table:
        row["ratio_to_shortest"] = round(row["mb_per_minute"] / table[0]["mb_per_minute"], 3)
    text = markdown_table(table, COLUMNS, lambda _, value: f"{value:g}")
    written = write_table(out, "log_growth", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
