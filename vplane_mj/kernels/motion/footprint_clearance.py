"""How far a polygon robot stands from the obstacles of a grid, at many poses at once.

`footprint_clearance` gives, for each pose (x, y, yaw), the signed distance (m) from the robot's
footprint, a convex polygon, to the nearest obstacle: the centre of an occupied grid cell, or
one of a set of exact points (a laser's echoes); the distance to the outline when the obstacle
lies outside the footprint, minus the distance to the outline when it lies inside. Planners
that check a rectangular robot's arcs call it for every sampled pose of every arc (thousands
a control tick), so the loop over poses and over the few cells around each is a numba
kernel: per pose it visits only the cells within reach of the footprint's circumscribed disc
(the points binned by the cell that holds them), and skips those that cannot come closer
than the best so far.

Importing this module imports numba; the kernel compiles on first use and is cached on disk
(`vplane_mj.kernels`).
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit

RING_MARGIN_M = 1e-9
"""How much nearer (m) than its cells' bound a ring of cells is taken to be, so that rounding
(a point binned a cell off) never skips an obstacle."""


def footprint_clearance(
    occupied: np.ndarray,
    first_cell: tuple[int, int],
    cell_m: float,
    footprint: np.ndarray,
    poses: np.ndarray,
    cap_m: float,
    points: np.ndarray | None = None,
) -> np.ndarray:
    """Signed clearance (M,) in m of the footprint at each pose from the occupied cells' centres
    and the `points`.

    `occupied` (rows, cols) bool: grid cell (i, j) is the world cell `first_cell` + (i, j), its
    centre at (first_cell + (i, j) + 1/2) * `cell_m`. `footprint` (k, 2): a convex polygon,
    counter-clockwise, in the robot's frame (m). `poses` (M, 3): x, y (m) and yaw (rad) in the
    world. `points` (N, 2): obstacle points in the world (m); those off the grid are not seen.
    A clearance of `cap_m` or more is reported as `cap_m` (obstacles farther than the
    circumscribed radius plus `cap_m` from a pose are not visited).
    """
    polygon = np.ascontiguousarray(footprint, dtype=float)
    radius = float(np.max(np.hypot(polygon[:, 0], polygon[:, 1])))
    grid = np.ascontiguousarray(occupied, dtype=np.bool_)
    starts, binned = _bin_points(points, grid.shape, first_cell, cell_m)
    out = np.empty(len(poses))
    _clearances(
        grid,
        starts,
        binned,
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


def _bin_points(
    points: np.ndarray | None, shape: tuple[int, ...], first_cell: tuple[int, int], cell_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """The points on the grid sorted by the cell that holds them (row-major), and where each
    cell's points start: cell c holds binned[starts[c] : starts[c + 1]]."""
    rows, cols = shape
    if points is None or not len(points):
        return np.zeros(rows * cols + 1, dtype=np.int64), np.empty((0, 2))
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    cells = np.floor(points / cell_m).astype(np.int64) - np.asarray(first_cell, dtype=np.int64)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < rows) & (cells[:, 1] >= 0) & (cells[:, 1] < cols)
    flat = cells[inside, 0] * cols + cells[inside, 1]
    order = np.argsort(flat, kind="stable")
    starts = np.zeros(rows * cols + 1, dtype=np.int64)
    np.cumsum(np.bincount(flat, minlength=rows * cols), out=starts[1:])
    return starts, np.ascontiguousarray(points[inside][order])


@njit
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


@njit
def _may_be_nearer(radius: float, dx: float, dy: float, best: float) -> bool:
    """Whether an obstacle at (dx, dy) (m) from a pose may lie nearer than `best` to the
    footprint: one at r from the pose is at least r - radius (the circumscribed radius) from
    it. (The test takes numbers alone: an array handed to a compiled function costs two atomic
    reference counts a call.)"""
    bound = radius + best
    return bound > 0.0 and dx * dx + dy * dy < bound * bound


@njit
def _clearances(
    occupied: np.ndarray,
    starts: np.ndarray,
    points: np.ndarray,
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
    for m in range(poses.shape[0]):
        x, y, yaw = poses[m, 0], poses[m, 1], poses[m, 2]
        c, s = math.cos(yaw), math.sin(yaw)
        best = cap
        # The cells that hold a point within `reach` of the pose, per axis (their centres lie
        # within reach plus half a cell).
        reach = radius + cap
        i_lo = max(math.floor((x - reach) / cell) - first_i, 0)
        i_hi = min(math.floor((x + reach) / cell) - first_i, rows - 1)
        j_lo = max(math.floor((y - reach) / cell) - first_j, 0)
        j_hi = min(math.floor((y + reach) / cell) - first_j, cols - 1)
        # The square's cells ring by ring outward from the pose's cell: a point in ring r lies
        # more than (r - 1) cells from the pose, so once that is as far as the bound (the
        # circumscribed radius plus the best so far), no later ring holds a nearer obstacle.
        pose_i = math.floor(x / cell) - first_i
        pose_j = math.floor(y / cell) - first_j
        rings = max(pose_i - i_lo, i_hi - pose_i, pose_j - j_lo, j_hi - pose_j)
        for r in range(rings + 1 if i_lo <= i_hi and j_lo <= j_hi else 0):
            if (r - 1) * cell - RING_MARGIN_M >= radius + best:
                break
            for i in range(max(pose_i - r, i_lo), min(pose_i + r, i_hi) + 1):
                whole_row = abs(i - pose_i) == r  # else only the ring's two cells of the row
                j_first = max(pose_j - r, j_lo) if whole_row else pose_j - r
                j_step = 1 if whole_row else 2 * r
                cx = (first_i + i + 0.5) * cell - x
                for j in range(j_first, min(pose_j + r, j_hi) + 1, j_step):
                    if j < j_lo:
                        continue
                    if occupied[i, j]:
                        dx, dy = cx, (first_j + j + 0.5) * cell - y
                        if _may_be_nearer(radius, dx, dy, best):
                            best = min(best, _signed_distance(polygon, c * dx + s * dy, -s * dx + c * dy))
                    for k in range(starts[i * cols + j], starts[i * cols + j + 1]):
                        dx, dy = points[k, 0] - x, points[k, 1] - y
                        if _may_be_nearer(radius, dx, dy, best):
                            best = min(best, _signed_distance(polygon, c * dx + s * dy, -s * dx + c * dy))
        out[m] = best
