"""A parameter sweep: success and path ratio against APF's distance of influence.

`influence` is f0 of eqs. 4-5: an echo farther than f0 does not repel the robot. This script
runs `vplane` and a peer that shares the parameter (`vobs` by default; `apf` works too) over
generated traps (`vplane-mj generate traps`) and the paper's scenarios, several seeds each
with sonar noise (the seed drives the noise), once per value of `influence`, through
`vplane_mj.sweep`. It prints the success rate and the median path ratio (path length over the
shortest path, of the runs that reached the goal) per planner and value, and writes them to
`influence.csv` and a two-panel figure `influence.png`. Each value's runs are kept in their own
`bench.jsonl` under --out, so running the same command again runs only what is missing.

    python examples/sweep_influence.py                    # 5 values x 2 planners x 10 worlds x 5 seeds
    python examples/sweep_influence.py --values 0.5,1.0 --traps 2 --scenarios "" --seeds 0 --jobs 1
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import sys
from argparse import RawDescriptionHelpFormatter
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: files only, never a window
import matplotlib.pyplot as plt

import vplane_mj
from vplane_mj.bench.sweep import parse_seeds  # the seeds as `vplane-mj bench` reads them

PAPER_SCENARIOS = "paper_c_avoid,paper_c_escape,paper_h_avoid,paper_h_escape"


def numbers(text: str) -> list[float]:
    """A comma-separated list of numbers, for argparse (which reports a bad one as a usage error)."""
    try:
        return [float(item) for item in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a comma-separated list of numbers: {text!r}") from None


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=RawDescriptionHelpFormatter)
    parser.add_argument("--values", type=numbers, default="0.4,0.6,0.8,1.0,1.2", help="values of f0 (m)")
    parser.add_argument("--planners", default="vplane,vobs", help="comma-separated planners with `influence`")
    parser.add_argument("--traps", type=int, default=6, help="generated trap worlds (0: none)")
    parser.add_argument("--world-seed", type=int, default=1, help="seed of the generated worlds")
    parser.add_argument(
        "--scenarios", default=PAPER_SCENARIOS, help='more worlds, comma-separated ("": none)'
    )
    parser.add_argument("--seeds", default="0-4", help='run seeds, as bench takes them ("0-4", "0,3")')
    parser.add_argument("--noise", type=float, default=0.01, help="sonar range noise, std in m")
    parser.add_argument("--time-limit", type=float, help="simulated seconds per run (default: each world's)")
    parser.add_argument("--jobs", type=int, help="worker processes (default: one per core)")
    parser.add_argument("--out", type=Path, default=Path("logs/sweep_influence"), help="output directory")
    args = parser.parse_args()
    if args.jobs is not None and args.jobs < 1:
        parser.error(f"argument --jobs: at least 1, not {args.jobs}")
    if args.traps < 0:
        parser.error(f"argument --traps: at least 0, not {args.traps}")
    return args


def generate_traps(count: int, seed: int, out_dir: Path) -> list[Path | str]:
    """`count` trap worlds written by `vplane-mj generate traps` (the command line is public; the
    same seed gives the same files). Returns the files it says it wrote."""
    if count == 0:
        return []
    command = [sys.executable, "-m", "vplane_mj", "generate", "traps"]
    command += ["--count", str(count), "--seed", str(seed), "--out", str(out_dir)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise vplane_mj.VPlaneError(f"generate traps: {done.stderr.strip()}")
    lines = done.stdout.splitlines()
    return [Path(line.removeprefix("wrote ")) for line in lines if line.startswith("wrote ")]


def plot(curves: dict[str, list[tuple[float, float, float | None]]], title: str, path: Path) -> None:
    """Success rate (left) and median path ratio (right) against influence, a line per planner."""
    figure, (success_axes, ratio_axes) = plt.subplots(1, 2, figsize=(11, 4.2))
    for planner, points in curves.items():
        values = [value for value, _, _ in points]
        success_axes.plot(values, [100 * rate for _, rate, _ in points], "o-", label=planner)
        reached = [(value, ratio) for value, _, ratio in points if ratio is not None]  # none: no point
        ratio_axes.plot([value for value, _ in reached], [ratio for _, ratio in reached], "o-", label=planner)
    success_axes.set(xlabel="influence f0 (m)", ylabel="success (%)", ylim=(-5, 105), title="success rate")
    ratio_axes.set(xlabel="influence f0 (m)", ylabel="path length / shortest path", title="median path ratio")
    for axes in (success_axes, ratio_axes):
        axes.grid(alpha=0.3)
        axes.legend()
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def main() -> None:
    args = parse_args()
    values, planners = args.values, args.planners.split(",")
    common = [f"sensors.noise_std={args.noise}"]
    if args.time_limit is not None:
        common.append(f"run.time_limit_s={args.time_limit}")
    # Check every planner, value, named world and seed first: bad input stops before any file.
    named = [name for name in args.scenarios.split(",") if name]
    for planner in planners:
        for value in values:
            choice = [*common, f"planner.name={planner}", f"planner.influence={value}"]
            for world in ["open_field", *named]:
                vplane_mj.load_scenario(world, overrides=choice)
    parse_seeds(args.seeds)

    worlds = generate_traps(args.traps, args.world_seed, args.out / "worlds")
    for world in worlds:
        print(f"wrote {world}")
    worlds += named

    # One sweep per value: every world x planner x seed with planner.influence set to it.
    curves: dict[str, list[tuple[float, float, float | None]]] = {planner: [] for planner in planners}
    runs = 0
    for value in values:
        result = vplane_mj.sweep(
            worlds,
            planners,
            seeds=args.seeds,
            overrides=[*common, f"planner.influence={value}"],
            jobs=args.jobs,
            out=args.out / f"influence-{value:g}",
            report=False,  # only bench.jsonl; this script makes its own table and figure
        )
        runs += len(result.rows)
        print(f"wrote {args.out / f'influence-{value:g}' / 'bench.jsonl'}")
        for row in result.table:  # one row per planner: success_rate, median_path_ratio, ...
            curves[row["planner"]].append((value, row["success_rate"], row["median_path_ratio"]))

    sizes = f"{len(worlds)} worlds x {len(planners)} planners x seeds {args.seeds} x {len(values)} values"
    print(f"{runs} runs: {sizes}")
    print(f"{'planner':<12} {'influence_m':>11} {'success_rate':>12} {'median_path_ratio':>17}")
    table_path = args.out / "influence.csv"
    with table_path.open("w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["planner", "influence_m", "success_rate", "median_path_ratio"])
        for planner, points in curves.items():
            for value, rate, ratio in points:
                ratio_text = "-" if ratio is None else f"{ratio:.3f}"
                print(f"{planner:<12} {value:>11g} {rate:>12.3f} {ratio_text:>17}")
                writer.writerow([planner, value, f"{rate:.4f}", "" if ratio is None else f"{ratio:.4f}"])
    print(f"wrote {table_path}")
    figure_path = args.out / "influence.png"
    title = f"{len(worlds)} worlds, seeds {args.seeds}, sonar noise {args.noise:g} m"
    plot(curves, title, figure_path)
    print(f"wrote {figure_path}")


if __name__ == "__main__":
    try:
        main()
    except vplane_mj.VPlaneError as exc:  # bad input: the message names the key and the reason
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
