"""Reading the local map's grid, compiled: its obstacle cells near a point, its clusters; marking
the cells the robot stands on."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
def square(first_cell: np.ndarray, n: int, cell_m: float, x: float, y: float, within_m: float) -> tuple:
    """The rows and columns [lo, hi) of an n x n grid (cell (0, 0) the world cell `first_cell`,
    cells of `cell_m`) in the square around the point (x, y) (m) that holds the disc of radius
    `within_m`: every cell closer than `within_m`, and some farther ones. The whole grid when
    `within_m` is not finite."""
    if not math.isfinite(within_m):
        return 0, 0, n, n
    reach = math.ceil(within_m / cell_m) + 1
    row = math.floor(x / cell_m) - first_cell[0]
    col = math.floor(y / cell_m) - first_cell[1]
    return (
        max(0, row - reach),
        max(0, col - reach),
        min(n, max(0, row + reach + 1)),
        min(n, max(0, col + reach + 1)),
    )


@njit
def _counted(certainty: int, min_certainty: int, skipped: bool) -> bool:
    """Whether a cell of `certainty` is one of `cells_near` (and `nearest_cell`): at or above
    `min_certainty`, and not skipped (`_row_count` counts them by this test without a branch)."""
    return certainty >= min_certainty and not skipped


@njit
def cells_near(
    grid: np.ndarray,
    first_cell: np.ndarray,
    cell_m: float,
    min_certainty: int,
    x: float,
    y: float,
    within_m: float,
    skip: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Centres (N, 2; m) and certainties (N,) of the cells at or above `min_certainty`, and not in
    `skip` (a mask like `grid`, or an empty one: none skipped), of the `square` around (x, y)
    (m) that holds the disc of radius `within_m`; row-major. Grid cell (i, j) is the world cell
    `first_cell` + (i, j), its centre ((first_cell + (i, j)) + 1/2) cell_m. Counted a row at a
    time first (`_row_count`), and only the rows that hold some gathered."""
    lo_i, lo_j, hi_i, hi_j = square(first_cell, grid.shape[0], cell_m, x, y, within_m)
    skipping = skip.size > 0
    skipped = skip.view(np.uint8) if skipping else np.zeros((1, grid.shape[1]), dtype=np.uint8)
    counts = np.zeros(max(0, hi_i - lo_i), dtype=np.int64)
    for i in range(lo_i, hi_i):
        counts[i - lo_i] = _row_count(grid[i], skipped[i if skipping else 0], lo_j, hi_j, min_certainty)
    count = counts.sum()
    centres = np.empty((count, 2))
    certainty = np.empty(count, dtype=np.int64)
    k = 0
    for i in range(lo_i, hi_i):
        row, skipped_row, j = grid[i], skipped[i if skipping else 0], lo_j
        for _ in range(counts[i - lo_i]):  # the row's cells up to its last one gathered
            while not _counted(row[j], min_certainty, skipped_row[j] == 1):
                j += 1
            centres[k, 0] = ((i + first_cell[0]) + 0.5) * cell_m
            centres[k, 1] = ((j + first_cell[1]) + 0.5) * cell_m
            certainty[k] = row[j]
            k += 1
            j += 1
    return centres, certainty


@njit
def _row_count(row: np.ndarray, skipped: np.ndarray, lo: int, hi: int, min_certainty: int) -> int:
    """How many cells [lo, hi) of a grid `row` are at or above `min_certainty` and not `skipped`
    (1 in that row of the mask): `_counted`'s test without a branch, which the compiler runs on
    many cells at once."""
    cells, skips = row[lo:hi], skipped[lo:hi]  # indices from 0: no wraparound to test
    count = 0
    for j in range(cells.size):
        count += (cells[j] >= min_certainty) & (skips[j] == 0)
    return count


@njit
def mark_disc(
    swept: np.ndarray,
    seen: np.ndarray,
    first_cell: np.ndarray,
    cell_m: float,
    x: float,
    y: float,
    radius_m: float,
) -> None:
    """Set in `swept` and `seen` (masks of the grid) the cells of the `square` around (x, y) (m)
    whose centres lie within `radius_m` of it; cell (i, j) as in `cells_near`."""
    lo_i, lo_j, hi_i, hi_j = square(first_cell, swept.shape[0], cell_m, x, y, radius_m)
    for i in range(lo_i, hi_i):
        rel_x = ((first_cell[0] + i) + 0.5) * cell_m - x
        for j in range(lo_j, hi_j):
            rel_y = ((first_cell[1] + j) + 0.5) * cell_m - y
            if math.hypot(rel_x, rel_y) <= radius_m:
                swept[i, j] = True
                seen[i, j] = True


@njit
def clear_discs(grid: np.ndarray, first_cell: np.ndarray, cell_m: float, discs: np.ndarray) -> None:
    """Set to 0 the certainty of the cells of `grid` whose centres lie within a disc of `discs`
    (N, 3: x, y, radius; m); cell (i, j) as in `cells_near`."""
    for k in range(discs.shape[0]):
        x, y, radius_m = discs[k, 0], discs[k, 1], discs[k, 2]
        lo_i, lo_j, hi_i, hi_j = square(first_cell, grid.shape[0], cell_m, x, y, radius_m)
        for i in range(lo_i, hi_i):
            rel_x = ((first_cell[0] + i) + 0.5) * cell_m - x
            for j in range(lo_j, hi_j):
                if grid[i, j] != 0:  # most are: no distance to measure
                    rel_y = ((first_cell[1] + j) + 0.5) * cell_m - y
                    if math.hypot(rel_x, rel_y) <= radius_m:
                        grid[i, j] = 0


@njit
def dilate(mask: np.ndarray, disk: np.ndarray) -> np.ndarray:
    """Binary dilation of `mask` by the centred structuring element `disk` (cells beyond the edge
    are off)."""
    rows, cols = mask.shape
    reach_i, reach_j = disk.shape[0] // 2, disk.shape[1] // 2
    out = np.zeros_like(mask)
    for i in range(rows):
        for j in range(cols):
            if not mask[i, j]:
                continue
            for di in range(disk.shape[0]):
                a = i + di - reach_i
                if a < 0 or a >= rows:
                    continue
                for dj in range(disk.shape[1]):
                    b = j + dj - reach_j
                    if disk[di, dj] and 0 <= b < cols:
                        out[a, b] = True
    return out


@njit
def label_regions(mask: np.ndarray) -> np.ndarray:
    """Labels (1, 2, ...) of the 4-connected regions of `mask`, 0 elsewhere, numbered in row-major
    order of their first cell (as scipy.ndimage.label numbers them)."""
    rows, cols = mask.shape
    labels = np.zeros((rows, cols), dtype=np.int32)
    stack = np.empty(rows * cols, dtype=np.int64)
    count = 0
    for i in range(rows):
        for j in range(cols):
            if not mask[i, j] or labels[i, j]:
                continue
            count += 1
            labels[i, j] = count
            stack[0] = i * cols + j
            top = 1
            while top:
                top -= 1
                a, b = divmod(stack[top], cols)
                for na, nb in ((a - 1, b), (a + 1, b), (a, b - 1), (a, b + 1)):
                    if 0 <= na < rows and 0 <= nb < cols and mask[na, nb] and not labels[na, nb]:
                        labels[na, nb] = count
                        stack[top] = na * cols + nb
                        top += 1
    return labels


@njit
def nearest_cell(
    grid: np.ndarray,
    first_cell: np.ndarray,
    cell_m: float,
    min_certainty: int,
    x: float,
    y: float,
    within_m: float,
    skip: np.ndarray,
) -> np.ndarray:
    """The centre (2,; m) of the cell of `cells_near` (the same cells) nearest (x, y) (m), the
    first in row-major order of equally near ones; empty (0,) when there is none."""
    lo_i, lo_j, hi_i, hi_j = square(first_cell, grid.shape[0], cell_m, x, y, within_m)
    skipping = skip.size > 0
    best = math.inf
    out = np.empty(2)
    found = False
    for i in range(lo_i, hi_i):
        cx = ((i + first_cell[0]) + 0.5) * cell_m
        for j in range(lo_j, hi_j):
            if _counted(grid[i, j], min_certainty, skipping and skip[i, j]):
                cy = ((j + first_cell[1]) + 0.5) * cell_m
                distance = np.hypot(cx - x, cy - y)
                if distance < best:
                    best, found = distance, True
                    out[0], out[1] = cx, cy
    return out if found else out[:0]
