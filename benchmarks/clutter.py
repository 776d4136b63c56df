"""Every planner on every scenario family, the paper's scenarios included: the clutter comparison.

Families: `paper` (the four built-in scenarios of the paper's figures), `suite` (the 34 cases
of the trap suite, `vplane_mj.worlds.families.trap_suite`), and the generated
`traps`, `clutter`, `corridors` (`--count` each, seed `--seed`) and `barn` (`--barn` worlds,
seed 0, like `vplane-mj generate barn`). Each family also runs with noisy sonar when
`--noise`/`--dropout` are given (by default 3 cm and 10% on `barn`, as `barn_noisy`). The
scenario files are written to `OUT/cases/`; the runs go through `vplane_mj.bench.sweep.run_sweep`,
so `OUT/bench.jsonl` journals them and the same command run again only does what is missing.

Writes `OUT/clutter.csv` (per family and planner: runs, success rate, runs with a collision,
timeouts, stuck, mean BARN score, median path ratio of the successes), `OUT/clutter.json` (the
same with the command and the date), `OUT/clutter.md` (success, then mean score and median path
ratio, per planner and family) and `OUT/clutter.png` (the three as annotated heatmaps), and
prints the Markdown.

    python benchmarks/clutter.py [--jobs 2] [--barn 100] [--count 10] [--out logs/clutter]
    python benchmarks/clutter.py --barn 4 --count 2 --planners vplane,vplane_plus --out /tmp/clutter
"""

from __future__ import annotations

import argparse
import statistics
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.sweep import plan_jobs, run_sweep
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir, write_atomically
from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.worlds.families import generate, trap_suite

PAPER = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
NOISY_SUFFIX = "_noisy"
COLUMNS = (
    "family",
    "planner",
    "runs",
    "success_rate",
    "collision_rate",
    "timeouts",
    "stuck",
    "mean_score",
    "median_path_ratio",
)


def write_cases(out: Path, barn: int, count: int, seed: int) -> dict[str, list[str]]:
    """Scenario files per family, written under `out/cases/`; the paper's by name."""
    cases_dir = out / "cases"
    cases_dir.mkdir(parents=True, exist_ok=True)
    families = {"paper": list(PAPER), "suite": []}
    for case in trap_suite():
        path = cases_dir / f"{case.name}.toml"
        path.write_text(case.toml(), encoding="utf-8")
        families["suite"].append(str(path))
    for family, number, family_seed in (
        ("traps", count, seed),
        ("clutter", count, seed),
        ("corridors", count, seed),
        ("barn", barn, 0),
    ):
        if number <= 0:
            continue
        cases = generate(family, number, family_seed)
        paths = []
        for case in cases:
            path = cases_dir / f"{case.name}.toml"
            path.write_text(case.toml(), encoding="utf-8")
            paths.append(str(path))
        families[family] = paths
    return families


def family_table(rows: list[dict], family_of: dict[str, str]) -> list[dict]:
    """One row per family and planner, in the order they first appear."""
    table = []
    keys = dict.fromkeys((family_of[row["scenario"]], row["planner"]) for row in rows)
    for family, planner in keys:
        mine = [r for r in rows if family_of[r["scenario"]] == family and r["planner"] == planner]
        scores = [r["score"] for r in mine if r.get("score") is not None]
        ratios = [r["path_ratio"] for r in mine if r["success"] and r.get("path_ratio")]
        table.append(
            {
                "family": family,
                "planner": planner,
                "runs": len(mine),
                "success_rate": sum(r["success"] for r in mine) / len(mine),
                "collision_rate": sum(r["collisions"] > 0 for r in mine) / len(mine),
                "timeouts": sum(r["outcome"] == "timeout" for r in mine),
                "stuck": sum(r["outcome"] == "stuck" for r in mine),
                "mean_score": statistics.fmean(scores) if scores else None,
                "median_path_ratio": statistics.median(ratios) if ratios else None,
            }
        )
    return table


def markdown(table: list[dict]) -> str:
    """Success, then mean BARN score and median path ratio, per planner (rows) and family
    (columns), each table under its caption."""
    runs = {row["family"]: row["runs"] for row in table}
    return "\n\n".join(
        [
            "Success (reached, no collision), with the share of runs that touched an obstacle when any did:",
            pivot(table, lambda family: f"{family} ({runs[family]})", success_cell),
            "Mean BARN score / median path ratio of the successes:",
            pivot(table, str, score_cell),
        ]
    )


def pivot(table: list[dict], header: Callable[[str], str], cell: Callable[[dict], str]) -> str:
    """A Markdown table of `cell(row)` per planner (rows) and family (columns, titled `header`)."""
    families = {row["family"]: header(row["family"]) for row in table}
    lines: dict[str, dict] = {}
    for row in table:
        line = lines.setdefault(row["planner"], {"planner": f"`{row['planner']}`"})
        line[families[row["family"]]] = cell(row)
    return markdown_table(list(lines.values()), ["planner", *families.values()], lambda _, v: v or "-")


def success_cell(row: dict) -> str:
    """The success rate, with the share of runs that touched an obstacle when any did."""
    success = f"{100 * row['success_rate']:.0f}%"
    return f"{success} ({100 * row['collision_rate']:.0f}% coll.)" if row["collision_rate"] else success


def score_cell(row: dict) -> str:
    """Mean BARN score / median path ratio, "-" for none."""
    keys = ("mean_score", "median_path_ratio")
    return " / ".join("-" if row[key] is None else f"{row[key]:.2f}" for key in keys)


def plot(table: list[dict], path: Path) -> None:
    """Success, mean BARN score and median path ratio per planner (rows) and family (columns)."""
    from vplane_mj.bench.report import annotated_heatmap, plt

    families = list(dict.fromkeys(row["family"] for row in table))
    planners = list(dict.fromkeys(row["planner"] for row in table))
    cells = {(row["planner"], row["family"]): row for row in table}

    def grid(key: str) -> np.ndarray:
        return np.array(
            [[_number(cells.get((p, f), {}).get(key)) for f in families] for p in planners], dtype=float
        )

    panels = (
        ("success_rate", "success (reached, no collision)", lambda v: f"{100 * v:.0f}%", 0.0, 1.0, "RdYlGn"),
        ("mean_score", "mean BARN score (0 to 0.5)", lambda v: f"{v:.2f}", 0.0, 0.5, "RdYlGn"),
        ("median_path_ratio", "median path ratio of successes", lambda v: f"{v:.2f}", 1.0, 2.5, "RdYlGn_r"),
    )
    figure, axes = plt.subplots(3, 1, figsize=(2 + 0.95 * len(families), 3 * (0.8 + 0.34 * len(planners))))
    for ax, (key, title, text, low, high, cmap) in zip(axes, panels, strict=True):
        values = grid(key)
        texts = np.array([[text(v) if np.isfinite(v) else "-" for v in row] for row in values], dtype=object)
        annotated_heatmap(ax, values, texts, planners, families, fontsize=8, vmin=low, vmax=high, cmap=cmap)
        ax.set_title(title, fontsize=10)
    figure.tight_layout()
    write_atomically(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))


def _number(value: float | None) -> float:
    return float("nan") if value is None else float(value)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planners", type=options.planners, default=",".join(sorted(PLANNERS)))
    parser.add_argument("--barn", type=options.whole(0), default=100, help="BARN-like worlds (seed 0)")
    parser.add_argument(
        "--count", type=options.whole(0), default=10, help="worlds of each other generated family"
    )
    parser.add_argument(
        "--seed", type=options.whole(0), default=1, help="seed of the traps, clutter and corridors"
    )
    parser.add_argument(
        "--noise", type=options.non_negative, default=0.03, help="sonar noise of the noisy barn runs (m)"
    )
    parser.add_argument(
        "--dropout", type=options.number(0.0, most=1.0), default=0.1, help="dropout of the noisy barn runs"
    )
    parser.add_argument("--jobs", type=options.whole(1), default=2, help="worker processes")
    parser.add_argument("--out", type=Path, default=Path("logs/clutter"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    families = write_cases(out, args.barn, args.count, args.seed)
    family_of = {}
    jobs = []
    for family, scenarios in families.items():
        mine = plan_jobs(scenarios, args.planners, [0])
        family_of.update((job.scenario, family) for job in mine)
        jobs += mine
    noisy = []
    if "barn" in families and (args.noise > 0 or args.dropout > 0):
        overrides = (f"sensors.noise_std={args.noise}", f"sensors.dropout={args.dropout}")
        noisy = [
            _renamed(job, job.scenario + NOISY_SUFFIX)
            for job in plan_jobs(families["barn"], args.planners, [0], overrides)
        ]
        for job in noisy:
            family_of[job.scenario] = "barn" + NOISY_SUFFIX
    rows = run_sweep(jobs + noisy, out, args.jobs)
    table = family_table(rows, family_of)
    text = markdown(table)
    written = write_table(out, "clutter", table, COLUMNS, text)
    plot(table, out / "clutter.png")
    print(text)
    print("\n".join(f"wrote {path}" for path in [*written, out / "clutter.png"]))
    return 0


def _renamed(job, name: str):
    """The same run under another scenario name (the name is part of the scenario text)."""
    from dataclasses import replace

    toml = job.toml.replace(f'name = "{job.scenario}"', f'name = "{name}"', 1)
    return replace(job, scenario=name, toml=toml)


if __name__ == "__main__":
    sys.exit(main())
