"""A scan's echoes as world points, compiled (`Observation.echo_points`, `scan.repulsion_points`)."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
def echo_points(position: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray) -> np.ndarray:
    """World points (N, 2; m) of the finite `ranges` (m) along `bearings` (rad, robot frame) from
    `position` (m) at `yaw` (rad), in the beams' order: position + r (cos(yaw + b), sin(yaw + b))."""
    count = 0
    for k in range(ranges.shape[0]):
        if math.isfinite(ranges[k]):
            count += 1
    points = np.empty((count, 2))
    row = 0
    for k in range(ranges.shape[0]):
        r = ranges[k]
        if math.isfinite(r):
            angle = yaw + bearings[k]
            points[row, 0] = position[0] + r * math.cos(angle)
            points[row, 1] = position[1] + r * math.sin(angle)
            row += 1
    return points


@njit
def nearest_per_sector(
    position: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray, sectors: int
) -> np.ndarray:
    """World points (N, 2; m), as `echo_points`, of the nearest finite echo in each of `sectors`
    sectors (bearings within half a sector of k 2 pi / `sectors`, robot frame), by sector; of
    equally near echoes the first; sectors without an echo give none."""
    width = 2 * math.pi / sectors
    nearest = np.full(sectors, -1, dtype=np.int64)
    for k in range(ranges.shape[0]):
        if not math.isfinite(ranges[k]):
            continue
        sector = math.floor(bearings[k] / width + 0.5) % sectors
        if nearest[sector] < 0 or ranges[k] < ranges[nearest[sector]]:
            nearest[sector] = k
    count = 0
    for sector in range(sectors):
        count += nearest[sector] >= 0
    points = np.empty((count, 2))
    row = 0
    for sector in range(sectors):
        k = nearest[sector]
        if k >= 0:
            angle = yaw + bearings[k]
            points[row, 0] = position[0] + ranges[k] * math.cos(angle)
            points[row, 1] = position[1] + ranges[k] * math.sin(angle)
            row += 1
    return points
