"""The governor's memory of obstacle points, compiled (`motion.Governor`): which remembered
points the sensor no longer looks at, one point kept per square cell, and the points to steer
among in the robot's frame."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit
from vplane_mj.kernels.maps.map_update import remainder_of_turn, side_of, sure_off_line
from vplane_mj.kernels.motion.outline import closer


@njit
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
    edges = (math.cos(yaw + low), math.sin(yaw + low), math.cos(yaw + low + span), math.sin(yaw + low + span))
    for k in range(remembered.shape[0]):
        rel_x, rel_y = remembered[k, 0] - x, remembered[k, 1] - y
        if closer(rel_x, rel_y, reach_m):
            if view == 0:
                unseen[k] = True
            elif view < 0:
                unseen[k] = not _in_view(rel_x, rel_y, yaw, low, span, edges)
    known = np.concatenate((points, remembered[unseen]))
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.empty_like(known)
    for k in range(known.shape[0]):
        rel_x, rel_y = known[k, 0] - x, known[k, 1] - y
        local[k, 0] = c * rel_x + s * rel_y
        local[k, 1] = -s * rel_x + c * rel_y
    return local, known[_first_in_each_cell(known, cell_m)]


@njit
def _in_view(rel_x, rel_y, yaw, low, span, edges):
    """Whether the point (`rel_x`, `rel_y`; m from the robot) is in view: its bearing past `low`
    (rad, robot frame; the robot heading `yaw`), modulo a turn, at most `span`. Decided by which
    side of the view's two edges (`edges`: the unit vectors of its first and last bearing,
    world) it lies on, wherever it lies surely off both (`map_update.side_of`); on an edge, by
    the angles themselves (an arctangent costs some twenty products)."""
    first_x, first_y, last_x, last_y = edges
    sure = sure_off_line(rel_x, rel_y)
    past_first = side_of(first_x, first_y, rel_x, rel_y, sure)  # 1: counter-clockwise of it
    past_last = side_of(last_x, last_y, rel_x, rel_y, sure)
    if past_first != 0 and past_last != 0:
        if span > math.pi:  # out of view: in the gap, past the last edge and short of the first
            return not (past_last > 0 and past_first < 0)
        return past_first > 0 and past_last < 0
    return remainder_of_turn(math.atan2(rel_y, rel_x) - yaw - low) <= span


@njit
def _first_in_each_cell(points: np.ndarray, cell_m: float) -> np.ndarray:
    """Indices (ascending) of the first of `points` (N, 2; m) in each square cell of `cell_m`:
    what `np.unique` of the cells' keys with `return_index` gives, sorted, by one pass with a
    hash table of the cells seen."""
    count = points.shape[0]
    size = 2
    while size < 2 * count:
        size *= 2
    cells = np.empty(count, dtype=np.int64)
    for k in range(count):  # a loop of its own, which the compiler runs on many points at once
        cells[k] = math.floor(points[k, 0] / cell_m) * (1 << 32) + math.floor(points[k, 1] / cell_m)
    keys = np.empty(size, dtype=np.int64)
    taken = np.zeros(size, dtype=np.bool_)
    first = np.empty(count, dtype=np.int64)
    found = 0
    for k in range(count):
        key = cells[k]
        slot = np.int64((np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(32)) & (size - 1)
        while taken[slot] and keys[slot] != key:
            slot = (slot + 1) & (size - 1)
        if not taken[slot]:
            taken[slot], keys[slot] = True, key
            first[found] = k
            found += 1
    return first[:found]
