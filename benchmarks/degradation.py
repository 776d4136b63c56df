"""Success on the trap suite against sonar range noise and dropout, for every planner.

Each sensor level is a pair (noise_std in m, dropout probability): a noise curve (dropout 0;
by default noise 0, 0.02, 0.05, 0.1 m), a dropout curve (noise 0; by default 0.1, 0.2, 0.4)
and one reference point with both (by default 0.03 m and 0.1). Every trap case
(`vplane_mj.worlds.families.trap_suite`, 34 cases) runs with every planner and seed at every level,
with the simulated time limit `--time-limit` (s): by default 8 x 34 x 5 = 1360 runs. The cases
are written to `OUT/cases/`; the runs go through `vplane_mj.bench.sweep.run_sweep`, so
`OUT/bench.jsonl` journals them and the same command run again only does what is missing. The
level is part of each run's scenario name (`u_front_0_noise_0p03_dropout_0p1`: noise 0.03 m,
dropout 0.1), so every journal row says which level it belongs to. A run succeeds when it reaches
the goal without a collision.

Writes `OUT/degradation.csv` (per planner and level: runs, successes, reached, runs with a
collision, timeouts, stuck, errors, success rate), `OUT/degradation.json` (the same with the
command and the date), `OUT/degradation.md` (success % per planner and level, the reference
level last) and `OUT/degradation.png` (success % against noise_std and against dropout, one line
per planner, the reference point starred), and prints the success table.

    python benchmarks/degradation.py [--jobs 2] [--seeds 0] [--time-limit 120] [--out logs/degradation]
    python benchmarks/degradation.py --cases 3 --noise 0,0.05 --dropout '' --out /tmp/degradation
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from vplane_mj.bench import options
from vplane_mj.bench.sweep import plan_jobs, run_sweep
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir, write_atomically
from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.worlds.families import trap_suite

COLUMNS = (
    "planner",
    "noise_std",
    "dropout",
    "runs",
    "successes",
    "reached",
    "collided",
    "timeouts",
    "stuck",
    "errors",
    "success_rate",
)
MARKERS = "os^Dv"


def curve(numbers: Callable[[str], list[float]]) -> Callable[[str], list[float]]:
    """An option's type: `numbers`, or none for the empty string."""
    return lambda text: numbers(text) if text.strip() else []


def sensor_levels(noise: list[float], dropout: list[float], reference: list[float]) -> list[tuple]:
    """The (noise_std, dropout) pairs: the noise curve, the dropout curve, the reference point."""
    pairs = [(n, 0.0) for n in noise] + [(0.0, d) for d in dropout]
    if reference:
        pairs.append((reference[0], reference[1]))
    return list(dict.fromkeys(pairs))


def level_name(case: str, noise: float, dropout: float) -> str:
    """The case's name at a level: "u_front_0_noise_0p03_dropout_0p1"."""
    return f"{case}_noise_{noise:g}_dropout_{dropout:g}".replace(".", "p")


def tally(jobs_levels: list[tuple], rows: list[dict]) -> list[dict]:
    """One row per planner and level, in planner then level order."""
    groups: dict[tuple, list[dict]] = {}
    for (planner, level), row in zip(jobs_levels, rows, strict=True):
        groups.setdefault((planner, level), []).append(row)
    table = []
    for (planner, (noise, dropout)), mine in sorted(groups.items(), key=lambda item: item[0][0]):
        successes = sum(row["success"] for row in mine)
        table.append(
            {
                "planner": planner,
                "noise_std": noise,
                "dropout": dropout,
                "runs": len(mine),
                "successes": successes,
                "reached": sum(row["reached"] for row in mine),
                "collided": sum(row["collisions"] > 0 for row in mine),
                "timeouts": sum(row["outcome"] == "timeout" for row in mine),
                "stuck": sum(row["outcome"] == "stuck" for row in mine),
                "errors": sum(row["outcome"] == "error" for row in mine),
                "success_rate": successes / len(mine),
            }
        )
    return table


def markdown(table: list[dict], levels: list[tuple]) -> str:
    """Success % per planner (rows) and level (columns, "noise_std / dropout") as Markdown."""
    corner = "noise_std (m) / dropout"
    labels = {f"{noise:g} / {dropout:g}": (noise, dropout) for noise, dropout in levels}
    rate = {(r["planner"], r["noise_std"], r["dropout"]): r["success_rate"] for r in table}
    rows = [
        {
            corner: f"`{planner}`",
            **{label: f"{100 * rate[planner, *level]:.0f}%" for label, level in labels.items()},
        }
        for planner in dict.fromkeys(r["planner"] for r in table)
    ]
    return markdown_table(rows, [corner, *labels], lambda _, value: value)


def plot(table: list[dict], reference: list[float], path: Path) -> Path:
    """Two panels: success % against noise_std (dropout 0) and against dropout (noise 0)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(1, 2, figsize=(13, 4.5), sharey=True)
    panels = (("noise_std", "dropout", "sonar range noise std (m)"), ("dropout", "noise_std", "dropout"))
    for (axis, (x_key, zero_key, label)), ax in zip(enumerate(panels), axes, strict=True):
        for k, planner in enumerate(dict.fromkeys(r["planner"] for r in table)):
            mine = [r for r in table if r["planner"] == planner]
            curve = sorted((r[x_key], 100 * r["success_rate"]) for r in mine if r[zero_key] == 0)
            style = {"color": f"C{k}", "marker": MARKERS[k % len(MARKERS)], "alpha": 0.8}
            ax.plot(*zip(*curve, strict=True), **style, label=planner)
            if reference:
                point = [r for r in mine if (r["noise_std"], r["dropout"]) == tuple(reference)]
                ax.plot(reference[axis], 100 * point[0]["success_rate"], "*", color=f"C{k}", ms=14)
        if reference:
            text = f"reference: noise {reference[0]:g} m + dropout {reference[1]:g}"
            ax.plot([], [], "*", color="grey", ms=12, label=text)
        ax.set(xlabel=label, ylim=(-2, 102), title=f"success against {x_key} ({zero_key} 0)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("success (%) on the trap suite")
    axes[1].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    figure.tight_layout()
    return write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    noise, dropout = curve(options.numbers(0.0)), curve(options.numbers(0.0, most=1.0))
    parser.add_argument("--noise", type=noise, default="0,0.02,0.05,0.1", help="noise curve (m; '' none)")
    parser.add_argument("--dropout", type=dropout, default="0.1,0.2,0.4", help="dropout curve ('' none)")
    parser.add_argument(
        "--reference", type=noise, default="0.03,0.1", help="NOISE,DROPOUT of the reference ('' none)"
    )
    parser.add_argument("--planners", type=options.planners, default=",".join(sorted(PLANNERS)))
    parser.add_argument("--seeds", type=options.seeds, default="0", help="seeds, e.g. 0-4")
    parser.add_argument("--cases", type=options.whole(1), help="only the first N trap cases")
    parser.add_argument(
        "--time-limit", type=options.positive, default=120.0, help="simulated seconds per run"
    )
    parser.add_argument("--jobs", type=options.whole(1), default=2, help="worker processes")
    parser.add_argument("--out", type=Path, default=Path("logs/degradation"))
    args = parser.parse_args(argv)
    if args.reference and (len(args.reference) != 2 or args.reference[1] > 1.0):
        parser.error("argument --reference: NOISE,DROPOUT expected, the dropout at most 1")
    return sweep(args)


def sweep(args: argparse.Namespace) -> int:
    cases_dir = prepare_out_dir(args.out / "cases")
    paths = []
    for case in trap_suite()[: args.cases]:
        text = case.toml()
        paths.append(write_atomically(cases_dir / f"{case.name}.toml", lambda tmp, t=text: tmp.write_text(t)))
    levels = sensor_levels(args.noise, args.dropout, args.reference)
    jobs, jobs_levels = [], []
    for noise, dropout in levels:
        for path in paths:
            overrides = [
                f"name={level_name(path.stem, noise, dropout)}",
                f"sensors.noise_std={noise}",
                f"sensors.dropout={dropout}",
                f"run.time_limit_s={args.time_limit}",
            ]
            for job in plan_jobs([str(path)], args.planners, args.seeds, overrides):
                jobs.append(job)
                jobs_levels.append((job.planner, (noise, dropout)))

    rows = run_sweep(jobs, args.out, args.jobs)
    table = tally(jobs_levels, rows)
    text = markdown(table, levels)
    written = write_table(args.out, "degradation", table, COLUMNS, text)
    png_path = plot(table, args.reference, args.out / "degradation.png")
    runs_per_cell = len(paths) * len(args.seeds)
    print(f"success per planner and sensor level (noise_std m / dropout), {runs_per_cell} runs each")
    print(text)
    wall = sum(row["wall_time_s"] for row in rows)
    print(f"simulation wall time: {wall:.0f} s over {len(rows)} runs ({wall / len(rows):.2f} s per run)")
    print("\n".join(f"wrote {path}" for path in [*written, png_path]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
