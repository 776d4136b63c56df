"""VFH polar histogram of the local map, its valleys and their widths (paper Algorithm 1, fig. 6).

Angles in radians, world frame; sector k covers [k, k+1) * sector width from +x. Each map
cell within `window_m` adds c^2 (window_m - d) to the sectors it blocks (Borenstein and
Koren's VFH magnitude); as in VFH+ a cell is enlarged by the robot radius plus a clearance,
so it blocks every sector within asin(enlarge / d) of its bearing, and any free sector is a
direction the robot's disc fits through. The sum is compiled (`kernels.histogram`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.perception.localmap import LocalMap


@dataclass(frozen=True)
class Valley:
    """A run of free sectors: first and last sector (inclusive, counter-clockwise) and count."""

    first: int
    last: int
    count: int


def polar_histogram(
    origin: np.ndarray,
    cells: np.ndarray,
    certainty: np.ndarray,
    n_sectors: int,
    window_m: float,
    enlarge_m: float,
) -> np.ndarray:
    """Obstacle density per sector (n_sectors,) around `origin` from map cells (N, 2)."""
    from vplane_mj.kernels.maps import histogram  # numba: loaded by the first call

    return histogram.polar_histogram(
        np.asarray(origin, float),
        np.asarray(cells, float).reshape(-1, 2),
        np.asarray(certainty, float),
        int(n_sectors),
        float(window_m),
        float(enlarge_m),
    )


def map_histogram(
    local_map: LocalMap,
    min_certainty: int,
    origin: np.ndarray,
    n_sectors: int,
    window_m: float,
    enlarge_m: float,
) -> tuple[np.ndarray, int]:
    """`polar_histogram` of the map cells at or above `min_certainty` in the square around `origin`
    that holds the window (`LocalMap.cells`), and how many such cells the square holds."""
    from vplane_mj.kernels.maps import histogram  # numba: loaded by the first call

    if local_map.origin is None:
        return np.zeros(n_sectors), 0
    return histogram.grid_histogram(
        local_map.grid,
        local_map.origin,
        local_map.cell_m,
        int(min_certainty),
        np.asarray(origin, float),
        int(n_sectors),
        float(window_m),
        float(enlarge_m),
    )


def sector_of(bearing: float, n_sectors: int) -> int:
    """The sector that holds `bearing` (rad)."""
    return int((bearing % (2 * math.pi)) // (2 * math.pi / n_sectors)) % n_sectors


def find_valleys(blocked: np.ndarray) -> list[Valley]:
    """Circular runs of free (not blocked) sectors; one valley of all sectors when none is blocked."""
    n = len(blocked)
    if not blocked.any():
        return [Valley(0, n - 1, n)]
    start = int(np.argmax(blocked))  # begin the scan on a blocked sector so no run is split
    valleys, run_start = [], None
    for step in range(1, n + 1):
        k = (start + step) % n
        if not blocked[k] and run_start is None:
            run_start = k
        if blocked[k] and run_start is not None:
            count = (k - run_start) % n
            valleys.append(Valley(run_start, (k - 1) % n, count))
            run_start = None
    return valleys


def nearest_wide_valley(
    valleys: list[Valley], bearing: float, n_sectors: int, min_sectors: int
) -> tuple[Valley | None, int]:
    """The valley at least `min_sectors` wide nearest to `bearing`, and how many sectors away.

    The distance is 0 when `bearing` lies in the valley; (None, n_sectors) when none is wide.
    """
    target = sector_of(bearing, n_sectors)
    best, best_gap = None, n_sectors
    for valley in valleys:
        if valley.count < min_sectors:
            continue
        offset = (target - valley.first) % n_sectors
        gap = 0 if offset < valley.count else min(offset - valley.count + 1, n_sectors - offset)
        if gap < best_gap:
            best, best_gap = valley, gap
    return best, best_gap
