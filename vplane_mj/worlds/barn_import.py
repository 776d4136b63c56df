"""`vplane-mj import barn`: BARN's Gazebo worlds as scenarios of the challenge's layout.

Each world file's static cylinders and boxes (`vplane_mj.worlds.sdf`) move from Gazebo's frame to
the arena's by the translation of `vplane_mj.worlds.barn_layout.to_arena`, which takes BARN's start
(-2.25, 3) to [2.1, 2.85] and its goal (-2.25, 13) to [2.1, 12.85]. BARN's obstacle field then
fills cells of the layout's field, and its wall cylinders stand just outside the arena, against
the arena's border walls (both are kept: the wall cylinders are what BARN's robot sees, the
border closes the side BARN leaves open beyond the goal). A world whose start or goal is closer
than the Jackal's half diagonal to an obstacle is refused.

BARN ships its own path with each world (`path_N.npy` beside `world_N.world`): the cells of the
0.15 m grid its generator's A* went through. Its length (the polyline (-2, 3), the cells at
Gazebo (0.15 r - 4.575, 0.15 c + 5.075), (-2, 13)) is the challenge's optimal path: it is
reported beside the project's reference path for the Jackal, and the scenario keeps it as
`[world] score_path_m`, so that a run's score takes OT from it as BARN's `report_test.py`
does (its length over the Jackal's 2 m/s). Without the path file the score's OT is the
reference path's, as for every other scenario. The path file is read strictly: its .npy header
first (integers, shape (N, 2), N at most MAX_PATH_CELLS), never a pickle, and every cell must
lie on BARN's 30 x 30 grid.

Every input is read and converted before anything is written; two files of the same world
number (world_01.world and world_1.world) or of the same scenario name are refused.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np

from vplane_mj.errors import ScenarioError, WorldFileError, cut, readable
from vplane_mj.geometry.shapes import scene_footprints
from vplane_mj.scenario import parse_document
from vplane_mj.worlds.barn_layout import (
    JACKAL_RADIUS_M,
    jackal_reference_length,
    layout_document,
    to_arena,
)
from vplane_mj.worlds.families import Case
from vplane_mj.worlds.sdf import WorldShape, read_world_shapes

if TYPE_CHECKING:
    from vplane_mj.scenario import Scenario

WORLD_FILE = re.compile(r"world_([0-9]+)\.world")
"""How BARN names its world files; `path_N.npy` beside one is its path."""
BARN_PATH_START_M, BARN_PATH_END_M = (-2.0, 3.0), (-2.0, 13.0)
"""The ends of BARN's optimal-path polyline, in Gazebo's frame (m)."""
BARN_GRID_CELLS = 30
"""BARN's grid is this many cells of 0.15 m on a side: a path cell's row and column are 0 to 29."""
MAX_PATH_CELLS = 10_000
"""The most cells a path_N.npy may hold, far more than a path on BARN's grid needs (at most 46
in the 250 training worlds)."""


@dataclass(frozen=True)
class ImportedWorld:
    """One converted world: the scenario, BARN's own path length (m; None without its
    path_N.npy) and the project's reference path length for the Jackal (m; None: no way through)."""

    case: Case
    barn_path_m: float | None
    reference_m: float | None


def world_number(path: Path) -> int | None:
    """N of a file named world_N.world, else None."""
    match = WORLD_FILE.fullmatch(path.name)
    return int(match.group(1)) if match else None


def directory_worlds(directory: Path) -> list[Path]:
    """The world_N.world files of a directory, in the order of N (then of their names)."""
    numbered = []
    for candidate in directory.iterdir():
        number = world_number(candidate)
        if number is not None and candidate.is_file():
            numbered.append((number, candidate.name, candidate))
    if not numbered:
        raise WorldFileError(str(directory), "", "holds no world_N.world file")
    return [candidate for _, _, candidate in sorted(numbered)]


def refuse_shared(files: list[Path], key: Callable[[Path], object], what: str) -> None:
    """A WorldFileError naming both files when two share a `key` (None: no key), `what` it is."""
    first: dict[object, Path] = {}
    for path in files:
        value = key(path)
        if value is None:
            continue
        if value in first:
            reason = f"has {what} {value!r}, as {readable(str(first[value]))} does"
            raise WorldFileError(str(path), "", reason)
        first[value] = path


def world_files(paths: list[Path], scenario: Callable[[Path], str]) -> list[Path]:
    """The world files `paths` name: each a file, or a directory of world_N.world files (in
    the order of N); no two of one world number or of one `scenario` name."""
    files: list[Path] = []
    for path in paths:
        if path.is_dir():
            files.extend(directory_worlds(path))
        elif path.is_file():
            files.append(path)
        else:
            raise WorldFileError(str(path), "", "no such file or directory")
    refuse_shared(files, world_number, "the world number")
    refuse_shared(files, scenario, "the scenario name")
    return files


def scenario_name(path: Path) -> str:
    """`barn_` and the file's stem in the scenario name's alphabet: world_7.world -> barn_world_7."""
    return "barn_" + re.sub(r"[^a-z0-9_]", "_", path.stem.lower())


def obstacle(shape: WorldShape) -> dict:
    """A shape as a scenario obstacle in arena coordinates."""
    center = list(to_arena(shape.x, shape.y))
    if shape.kind == "cylinder":
        return {"kind": "cylinder", "center": center, "radius": shape.radius}
    yaw_deg = round(float(np.degrees(shape.yaw)), 6)
    return {"kind": "box", "center": center, "size": list(shape.size), "yaw_deg": yaw_deg}


def barn_path_file(world: Path) -> Path | None:
    """BARN's path_N.npy beside world_N.world, if it is there."""
    match = WORLD_FILE.fullmatch(world.name)
    path = world.with_name(f"path_{match.group(1)}.npy") if match else None
    return path if path is not None and path.is_file() else None


def npy_header(file: BinaryIO) -> tuple[tuple[int, ...], bool, np.dtype]:
    """The shape, Fortran order and dtype an .npy file's header declares (format 1.0 or 2.0);
    a ValueError if it is not one."""
    version = np.lib.format.read_magic(file)
    if version == (1, 0):
        return np.lib.format.read_array_header_1_0(file)
    if version == (2, 0):
        return np.lib.format.read_array_header_2_0(file)
    raise ValueError(f".npy format version {version[0]}.{version[1]}, not 1.0 or 2.0")


def path_header_error(dtype: np.dtype, shape: tuple[int, ...]) -> str | None:
    """Why an .npy header cannot be BARN's path (None: it can): it must declare N (row,
    column) integer pairs, 1 <= N <= MAX_PATH_CELLS."""
    if dtype.kind not in "iu" or len(shape) != 2 or shape[1] != 2 or not 1 <= shape[0] <= MAX_PATH_CELLS:
        return (
            f"must hold 1 to {MAX_PATH_CELLS} (row, column) integer pairs, its header declares "
            f"{cut(str(dtype))} of shape {cut(str(shape))}"
        )
    return None


def off_grid_error(cells: np.ndarray) -> str | None:
    """Why BARN's path cells do not all lie on its grid (None: they do)."""
    off = np.flatnonzero(((cells < 0) | (cells >= BARN_GRID_CELLS)).any(axis=1))
    if not off.size:
        return None
    row, column = cells[off[0]]
    last = BARN_GRID_CELLS - 1
    return f"cell {off[0]} (row {row}, column {column}) is off BARN's grid: rows and columns are 0 to {last}"


def read_barn_path(path: Path) -> np.ndarray:
    """BARN's path cells, (row, column) pairs on its grid, from a path_N.npy file: its header is
    checked before any data is read, and no pickle is ever loaded."""
    source = str(path)
    try:
        with path.open("rb") as file:
            shape, fortran_order, dtype = npy_header(file)
            reason = path_header_error(dtype, shape)
            if reason is not None:
                raise WorldFileError(source, "", reason)
            size = shape[0] * shape[1] * dtype.itemsize
            data = file.read(size + 1)
    except (OSError, ValueError) as exc:
        raise WorldFileError(source, "", f"cannot read BARN's path: {cut(str(exc))}") from None
    if len(data) != size:
        raise WorldFileError(source, "", f"holds {len(data)} bytes of data, its header declares {size}")
    cells = np.frombuffer(data, dtype).reshape(shape, order="F" if fortran_order else "C")
    reason = off_grid_error(cells)
    if reason is not None:
        raise WorldFileError(source, "", reason)
    return cells


def barn_path_length(path: Path) -> float:
    """Length (m) of BARN's optimal-path polyline for the (row, column) cells in `path`."""
    cells = read_barn_path(path).astype(float)
    gazebo = np.column_stack([0.15 * cells[:, 0] - 0.075 - 4.5, 0.15 * cells[:, 1] + 0.075 + 5.0])
    polyline = np.vstack([BARN_PATH_START_M, gazebo, BARN_PATH_END_M])
    return float(np.sum(np.hypot(*np.diff(polyline, axis=0).T)))


def _check_jackal_clear(scenario: Scenario) -> None:
    """The Jackal's disc at the start and at the goal touches no obstacle (nor the border)."""
    world = scenario.world
    scene = scene_footprints(world.obstacles, world.size)
    for key, point in (("start", scenario.robot.start), ("goal", scenario.robot.goal)):
        gap = float(scene.distance(np.array([point]))[0])
        if gap < JACKAL_RADIUS_M:
            reason = (
                f"the {key} {list(point)} is {gap:.3f} m from an obstacle, closer than the "
                f"Jackal's half diagonal ({JACKAL_RADIUS_M:.3f} m)"
            )
            raise WorldFileError(scenario.source, "", reason)


def import_world(path: Path) -> ImportedWorld:
    """One BARN world file as a scenario of the challenge's layout (a WorldFileError if it
    cannot be converted)."""
    source = str(path)
    shapes = read_world_shapes(path, source)
    name = scenario_name(path)
    path_file = barn_path_file(path)
    barn_path_m = None if path_file is None else barn_path_length(path_file)
    description = (
        f"BARN world {readable(path.name)} (Gazebo), {len(shapes)} obstacles in the challenge's layout"
    )
    if path_file is not None:
        description += f"; BARN's own path ({path_file.name}) is {barn_path_m:.3f} m"
    document = layout_document(name, description, [obstacle(shape) for shape in shapes])
    if barn_path_m is not None:
        document["world"]["score_path_m"] = round(barn_path_m, 6)
    try:
        scenario = parse_document(document, source)
    except ScenarioError as exc:
        raise WorldFileError(source, "", f"does not make a valid scenario: {exc.key}: {exc.reason}") from None
    _check_jackal_clear(scenario)
    return ImportedWorld(Case(name, document), barn_path_m, jackal_reference_length(scenario))


def import_worlds(paths: list[Path]) -> list[ImportedWorld]:
    """Every world `paths` name, converted, or the first error: nothing is written here."""
    return [import_world(path) for path in world_files(paths, scenario_name)]


def report_line(world: ImportedWorld) -> str:
    """One line on a converted world: its obstacles and its path lengths, BARN's and the project's."""
    name = world.case.name
    count = len(world.case.document["world"]["obstacles"])
    reference = (
        "no reference path for the Jackal's disc"
        if world.reference_m is None
        else f"reference path {world.reference_m:.3f} m for the Jackal's disc ({JACKAL_RADIUS_M:.3f} m)"
    )
    if world.barn_path_m is None:
        return f"{name}: {count} obstacles; {reference}"
    versus = ""
    if world.reference_m is not None:
        versus = f" ({100 * (world.barn_path_m / world.reference_m - 1):+.1f}% against the reference)"
    return f"{name}: {count} obstacles; {reference}; BARN's own path {world.barn_path_m:.3f} m{versus}"
