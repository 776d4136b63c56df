"""The governor's memory of obstacle points, compiled (`motion.Governor`): which remembered
points the sensor no longer looks at, one point kept per square cell, and the points to steer
among in the robot's frame."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from vplane_mj.planning.kernels.map_update import remainder_of_turn


@njit(cache=True)
def recall(
    points: np.ndarray,
    remembered: np.ndarray,
    x: float,
    y: float,
    yaw: float,
    reach_m: float,
    view: int,
    low: float,
    span: float,
    cell_m: float,
) -> tuple[np.ndarray, np.ndarray]:
    """`points` (N, 2; world, m) followed by the `remembered` points (M, 2) within `reach_m` of
    the robot at (x, y) heading `yaw` (rad) that lie out of the sensor's view: in the robot's
    frame (x forward, y left; m), what to steer among; and in the world, the first of them in
    each square cell of `cell_m` (the cell (floor(x / cell_m), floor(y / cell_m))), in their
    order, what to remember. `view` is 1 for a sensor that looks all round, 0 for none, else
    -1: a point's bearing (rad, robot frame) is in view when its angle past `low`, modulo a
    turn (`map_update.remainder_of_turn`, numpy's mod bit for bit), is at most `span`."""
    unseen = np.zeros(remembered.shape[0], dtype=np.bool_)
    for k in range(remembered.shape[0]):
        rel_x, rel_y = remembered[k, 0] - x, remembered[k, 1] - y
        if math.hypot(rel_x, rel_y) < reach_m:
            if view == 0:
                unseen[k] = True
            elif view < 0:
                unseen[k] = not (remainder_of_turn(math.atan2(rel_y, rel_x) - yaw - low) <= span)
    known = np.concatenate((points, remembered[unseen]))
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.empty_like(known)
    for k in range(known.shape[0]):
        rel_x, rel_y = known[k, 0] - x, known[k, 1] - y
        local[k, 0] = c * rel_x + s * rel_y
        local[k, 1] = -s * rel_x + c * rel_y
    return local, known[_first_in_each_cell(known, cell_m)]


@njit(cache=True)
def _first_in_each_cell(points: np.ndarray, cell_m: float) -> np.ndarray:
    """Indices (ascending) of the first of `points` (N, 2; m) in each square cell of `cell_m`:
    what `np.unique` of the cells' keys with `return_index` gives, sorted, by one pass with a
    hash table of the cells seen."""
    count = points.shape[0]
    size = 2
    while size < 2 * count:
        size *= 2
    keys = np.empty(size, dtype=np.int64)
    taken = np.zeros(size, dtype=np.bool_)
    first = np.empty(count, dtype=np.int64)
    found = 0
    for k in range(count):
        key = math.floor(points[k, 0] / cell_m) * (1 << 32) + math.floor(points[k, 1] / cell_m)
        slot = np.int64((np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(32)) & (size - 1)
        while taken[slot] and keys[slot] != key:
            slot = (slot + 1) & (size - 1)
        if not taken[slot]:
            taken[slot], keys[slot] = True, key
            first[found] = k
            found += 1
    return first[:found]
