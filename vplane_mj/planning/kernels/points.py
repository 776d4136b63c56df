"""A scan's echoes as world points, compiled (`Observation.echo_points`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
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
