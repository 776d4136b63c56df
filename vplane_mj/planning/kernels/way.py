"""Following a way of waypoints, compiled: the speed its bends allow (`SpeedPolicy.bend_speed`)
and whether mapped cells block its next stretch (`vplane_plus`'s check of the way ahead)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

TURN = 2 * math.pi


@njit(cache=True)
def bend_speed(
    x: float,
    y: float,
    yaw: float,
    way: np.ndarray,
    bearings: np.ndarray,
    horizon_m: float,
    radius_m: float,
    limits: tuple[float, float, float],
) -> float:
    """The largest speed (m/s, at most the top speed) at which the robot at `x`, `y` (m),
    heading `yaw` (rad), turns to face each point of `way` (K, 2; world, m, in order along it)
    within `horizon_m` along the way before it has travelled the way's length to that point;
    `bearings[k]` (rad, world) is point k's from the robot (numpy's `arctan2`, taken by the
    caller: numpy's own routines may differ from the C library's in the last bit). Points
    within `radius_m` along the way do not count. `limits` are the top speed (m/s), turn rate
    (rad/s) and turn acceleration (rad/s^2). See `SpeedPolicy.bend_speed` for the rule."""
    top, rate, accel = limits
    quick = rate * rate / (2 * accel)  # the turn that the top turn rate does not limit
    travelled, slowest = 0.0, math.inf
    last_x, last_y = x, y
    for k in range(way.shape[0]):
        travelled += math.hypot(way[k, 0] - last_x, way[k, 1] - last_y)
        last_x, last_y = way[k, 0], way[k, 1]
        if travelled > horizon_m:
            break
        if travelled < radius_m:
            continue
        turn = abs((bearings[k] - yaw + math.pi) % TURN - math.pi)
        time = math.sqrt(2 * turn / accel) if turn <= quick else turn / rate + rate / (2 * accel)
        slowest = min(slowest, travelled / max(time, 1e-9))
    return min(top, slowest)


@njit(cache=True)
def blocked(x: float, y: float, way: np.ndarray, reach_m: float, cells: np.ndarray, gap_m: float) -> bool:
    """Whether one of `cells` (N, 2; m) lies closer than `gap_m` (m) to a point of `way` (K, 2;
    m) within `reach_m` of `x`, `y` (m)."""
    for k in range(way.shape[0]):
        if math.hypot(way[k, 0] - x, way[k, 1] - y) > reach_m:
            continue
        for c in range(cells.shape[0]):
            if math.hypot(cells[c, 0] - way[k, 0], cells[c, 1] - way[k, 1]) < gap_m:
                return True
    return False
