"""Generated scenario families, as TOML documents, in a 10 x 10 m arena.

The trap suite (`trap_suite`): fixed U/C and H traps at orientations off the axes, the
start in front of the mouth or inside the cup, the goal behind the trap, so that the
straight line from start to goal runs into the cup. Rotating a case (every obstacle, the
start and the goal together about the arena's centre) gives the same problem at another
angle. The seeded families of `vplane-mj generate` (`FAMILIES`): random traps, clutter
with a trap on the straight line, and zigzag corridors.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import tomli_w

if TYPE_CHECKING:
    from vplane_mj.scenario import Scenario

ARENA = 10.0
CENTER = (ARENA / 2, ARENA / 2)


@dataclass(frozen=True)
class Case:
    """One generated scenario: its name and its TOML document (as a dict)."""

    name: str
    document: dict

    def toml(self) -> str:
        return tomli_w.dumps(self.document)


def _polar(origin: tuple[float, float], radius: float, angle_deg: float) -> list[float]:
    a = math.radians(angle_deg)
    return [round(origin[0] + radius * math.cos(a), 6), round(origin[1] + radius * math.sin(a), 6)]


def _rotate(point: list[float], angle_deg: float) -> list[float]:
    """Rotate `point` about the arena's centre."""
    a = math.radians(angle_deg)
    x, y = point[0] - CENTER[0], point[1] - CENTER[1]
    return [
        round(CENTER[0] + x * math.cos(a) - y * math.sin(a), 6),
        round(CENTER[1] + x * math.sin(a) + y * math.cos(a), 6),
    ]


def rotated(case: Case, angle_deg: float, name: str | None = None) -> Case:
    """The same case with obstacles, start and goal rotated together about the arena centre."""
    doc = {**case.document, "name": name or f"{case.name}_rot{round(angle_deg) % 360}"}
    obstacles = []
    for ob in case.document["world"].get("obstacles", []):
        turned = dict(ob)
        for key in ("center", "from", "to"):
            if key in turned:
                turned[key] = _rotate(turned[key], angle_deg)
        if turned["kind"] in ("box", "u", "c", "h"):
            turned["yaw_deg"] = round(turned.get("yaw_deg", 0.0) + angle_deg, 6)
        obstacles.append(turned)
    doc["world"] = {**case.document["world"], "obstacles": obstacles}
    doc["robot"] = {
        **case.document["robot"],
        "start": _rotate(case.document["robot"]["start"], angle_deg),
        "goal": _rotate(case.document["robot"]["goal"], angle_deg),
    }
    return Case(doc["name"], doc)


def _document(name: str, obstacles: list[dict], start: list[float], goal: list[float]) -> dict:
    return {
        "format": 1,
        "name": name,
        "description": "generated trap case",
        "world": {"size": [ARENA, ARENA], "obstacles": obstacles},
        "robot": {"start": start, "goal": goal},
        "run": {"time_limit_s": 180.0},
    }


def cup_case(
    name: str,
    yaw_deg: float,
    width: float = 1.6,
    depth: float = 1.2,
    inside: bool = False,
    kind: str = "u",
) -> Case:
    """A U (or H) trap at the centre, the mouth toward the start, the goal behind it."""
    mouth = yaw_deg + 180.0
    if kind == "h":
        obstacle = {
            "kind": "h",
            "center": list(CENTER),
            "length": 2 * depth,
            "width": width,
            "yaw_deg": yaw_deg,
            "thickness": 0.1,
        }
        inside_offset = depth / 2  # the middle of the cup that opens toward the start
    else:
        obstacle = {
            "kind": kind,
            "center": list(CENTER),
            "width": width,
            "depth": depth,
            "yaw_deg": yaw_deg,
            "thickness": 0.1,
        }
        inside_offset = 0.1
    start = _polar(CENTER, inside_offset if inside else 3.5, mouth)
    goal = _polar(CENTER, 3.8, yaw_deg)
    return Case(name, _document(name, [obstacle], start, goal))


def asymmetric_case(name: str, yaw_deg: float) -> Case:
    """A cup built of walls whose arms differ in length (1.6 m and 0.8 m)."""

    def local(x: float, y: float) -> list[float]:
        a = math.radians(yaw_deg)
        return [
            round(CENTER[0] + x * math.cos(a) - y * math.sin(a), 6),
            round(CENTER[1] + x * math.sin(a) + y * math.cos(a), 6),
        ]

    walls = [
        {"kind": "wall", "from": local(0.6, -0.8), "to": local(0.6, 0.8), "thickness": 0.1},
        {"kind": "wall", "from": local(-1.0, 0.75), "to": local(0.6, 0.75), "thickness": 0.1},
        {"kind": "wall", "from": local(-0.2, -0.75), "to": local(0.6, -0.75), "thickness": 0.1},
    ]
    start = _polar(CENTER, 3.5, yaw_deg + 180.0)
    goal = _polar(CENTER, 3.8, yaw_deg)
    return Case(name, _document(name, walls, start, goal))


def two_traps_case(name: str, yaw_deg: float) -> Case:
    """Two cups in a row on the line from start to goal, both opening toward the start."""
    a = math.radians(yaw_deg)
    cups = []
    for offset in (-1.4, 1.6):
        center = [round(CENTER[0] + offset * math.cos(a), 6), round(CENTER[1] + offset * math.sin(a), 6)]
        cups.append(
            {"kind": "u", "center": center, "width": 1.4, "depth": 1.0, "yaw_deg": yaw_deg, "thickness": 0.1}
        )
    start = _polar(CENTER, 4.2, yaw_deg + 180.0)
    goal = _polar(CENTER, 4.2, yaw_deg)
    return Case(name, _document(name, cups, start, goal))


def goal_near_wall_case(name: str) -> Case:
    """A cup with the goal 0.3 m from the border wall behind it."""
    obstacle = {"kind": "u", "center": [6.5, 5.0], "width": 1.6, "depth": 1.2, "thickness": 0.1}
    return Case(name, _document(name, [obstacle], [2.0, 5.0], [9.7, 5.0]))


def trap_suite() -> list[Case]:
    """The trap suite: orientations off the axes, mouths narrow and wide, starts in and out."""
    cases = []
    for yaw in (0, 23, 75, 130, 200, 287):
        cases.append(cup_case(f"u_front_{yaw}", yaw))
        cases.append(cup_case(f"u_inside_{yaw}", yaw, inside=True))
        cases.append(cup_case(f"h_front_{yaw}", yaw, kind="h"))
    for yaw in (40, 160, 250):
        cases.append(cup_case(f"h_inside_{yaw}", yaw, kind="h", inside=True))
        cases.append(cup_case(f"u_narrow_{yaw}", yaw, width=0.9, depth=1.0))
        cases.append(cup_case(f"u_wide_{yaw}", yaw, width=2.6, depth=1.6))
        cases.append(asymmetric_case(f"asym_{yaw}", yaw))
        cases.append(two_traps_case(f"two_{yaw}", yaw))
    cases.append(goal_near_wall_case("goal_near_wall"))
    return cases


# -- seeded random families for sweeps (`vplane-mj generate FAMILY`) ---------------------------


def random_trap(name: str, rng: np.random.Generator) -> Case:
    """A U or H trap of random size and orientation; the start in front of the mouth (from an
    approach angle up to 35 degrees off its axis) or, one time in five, inside the cup."""
    kind = "h" if rng.random() < 0.4 else "u"
    case = cup_case(
        name,
        yaw_deg=0.0,
        width=round(float(rng.uniform(0.9, 2.4)), 3),
        depth=round(float(rng.uniform(0.8, 1.6)), 3),
        inside=bool(rng.random() < 0.2),
        kind=kind,
    )
    if not _inside_start(case):
        approach = float(rng.uniform(-35.0, 35.0))
        case.document["robot"]["start"] = _polar(CENTER, 3.5, 180.0 + approach)
    return rotated(case, float(rng.uniform(0.0, 360.0)), name=name)


def _inside_start(case: Case) -> bool:
    return math.dist(case.document["robot"]["start"], CENTER) < 1.0


def random_clutter(name: str, rng: np.random.Generator) -> Case:
    """Boxes and cylinders scattered over the arena, and a U trap on the straight line."""
    angle = float(rng.uniform(0.0, 360.0))
    start = _polar(CENTER, 4.2, angle + 180.0)
    goal = _polar(CENTER, 4.2, angle)
    trap = {
        "kind": "u",
        "center": list(CENTER),
        "width": round(float(rng.uniform(1.2, 2.0)), 3),
        "depth": round(float(rng.uniform(0.9, 1.4)), 3),
        "yaw_deg": round(angle, 3),
        "thickness": 0.1,
    }
    obstacles = [trap]
    for _ in range(int(rng.integers(6, 14))):
        centre = [round(float(v), 3) for v in rng.uniform(0.6, ARENA - 0.6, 2)]
        if min(math.dist(centre, p) for p in (start, goal, CENTER)) < 1.4:
            continue  # keep the start, the goal and the trap itself clear
        if rng.random() < 0.5:
            obstacles.append(
                {"kind": "cylinder", "center": centre, "radius": round(float(rng.uniform(0.15, 0.4)), 3)}
            )
        else:
            size = [round(float(v), 3) for v in rng.uniform(0.2, 0.9, 2)]
            obstacles.append(
                {
                    "kind": "box",
                    "center": centre,
                    "size": size,
                    "yaw_deg": round(float(rng.uniform(0, 180)), 3),
                }
            )
    return Case(name, _document(name, obstacles, start, goal))


def random_corridor(name: str, rng: np.random.Generator) -> Case:
    """A zigzag of walls across the arena: the way to the goal winds through their gaps."""
    gap = float(rng.uniform(0.8, 1.4))
    count = int(rng.integers(2, 5))
    xs = np.linspace(2.0, ARENA - 2.0, count)
    walls = []
    for k, x in enumerate(xs):
        opening = float(rng.uniform(1.0, ARENA - 1.0 - gap))
        if k % 2:  # alternate: the opening near the top or near the bottom half
            opening = ARENA - opening - gap
        walls.append(
            {
                "kind": "wall",
                "from": [round(float(x), 3), 0.0],
                "to": [round(float(x), 3), round(opening, 3)],
                "thickness": 0.1,
            }
        )
        walls.append(
            {
                "kind": "wall",
                "from": [round(float(x), 3), round(opening + gap, 3)],
                "to": [round(float(x), 3), ARENA],
                "thickness": 0.1,
            }
        )
    start = [1.0, round(float(rng.uniform(1.0, ARENA - 1.0)), 3)]
    goal = [ARENA - 1.0, round(float(rng.uniform(1.0, ARENA - 1.0)), 3)]
    return Case(name, _document(name, [w for w in walls if w["from"] != w["to"]], start, goal))


# -- BARN-like cluttered worlds ------------------------------------------------------------------

BARN_CELL_M = 0.15
"""Side of one obstacle cell (m), as in BARN."""
BARN_COLUMNS, BARN_ROWS = 28, 30
"""The obstacle field: 28 cells across the arena's whole width (4.2 m), 30 along it (4.5 m)."""
BARN_LENGTH_M = 10.5
"""Arena length (m) along y: the robot drives from y = BARN_START_Y_M to past the field."""
BARN_START_Y_M, BARN_FIELD_Y_M, BARN_GOAL_PAST_M = 1.0, 4.5, 0.7
"""Start 3.5 m in front of the field, which begins at y = 4.5 m; the goal 0.7 m past its far end."""
BARN_FILL = (0.10, 0.40)
BARN_SMOOTHING_PASSES = (0, 4)
BARN_CLEARANCE_M = 0.05
"""A world is kept only when the robot's disc plus this clearance has a path to the goal."""


def barn_cells(rng: np.random.Generator) -> np.ndarray:
    """An occupancy grid (BARN_ROWS, BARN_COLUMNS) drawn by a cellular automaton (Perille et al.).

    Cells are filled at random with a probability drawn from BARN_FILL, then smoothed by 0-4
    passes (drawn from BARN_SMOOTHING_PASSES) of BARN's rule (`smooth_cells`).
    """
    fill = rng.uniform(*BARN_FILL)
    grid = rng.random((BARN_ROWS, BARN_COLUMNS)) < fill
    return smooth_cells(grid, int(rng.integers(BARN_SMOOTHING_PASSES[0], BARN_SMOOTHING_PASSES[1] + 1)))


def smooth_cells(grid: np.ndarray, passes: int) -> np.ndarray:
    """`passes` passes of BARN's cellular-automaton rule over an occupancy grid (rows along y,
    columns across x): a cell fills when more than 4 of its 8 neighbours are filled and empties
    when fewer than 2 are. Beyond the side columns stand the arena's walls (they count as
    filled); before and after the field is open floor. Few passes leave scattered cells; more
    passes grow them into blobs with narrow, winding passages.
    """
    rows, columns = grid.shape
    for _ in range(passes):
        padded = np.pad(grid, ((1, 1), (0, 0)), constant_values=False)
        padded = np.pad(padded, ((0, 0), (1, 1)), constant_values=True).astype(int)
        neighbours = sum(
            padded[1 + dy : 1 + dy + rows, 1 + dx : 1 + dx + columns]
            for dy in (-1, 0, 1)
            for dx in (-1, 0, 1)
            if dy or dx
        )
        grid = np.where(neighbours > 4, True, np.where(neighbours < 2, False, grid))
    return grid


def cell_rectangles(grid: np.ndarray) -> list[tuple[int, int, int, int]]:
    """Filled cells merged into few rectangles (row0, col0, rows, cols) covering exactly them.

    Runs of filled cells along each row are merged with the identical runs of the rows
    above them, so a blob becomes a handful of boxes instead of one box per cell.
    """
    rectangles: list[tuple[int, int, int, int]] = []
    open_runs: dict[tuple[int, int], int] = {}  # (col0, cols) -> the row where the run began
    for row in range(grid.shape[0] + 1):
        runs: set[tuple[int, int]] = set()
        if row < grid.shape[0]:
            edges = np.flatnonzero(np.diff(np.concatenate(([0], grid[row].astype(int), [0]))))
            runs = {(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2], strict=True)}
        for col0, cols in sorted(set(open_runs) - runs):
            first = open_runs.pop((col0, cols))
            rectangles.append((first, col0, row - first, cols))
        for run in sorted(runs - set(open_runs)):
            open_runs[run] = row
    return rectangles


def random_barn(name: str, rng: np.random.Generator) -> Case:
    """A BARN-like world: a 4.2 x 10.5 m arena crossed by a cellular-automaton obstacle field."""
    width = BARN_COLUMNS * BARN_CELL_M
    obstacles = []
    for row0, col0, rows, cols in cell_rectangles(barn_cells(rng)):
        obstacles.append(
            {
                "kind": "box",
                "center": [
                    round((col0 + cols / 2) * BARN_CELL_M, 6),
                    round(BARN_FIELD_Y_M + (row0 + rows / 2) * BARN_CELL_M, 6),
                ],
                "size": [round(cols * BARN_CELL_M, 6), round(rows * BARN_CELL_M, 6)],
            }
        )
    goal_y = BARN_FIELD_Y_M + BARN_ROWS * BARN_CELL_M + BARN_GOAL_PAST_M
    document = {
        "format": 1,
        "name": name,
        "description": "generated BARN-like world",
        "world": {"size": [round(width, 6), BARN_LENGTH_M], "obstacles": obstacles},
        "robot": {"start": [round(width / 2, 6), BARN_START_Y_M], "goal": [round(width / 2, 6), goal_y]},
        "run": {"time_limit_s": 150.0},
    }
    return Case(name, document)


@dataclass(frozen=True)
class Family:
    """A seeded family of `vplane-mj generate`: one case from a name and a generator, and the
    clearance (m) beyond the robot radius that a kept case's reference path must have."""

    make: Callable[[str, np.random.Generator], Case]
    clearance_m: float = 0.0


FAMILIES = {
    "traps": Family(random_trap),
    "clutter": Family(random_clutter),
    "corridors": Family(random_corridor),
    "barn": Family(random_barn, BARN_CLEARANCE_M),
}
"""The families of `vplane-mj generate`."""


def _robot_has_path(scenario: Scenario, clearance_m: float) -> bool:
    """Whether the robot's disc plus `clearance_m` has a reference path to the goal."""
    from vplane_mj.geometry.reference import shortest_path_length
    from vplane_mj.robots.facts import robot_radius_m

    return shortest_path_length(scenario, robot_radius_m(), clearance_m) is not None


def generate(
    family: str,
    count: int,
    seed: int,
    has_path: Callable[[Scenario, float], bool] | None = None,
) -> list[Case]:
    """`count` valid cases of `family` from `seed`; `has_path(scenario, clearance_m)` rejects
    the unsolvable ones (by default: those where the robot's disc plus the family's clearance
    has no reference path to the goal, `vplane_mj.geometry.reference`).

    Candidates are drawn from one generator seeded with `seed`, so the same arguments always
    give the same files; a candidate that fails validation or has no path is drawn again.
    An unknown family is a VPlaneError that names the closest one.
    """
    from vplane_mj.errors import ScenarioError, VPlaneError, did_you_mean
    from vplane_mj.scenario import parse_scenario

    if family not in FAMILIES:
        hint = did_you_mean(family, FAMILIES)
        raise VPlaneError(f"family: unknown family {family!r} (known: {', '.join(sorted(FAMILIES))}){hint}")
    if has_path is None:
        has_path = _robot_has_path
    rng = np.random.default_rng(seed)
    cases: list[Case] = []
    attempts = 0
    while len(cases) < count:
        attempts += 1
        if attempts > 50 * count:
            raise RuntimeError(f"family {family}: too few valid cases after {attempts} attempts")
        case = FAMILIES[family].make(f"{family}_{seed}_{len(cases):03d}", rng)
        try:
            scenario = parse_scenario(case.toml(), case.name)
        except ScenarioError:
            continue
        if has_path(scenario, FAMILIES[family].clearance_m):
            cases.append(case)
    return cases
