"""Runs per core-minute: what a sweep of many BARN worlds costs, planner by planner.

Generates `--worlds` worlds of `vplane-mj generate barn` (seed `--seed`, the default robot and
its sonar), and with `--protocol` those of `generate barn --protocol` (the Jackal and its
laser), then sweeps each planner of `--planners` over them (run seed 0, 2 cm range noise, no
log, no render; on protocol worlds `dwa` follows its map's way, as in `barn_protocol.py`)
through `vplane_mj.bench.sweep.run_sweep` with `--jobs` workers. Reported per
planner: runs, success, the sweep's wall time, the CPU time of its workers (their own
accounting, so other processes on a shared machine do not inflate it), and runs per
core-minute: runs over that CPU time in minutes. Writes the table to `OUT/sweep_rate.csv`, `.md`
and `.json` (with the command and the date) and a bar chart to `OUT/sweep_rate.png`.

    python benchmarks/sweep_rate.py [--worlds 300] [--planners vplane,vplane_plus,dwa] [--protocol] [--jobs 2]
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

from barn_protocol import write_scenarios

from vplane_mj.bench import options
from vplane_mj.bench.sweep import plan_jobs, run_sweep
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir, write_atomically
from vplane_mj.worlds.barn_protocol import generate_protocol
from vplane_mj.worlds.families import generate

COLUMNS = ("worlds", "planner", "runs", "success_rate", "wall_s", "cpu_s", "runs_per_core_minute")


def children_cpu_s() -> float:
    """CPU time (s, user and system) of this process's finished children."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def sweep_row(label: str, scenarios: list[str], planner: str, jobs: int) -> dict:
    """One planner's sweep over `scenarios`: its rows' success and what it cost."""
    planned = plan_jobs(scenarios, [planner], [0], ["sensors.noise_std=0.02"])
    with tempfile.TemporaryDirectory() as tmp:
        cpu, wall = children_cpu_s(), time.perf_counter()
        rows = run_sweep(planned, Path(tmp), jobs)
        wall, cpu = time.perf_counter() - wall, children_cpu_s() - cpu
    reached = sum(row["outcome"] == "reached" and row["collisions"] == 0 for row in rows)
    return {
        "worlds": label,
        "planner": planner,
        "runs": len(rows),
        "success_rate": reached / len(rows),
        "wall_s": wall,
        "cpu_s": cpu,
        "runs_per_core_minute": len(rows) / (cpu / 60.0),
    }


def plot(table: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = [f"{row['planner']}\n{row['worlds']}" for row in table]
    figure, ax = plt.subplots(figsize=(2 + 1.2 * len(table), 3.6), layout="constrained")
    bars = ax.bar(range(len(table)), [row["runs_per_core_minute"] for row in table], color="tab:blue")
    ax.bar_label(bars, fmt="%.0f")
    ax.set_xticks(range(len(table)), labels, fontsize=8)
    ax.set_ylabel("runs per core-minute")
    ax.margins(y=0.12)
    ax.set_title(f"A sweep of {table[0]['runs']} BARN worlds\n(one run each, no log, no render)", fontsize=10)
    write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))
    plt.close(figure)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=options.whole(1), default=300)
    parser.add_argument("--seed", type=options.whole(0), default=0)
    parser.add_argument("--planners", type=options.planners, default="vplane,vplane_plus,dwa")
    parser.add_argument("--protocol", action="store_true", help="also the protocol worlds (the Jackal)")
    parser.add_argument("--jobs", type=options.whole(1), default=2, help="worker processes")
    parser.add_argument("--out", type=Path, default=Path("logs/sweep_rate"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    sets = {"barn, default robot": write_scenarios(out / "barn", generate("barn", args.worlds, args.seed))}
    if args.protocol:
        sets["protocol, Jackal"] = write_scenarios(
            out / "protocol", generate_protocol(args.worlds, args.seed)
        )
    table = [
        sweep_row(label, scenarios, planner, args.jobs)
        for label, scenarios in sets.items()
        for planner in args.planners
    ]
    text = markdown(table)
    written = write_table(out, "sweep_rate", table, COLUMNS, text)
    plot(table, out / "sweep_rate.png")
    print(text)
    print("\n".join(f"wrote {path}" for path in [*written, out / "sweep_rate.png"]))
    return 0


def markdown(table: list[dict]) -> str:
    """The table as Markdown: success in %, times and rates in whole numbers."""

    def cell(key: str, value) -> str:
        if key == "planner":
            return f"`{value}`"
        if key == "success_rate":
            return f"{value:.1%}"
        return f"{value:.0f}" if isinstance(value, float) else str(value)

    return markdown_table(table, COLUMNS, cell)


if __name__ == "__main__":
    sys.exit(main())
