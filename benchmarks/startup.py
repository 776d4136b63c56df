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

    python benchmarks/startup.py [SCENARIO ...] [--repeat 5]
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

DEFAULT_SCENARIOS = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")


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


def job_table(scenario: str, repeat: int, out: Path) -> None:
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
    print(f"\n| `vplane-mj run {scenario}` | process wall s |\n|---|---:|")
    for name in variants:
        print(f"| {name} | {statistics.median(walls[name]):.3f} |")


def command_table(scenario: str, repeat: int) -> None:
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
    floor = statistics.median(walls["python -c 'import numpy'"])
    print("\n| command | process wall s | / python with numpy |\n|---|---:|---:|")
    for name in commands:
        wall = statistics.median(walls[name])
        print(f"| `{name}` | {wall:.3f} | {wall / floor:.2f} |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", default=list(DEFAULT_SCENARIOS))
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    print("| scenario | process wall s | loop wall s | process / loop |\n|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        for scenario in args.scenarios:
            one_run(scenario, out)  # fills the reference-path cache
            walls, loops = zip(*(one_run(scenario, out) for _ in range(args.repeat)), strict=True)
            wall, loop = statistics.median(walls), statistics.median(loops)
            print(f"| {scenario} | {wall:.3f} | {loop:.3f} | {wall / loop:.2f} |")
            sys.stdout.flush()
        job_table(args.scenarios[0], args.repeat, out)
    command_table(args.scenarios[0], args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
