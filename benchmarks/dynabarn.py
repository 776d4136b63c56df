"""The planners on generated DynaBARN worlds with the Jackal and its laser, per difficulty third.

Generates `--count` worlds as `vplane-mj generate dynabarn` does (seed `--world-seed`; the
count split into easy, medium and hard as DynaBARN numbers its worlds; an open 23 x 22 m
plane, cylinders of radius 0.5 m looping on spline paths from a phase drawn from each run's
seed), writes them to `OUT/cases/`, and runs each planner of `--planners` on each world for
each seed of `--seeds`, with laser noise `--noise` (m, `sensors.noise_std`). The runs go
through `vplane_mj.bench.sweep.run_sweep`, so `OUT/bench.jsonl` journals them and the same
command run again only does what is missing.

Prints, per planner and third (and over all), the runs, the success rate (reached without a
collision), the share of runs with a collision, timeouts, stuck runs, errors and the mean time
to the goal of the successes, beside the success rates DynaBARN's paper and later work
publish (Gazebo, the harness's own runs: DWA 78% / 43% / 17%, TD3 trained on the worlds
74% / 60% / 28%, Dyna-LfLH 22.5% and LfH-CP 30.8% over all 60). Writes the table to
`OUT/dynabarn.csv` and `OUT/dynabarn.md`, and a figure of the success per third and planner
to `OUT/dynabarn.png`.

    python benchmarks/dynabarn.py [--count 60] [--seeds 0-4] [--noise 0.01] [--jobs 2]
    python benchmarks/dynabarn.py --count 3 --seeds 0 --planners vplane_plus,dwa --out /tmp/dyn
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.sweep import plan_jobs, run_sweep
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir, write_atomically
from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.worlds.dynabarn_generate import generate_dynabarn
from vplane_mj.worlds.dynabarn_layout import DIFFICULTIES

PLANNER_ORDER = ("vplane_plus", "dwa", "vplane", "vfh", "apf", "vobs", "bug2")
THIRDS = (*DIFFICULTIES, "all")
COLUMNS = (
    "planner",
    "third",
    "runs",
    "success_rate",
    "collision_rate",
    "timeouts",
    "stuck",
    "errors",
    "mean_time_s",
)
PUBLISHED = (
    ("DynaBARN: DWA", (0.78, 0.43, 0.17, None)),
    ("DynaBARN: TD3 (trained on the worlds)", (0.74, 0.60, 0.28, None)),
    ("Dyna-LfLH", (None, None, None, 0.225)),
    ("LfH-CP", (None, None, None, 0.308)),
)
"""Published success rates on DynaBARN's 60 worlds (easy, medium, hard, all), Gazebo."""


def third_of(name: str) -> str:
    """The difficulty third in a generated world's name (`dynabarn_<seed>_<third>_<k>`)."""
    return next(third for third in DIFFICULTIES if f"_{third}_" in name)


def write_cases(out: Path, count: int, seed: int) -> list[str]:
    """The generated worlds' scenario files under `out/cases/`, their paths."""
    directory = out / "cases"
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for case in generate_dynabarn(count, seed):
        path = directory / f"{case.name}.toml"
        path.write_text(case.toml(), encoding="utf-8")
        paths.append(str(path))
    return paths


def summarize(planner: str, third: str, rows: list[dict]) -> dict:
    """One row of the table: `rows` are one planner's runs in one third (or all)."""
    times = [r["time_to_goal_s"] for r in rows if r["success"]]
    return {
        "planner": planner,
        "third": third,
        "runs": len(rows),
        "success_rate": sum(bool(r["success"]) for r in rows) / len(rows),
        "collision_rate": sum((r.get("collisions") or 0) > 0 for r in rows) / len(rows),
        "timeouts": sum(r["outcome"] == "timeout" for r in rows),
        "stuck": sum(r["outcome"] == "stuck" for r in rows),
        "errors": sum(r["outcome"] == "error" for r in rows),
        "mean_time_s": statistics.fmean(times) if times else None,
    }


def planner_table(rows: list[dict]) -> list[dict]:
    """Per planner (in the order they first appear), a row per third and one over all."""
    table = []
    for planner in dict.fromkeys(row["planner"] for row in rows):
        mine = [r for r in rows if r["planner"] == planner]
        for third in THIRDS:
            chosen = mine if third == "all" else [r for r in mine if third_of(r["scenario"]) == third]
            if chosen:
                table.append(summarize(planner, third, chosen))
    return table


def published_rows() -> list[dict]:
    """The published success rates as rows of the table."""
    return [
        {"planner": name, "third": third, "success_rate": rate}
        for name, rates in PUBLISHED
        for third, rate in zip(THIRDS, rates, strict=True)
        if rate is not None
    ]


def markdown(rows: list[dict]) -> str:
    """The table as Markdown."""

    def cell(key: str, value) -> str:
        if value is None:
            return "-"
        if key.endswith("_rate") and isinstance(value, float):
            return f"{100 * value:.1f}%"
        return f"{value:.1f}" if isinstance(value, float) else str(value)

    return markdown_table(rows, COLUMNS, cell)


def plot(table: list[dict], path: Path) -> None:
    """Success per third and planner (bars), DWA's and TD3's published rates as markers."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    planners = list(dict.fromkeys(row["planner"] for row in table))
    x = np.arange(len(THIRDS))
    width = 0.8 / max(1, len(planners))
    figure, ax = plt.subplots(figsize=(7, 4.8))
    for k, planner in enumerate(planners):
        rates = {row["third"]: row["success_rate"] for row in table if row["planner"] == planner}
        ax.bar(
            x + (k - (len(planners) - 1) / 2) * width,
            [100 * rates.get(t, 0) for t in THIRDS],
            width,
            label=planner,
        )
    for (name, rates), marker in zip(PUBLISHED, ("v", "^", "s", "D"), strict=True):
        shown = [(i, 100 * r) for i, r in enumerate(rates) if r is not None]
        ax.scatter(*zip(*shown, strict=True), marker=marker, color="black", zorder=3, label=name)
    ax.set_xticks(x, THIRDS)
    ax.set_ylabel("success, % of runs")
    ax.set_ylim(0, 100)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncols=4)
    runs = next(row["runs"] for row in table if row["third"] == "all")
    ax.set_title(f"Generated DynaBARN worlds, Jackal with laser ({runs} runs per planner)")
    figure.tight_layout()
    write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))
    plt.close(figure)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = [name for name in PLANNER_ORDER if name in PLANNERS]
    parser.add_argument("--planners", type=options.planners, default=",".join(default))
    options.add_world_sweep(parser, (60, "worlds, split into the three thirds"), "0-4", "dynabarn")
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    scenarios = write_cases(out, args.count, args.world_seed)
    overrides = [f"sensors.noise_std={args.noise}"] if args.noise > 0 else []
    rows = run_sweep(plan_jobs(scenarios, args.planners, args.seeds, overrides), out, args.jobs)
    table = planner_table(rows)
    text = markdown([*table, *published_rows()])
    written = write_table(out, "dynabarn", table, COLUMNS, text)
    plot(table, out / "dynabarn.png")
    print(text)
    print("\n".join(f"wrote {path}" for path in [*written, out / "dynabarn.png"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
