"""A scan's echoes as world points, compiled (`Observation.echo_points`, `scan.repulsion_points`)."""

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


@njit(cache=True)
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


@njit(cache=True)
def remembered_with_unseen(
    points: np.ndarray,
    remembered: np.ndarray,
    position: np.ndarray,
    yaw: float,
    reach_m: float,
    view: np.ndarray,
    memory_cell_m: float,
) -> tuple[np.ndarray, np.ndarray]:
    """`points` (N, 2; world, m) followed by the `remembered` ones (M, 2) within `reach_m` of
    `position` that lie out of view, and which of those rows to remember: the first of each
    square of `memory_cell_m` (m), in their order (`motion.Governor._with_unseen`). `view`
    is (low, span) of the field of view (rad, robot frame, from low counter-clockwise; a span
    of 2 pi or more sees all round, a negative one nothing)."""
    low, span = view[0], view[1]
    unseen = np.zeros(remembered.shape[0], dtype=np.bool_)
    count = points.shape[0]
    for k in range(remembered.shape[0]):
        rel_x, rel_y = remembered[k, 0] - position[0], remembered[k, 1] - position[1]
        if not np.hypot(rel_x, rel_y) < reach_m:
            continue
        if span >= 2 * math.pi:
            in_view = True
        elif span < 0.0:
            in_view = False
        else:
            in_view = (np.arctan2(rel_y, rel_x) - yaw - low) % (2 * math.pi) <= span
        if not in_view:
            unseen[k] = True
            count += 1
    known = np.empty((count, 2))
    known[: points.shape[0]] = points
    row = points.shape[0]
    for k in range(remembered.shape[0]):
        if unseen[k]:
            known[row] = remembered[k]
            row += 1
    keys = np.empty(count, dtype=np.int64)
    for k in range(count):
        keys[k] = math.floor(known[k, 0] / memory_cell_m) * (1 << 32) + math.floor(
            known[k, 1] / memory_cell_m
        )
    order = np.argsort(keys, kind="mergesort")  # stable: the first of equal keys first
    first = np.empty(count, dtype=np.int64)
    kept = 0
    for k in range(count):
        if k == 0 or keys[order[k]] != keys[order[k - 1]]:
            first[kept] = order[k]
            kept += 1
    return known, np.sort(first[:kept])
