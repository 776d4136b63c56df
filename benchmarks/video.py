"""Cost of `vplane-mj video`, measured side by side with the logged run it replays.

For each scenario: one logged run (`vplane-mj run`'s simulation and MCAP log, no render)
takes T_run wall seconds; the MP4 at real time (25 fps) and the GIF at 2x (10 fps) made
from that log take T_mp4 and T_gif. Reported: the frames, the encoding's wall time per
simulated second and its ratio to T_run (the medians of `--repeat` measurements), and the
file sizes.

The table is written to `OUT/video.csv`, `.md` and `.json` (with the command and the date).

    python benchmarks/video.py [SCENARIO ...] [--planner vplane] [--repeat 3] [--out logs/video]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.logs.reader import read_log
from vplane_mj.logs.writer import McapLog
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.sensors import scan_bearings
from vplane_mj.viz.video import FORMATS, frame_count, write_video

DEFAULT_SCENARIOS = ("paper_c_escape", "paper_h_escape")
MP4_SPEED, GIF_SPEED = 1.0, 2.0
CELLS = {
    "scenario": "",
    "simulated s": ".1f",
    "MP4 frames": "d",
    "MP4: wall s per simulated s": ".2f",
    "MP4 / run": ".1f",
    "MP4 kB": ".0f",
    "GIF frames (2x)": "d",
    "GIF / run": ".1f",
    "GIF kB": ".0f",
}
"""The table's columns and how each is written."""


def logged_run(scenario, path: Path) -> float:
    """Wall seconds of one run writing its MCAP log to `path`."""
    started = time.perf_counter()
    bearings = scan_bearings(scenario)
    log = McapLog(path, scenario, bearings, {})
    result = run_scenario(scenario, observers=(log,))
    log.close(result.summary.to_dict())
    return time.perf_counter() - started


def encoding(log: Path, target: Path, speed: float) -> float:
    """Wall seconds of one `write_video`."""
    started = time.perf_counter()
    write_video(log, target, speed, show_progress=False)
    return time.perf_counter() - started


def measure(name: str, planner: str, repeat: int, work: Path) -> dict:
    scenario = load_scenario(name, [f"planner.name={planner}"])
    log, mp4, gif = work / f"{name}.mcap", work / f"{name}.mp4", work / f"{name}.gif"
    times = {"run": [], "mp4": [], "gif": []}
    for _ in range(repeat):
        times["run"].append(logged_run(scenario, log))
        times["mp4"].append(encoding(log, mp4, MP4_SPEED))
        times["gif"].append(encoding(log, gif, GIF_SPEED))
    median = {key: statistics.median(values) for key, values in times.items()}
    simulated = read_log(log).times_ns[-1] / 1e9
    return {
        "scenario": name,
        "simulated_s": simulated,
        "run_s": median["run"],
        "mp4_frames": sum(frame_count(simulated, MP4_SPEED, FORMATS[".mp4"].fps)),
        "mp4_s": median["mp4"],
        "mp4_kb": mp4.stat().st_size / 1000,
        "gif_frames": sum(frame_count(simulated, GIF_SPEED, FORMATS[".gif"].fps)),
        "gif_s": median["gif"],
        "gif_kb": gif.stat().st_size / 1000,
    }


def table_row(r: dict) -> dict:
    """A measurement as the table's row: per simulated second and over the run's time."""
    return {
        "scenario": r["scenario"],
        "simulated s": r["simulated_s"],
        "MP4 frames": r["mp4_frames"],
        "MP4: wall s per simulated s": r["mp4_s"] / r["simulated_s"],
        "MP4 / run": r["mp4_s"] / r["run_s"],
        "MP4 kB": r["mp4_kb"],
        "GIF frames (2x)": r["gif_frames"],
        "GIF / run": r["gif_s"] / r["run_s"],
        "GIF kB": r["gif_kb"],
    }


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=options.scenario, default=list(DEFAULT_SCENARIOS))
    parser.add_argument("--planner", type=options.planner, default="vplane")
    parser.add_argument("--repeat", type=options.whole(1), default=3)
    parser.add_argument("--out", type=Path, default=Path("logs/video"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    with tempfile.TemporaryDirectory() as work:
        table = [table_row(measure(name, args.planner, args.repeat, Path(work))) for name in args.scenarios]
    text = markdown_table(table, list(CELLS), formatted(CELLS))
    print(text)
    print("\n".join(f"wrote {path}" for path in write_table(out, "video", table, list(CELLS), text)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
