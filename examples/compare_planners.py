"""A planner of your own against the built-in ones, on the same worlds and seeds.

The random-walk planner of examples/random_walk_planner.py (APF with a random-walk escape) is
swept with built-in planners through `vplane_mj.sweep`, which takes it as an import spec
(`path/to/file.py:Class`; a `module:Class` or the class itself work too) and has the worker
processes import it. The worlds are the paper's scenarios (or those given) with sonar noise,
several seeds each (the seed drives the noise). The script prints the bench table (one row per
planner) and each planner's success per scenario, and writes the bench report into --out:
bench.csv, bench.json, bench.png, bench-scenarios.png and bench.html (open it in a browser).

    python examples/compare_planners.py                   # 4 worlds x 7 planners x 5 seeds
    python examples/compare_planners.py paper_c_escape my_world.toml --planners apf,vplane --seeds 0
"""

from __future__ import annotations

import argparse
import sys
from argparse import RawDescriptionHelpFormatter
from pathlib import Path

import vplane_mj

PAPER_SCENARIOS = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
RANDOM_WALK = f"{Path(__file__).resolve().with_name('random_walk_planner.py')}:RandomWalkPlanner"
"""The example planner as an import spec: its file (beside this script) and its class."""


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=RawDescriptionHelpFormatter)
    parser.add_argument("scenarios", nargs="*", default=list(PAPER_SCENARIOS), help="files or built-in names")
    parser.add_argument(
        "--planners",
        default="apf,vobs,bug2,vfh,dwa,vplane,vplane_plus",
        help="comma-separated built-in planners to compare the random walk with",
    )
    parser.add_argument("--seeds", default="0-4", help='run seeds, as bench takes them ("0-4", "0,3")')
    parser.add_argument("--noise", type=float, default=0.01, help="sonar range noise, std in m")
    parser.add_argument("--time-limit", type=float, help="simulated seconds per run (default: each world's)")
    parser.add_argument("--jobs", type=int, help="worker processes (default: one per core)")
    parser.add_argument("--out", type=Path, default=Path("logs/compare_planners"), help="output directory")
    return parser.parse_args()


def main() -> None:
    args = parse_args()
    overrides = [f"sensors.noise_std={args.noise}"]
    if args.time_limit is not None:
        overrides.append(f"run.time_limit_s={args.time_limit}")
    planners = [RANDOM_WALK, *args.planners.split(",")]

    result = vplane_mj.sweep(
        args.scenarios, planners, seeds=args.seeds, overrides=overrides, jobs=args.jobs, out=args.out
    )

    # The table bench prints: success rate, collisions, timeouts, medians, escapes per planner.
    print(result.table_text())
    # Success per scenario and planner, from the rows (one per run; the random walk's planner
    # name is its class's `name`, "random_walk").
    names = list(dict.fromkeys(row["planner"] for row in result.rows))
    width = max(len(name) for name in names) + 2
    print()
    print("successes per scenario".ljust(24) + "".join(name.rjust(width) for name in names))
    for scenario in dict.fromkeys(row["scenario"] for row in result.rows):
        cells = []
        for name in names:
            mine = [row for row in result.rows if row["scenario"] == scenario and row["planner"] == name]
            cells.append(f"{sum(row['success'] for row in mine)}/{len(mine)}".rjust(width))
        print(scenario.ljust(24) + "".join(cells))
    print()
    for path in result.files:
        print(f"wrote {path}")


if __name__ == "__main__":
    try:
        main()
    except vplane_mj.VPlaneError as exc:  # bad input: the message names the key and the reason
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
