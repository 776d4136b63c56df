"""Laser scans: the 2D cast of `vplane_mj.sim.laser` against MuJoCo's ray caster, side by side.

Two worlds, both built by `vplane_mj.sim.world`: a BARN-size world (the BARN challenge's layout,
a 4.2 x 14 m arena with its border and 150-250 cylinders of radius 0.075 m on the 0.15 m
grid filling y in [4.95, 9.6], drawn with `--seed`) and a paper-size world (the paper's
9.84 x 10.46 m arena with its border, the C trap of paper_c_escape and four boxes). From
`--origins` random points of each world clear of every obstacle by 0.1 m, both casters cast
the same scans: the Jackal's (720 beams over 270 degrees, 30 m) and the TurtleBot3 Burger's
(360 beams all round, 3.5 m). MuJoCo's `mj_multiRay` casts from the laser's mount height
and sees the obstacles and the border only (the robot's and the floor's geoms are masked
out by their group). Each origin's scan is cast `--repeat` times by one caster, then by the
other; the time is the process's CPU time, which a busy machine delays but does not inflate
the way it does wall time. Reported: the median over the origins of each caster's time per
scan (us), their ratio, and the largest difference between their ranges (mm).

Last, the kernel's first call in a new process, in two processes run one after the other
with an empty numba cache: the first compiles the kernel and writes the cache, the second
loads it. Importing `vplane_mj.sim.laser` (numba with it) is timed apart.

The table is written to `OUT/laser_cast.csv`, `.md` and `.json` (with the command and the date).

    python benchmarks/laser_cast.py [--origins 200] [--repeat 20] [--seed 0] [--out logs/laser_cast]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from vplane_mj.bench import options
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.files import prepare_out_dir
from vplane_mj.geometry import shapes
from vplane_mj.scenario import Scenario, box, build_scenario, cup, cylinder
from vplane_mj.sim.laser import MOUNT_HEIGHT_M, RayCaster
from vplane_mj.sim.world import OBSTACLES_BODY, build_model

BARN_CELL_M, BARN_RADIUS_M = 0.15, 0.075
BARN_FIELD_Y_M = (4.95, 9.6)
BARN_CYLINDERS = (150, 250)
LASERS = {
    "Jackal: 720 beams, 270 deg, 30 m": (math.radians(270) / 719, 720, 30.0),
    "Burger: 360 beams, 360 deg, 3.5 m": (2 * math.pi / 360, 360, 3.5),
}
"""Scan name -> (angle step rad, beams, range_max m)."""
ORIGIN_CLEARANCE_M = 0.1
OBSTACLES_ONLY = np.array([1, 1, 1, 1, 1, 0], dtype=np.uint8)
"""Geom groups `mj_multiRay` sees: all but 5, where the robot's and the floor's geoms are moved."""
CELLS = {
    "world": "",
    "pieces": "d",
    "scan": "",
    "`laser` us": ".1f",
    "`mj_multiRay` us": ".1f",
    "ratio": ".1f",
    "max diff mm": ".1e",
}
"""The table's columns and how each is written: CPU us per scan, medians over the origins."""
FIRST_CALL = """
import json, time
started = time.perf_counter()
from vplane_mj.sim.laser import RayCaster
from vplane_mj.geometry.shapes import Disc
imported = time.perf_counter()
RayCaster([Disc((1.0, 0.0), 0.1)]).cast((0.0, 0.0), 0.0, 0.01, 10, 5.0)
print(json.dumps({"import_s": imported - started, "first_cast_s": time.perf_counter() - imported}))
"""


def barn_world(seed: int) -> tuple[str, Scenario]:
    """A BARN-size world: cylinders in random cells of the 0.15 m grid over the obstacle field."""
    rng = np.random.default_rng(seed)
    columns = round(4.2 / BARN_CELL_M)
    rows = round((BARN_FIELD_Y_M[1] - BARN_FIELD_Y_M[0]) / BARN_CELL_M)
    count = int(rng.integers(BARN_CYLINDERS[0], BARN_CYLINDERS[1] + 1))
    cells = rng.choice(columns * rows, size=count, replace=False)
    obstacles = [
        cylinder(
            [(cell % columns + 0.5) * BARN_CELL_M, BARN_FIELD_Y_M[0] + (cell // columns + 0.5) * BARN_CELL_M],
            BARN_RADIUS_M,
        )
        for cell in cells
    ]
    return "BARN-size", build_scenario(
        "barn_size",
        size=[4.2, 14.0],
        start=[2.1, 2.85],
        goal=[2.1, 12.85],
        obstacles=obstacles,
        border=True,
    )


def paper_world() -> tuple[str, Scenario]:
    """The paper's arena with the C trap of paper_c_escape and four boxes around it."""
    obstacles = [
        cup([4.9, 5.2], 1.6, 1.2, thickness=0.1),
        box([2.0, 2.0], [0.8, 0.5], 20.0),
        box([7.5, 8.0], [1.0, 0.6], -35.0),
        box([2.5, 8.5], [0.5, 0.5], 45.0),
        box([7.0, 2.5], [1.2, 0.3], 70.0),
    ]
    return "paper-size", build_scenario(
        "paper_size",
        size=[9.84, 10.46],
        start=[4.2, 5.2],
        goal=[8.8, 5.2],
        obstacles=obstacles,
        border=True,
    )


def scene_of(scenario: Scenario) -> shapes.Footprints:
    """The world's obstacle and border pieces."""
    world = scenario.world
    return shapes.scene_footprints(world.obstacles, world.size if world.border else None)


def free_origins(scene: shapes.Footprints, size: tuple[float, float], count: int, seed: int) -> np.ndarray:
    """`count` random points (count, 2) of the arena at least ORIGIN_CLEARANCE_M from every piece."""
    rng = np.random.default_rng(seed)
    points = rng.uniform((0.0, 0.0), size, (20 * count + 100, 2))
    return points[scene.distance(points) >= ORIGIN_CLEARANCE_M][:count]


class MujocoScan:
    """`mj_multiRay` on a scenario's compiled world, from the laser's height, obstacles only."""

    def __init__(self, scenario: Scenario):
        self.model = build_model(scenario, rangefinders=False)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_kinematics(self.model, self.data)
        self.model.geom_group[self.model.geom_bodyid != self.model.body(OBSTACLES_BODY).id] = 5

    def prepare(self, origin: np.ndarray, first: float, step: float, beams: int) -> tuple[np.ndarray, ...]:
        """The scan's start point, its beams' directions (beams * 3,) and the output arrays,
        made before the timing."""
        point = np.array([origin[0], origin[1], MOUNT_HEIGHT_M])
        angles = first + step * np.arange(beams)
        vec = np.zeros((beams, 3))
        vec[:, 0], vec[:, 1] = np.cos(angles), np.sin(angles)
        return point, vec.ravel(), np.zeros(beams, np.int32), np.zeros(beams)

    def cast(self, rays: tuple[np.ndarray, ...], range_max: float) -> None:
        point, vec, geom, dist = rays
        mujoco.mj_multiRay(
            self.model, self.data, point, vec, OBSTACLES_ONLY, 1, -1, geom, dist, None, len(dist), range_max
        )


def compare(scenario: Scenario, origins: np.ndarray, step: float, beams: int, range_max: float, repeat: int):
    """(median us per scan of the 2D cast, of mj_multiRay, largest range difference mm)."""
    caster, reference = RayCaster(scene_of(scenario)), MujocoScan(scenario)
    caster.cast((0.0, 0.0), 0.0, step, beams, range_max)  # compiles or loads the kernel, untimed
    ours_us, theirs_us, worst_mm = [], [], 0.0
    rng = np.random.default_rng(1)
    for origin in origins:
        first = float(rng.uniform(-math.pi, math.pi))
        rays = reference.prepare(origin, first, step, beams)
        started = time.process_time()
        for _ in range(repeat):
            ranges = caster.cast((origin[0], origin[1]), first, step, beams, range_max)
        ours_us.append(1e6 * (time.process_time() - started) / repeat)
        started = time.process_time()
        for _ in range(repeat):
            reference.cast(rays, range_max)
        theirs_us.append(1e6 * (time.process_time() - started) / repeat)
        dist = rays[3]
        theirs = np.where((dist < 0) | (dist > range_max), np.inf, dist)
        same = np.isclose(ranges, theirs, rtol=0.0, atol=1e-3)  # inf equals inf
        if not same.all():
            raise SystemExit(
                f"{scenario.name}: the casts disagree from {origin}: {ranges[~same]} != {theirs[~same]}"
            )
        finite = np.isfinite(theirs)
        if finite.any():
            worst_mm = max(worst_mm, 1e3 * float(np.max(np.abs(ranges[finite] - theirs[finite]))))
    return statistics.median(ours_us), statistics.median(theirs_us), worst_mm


def first_calls() -> list[dict]:
    """Import and first-cast times (s) of two new processes sharing an empty numba cache."""
    with tempfile.TemporaryDirectory(prefix="numba-cache-") as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        return [
            json.loads(
                subprocess.run(
                    [sys.executable, "-c", FIRST_CALL], env=env, check=True, capture_output=True, text=True
                ).stdout
            )
            for _ in range(2)
        ]


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--origins", type=options.whole(1), default=200)
    parser.add_argument("--repeat", type=options.whole(1), default=20)
    parser.add_argument("--seed", type=options.whole(0), default=0)
    parser.add_argument("--out", type=Path, default=Path("logs/laser_cast"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    table = []
    for label, scenario in (barn_world(args.seed), paper_world()):
        scene = scene_of(scenario)
        origins = free_origins(scene, scenario.world.size, args.origins, args.seed)
        for name, (step, beams, range_max) in LASERS.items():
            ours, theirs, worst = compare(scenario, origins, step, beams, range_max, args.repeat)
            cells = (label, len(scene), name, ours, theirs, theirs / ours, worst)
            table.append(dict(zip(CELLS, cells, strict=True)))
    text = markdown_table(table, list(CELLS), formatted(CELLS))
    print(text)
    compiled, loaded = first_calls()
    print(
        f"\nFirst cast in a new process: {compiled['first_cast_s']:.3f} s with an empty numba cache "
        f"(compile), {loaded['first_cast_s']:.3f} s with the cache (load); importing vplane_mj.sim.laser: "
        f"{compiled['import_s']:.3f} s and {loaded['import_s']:.3f} s."
    )
    print("\n".join(f"wrote {path}" for path in write_table(out, "laser_cast", table, list(CELLS), text)))

    return 0


if __name__ == "__main__":
    sys.exit(main())
