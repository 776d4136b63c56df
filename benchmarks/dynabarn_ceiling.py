"""How far perfect tracks would take a planner's collisions on generated DynaBARN worlds.

A planner sees moving obstacles through its tracker: from the laser's scans, late when one
comes into view, with errors while its velocity settles, and never behind another. To tell
what that costs from what a reactive planner can do at all, this runs a planner (default
`apf`, the benchmark's best) with the Jackal and its laser on `vplane-mj generate dynabarn`
worlds each way of `--modes`. In all but `tracker`, the tracks the planner is handed at every
scan are the simulator's, exact (true position, velocity and radius), and one that is no
longer handed over coasts at its last velocity for the tracker's `coast_s`, as a track does:

- `tracker`: as every run goes (the DynaBARN benchmark's runs);
- `seen`: the obstacles the scan shows, at least `--echoes` echoes on their surface (a perfect
  tracker of what the laser sees);
- `seen_late`: as `seen`, each handed over once the scans have shown it for `--latency` s;
- `in_view`: every obstacle whose centre lies within the laser's field of view and range,
  hidden behind another or not.

The rest is the planner's own: its maps, the evasion, and the echoes it takes as moving (the
tracker runs in every mode, for them). No planner reads the simulator: like pose_ceiling.py for
the estimated pose, this measures a bound. Prints per mode the runs, the collisions and their
share, the successes and their mean time, into `OUT/dynabarn_ceiling.{csv,md,json}`.

Usage:
    python benchmarks/dynabarn_ceiling.py [--count 60] [--seeds 0-4] [--modes tracker,seen,in_view]
    python benchmarks/dynabarn_ceiling.py --count 3 --seeds 0 --out /tmp/ceiling
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.planning.perception.tracker import Track, Tracker, TrackerParams
from vplane_mj.scenario import Scenario
from vplane_mj.scenario.parse import parse_document
from vplane_mj.sim.loop import Run
from vplane_mj.worlds.dynabarn_generate import generate_dynabarn

MODES = ("tracker", "seen", "seen_late", "in_view")
COLUMNS = ("mode", "runs", "collisions", "collision_rate", "successes", "success_rate", "mean_time_s")
SURFACE_M = 0.03
"""An echo lies on an obstacle when its distance from the true circle is at most this plus three
standard deviations of the laser's noise."""


@dataclass(frozen=True)
class Handover:
    """Which obstacles `TrueTracks` hands over: those the scan shows (`echoes` on their surface,
    0: every one in the laser's view, hidden or not), once shown for `latency_s` (s)."""

    echoes: int
    latency_s: float = 0.0


class TrueTracks:
    """Stands in for a run's tracker: folds each scan into it (its moving echoes stay the
    planner's) and hands out the simulator's tracks instead of its own (module docstring)."""

    def __init__(self, tracker: Tracker, scenario: Scenario, handover: Handover):
        self.tracker = tracker
        self.obstacles = scenario.world.moving
        self.radii = [obstacle.shape.footprint()[0].radius for obstacle in self.obstacles]
        self.half_view = math.radians(scenario.sensors.fov_deg) / 2
        self.range_m = scenario.sensors.range_max
        self.surface_m = SURFACE_M + 3 * scenario.sensors.noise_std
        self.handover = handover
        self.coast_s = TrackerParams().coast_s
        self.shown_since: dict[int, float] = {}
        self.last_seen: dict[int, Track] = {}

    @property
    def moving_beams(self) -> np.ndarray:
        """The tracker's beams whose echoes it takes as moving."""
        return self.tracker.moving_beams

    def update(
        self, time_s: float, xy: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray
    ) -> tuple[Track, ...]:
        """The true tracks at `time_s` (s) for a robot at `xy` (m) facing `yaw` (rad), after the
        tracker took the scan (`bearings`, `ranges`; m)."""
        self.tracker.update(time_s, xy, yaw, bearings, ranges)
        echoes = _echoes(xy, yaw, bearings, ranges) if self.handover.echoes else np.empty((0, 2))
        for k, obstacle in enumerate(self.obstacles):
            centre = obstacle.motion.position(time_s)
            if not self._shown(centre, self.radii[k], xy, yaw, echoes):
                self.shown_since.pop(k, None)
                continue
            since = self.shown_since.setdefault(k, time_s)
            if time_s - since >= self.handover.latency_s - 1e-9:
                velocity, radius = obstacle.motion.velocity(time_s), self.radii[k]
                self.last_seen[k] = Track(
                    k + 1, centre, velocity, radius, 0.0, 0.0, since, time_s, True, time_s
                )
        return tuple(
            track if track.stamp_s == time_s else _coasted(track, time_s)
            for track in self.last_seen.values()
            if time_s - track.last_seen_s <= self.coast_s
        )

    def _shown(
        self, centre: np.ndarray, radius: float, xy: np.ndarray, yaw: float, echoes: np.ndarray
    ) -> bool:
        """Whether the disc at `centre` (m) of `radius` (m) is handed over: with `echoes` (N, 2;
        m) of the scan on its surface, or without any, within the laser's field of view and
        range from `xy` (m) facing `yaw` (rad)."""
        if self.handover.echoes:
            on_it = np.abs(np.hypot(*(echoes - centre).T) - radius) <= self.surface_m
            return bool(np.count_nonzero(on_it) >= self.handover.echoes)
        offset = centre - xy
        bearing = math.remainder(math.atan2(offset[1], offset[0]) - yaw, math.tau)
        return abs(bearing) <= self.half_view and math.hypot(offset[0], offset[1]) <= self.range_m


def _echoes(xy: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray) -> np.ndarray:
    """The scan's echoes (N, 2; m) of a robot at `xy` (m) facing `yaw` (rad): beams without one
    left out."""
    hit = np.isfinite(ranges)
    angles = yaw + bearings[hit]
    return xy + ranges[hit, None] * np.column_stack((np.cos(angles), np.sin(angles)))


def _coasted(track: Track, time_s: float) -> Track:
    """`track` carried on at its velocity to `time_s` (s)."""
    return Track(
        track.track_id, track.predicted(time_s), track.velocity, track.radius_m, 0.0, 0.0,
        track.first_seen_s, track.last_seen_s, True, time_s,
    )  # fmt: skip


def run_one(job: tuple[dict, int, str, str, float, Handover | None]) -> tuple[str, bool, bool, float | None]:
    """One run: (its mode, whether it collided, whether it succeeded, its time in s)."""
    document, seed, mode, planner, noise, handover = job
    overrides = [f"run.seed={seed}", f"planner.name={planner}", f"sensors.noise_std={noise}"]
    scenario = parse_document(document, f"{document['name']}.toml", overrides)
    run = Run(scenario, ())
    if handover is not None and run.tracker is not None:
        run.tracker = TrueTracks(run.tracker, scenario, handover)
    summary = run.run().summary
    return mode, summary.collisions > 0, summary.success, summary.time_to_goal_s


def table_row(mode: str, results: list[tuple[str, bool, bool, float | None]]) -> dict:
    """The table's row of one mode."""
    mine = [result for result in results if result[0] == mode]
    collided = sum(result[1] for result in mine)
    times = [result[3] for result in mine if result[2]]
    return {
        "mode": mode,
        "runs": len(mine),
        "collisions": collided,
        "collision_rate": collided / len(mine),
        "successes": len(times),
        "success_rate": len(times) / len(mine),
        "mean_time_s": statistics.fmean(times) if times else None,
    }


def cell(column: str, value) -> str:
    """A table cell: rates as percentages, times to one decimal."""
    if value is None:
        return "-"
    if column.endswith("_rate"):
        return f"{100 * value:.1f}%"
    return f"{value:.1f}" if isinstance(value, float) else f"`{value}`" if column == "mode" else str(value)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planner", type=options.planner, default="apf")
    parser.add_argument("--modes", type=options.names(MODES, "mode"), default=",".join(MODES))
    parser.add_argument("--echoes", type=options.whole(1), default=3, help="echoes that show an obstacle")
    parser.add_argument(
        "--latency", type=options.positive, default=0.1, help="seconds shown before seen_late hands over"
    )
    options.add_world_sweep(parser, (60, "worlds, split into the three thirds"), "0-4", "dynabarn_ceiling")
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    handovers = {
        "tracker": None,
        "seen": Handover(args.echoes),
        "seen_late": Handover(args.echoes, args.latency),
        "in_view": Handover(0),
    }
    cases = generate_dynabarn(args.count, args.world_seed)
    jobs = [
        (case.document, seed, mode, args.planner, args.noise, handovers[mode])
        for mode in args.modes
        for case in cases
        for seed in args.seeds
    ]
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(run_one, jobs))
    table = [table_row(mode, results) for mode in args.modes]
    text = markdown_table(table, COLUMNS, cell)
    written = write_table(out, "dynabarn_ceiling", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
