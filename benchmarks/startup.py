"""Whole `vplane-mj run` processes against their simulation loop: what starting up costs.

For each scenario, `vplane-mj run SCENARIO --no-render --no-log` runs as a new process,
several times; reported are the process's wall time (from launch to exit), the loop's
wall time (the summary's `wall_time_s`) and their ratio, medians over the repeats. The
first run of each scenario fills the reference-path cache and is not counted.

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
    return wall, summary.wall_time_s


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
    return 0


if __name__ == "__main__":
    sys.exit(main())
