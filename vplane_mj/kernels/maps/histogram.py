"""The VFH polar histogram, compiled (`vplane_mj.planning.perception.histogram` describes it)."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit
from vplane_mj.kernels.maps.grid import cells_near

NO_SKIP = np.zeros((0, 0), dtype=np.bool_)


@njit
def polar_histogram(
    origin: np.ndarray,
    cells: np.ndarray,
    certainty: np.ndarray,
    n_sectors: int,
    window_m: float,
    enlarge_m: float,
) -> np.ndarray:
    """Obstacle density per sector (n_sectors,) around `origin` (m) from map cells (N, 2; m) of
    `certainty` (N,). Each cell within `window_m` adds c^2 (window_m - d) to the sectors within
    asin(enlarge_m / d) of its bearing: its run [first, last] of a difference array over three
    laps of the circle (every start, then every end, each in cell order), summed and folded
    back onto one."""
    sector = 2 * math.pi / n_sectors
    count = cells.shape[0]
    first = np.empty(count, dtype=np.int64)
    last = np.empty(count, dtype=np.int64)
    magnitude = np.empty(count)
    inside = 0
    for k in range(count):
        rel_x, rel_y = cells[k, 0] - origin[0], cells[k, 1] - origin[1]
        d = math.hypot(rel_x, rel_y)
        if not d < window_m:
            continue
        bearing = math.atan2(rel_y, rel_x)
        if bearing < 0.0:
            bearing += 2 * math.pi  # [0, 2 pi), as % would
        half = math.asin(min(1.0, enlarge_m / max(d, 1e-6)))
        magnitude[inside] = certainty[k] * certainty[k] * (window_m - d)
        first[inside] = math.floor((bearing - half) / sector) + n_sectors
        last[inside] = min(math.floor((bearing + half) / sector) + n_sectors, first[inside] + (n_sectors - 1))
        inside += 1
    steps = np.zeros(3 * n_sectors + 1)
    for k in range(inside):
        steps[first[k]] += magnitude[k]
    for k in range(inside):
        steps[last[k] + 1] -= magnitude[k]
    h = np.zeros(n_sectors)
    total = 0.0
    for k in range(3 * n_sectors):
        total += steps[k]
        h[k % n_sectors] += total
    return h


@njit
def grid_histogram(
    grid: np.ndarray,
    first_cell: np.ndarray,
    cell_m: float,
    min_certainty: int,
    origin: np.ndarray,
    n_sectors: int,
    window_m: float,
    enlarge_m: float,
) -> tuple[np.ndarray, int]:
    """`polar_histogram` of the grid cells at or above `min_certainty` in the square around `origin`
    that holds the window (`cells_near`), and how many such cells the square holds."""
    cells, certainty = cells_near(
        grid, first_cell, cell_m, min_certainty, origin[0], origin[1], window_m, NO_SKIP
    )
    h = polar_histogram(origin, cells, certainty.astype(np.float64), n_sectors, window_m, enlarge_m)
    return h, cells.shape[0]
