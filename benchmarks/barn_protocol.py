"""The planners on the BARN challenge's protocol worlds with the Jackal and its laser.

Generates `--count` worlds as `vplane-mj generate barn --protocol` does (seed `--world-seed`;
4.2 x 14 m, 0.15 m posts, the Jackal, its 270-degree 720-beam laser), writes them to
`OUT/cases/`, and runs each planner of `--planners` on each world for each seed of `--seeds`,
with laser noise `--noise` (m, `sensors.noise_std`); `dwa` follows the map's shortest way to
the goal, as BARN's DWA follows its global plan (the Jackal profile's `planner_settings`). The runs go through
`vplane_mj.bench.sweep.run_sweep`, so `OUT/bench.jsonl` journals them and the same command
run again only does what is missing.

Prints, per planner, the runs, success rate (reached without a collision), the share of runs
with a collision, timeouts, stuck runs, the mean BARN score (success x OT / clip(T, 2 OT,
8 OT), at most 0.5) and the planner's mean CPU time per tick, beside BARN's published figures:
the DWA baseline of the benchmark paper (Perille et al., 2020: score 0.159, 85% success, 5.6%
collisions) and the best entries of the BARN challenges (mean scores 0.40 to 0.48). Writes the
table to `OUT/barn_protocol.csv`, `.md` and `.json` (with the command and the date) and a figure
of success and mean score per planner, with the published figures as lines, to
`OUT/barn_protocol.png`.

    python benchmarks/barn_protocol.py [--count 50] [--seeds 0-2] [--noise 0.01] [--jobs 2]
    python benchmarks/barn_protocol.py --count 2 --seeds 0 --planners vplane_plus,dwa --out /tmp/barn
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
from vplane_mj.worlds.barn_protocol import generate_protocol

PLANNER_ORDER = ("vplane_plus", "dwa", "vplane", "vfh", "apf", "vobs", "bug2")
COLUMNS = (
    "planner",
    "runs",
    "success_rate",
    "collision_rate",
    "timeouts",
    "stuck",
    "mean_score",
    "planner_cpu_ms_mean",
)
PUBLISHED = (
    {"planner": "BARN: DWA baseline", "success_rate": 0.85, "collision_rate": 0.056, "mean_score": 0.159},
    {"planner": "BARN: best entries", "mean_score": "0.40-0.48"},
)
"""BARN's published figures: the benchmark paper's DWA and the challenges' best mean scores."""


def write_scenarios(directory: Path, cases) -> list[str]:
    """The generated `cases` as scenario files under `directory`, their paths."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for case in cases:
        path = directory / f"{case.name}.toml"
        path.write_text(case.toml(), encoding="utf-8")
        paths.append(str(path))
    return paths


def write_cases(out: Path, count: int, seed: int) -> list[str]:
    """The protocol worlds' scenario files under `out/cases/`, their paths."""
    return write_scenarios(out / "cases", generate_protocol(count, seed))


def planner_table(rows: list[dict]) -> list[dict]:
    """One row per planner, in the order they first appear."""
    table = []
    for planner in dict.fromkeys(row["planner"] for row in rows):
        mine = [r for r in rows if r["planner"] == planner]
        cpu = [r["planner_cpu_ms_mean"] for r in mine if r.get("planner_cpu_ms_mean") is not None]
        table.append(
            {
                "planner": planner,
                "runs": len(mine),
                "success_rate": sum(bool(r["success"]) for r in mine) / len(mine),
                "collision_rate": sum((r.get("collisions") or 0) > 0 for r in mine) / len(mine),
                "timeouts": sum(r["outcome"] == "timeout" for r in mine),
                "stuck": sum(r["outcome"] == "stuck" for r in mine),
                "mean_score": statistics.fmean(r.get("score") or 0.0 for r in mine),
                "planner_cpu_ms_mean": statistics.fmean(cpu) if cpu else None,
            }
        )
    return table


def markdown(rows: list[dict]) -> str:
    """The table and BARN's published figures as Markdown."""

    def cell(key: str, value) -> str:
        if value is None:
            return "-"
        if key.endswith("_rate") and isinstance(value, float):
            return f"{100 * value:.1f}%"
        if key == "mean_score" and isinstance(value, float):
            return f"{value:.3f}"
        return f"{value:.2f}" if isinstance(value, float) else str(value)

    return markdown_table(rows, COLUMNS, cell)


def plot(table: list[dict], path: Path) -> None:
    """Success rate and mean BARN score per planner, with BARN's published figures as lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [row["planner"] for row in table]
    x = np.arange(len(names))
    figure, (left, right) = plt.subplots(1, 2, figsize=(4 + 1.1 * len(names), 4))
    left.bar(x, [100 * row["success_rate"] for row in table], color="tab:green", zorder=2)
    left.axhline(85, color="tab:red", linestyle="--", label="BARN DWA baseline (85%)")
    left.set_ylabel("success, % of runs")
    left.set_ylim(0, 100)
    right.bar(x, [row["mean_score"] for row in table], color="tab:blue", zorder=2)
    right.axhline(0.159, color="tab:red", linestyle="--", label="BARN DWA baseline (0.159)")
    right.axhspan(0.40, 0.48, color="tab:orange", alpha=0.3, zorder=0, label="BARN best entries (0.40-0.48)")
    right.set_ylabel("mean BARN score")
    right.set_ylim(0, 0.5)
    for ax in (left, right):
        ax.set_xticks(x, names, rotation=30, ha="right")
        ax.legend(fontsize=8, loc="upper right")
    figure.suptitle(f"BARN protocol worlds, Jackal with laser ({table[0]['runs']} runs per planner)")
    figure.tight_layout()
    write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))
    plt.close(figure)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = [name for name in PLANNER_ORDER if name in PLANNERS]
    parser.add_argument("--planners", type=options.planners, default=",".join(default))
    options.add_world_sweep(parser, (50, "protocol worlds"), "0-2", "barn_protocol")
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    scenarios = write_cases(out, args.count, args.world_seed)
    overrides = [f"sensors.noise_std={args.noise}"] if args.noise > 0 else []
    jobs = plan_jobs(scenarios, args.planners, args.seeds, overrides)
    rows = run_sweep(jobs, out, args.jobs)
    table = planner_table(rows)
    text = markdown([*table, *PUBLISHED])
    written = write_table(out, "barn_protocol", table, COLUMNS, text)
    plot(table, out / "barn_protocol.png")
    print(text)
    print("\n".join(f"wrote {path}" for path in [*written, out / "barn_protocol.png"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
