"""`dwa`'s arcs and the clearance along them, compiled (`dwa.arc_poses`, `ClearanceField.at`,
the round robot's free distance)."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit(inline="always")
def _arc_point(x0: float, y0: float, cos_yaw: float, sin_yaw: float, travel: float, turn: float) -> tuple:
    """The point (m) after travelling `travel` (m) along a circle while turning by `turn` (rad)
    from (x0, y0) heading (cos_yaw, sin_yaw): the chord 2 sin(turn / 2) / curvature (the travel
    itself when the turn is below 2e-12 rad) along yaw + turn / 2."""
    half = turn / 2
    sin_half, cos_half = math.sin(half), math.cos(half)
    chord = travel * (sin_half / half if abs(half) > 1e-12 else 1.0)
    return (
        x0 + chord * (cos_yaw * cos_half - sin_yaw * sin_half),
        y0 + chord * (sin_yaw * cos_half + cos_yaw * sin_half),
    )


@njit(inline="always")
def _bilinear_at(values: np.ndarray, first_i: float, first_j: float, cell_m: float, x: float, y: float):
    """`values` at the world point (x, y) (m); see `bilinear`."""
    rows, cols = values.shape
    u = x / cell_m - first_i - 0.5
    v = y / cell_m - first_j - 0.5
    i = min(max(math.floor(u), 0), rows - 2)
    j = min(max(math.floor(v), 0), cols - 2)
    fx = min(max(u - i, 0.0), 1.0)
    fy = min(max(v - j, 0.0), 1.0)
    below = values[i, j] + (values[i + 1, j] - values[i, j]) * fx
    above = values[i, j + 1] + (values[i + 1, j + 1] - values[i, j + 1]) * fx
    return below + (above - below) * fy


@njit
def arc_points(x0: float, y0: float, yaw: float, travel: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Points (N, 2; m) after travelling `travel` (N,; m) along a circle while turning by `turn`
    (N,; rad) from (x0, y0) at `yaw` (rad) (`_arc_point`)."""
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    out = np.empty((travel.shape[0], 2))
    for k in range(travel.shape[0]):
        out[k, 0], out[k, 1] = _arc_point(x0, y0, cos_yaw, sin_yaw, travel[k], turn[k])
    return out


@njit
def bilinear(
    values: np.ndarray, first_i: float, first_j: float, cell_m: float, points: np.ndarray
) -> np.ndarray:
    """`values` (rows, cols; at the centres of the cells from world cell (first_i, first_j), of
    `cell_m` m) at world points (N, 2; m), bilinear between the centres; points beyond the
    outermost centres take the border's values."""
    out = np.empty(points.shape[0])
    for k in range(points.shape[0]):
        out[k] = _bilinear_at(values, first_i, first_j, cell_m, points[k, 0], points[k, 1])
    return out


@njit
def first_hits(
    x0: float,
    y0: float,
    yaw: float,
    curvature: np.ndarray,
    lengths: np.ndarray,
    values: np.ndarray,
    first_i: float,
    first_j: float,
    cell_m: float,
    safe_m: float,
    goal: np.ndarray,
    goal_tolerance_m: float,
) -> np.ndarray:
    """For each arc of `curvature` (speeds, turns; 1/m) from (x0, y0) at `yaw`, sampled at the
    `lengths` (L,; m) along it: the index of the first sample whose clearance (`values`, as in
    `bilinear`) is below the limit, -1 when none is. The limit is `safe_m`, or the clearance
    at (x0, y0) when that is less (never closer than the robot already is). A sample at or
    after one within `goal_tolerance_m` of `goal` (m; a negative tolerance: never) is no hit:
    the arc has arrived."""
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    limit = min(safe_m, _bilinear_at(values, first_i, first_j, cell_m, x0, y0))
    rows, cols = curvature.shape
    first = np.full((rows, cols), -1, dtype=np.int64)
    for a in range(rows):
        for b in range(cols):
            for k in range(lengths.shape[0]):
                x, y = _arc_point(x0, y0, cos_yaw, sin_yaw, lengths[k], curvature[a, b] * lengths[k])
                if goal_tolerance_m >= 0.0 and np.hypot(x - goal[0], y - goal[1]) <= goal_tolerance_m:
                    break
                if _bilinear_at(values, first_i, first_j, cell_m, x, y) < limit:
                    first[a, b] = k
                    break
    return first


@njit
def objective(
    x0: float,
    y0: float,
    yaw: float,
    travel: np.ndarray,
    turned: np.ndarray,
    aim: np.ndarray,
    dist: np.ndarray,
    speeds: np.ndarray,
    weights: np.ndarray,
    lookahead_m: float,
    top_speed: float,
) -> np.ndarray:
    """dwa's objective (speeds, turns): alpha heading + beta dist / L + gamma speed / top, each
    term in [0, 1] (`weights` alpha, beta, gamma), the heading term 1 - |theta| / pi with theta
    the angle (wrapped into [-pi, pi)) from the robot's heading after travelling `travel[s]`
    (m) while turning by `turned[t]` (rad) from (x0, y0) at `yaw` (`_arc_point`) to `aim` (m)."""
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    rows, cols = travel.shape[0], turned.shape[0]
    out = np.empty((rows, cols))
    for s in range(rows):
        speed_term = weights[2] * (speeds[s] / top_speed)
        for t in range(cols):
            x, y = _arc_point(x0, y0, cos_yaw, sin_yaw, travel[s], turned[t])
            theta = (np.arctan2(aim[1] - y, aim[0] - x) - (yaw + turned[t]) + math.pi) % (
                2 * math.pi
            ) - math.pi
            out[s, t] = (
                weights[0] * (1 - abs(theta) / math.pi) + weights[1] * dist[s, t] / lookahead_m + speed_term
            )
    return out
