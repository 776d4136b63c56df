"""`dwa`'s arcs and the clearance along them, compiled (`dwa.arc_poses`, `ClearanceField.at`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def arc_points(x0: float, y0: float, yaw: float, travel: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Points (N, 2; m) after travelling `travel` (N,; m) along a circle while turning by `turn`
    (N,; rad) from (x0, y0) at `yaw` (rad): the chord 2 sin(turn / 2) / curvature (the travel
    itself when the turn is below 2e-12 rad) along yaw + turn / 2."""
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    out = np.empty((travel.shape[0], 2))
    for k in range(travel.shape[0]):
        half = turn[k] / 2
        sin_half, cos_half = math.sin(half), math.cos(half)
        chord = travel[k] * (sin_half / half if abs(half) > 1e-12 else 1.0)
        out[k, 0] = x0 + chord * (cos_yaw * cos_half - sin_yaw * sin_half)
        out[k, 1] = y0 + chord * (sin_yaw * cos_half + cos_yaw * sin_half)
    return out


@njit(cache=True)
def bilinear(
    values: np.ndarray, first_i: float, first_j: float, cell_m: float, points: np.ndarray
) -> np.ndarray:
    """`values` (rows, cols; at the centres of the cells from world cell (first_i, first_j), of
    `cell_m` m) at world points (N, 2; m), bilinear between the centres; points beyond the
    outermost centres take the border's values."""
    rows, cols = values.shape
    out = np.empty(points.shape[0])
    for k in range(points.shape[0]):
        u = points[k, 0] / cell_m - first_i - 0.5
        v = points[k, 1] / cell_m - first_j - 0.5
        i = min(max(math.floor(u), 0), rows - 2)
        j = min(max(math.floor(v), 0), cols - 2)
        fx = min(max(u - i, 0.0), 1.0)
        fy = min(max(v - j, 0.0), 1.0)
        below = values[i, j] + (values[i + 1, j] - values[i, j]) * fx
        above = values[i, j + 1] + (values[i + 1, j + 1] - values[i, j + 1]) * fx
        out[k] = below + (above - below) * fy
    return out
