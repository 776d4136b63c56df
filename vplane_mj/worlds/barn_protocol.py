"""`vplane-mj generate barn --protocol`: seeded worlds in the BARN challenge's layout
(`vplane_mj.worlds.barn_layout`), their obstacle field drawn as BARN draws its own (Perille et al.,
"Benchmarking Metric Ground Navigation", SSRR 2020).

Method, after BARN's generator:
1. A cellular automaton (`vplane_mj.worlds.families.smooth_cells`): the field's 31 x 28 cells are
   filled at random with a probability drawn from FILL_RANGE, then smoothed by a number of
   passes drawn from PASSES_RANGE. The arena's side walls count as filled cells.
2. The Jackal's space: BARN takes the Jackal as JACKAL_CELLS x JACKAL_CELLS cells (0.75 m) and
   calls a place open when that whole window of cells is empty (its centre is then at least
   0.375 m from every cylinder). When the largest open region that touches the field's near
   end is not the one that touches its far end, BARN carves a corridor of open windows between
   them: from the first region's farthest window straight ahead, then across to the second's
   nearest window. A field with no open window at either end is drawn again.
3. Every filled cell becomes a cylinder of radius 0.075 m at its centre, except the cells whose
   8 neighbours are all filled (BARN's world writer leaves those out: nothing can reach them).
4. The world is kept only when the project's reference path (`vplane_mj.geometry.reference`) finds a
   way from start to goal for a disc of the Jackal's half diagonal (0.333 m); else drawn again.

The difficulty spreads with the fill and the passes: scattered cells, open blobs, or dense
blobs that leave one winding (or carved) passage.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from vplane_mj.errors import ScenarioError
from vplane_mj.scenario import parse_document
from vplane_mj.worlds.barn_layout import (
    CELL_M,
    FIELD_COLUMNS,
    FIELD_ROWS,
    cell_center,
    jackal_reference_length,
    layout_document,
)
from vplane_mj.worlds.families import Case, smooth_cells

FILL_RANGE = (0.15, 0.35)
"""Initial fill probability of a cell, drawn uniformly per world."""
PASSES_RANGE = (2, 5)
"""Smoothing passes per world, drawn uniformly (both ends included)."""
JACKAL_CELLS = 5
"""BARN's Jackal kernel: the robot takes this many cells (0.75 m) each way."""
MAX_ATTEMPTS_PER_WORLD = 50
"""Candidates drawn per requested world before generation gives up."""


def open_windows(grid: np.ndarray) -> np.ndarray:
    """Whether each JACKAL_CELLS x JACKAL_CELLS window of the grid (by its first row and column)
    holds no filled cell: the Jackal's space, (rows - 4, columns - 4)."""
    windows = np.lib.stride_tricks.sliding_window_view(grid, (JACKAL_CELLS, JACKAL_CELLS))
    return np.asarray(~windows.any(axis=(2, 3)))


def _end_region(labels: np.ndarray, row: int) -> int:
    """The label of the largest region with a window in `row` (0: none)."""
    touching = np.unique(labels[row][labels[row] > 0])
    if not len(touching):
        return 0
    sizes = np.bincount(labels.ravel())[touching]
    return int(touching[int(np.argmax(sizes))])


def connect_ends(grid: np.ndarray) -> tuple[np.ndarray, bool] | None:
    """The grid with BARN's corridor carved between the near and the far end's largest open
    regions when they differ, and whether one was carved; None when an end has no open window."""
    labels, _ = ndimage.label(open_windows(grid))  # 4-connected, as BARN's flood fill
    near, far = _end_region(labels, 0), _end_region(labels, labels.shape[0] - 1)
    if not near or not far:
        return None
    if near == far:
        return grid, False
    near_cells, far_cells = np.argwhere(labels == near), np.argwhere(labels == far)
    a = near_cells[np.lexsort((near_cells[:, 1], near_cells[:, 0]))[-1]]  # farthest ahead
    b = far_cells[np.lexsort((-far_cells[:, 1], far_cells[:, 0]))[0]]  # nearest
    step_row = 1 if b[0] >= a[0] else -1
    step_col = 1 if b[1] >= a[1] else -1
    corridor = [(row, a[1]) for row in range(a[0], b[0] + step_row, step_row)]
    corridor += [(b[0], col) for col in range(a[1], b[1] + step_col, step_col)]
    carved = grid.copy()
    for row, col in corridor:
        carved[row : row + JACKAL_CELLS, col : col + JACKAL_CELLS] = False
    return carved, True


def field_cylinders(grid: np.ndarray) -> list[dict]:
    """A cylinder for every filled cell that has an empty neighbour (the arena's side walls
    count as filled, the open floor before and after the field as empty)."""
    padded = np.pad(grid, ((1, 1), (0, 0)), constant_values=False)
    padded = np.pad(padded, ((0, 0), (1, 1)), constant_values=True)
    enclosed = np.lib.stride_tricks.sliding_window_view(padded, (3, 3)).all(axis=(2, 3))
    return [
        {"kind": "cylinder", "center": cell_center(int(row), int(col)), "radius": CELL_M / 2}
        for row, col in np.argwhere(grid & ~enclosed)
    ]


def random_protocol_world(name: str, rng: np.random.Generator) -> Case | None:
    """One candidate world of the challenge's layout, or None when its field has no open
    window at an end; not yet checked for a path."""
    fill = float(rng.uniform(*FILL_RANGE))
    grid = rng.random((FIELD_ROWS, FIELD_COLUMNS)) < fill
    passes = int(rng.integers(PASSES_RANGE[0], PASSES_RANGE[1] + 1))
    connected = connect_ends(smooth_cells(grid, passes))
    if connected is None:
        return None
    field, carved = connected
    description = (
        f"BARN challenge layout, generated: initial fill {fill:.2f}, {passes} smoothing passes, "
        f"{field.mean():.0%} of the field's cells filled" + (", a corridor carved" if carved else "")
    )
    return Case(name, layout_document(name, description, field_cylinders(field)))


def generate_protocol(count: int, seed: int) -> list[Case]:
    """`count` worlds of the challenge's layout from `seed`, each passable for the Jackal.

    Candidates are drawn from one generator seeded with `seed`, so the same arguments always
    give the same files; a candidate that fails validation or has no path is drawn again.
    """
    rng = np.random.default_rng(seed)
    cases: list[Case] = []
    attempts = 0
    while len(cases) < count:
        attempts += 1
        if attempts > MAX_ATTEMPTS_PER_WORLD * count:
            raise RuntimeError(f"barn --protocol: too few passable worlds after {attempts} attempts")
        case = random_protocol_world(f"barn_protocol_{seed}_{len(cases):03d}", rng)
        if case is None:
            continue
        try:
            scenario = parse_document(case.document, f"{case.name}.toml")
        except ScenarioError:
            continue
        if jackal_reference_length(scenario) is not None:
            cases.append(case)
    return cases
