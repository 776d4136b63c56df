"""Distances from points to a convex footprint at many poses, compiled (`motion.pose_distances`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def pose_distances(
    footprint: np.ndarray, normals: np.ndarray, local: np.ndarray, poses: np.ndarray
) -> np.ndarray:
    """Distance (m) from each point of `local` (N, 2) to the convex `footprint` (k, 2; counter-
    clockwise, with each edge's outward unit normal in `normals`, k x 2) placed at each of
    `poses` (M, 3: x, y in m, yaw in rad, all in the frame of `local`): (M, N), 0 inside."""
    count, sides = local.shape[0], footprint.shape[0]
    out = np.empty((poses.shape[0], count))
    for m in range(poses.shape[0]):
        c, s = math.cos(poses[m, 2]), math.sin(poses[m, 2])
        for n in range(count):
            dx, dy = local[n, 0] - poses[m, 0], local[n, 1] - poses[m, 1]
            x, y = c * dx + s * dy, -s * dx + c * dy  # the point seen from the footprint
            outside = False
            gap = math.inf
            for k in range(sides):
                ax, ay = footprint[k, 0], footprint[k, 1]
                nxt = (k + 1) % sides
                ex, ey = footprint[nxt, 0] - ax, footprint[nxt, 1] - ay
                px, py = x - ax, y - ay
                if px * normals[k, 0] + py * normals[k, 1] > 0.0:
                    outside = True
                t = min(max((px * ex + py * ey) / (ex * ex + ey * ey), 0.0), 1.0)
                gap = min(gap, math.hypot(px - t * ex, py - t * ey))
            out[m, n] = gap if outside else 0.0
    return out
