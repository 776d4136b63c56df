"""How far a polygon robot stands from the obstacle cells of a grid, at many poses at once.

`footprint_clearance` gives, for each pose (x, y, yaw), the signed distance (m) from the robot's
footprint, a convex polygon, to the nearest centre of an occupied grid cell: the distance to the
outline when the centre lies outside the footprint, minus the distance to the outline when it
lies inside. Planners that check a rectangular robot's arcs call it for every sampled pose of
every arc (thousands a control tick), so the loop over poses and over the few cells around
each is a numba kernel: per pose it visits only the cells within reach of the footprint's
circumscribed disc, and skips those that cannot come closer than the best so far.

Importing this module imports numba; the kernel compiles on first use and is cached on disk.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def footprint_clearance(
    occupied: np.ndarray,
    first_cell: tuple[int, int],
    cell_m: float,
    footprint: np.ndarray,
    poses: np.ndarray,
    cap_m: float,
) -> np.ndarray:
    """Signed clearance (M,) in m of the footprint at each pose from the occupied cells' centres.

    `occupied` (rows, cols) bool: grid cell (i, j) is the world cell `first_cell` + (i, j), its
    centre at (first_cell + (i, j) + 1/2) * `cell_m`. `footprint` (k, 2): a convex polygon,
    counter-clockwise, in the robot's frame (m). `poses` (M, 3): x, y (m) and yaw (rad) in the
    world. A clearance of `cap_m` or more is reported as `cap_m` (cells farther than the
    circumscribed radius plus `cap_m` from a pose are not visited).
    """
    polygon = np.ascontiguousarray(footprint, dtype=float)
    radius = float(np.max(np.hypot(polygon[:, 0], polygon[:, 1])))
    out = np.empty(len(poses))
    _clearances(
        np.ascontiguousarray(occupied, dtype=np.bool_),
        int(first_cell[0]),
        int(first_cell[1]),
        float(cell_m),
        polygon,
        radius,
        np.ascontiguousarray(poses, dtype=float).reshape(-1, 3),
        float(cap_m),
        out,
    )
    return out


@njit(cache=True)
def _signed_distance(polygon: np.ndarray, px: float, py: float) -> float:
    """Signed distance (m) from the point (px, py) to the convex counter-clockwise polygon:
    negative inside."""
    inside = True
    nearest = math.inf
    count = polygon.shape[0]
    for k in range(count):
        ax, ay = polygon[k, 0], polygon[k, 1]
        ex, ey = polygon[(k + 1) % count, 0] - ax, polygon[(k + 1) % count, 1] - ay
        wx, wy = px - ax, py - ay
        if ex * wy - ey * wx < 0.0:  # right of a counter-clockwise edge: outside
            inside = False
        t = min(max((wx * ex + wy * ey) / (ex * ex + ey * ey), 0.0), 1.0)
        dx, dy = wx - t * ex, wy - t * ey
        nearest = min(nearest, dx * dx + dy * dy)
    distance = math.sqrt(nearest)
    return -distance if inside else distance


@njit(cache=True)
def _clearances(
    occupied: np.ndarray,
    first_i: int,
    first_j: int,
    cell: float,
    polygon: np.ndarray,
    radius: float,
    poses: np.ndarray,
    cap: float,
    out: np.ndarray,
) -> None:
    """Fill `out` (M,) with `footprint_clearance`'s values."""
    rows, cols = occupied.shape
    reach = radius + cap
    for m in range(poses.shape[0]):
        x, y, yaw = poses[m, 0], poses[m, 1], poses[m, 2]
        c, s = math.cos(yaw), math.sin(yaw)
        best = cap
        # Cells whose centre (first + i + 1/2) * cell lies within `reach` of the pose, per axis.
        i_lo = max(math.ceil((x - reach) / cell - 0.5) - first_i, 0)
        i_hi = min(math.floor((x + reach) / cell - 0.5) - first_i, rows - 1)
        j_lo = max(math.ceil((y - reach) / cell - 0.5) - first_j, 0)
        j_hi = min(math.floor((y + reach) / cell - 0.5) - first_j, cols - 1)
        for i in range(i_lo, i_hi + 1):
            cx = (first_i + i + 0.5) * cell - x
            for j in range(j_lo, j_hi + 1):
                if not occupied[i, j]:
                    continue
                cy = (first_j + j + 0.5) * cell - y
                # A centre at r from the pose is at least r - radius from the footprint.
                bound = radius + best
                if bound <= 0.0 or cx * cx + cy * cy >= bound * bound:
                    continue
                distance = _signed_distance(polygon, c * cx + s * cy, -s * cx + c * cy)
                if distance < best:
                    best = distance
        out[m] = best
