"""Following a way of waypoints, compiled: the next waypoint the robot sees in a straight line,
the speed the way's bends allow (`SpeedPolicy.bend_speed`) and whether mapped cells block its
next stretch (`vplane_plus`'s check of the way ahead)."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit
from vplane_mj.kernels.motion.outline import closer

TURN = 2 * math.pi


@njit
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


@njit
def blocked(x: float, y: float, way: np.ndarray, reach_m: float, cells: np.ndarray, gap_m: float) -> bool:
    """Whether one of `cells` (N, 2; m) lies closer than `gap_m` (m) to a point of `way` (K, 2;
    m) within `reach_m` of `x`, `y` (m)."""
    for k in range(way.shape[0]):
        if math.hypot(way[k, 0] - x, way[k, 1] - y) > reach_m:
            continue
        for c in range(cells.shape[0]):
            if closer(cells[c, 0] - way[k, 0], cells[c, 1] - way[k, 1], gap_m):  # hypot's answer
                return True
    return False


@njit
def next_waypoint(x: float, y: float, way: np.ndarray, reach_m: float, sight: tuple) -> tuple[int, int]:
    """For the robot at `x`, `y` (m) on `way` (K >= 1, 2; m): the index of the way's point
    nearest it (the first of equally near ones), and of the farthest point of the run that
    follows it within `reach_m` (m) of the robot that it sees in a straight line
    (`segment_free` on `sight`; costs of 0 x 0: it sees every one), else the nearest's.
    Distances are the C library's `hypot`, as numpy's."""
    count = way.shape[0]
    distances = np.empty(count)
    nearest = 0
    for k in range(count):
        distances[k] = math.hypot(way[k, 0] - x, way[k, 1] - y)
        if distances[k] < distances[nearest]:
            nearest = k
    last = nearest
    while last + 1 < count and not distances[last + 1] > reach_m:
        last += 1
    for k in range(last, nearest, -1):  # the farthest first
        if segment_free(sight, x, y, way[k, 0], way[k, 1]):
            return nearest, k
    return nearest, nearest


@njit
def segment_free(sight: tuple, ax: float, ay: float, bx: float, by: float) -> bool:
    """Whether the points every half cell from a to b (m; `np.linspace`'s points, bit for bit,
    max(2, ceil(2 |b - a| / cell_m) + 1) of them) all lie on finite cells of a window's step
    costs or outside it: `sight` is the costs, the window's corner's x and y and its cell size
    `cell_m` (m)."""
    cost, corner_x, corner_y, cell_m = sight
    rows, cols = cost.shape
    dx, dy = bx - ax, by - ay
    steps = max(2, math.ceil(2 * math.hypot(dx, dy) / cell_m) + 1)
    div = steps - 1
    step_x, step_y = dx / div, dy / div
    tiny = step_x == 0 or step_y == 0  # linspace then scales by the whole difference
    for k in range(steps):
        if k == div:
            x, y = bx, by
        elif tiny:
            x, y = k / div * dx + ax, k / div * dy + ay
        else:
            x, y = k * step_x + ax, k * step_y + ay
        i = math.floor((x - corner_x) / cell_m)
        j = math.floor((y - corner_y) / cell_m)
        if 0 <= i < rows and 0 <= j < cols and not math.isfinite(cost[i, j]):
            return False
    return True
