"""The tracker's estimates of moving obstacles against the simulator's truth, on DynaBARN worlds.

Runs a planner (`--planner`, default vplane_plus) on `--count` worlds generated as
`vplane-mj generate dynabarn` does (seed `--world-seed`, the thirds as in the benchmark of
benchmarks/dynabarn.py) for each seed of `--seeds`, with laser noise `--noise` (m), and at every
control tick compares the tracks the planner was handed (`Tick.tracks`) with the moving
obstacles where the simulator had them. An obstacle counts as seen in a scan when at least
`--beams` of the laser's echoes lie on its surface (within 3 cm, plus the noise, of its true
circle); it is scored at the ticks it has been seen in every scan for `--seen` seconds and
lies within `--within` metres of the robot. There, the track nearest its true centre (within
1 m) is its estimate: position error (m), velocity error (m/s, against the motion's
derivative), and whether that track is marked moving. Obstacles scored with no track within
1 m count as missed.

Prints per third and over all: the scored obstacle-ticks, the share found (a track within
1 m), the share found moving, and the median and 90th percentile of the position and velocity
errors; writes `OUT/tracker_accuracy.csv` and `.md`.

    python benchmarks/tracker_accuracy.py [--count 60] [--seeds 0] [--jobs 2] [--out DIR]
"""

from __future__ import annotations

import argparse
import math
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.scenario import parse_document
from vplane_mj.sim.loop import Run, Tick
from vplane_mj.sim.sensors import scan_bearings
from vplane_mj.worlds.dynabarn_generate import generate_dynabarn
from vplane_mj.worlds.dynabarn_layout import DIFFICULTIES

SURFACE_M = 0.03
"""An echo lies on an obstacle when its distance from the true circle is at most this plus the
laser's noise (three standard deviations of it)."""
MATCH_M = 1.0
"""The nearest track within this distance (m) of an obstacle's true centre is its estimate."""
COLUMNS = (
    "third",
    "obstacle_ticks",
    "found",
    "found_moving",
    "position_error_median_m",
    "position_error_p90_m",
    "velocity_error_median_mps",
    "velocity_error_p90_mps",
)


class Scorer:
    """An observer of one run that scores the tracks at every tick (module docstring)."""

    def __init__(self, scenario, beams: int, seen_s: float, within_m: float, noise_m: float):
        self.moving = scenario.world.moving
        self.bearings = scan_bearings(scenario)
        self.beams, self.seen_s, self.within_m = beams, seen_s, within_m
        self.surface_m = SURFACE_M + 3 * noise_m
        self.seen_since: dict[int, float] = {}
        self.rows: list[tuple[float, float, bool]] = []  # position error, velocity error, moving
        self.missed = 0

    def on_event(self, time_s: float, event) -> None:
        pass

    def on_tick(self, tick: Tick) -> None:
        if tick.obstacles is None or tick.decision.mode == "finished":
            return
        angles = tick.yaw + self.bearings
        echoes = tick.position + tick.ranges[:, None] * np.column_stack((np.cos(angles), np.sin(angles)))
        echoes = echoes[np.isfinite(tick.ranges)]
        for k, (centre, obstacle) in enumerate(zip(tick.obstacles, self.moving, strict=True)):
            radius = obstacle.shape.footprint()[0].radius
            on_it = np.abs(np.hypot(*(echoes - centre).T) - radius) <= self.surface_m
            if np.count_nonzero(on_it) < self.beams:
                self.seen_since.pop(k, None)
                continue
            since = self.seen_since.setdefault(k, tick.time_s)
            if tick.time_s - since < self.seen_s - 1e-9 or math.dist(centre, tick.position) > self.within_m:
                continue
            self._score(tick, centre, obstacle.motion.velocity(tick.time_s))

    def _score(self, tick: Tick, centre: np.ndarray, velocity: np.ndarray) -> None:
        found = [(math.dist(track.predicted(tick.time_s), centre), track) for track in tick.tracks]
        error, track = min(found, key=lambda pair: pair[0], default=(math.inf, None))
        if track is None or error > MATCH_M:
            self.missed += 1
            return
        self.rows.append((error, math.dist(track.velocity, velocity), track.moving))


def score_run(job: tuple[dict, str, int, str, int, float, float, float]) -> tuple[str, list, int]:
    """One run scored: (its world's third, the (position error, velocity error, moving) rows,
    the missed obstacle-ticks)."""
    document, third, seed, planner, beams, seen_s, within_m, noise = job
    overrides = [f"run.seed={seed}", f"planner.name={planner}", f"sensors.noise_std={noise}"]
    scenario = parse_document(document, f"{document['name']}.toml", overrides)
    scorer = Scorer(scenario, beams, seen_s, within_m, noise)
    Run(scenario, (scorer,)).run()
    return third, scorer.rows, scorer.missed


def table_row(third: str, rows: list, missed: int) -> dict:
    """The table's row of one third (or all) from its scored rows and missed count."""
    count = len(rows) + missed
    errors = np.array([row[:2] for row in rows]).reshape(-1, 2)

    def stat(column: int, q: float) -> float | None:
        return float(np.percentile(errors[:, column], q)) if len(errors) else None

    return {
        "third": third,
        "obstacle_ticks": count,
        "found": len(rows) / count if count else None,
        "found_moving": sum(row[2] for row in rows) / count if count else None,
        "position_error_median_m": stat(0, 50),
        "position_error_p90_m": stat(0, 90),
        "velocity_error_median_mps": stat(1, 50),
        "velocity_error_p90_mps": stat(1, 90),
    }


def markdown(table: list[dict]) -> str:
    def cell(key: str, value) -> str:
        if value is None:
            return "-"
        if key.startswith("found"):
            return f"{100 * value:.1f}%"
        return f"{value:.3f}" if isinstance(value, float) else str(value)

    return markdown_table(table, COLUMNS, cell)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planner", type=options.planner, default="vplane_plus")
    options.add_world_sweep(parser, (60, "worlds, split into the three thirds"), "0", "tracker_accuracy")
    parser.add_argument(
        "--beams", type=options.whole(1), default=3, help="echoes on an obstacle for it to count as seen"
    )
    parser.add_argument(
        "--seen",
        type=options.non_negative,
        default=0.5,
        help="seconds an obstacle is seen before it is scored",
    )
    parser.add_argument(
        "--within", type=options.positive, default=5.0, help="scored only this near the robot (m)"
    )
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    cases = generate_dynabarn(args.count, args.world_seed)
    jobs = [
        (case.document, third, seed, args.planner, args.beams, args.seen, args.within, args.noise)
        for case in cases
        for third in DIFFICULTIES
        if f"_{third}_" in case.name
        for seed in args.seeds
    ]
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(score_run, jobs))
    table = [
        table_row(
            third,
            [row for t, rows, _ in results if third in (t, "all") for row in rows],
            sum(missed for t, _, missed in results if third in (t, "all")),
        )
        for third in (*DIFFICULTIES, "all")
    ]
    text = markdown(table)
    written = write_table(out, "tracker_accuracy", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
