"""VFH polar histogram of the local map, its valleys and their widths (paper Algorithm 1, fig. 6).

Angles in radians, world frame; sector k covers [k, k+1) * sector width from +x. Each map
cell within `window_m` adds c^2 (window_m - d) to the sectors it blocks (Borenstein and
Koren's VFH magnitude); as in VFH+ a cell is enlarged by the robot radius plus a clearance,
so it blocks every sector within asin(enlarge / d) of its bearing, and any free sector is a
direction the robot's disc fits through.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


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
    if len(cells) == 0:
        return np.zeros(n_sectors)
    rel = np.asarray(cells, float) - origin
    d = np.hypot(rel[:, 0], rel[:, 1])
    inside = d < window_m
    if not inside.any():
        return np.zeros(n_sectors)
    rel, d, c = rel[inside], d[inside], np.asarray(certainty)[inside]
    sector = 2 * math.pi / n_sectors
    bearing = np.arctan2(rel[:, 1], rel[:, 0])
    bearing = np.where(bearing < 0.0, bearing + 2 * math.pi, bearing)  # [0, 2 pi), as % would
    half = np.arcsin(np.minimum(1.0, enlarge_m / np.maximum(d, 1e-6)))
    magnitude = c * c * (window_m - d)
    # Each cell adds its magnitude to the run of sectors [first, last] (indices may wrap):
    # a difference array over two laps of the circle (every start, then every end, each in
    # cell order), folded back onto one.
    first = np.floor((bearing - half) / sector).astype(int) + n_sectors
    last = np.floor((bearing + half) / sector).astype(int) + n_sectors
    last = np.minimum(last, first + (n_sectors - 1))
    steps = np.bincount(
        np.concatenate((first, last + 1)), np.concatenate((magnitude, -magnitude)), 3 * n_sectors + 1
    )
    laps = np.cumsum(steps)[: 3 * n_sectors].reshape(3, n_sectors)
    return laps.sum(axis=0)


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
