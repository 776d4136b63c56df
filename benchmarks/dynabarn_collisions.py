"""Where the DynaBARN benchmark's collisions come from: what touched the robot, seen or not.

Reads the journal of `benchmarks/dynabarn.py` (`OUT/bench.jsonl` and the worlds in
`OUT/cases/`), runs each run of `--planners` that had a collision again (the same world,
planner, seed and laser noise: the same trajectory, checked against the journal's digest) and
classifies its first contact from the simulator's truth, which no planner sees:

- **landed**: the obstacle nearest the robot at the first control tick after the contact
  jumped more than JUMP_M since the tick before the contact. DynaBARN's cylinders loop: at the
  end of its loop a cylinder jumps back to its first keyframe, on the square's border, and the
  robot's start is 1 m outside the border; this one landed on or against the robot without a
  single scan in between that a planner could have acted on.
- **appeared**: it jumped within APPEAR_S before the contact, a control tick in between.
- **unseen**: it stayed out of the laser's view (beyond its half angle from the robot's
  heading, or its range) at every tick of the UNSEEN_S before the contact: it came from
  behind the Jackal's 270 degree laser.
- **in view**: neither; of these, how many moved faster than the robot's top speed (the
  splines' speeds reach about 2.3 m/s, the Jackal's top is 2 m/s).

Writes the counts per planner, and the share of its runs (%) whose first collision was not a
landing, to `OUT/dynabarn_collisions.{csv,md,json}` (`--out`, else beside the journal) and
prints them.

    python benchmarks/dynabarn_collisions.py --sweep logs/dynabarn [--planners apf,vplane_plus] [--jobs 2]
"""

from __future__ import annotations

import argparse
import math
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.sweep import JOURNAL, job_choice, read_journal
from vplane_mj.bench.tables import markdown_table, write_table
from vplane_mj.errors import VPlaneError
from vplane_mj.files import prepare_out_dir
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario

JUMP_M = 1.0
"""A move between two control ticks longer than this (m) is a jump: at 20 Hz an obstacle at
2.3 m/s moves 0.12 m."""
APPEAR_S = 1.0
"""A contact this soon (s) after the obstacle's jump is one it appeared into."""
UNSEEN_S = 1.0
"""An obstacle out of the laser's view for this long (s) before the contact came unseen."""
COLUMNS = (
    "planner",
    "runs",
    "collided",
    "landed",
    "appeared",
    "unseen",
    "in_view",
    "in_view_faster_than_robot",
    "collided_not_landed_pct",
)
KINDS = ("landed", "appeared", "unseen", "in_view")


class _Contacts:
    """An observer that keeps the times (s) of the run's collision events."""

    def __init__(self) -> None:
        self.times: list[float] = []

    def on_tick(self, tick) -> None:
        pass

    def on_event(self, time_s: float, event) -> None:
        if event.kind is EventKind.COLLISION:
            self.times.append(time_s)


def classify(case: Path, planner: str, seed: int, noise: float, digest: str) -> dict:
    """The first contact of one run (a row of the journal), classified (module docstring)."""
    overrides = [f"sensors.noise_std={noise}"] if noise > 0 else []
    scenario = load_scenario(str(case), [*overrides, *job_choice(planner, seed)])
    contacts = _Contacts()
    result = run_scenario(scenario, (contacts,))
    if result.summary.trajectory_sha256 != digest:
        raise VPlaneError(
            f"{case}: {planner} seed {seed} ran another trajectory than the journal's (--noise?)"
        )
    times, places = result.times, result.obstacle_places
    after = min(int(np.searchsorted(times, contacts.times[0], side="left")), len(times) - 1)
    before = max(0, after - 1)  # the last control tick before the contact
    offset = places - result.positions[:, None, :]
    radius = np.array(
        [getattr(moving.shape.footprint()[0], "radius", 0.0) for moving in scenario.world.moving]
    )
    nearest = int(np.argmin(np.hypot(offset[after, :, 0], offset[after, :, 1]) - radius))
    tick_s = times[1] - times[0]
    steps = np.hypot(*np.diff(places[:, nearest], axis=0).T)  # steps[i]: tick i to i + 1
    if after > before and steps[before] > JUMP_M:
        return {"kind": "landed"}
    if (steps[max(0, before - round(APPEAR_S / tick_s)) : before] > JUMP_M).any():
        return {"kind": "appeared"}
    window = range(max(0, before - round(UNSEEN_S / tick_s)), before + 1)
    half_fov = math.radians(scenario.sensors.fov_deg) / 2
    bearings = [math.atan2(offset[i, nearest, 1], offset[i, nearest, 0]) - result.yaws[i] for i in window]
    reach = [math.hypot(*offset[i, nearest]) - radius[nearest] for i in window]
    seen = any(
        abs(math.remainder(b, 2 * math.pi)) <= half_fov and r <= scenario.sensors.range_max
        for b, r in zip(bearings, reach, strict=True)
    )
    if not seen:
        return {"kind": "unseen"}
    speed = steps[before - 1] / tick_s if before > 0 else 0.0
    top = robot_profile(scenario.robot.profile).limits.max_speed_mps
    return {"kind": "in_view", "faster": bool(speed > top)}


def _classify(job: tuple) -> dict:
    return classify(*job)


def row_of(planner: str, runs: int, kinds: list[dict]) -> dict:
    """A planner's row: its runs, the collided ones, and their first contacts by kind."""
    counts = {kind: sum(k["kind"] == kind for k in kinds) for kind in KINDS}
    faster = sum(k.get("faster", False) for k in kinds)
    return {
        "planner": planner,
        "runs": runs,
        "collided": len(kinds),
        **counts,
        "in_view_faster_than_robot": faster,
        "collided_not_landed_pct": round(100 * (len(kinds) - counts["landed"]) / runs, 1),
    }


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweep", type=Path, default=Path("logs/dynabarn"), help="dynabarn.py's --out")
    parser.add_argument("--planners", type=options.planners, default="apf,vplane_plus")
    parser.add_argument(
        "--noise", type=options.non_negative, default=0.01, help="the sweep's laser noise (m)"
    )
    parser.add_argument("--jobs", type=options.whole(1), default=2, help="worker processes")
    parser.add_argument("--out", type=Path, help="default: the sweep's directory")
    args = parser.parse_args(argv)
    journal = args.sweep / JOURNAL
    if not journal.is_file():
        raise VPlaneError(f"{journal}: no such journal (run benchmarks/dynabarn.py first)")
    rows = list(read_journal(journal).values())
    runs = {planner: [r for r in rows if r.get("planner") == planner] for planner in args.planners}
    if missing := [planner for planner, mine in runs.items() if not mine]:
        raise VPlaneError(f"{journal}: no runs of planner {missing[0]!r}")
    out = prepare_out_dir(args.out or args.sweep)
    collided = [
        (
            args.sweep / "cases" / f"{r['scenario']}.toml",
            planner,
            r["seed"],
            args.noise,
            r["trajectory_sha256"],
        )
        for planner, mine in runs.items()
        for r in mine
        if r["collisions"]
    ]
    with ProcessPoolExecutor(args.jobs) as pool:
        kinds = list(pool.map(_classify, collided))
    table = [
        row_of(planner, len(mine), [k for k, job in zip(kinds, collided, strict=True) if job[1] == planner])
        for planner, mine in runs.items()
    ]
    text = markdown_table(table, COLUMNS, lambda _, value: str(value))
    written = write_table(out, "dynabarn_collisions", table, COLUMNS, text)
    print(text)
    print("\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
