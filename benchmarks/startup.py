"""Whole `vplane-mj run` processes against their simulation loop: what starting up costs.

For each scenario, `vplane-mj run SCENARIO --no-render --no-log` runs as a new process,
several times; reported are the process's wall time (from launch to exit), the loop's
wall time (the summary's `wall_time_s`) and their ratio, medians over the repeats. The
first run of each scenario fills the reference-path cache and is not counted.

Then the main job, `vplane-mj run SCENARIO` of the first scenario as the set-up runs it
(with its MCAP log and its render), against the same run without the render and without
either: what the log and the render add to a run's wall time.

Last, the commands that simulate nothing, `vplane-mj check` of the first scenario and
`vplane-mj list`, against the floor every command pays: Python starting and importing
numpy. Their processes alternate with the floor's, so a busy machine slows all alike.

Each table is printed and written to `OUT/startup.md`, `startup_job.md` and
`startup_commands.md`, with their `.csv` and `.json` (the command and the date).

    python benchmarks/startup.py [SCENARIO ...] [--repeat 5] [--out logs/startup]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir

DEFAULT_SCENARIOS = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
FORMATS = {
    "process wall s": ".3f",
    "loop wall s": ".3f",
    "process / loop": ".2f",
    "/ python with numpy": ".2f",
}
"""The tables' cells: seconds to the millisecond, ratios to the hundredth."""


def one_run(scenario: str, out: Path) -> tuple[float, float]:
    """(process wall time, loop wall time) of one `vplane-mj run`, in seconds."""
    command = [
        sys.executable,
        "-m",
        "vplane_mj",
        "run",
        scenario,
        "--no-render",
        "--no-log",
        "--out",
        str(out),
    ]
    start = time.perf_counter()
    subprocess.run(command, check=False, capture_output=True)
    wall = time.perf_counter() - start
    summary = json.loads(next(out.glob("*.json")).read_text())
    for path in out.glob("*.json"):
        path.unlink()
    return wall, summary["wall_time_s"]


def process_wall(arguments: list[str]) -> float:
    """Wall time (s) of one `python ARGUMENTS` process, from launch to exit."""
    start = time.perf_counter()
    subprocess.run([sys.executable, *arguments], check=True, capture_output=True)
    return time.perf_counter() - start


def scenario_table(scenarios: list[str], repeat: int, out: Path) -> list[dict]:
    """Per scenario, medians over `repeat` runs: the process's wall time, the loop's and their ratio."""
    table = []
    for scenario in scenarios:
        one_run(scenario, out)  # fills the reference-path cache
        walls, loops = zip(*(one_run(scenario, out) for _ in range(repeat)), strict=True)
        wall, loop = statistics.median(walls), statistics.median(loops)
        table.append(
            {"scenario": scenario, "process wall s": wall, "loop wall s": loop, "process / loop": wall / loop}
        )
    return table


def job_table(scenario: str, repeat: int, out: Path) -> list[dict]:
    """`vplane-mj run` with its log and render, without the render, without either; medians
    over `repeat` alternations."""
    variants = {
        "log and render": [],
        "log, --no-render": ["--no-render"],
        "--no-render --no-log": ["--no-render", "--no-log"],
    }
    walls: dict[str, list[float]] = {name: [] for name in variants}
    for _ in range(repeat):
        for name, flags in variants.items():
            walls[name].append(process_wall(["-m", "vplane_mj", "run", scenario, *flags, "--out", str(out)]))
    title = f"`vplane-mj run {scenario}`"
    return [{title: name, "process wall s": statistics.median(walls[name])} for name in variants]


def command_table(scenario: str, repeat: int) -> list[dict]:
    """check and list processes against Python with numpy, medians over `repeat` alternations."""
    commands = {
        "python -c 'import numpy'": ["-c", "import numpy"],
        f"vplane-mj check {scenario}": ["-m", "vplane_mj", "check", scenario],
        "vplane-mj list": ["-m", "vplane_mj", "list"],
    }
    walls: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(repeat):
        for name, arguments in commands.items():
            walls[name].append(process_wall(arguments))
    median = {name: statistics.median(times) for name, times in walls.items()}
    floor = median["python -c 'import numpy'"]
    return [
        {"command": f"`{name}`", "process wall s": wall, "/ python with numpy": wall / floor}
        for name, wall in median.items()
    ]


def publish(out: Path, stem: str, table: list[dict]) -> list[Path]:
    """`table` printed and written as `stem` into `out`."""
    columns = list(table[0])
    text = markdown_table(table, columns, formatted(FORMATS))
    print(f"\n{text}")
    return write_table(out, stem, table, columns, text)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=options.scenario, default=list(DEFAULT_SCENARIOS))
    parser.add_argument("--repeat", type=options.whole(1), default=5)
    parser.add_argument("--out", type=Path, default=Path("logs/startup"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    with tempfile.TemporaryDirectory() as tmp:
        runs = Path(tmp)
        written = publish(out, "startup", scenario_table(args.scenarios, args.repeat, runs))
        written += publish(out, "startup_job", job_table(args.scenarios[0], args.repeat, runs))
    written += publish(out, "startup_commands", command_table(args.scenarios[0], args.repeat))
    print("\n" + "\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
