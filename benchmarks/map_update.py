"""Cost of one local-map update, per sensor layout and per planner's map.

The scene is BARN-like: a 4.2 m wide corridor along y (walls at x = 0 and 4.2 m, closed 30 m
ahead and 10 m behind the start) crossed by a field of posts of 0.075 m radius on the 0.15 m
cells of a BARN cellular automaton (`families.barn_cells`, the first seed from `--seed` whose
field the robot can cross). The robot drives from 3.5 m before the field along a shortest way
through its free cells, one pose every 3 cm (`--poses` of them at most). Each sensor of
`synthetic.LAYOUTS` (the 16-sonar ring, the Pioneer 3-DX's uneven sonars, the TurtleBot3's
360-beam and the Jackal's 720-beam, 270 degree laser) scans the scene from every pose by exact
ray casts (not timed), and the map of `vplane_plus`, `vplane` and `dwa`, each as its planner
builds it, folds the scans in, one after another from empty. The time is the process's CPU
time; reported is the median over `--repeat` rounds of the mean per update (ms), the rounds of
all maps and layouts in turn. Before the table, the CPU time of the process's first update
that walks its cones (importing numba and loading, or compiling, its kernel).

The table is written to `OUT/map_update.csv`, `.md` and `.json` (with the command and the date).

    python benchmarks/map_update.py [--repeat 5] [--poses 300] [--seed 0] [--out logs/map_update]
"""

from __future__ import annotations

import argparse
import itertools
import math
import statistics
import sys
import time
from collections import deque
from pathlib import Path

import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import LAYOUTS
from vplane_mj.planning.perception.localmap import LocalMap
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.worlds.families import BARN_CELL_M, BARN_COLUMNS, BARN_FIELD_Y_M, barn_cells

MAPS = ("vplane_plus", "vplane", "dwa")
POST_RADIUS_M = 0.075
STEP_M = 0.03
"""Distance (m) between successive poses."""
LEAD_IN_M = 3.5
"""The drive starts this far before the field (m)."""
CORRIDOR_AHEAD_M, CORRIDOR_BEHIND_M = 30.0, 10.0
"""Where the corridor's end walls stand, from the start (m)."""


def field(seed: int) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The first BARN field from `seed` on whose free cells a way crosses it, and that way."""
    while True:
        cells = barn_cells(np.random.default_rng(seed))
        way = crossing(cells)
        if way:
            return cells, way
        seed += 1


def crossing(cells: np.ndarray) -> list[tuple[int, int]]:
    """A shortest 4-connected way of free cells (row, column) from the first row to the last."""
    rows, cols = cells.shape
    before: dict[tuple[int, int], tuple[int, int] | None] = {}
    queue: deque[tuple[int, int]] = deque()
    for col in range(cols):
        if not cells[0, col]:
            before[(0, col)] = None
            queue.append((0, col))
    while queue:
        row, col = queue.popleft()
        if row == rows - 1:
            way = [(row, col)]
            while (previous := before[way[-1]]) is not None:
                way.append(previous)
            return way[::-1]
        for step in ((1, 0), (0, 1), (0, -1), (-1, 0)):
            nxt = (row + step[0], col + step[1])
            if 0 <= nxt[0] < rows and 0 <= nxt[1] < cols and not cells[nxt] and nxt not in before:
                before[nxt] = (row, col)
                queue.append(nxt)
    return []


def scene(seed: int, poses: int) -> tuple[shapes.Footprints, list[tuple[np.ndarray, float]]]:
    """The corridor with its posts, and the robot's poses (position m, yaw rad) through it."""
    cells, way = field(seed)
    width = BARN_COLUMNS * BARN_CELL_M
    rows, cols = np.nonzero(cells)
    pieces: list[shapes.Piece] = [
        shapes.Disc(((c + 0.5) * BARN_CELL_M, BARN_FIELD_Y_M + (r + 0.5) * BARN_CELL_M), POST_RADIUS_M)
        for r, c in zip(rows.tolist(), cols.tolist(), strict=True)
    ]
    points = [((c + 0.5) * BARN_CELL_M, BARN_FIELD_Y_M + (r + 0.5) * BARN_CELL_M) for r, c in way]
    points.insert(0, (points[0][0], BARN_FIELD_Y_M - LEAD_IN_M))
    low, high = points[0][1] - CORRIDOR_BEHIND_M, points[0][1] + CORRIDOR_AHEAD_M
    for wall in (
        shapes.Wall((-0.05, low), (-0.05, high), 0.1),
        shapes.Wall((width + 0.05, low), (width + 0.05, high), 0.1),
        shapes.Wall((0.0, low - 0.05), (width, low - 0.05), 0.1),
        shapes.Wall((0.0, high + 0.05), (width, high + 0.05), 0.1),
    ):
        pieces.extend(wall.footprint())
    return shapes.Footprints(pieces), drive(np.array(points), poses)


def drive(points: np.ndarray, poses: int) -> list[tuple[np.ndarray, float]]:
    """Poses every STEP_M along the polyline `points` (at most `poses`), facing along it."""
    out = []
    for a, b in itertools.pairwise(points):
        length = float(np.hypot(*(b - a)))
        yaw = math.atan2(b[1] - a[1], b[0] - a[0])
        for t in np.arange(0.0, length, STEP_M):
            out.append((a + (b - a) * (t / length), yaw))
    return out[:poses]


def fresh_map(planner: str) -> LocalMap:
    """An empty map, as the planner builds it."""
    return make_planner(planner, {}, robot_radius_m()).map


def first_walk_s(footprints: shapes.Footprints, pose: tuple[np.ndarray, float]) -> float:
    """CPU time (s) of the process's first update that walks its cones (numba's start-up)."""
    layout = LAYOUTS["jackal_laser"]
    grid = fresh_map("dwa")
    ranges = layout.scan(footprints, *pose)
    start = time.process_time()
    grid.update(pose[0], pose[1], layout.bearings, ranges, layout.beam)
    return time.process_time() - start


def per_update_ms(scans: dict[str, list[np.ndarray]], poses, repeat: int) -> dict[tuple[str, str], float]:
    """Median over `repeat` rounds of the mean CPU time (ms) of one update, per layout and map."""
    times: dict[tuple[str, str], list[float]] = {(lay, m): [] for lay in scans for m in MAPS}
    for _ in range(repeat):
        for layout_name, planner in times:
            layout = LAYOUTS[layout_name]
            grid = fresh_map(planner)
            start = time.process_time()
            for (position, yaw), ranges in zip(poses, scans[layout_name], strict=True):
                grid.update(position, yaw, layout.bearings, ranges, layout.beam)
            times[(layout_name, planner)].append(1e3 * (time.process_time() - start) / len(poses))
    return {key: statistics.median(values) for key, values in times.items()}


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=options.whole(1), default=5)
    parser.add_argument("--poses", type=options.whole(1), default=300, help="poses of the drive at most")
    parser.add_argument("--seed", type=options.whole(0), default=0, help="first seed of the BARN field")
    parser.add_argument("--out", type=Path, default=Path("logs/map_update"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    footprints, poses = scene(args.seed, args.poses)
    print(f"The first update that walks its cones: {first_walk_s(footprints, poses[0]):.2f} s CPU.\n")
    scans = {name: [layout.scan(footprints, *pose) for pose in poses] for name, layout in LAYOUTS.items()}
    cost = per_update_ms(scans, poses, args.repeat)
    columns = {"layout": "", "beams": "d", **{f"`{m}` ms": ".3f" for m in MAPS}}
    table = [
        {"layout": name, "beams": len(layout.bearings), **{f"`{m}` ms": cost[(name, m)] for m in MAPS}}
        for name, layout in LAYOUTS.items()
    ]
    text = markdown_table(table, list(columns), formatted(columns))
    print(text)
    echoes = np.concatenate(scans["jackal_laser"])
    print(
        f"\n{len(poses)} poses; the Jackal's farthest echo {np.nanmax(echoes):.1f} m, "
        f"{np.mean(np.isnan(echoes)):.0%} of its beams without one."
    )
    print("\n".join(f"wrote {path}" for path in write_table(out, "map_update", table, list(columns), text)))

    return 0


if __name__ == "__main__":
    sys.exit(main())
