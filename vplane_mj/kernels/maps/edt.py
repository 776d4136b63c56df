"""The exact Euclidean distance transform of a grid, compiled (Meijster, Roerdink and Hesselink's
two passes: along each column, then the lower envelope of parabolas along each row).

Each distance is the square root of a whole number of squared cells, so it is the same, bit for
bit, as scipy.ndimage.distance_transform_edt's.
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
def distance_transform(free: np.ndarray) -> np.ndarray:
    """Distance (cells) from each cell of `free` (nx, ny bool) to the nearest cell that is not
    free (0 on those); inf everywhere when every cell is free."""
    nx, ny = free.shape
    if free.all():
        return np.full((nx, ny), np.inf)
    far = nx + ny  # farther than any cell of the grid
    column = np.empty((nx, ny), dtype=np.int64)  # distance along axis 0 to the nearest non-free cell
    for j in range(ny):  # down the columns, then back up, a row at a time (the grid's order)
        column[0, j] = far if free[0, j] else 0
    for i in range(1, nx):
        for j in range(ny):
            column[i, j] = min(column[i - 1, j] + 1, far) if free[i, j] else 0
    for i in range(nx - 2, -1, -1):
        for j in range(ny):
            if column[i + 1, j] < column[i, j]:
                column[i, j] = column[i + 1, j] + 1
    out = np.empty((nx, ny))
    apex = np.empty(ny, dtype=np.int64)  # the parabolas of the lower envelope, by their apex
    start = np.empty(ny, dtype=np.int64)  # where each begins to be the lowest
    for i in range(nx):
        g = column[i]
        count = 0
        apex[0], start[0] = 0, 0
        for u in range(1, ny):
            while count >= 0 and _height(start[count], apex[count], g[apex[count]]) > _height(
                start[count], u, g[u]
            ):
                count -= 1
            if count < 0:
                count = 0
                apex[0], start[0] = u, 0
            else:
                w = 1 + _separation(apex[count], u, g[apex[count]], g[u])
                if w < ny:
                    count += 1
                    apex[count], start[count] = u, w
        for u in range(ny - 1, -1, -1):
            out[i, u] = math.sqrt(float(_height(u, apex[count], g[apex[count]])))
            if u == start[count]:
                count -= 1
    return out


@njit
def _height(x, apex, g_apex):
    """The squared distance (cells^2) from column x of a row to the nearest non-free cell of
    column `apex` (its distance `g_apex` along the column)."""
    return (x - apex) * (x - apex) + g_apex * g_apex


@njit
def _separation(a, b, g_a, g_b):
    """The last column (a < b) at which the parabola of `a` (its column's distance `g_a`) is at
    most that of `b` (`g_b`)."""
    return (b * b - a * a + g_b * g_b - g_a * g_a) // (2 * (b - a))
