"""The Jackal's footprint checks of one `dwa` tick: the numba kernel against plain numpy.

A BARN protocol world (`generate barn --protocol`, `--seed`) is drawn into a `dwa` planner's
map built for the Jackal (0.1 m cells: every cell whose centre lies within a cylinder's radius
plus half a cell of its centre), and the Jackal stands at `--points` random free poses in the
obstacle field. At each, the planner computes dist(v, omega) for the window of a robot at
1 m/s (the 7 x 31 arcs and, since the window holds v = 0 from rest, the turns on the spot),
and every set of poses it hands `footprint_clearance` is kept. The same poses are then
measured `--repeat` times by the kernel and by a vectorised numpy version of the same
computation (every occupied cell within the circumscribed radius plus the cap of a pose, by
a distance matrix in chunks of poses, then the signed distance to the polygon of those
pairs). The time is the process's CPU time; reported per tick (ms, median over the points)
for both, their ratio, and the largest difference between their results, as a table row.

The table is written to `OUT/footprint_clearance.csv`, `.md` and `.json` (with the command and
the date).

    python benchmarks/footprint_clearance.py [--points 20] [--repeat 5] [--seed 7] [--out DIR]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.kernels.motion.footprint_clearance import footprint_clearance
from vplane_mj.planning.planners.dwa import DwaPlanner
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import parse_scenario
from vplane_mj.worlds.barn_protocol import generate_protocol

CHUNK = 2048
"""Poses per distance matrix in the numpy version (a chunk's matrix: CHUNK x occupied cells)."""
CELLS = {
    "poses a tick": ".0f",
    "numba kernel (ms)": ".2f",
    "numpy (ms)": ".2f",
    "ratio": ".0f",
    "largest difference (m)": ".1e",
}
"""The table's columns (medians over the points) and how each is written."""


def numpy_clearance(occupied, first_cell, cell_m, footprint, poses, cap_m, points=None):
    """`footprint_clearance` in plain numpy: the pairs of poses and obstacles (occupied cells'
    centres, points on the grid) within reach."""
    radius = float(np.max(np.hypot(footprint[:, 0], footprint[:, 1])))
    i, j = np.nonzero(occupied)
    centres = (np.column_stack((i, j)) + first_cell + 0.5) * cell_m
    if points is not None:
        cells = np.floor(points / cell_m) - first_cell
        on_grid = np.all((cells >= 0) & (cells < occupied.shape), axis=1)
        centres = np.vstack((centres, points[on_grid]))
    result = np.full(len(poses), cap_m)
    start, edge = footprint[None], (np.roll(footprint, -1, axis=0) - footprint)[None]
    for first in range(0, len(poses), CHUNK):
        chunk = poses[first : first + CHUNK]
        rel = centres[None, :, :] - chunk[:, None, :2]
        near_pose, near_cell = np.nonzero(np.hypot(rel[..., 0], rel[..., 1]) < radius + cap_m)
        if not len(near_pose):
            continue
        c, s = np.cos(chunk[near_pose, 2]), np.sin(chunk[near_pose, 2])
        dx, dy = rel[near_pose, near_cell, 0], rel[near_pose, near_cell, 1]
        body = np.column_stack((c * dx + s * dy, -s * dx + c * dy))[:, None, :] - start
        t = np.clip((body * edge).sum(-1) / (edge * edge).sum(-1), 0.0, 1.0)
        gap = np.hypot(*np.moveaxis(body - t[..., None] * edge, -1, 0)).min(axis=1)
        outside = (edge[..., 0] * body[..., 1] - edge[..., 1] * body[..., 0] < 0).any(axis=1)
        np.minimum.at(result, first + near_pose, np.where(outside, gap, -gap))
    return result


def recorded_checks(seed: int, points: int) -> list[list[tuple]]:
    """Per point, the arguments of every `footprint_clearance` call of one dwa tick."""
    case = generate_protocol(1, seed)[0]
    scenario = parse_scenario(case.toml(), f"{case.name}.toml", [])
    centres = np.array([obstacle.center for obstacle in scenario.world.obstacles])
    rng = np.random.default_rng(seed)
    body = robot_body("jackal")
    ticks: list[list[tuple]] = []
    while len(ticks) < points:
        x, y, yaw = rng.uniform(0.4, 3.8), rng.uniform(5.0, 9.5), rng.uniform(-np.pi, np.pi)
        if np.min(np.hypot(*(centres - (x, y)).T)) < body.radius_m + 0.2:
            continue
        planner = DwaPlanner.build({}, body)
        empty = np.full(16, np.nan)
        obs = Observation(0.0, np.array([x, y]), yaw, np.array([2.1, 12.85]), 1.0, np.zeros(16), empty, 0.1)
        planner.step(obs)
        cell, origin = planner.map.cell_m, planner.map.origin
        rows = (origin[0] + np.arange(planner.map.n) + 0.5) * cell
        cols = (origin[1] + np.arange(planner.map.n) + 0.5) * cell
        grid_x, grid_y = np.meshgrid(rows, cols, indexing="ij")
        for cx, cy in centres:
            inside = np.hypot(grid_x - cx, grid_y - cy) <= 0.075 + cell / 2
            planner.map.grid[inside] = planner.map.max_certainty
        calls: list[tuple] = []

        def record(*args, calls=calls):
            calls.append(args)
            return footprint_clearance(*args)

        planner.footprint_clearance = record
        speeds = np.linspace(0.9, 1.1, 7)
        speeds[0] = 0.0  # the window of a robot that may still stop: turns on the spot too
        planner.free_distance(obs, speeds, np.linspace(-1.0, 1.0, 31))
        ticks.append(calls)
    return ticks


def cpu_ms_per_tick(measure, calls: list[tuple], repeat: int) -> float:
    started = time.process_time()
    for _ in range(repeat):
        for args in calls:
            measure(*args)
    return (time.process_time() - started) / repeat * 1e3


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=options.whole(1), default=20)
    parser.add_argument("--repeat", type=options.whole(1), default=5)
    parser.add_argument("--seed", type=options.whole(0), default=7)
    parser.add_argument("--out", type=Path, default=Path("logs/footprint_clearance"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    ticks = recorded_checks(args.seed, args.points)
    kernel, plain, worst, poses = [], [], 0.0, []
    for calls in ticks:
        kernel.append(cpu_ms_per_tick(footprint_clearance, calls, args.repeat))
        plain.append(cpu_ms_per_tick(numpy_clearance, calls, args.repeat))
        for call in calls:
            worst = max(worst, float(np.max(np.abs(footprint_clearance(*call) - numpy_clearance(*call)))))
        poses.append(sum(len(call[4]) for call in calls))
    fast, slow = statistics.median(kernel), statistics.median(plain)
    cells = (statistics.median(poses), fast, slow, slow / fast, worst)
    table = [dict(zip(CELLS, cells, strict=True))]
    text = markdown_table(table, list(CELLS), formatted(CELLS))
    print(f"The Jackal at {len(ticks)} points of barn_protocol_{args.seed}_000 (CPU ms per dwa tick):\n")
    print(text)
    print(
        "\n".join(
            f"wrote {path}" for path in write_table(out, "footprint_clearance", table, list(CELLS), text)
        )
    )

    return 0


if __name__ == "__main__":
    sys.exit(main())
