"""Distances from points to a convex footprint at many poses, and how far a motion of the
footprint intrudes on them, compiled (`motion.pose_distances`, `motion.intrusion`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _gap(footprint: np.ndarray, normals: np.ndarray, x: float, y: float) -> float:
    """Distance (m) from the point (x, y), in the footprint's frame, to the convex `footprint`
    (k, 2; counter-clockwise, each edge's outward unit normal in `normals`); 0 inside."""
    sides = footprint.shape[0]
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
    return gap if outside else 0.0


@njit(cache=True)
def pose_distances(
    footprint: np.ndarray, normals: np.ndarray, local: np.ndarray, poses: np.ndarray
) -> np.ndarray:
    """Distance (m) from each point of `local` (N, 2) to the convex `footprint` (k, 2; counter-
    clockwise, with each edge's outward unit normal in `normals`, k x 2) placed at each of
    `poses` (M, 3: x, y in m, yaw in rad, all in the frame of `local`): (M, N), 0 inside."""
    count = local.shape[0]
    out = np.empty((poses.shape[0], count))
    for m in range(poses.shape[0]):
        c, s = math.cos(poses[m, 2]), math.sin(poses[m, 2])
        for n in range(count):
            dx, dy = local[n, 0] - poses[m, 0], local[n, 1] - poses[m, 1]
            out[m, n] = _gap(footprint, normals, c * dx + s * dy, -s * dx + c * dy)
    return out


@njit(cache=True)
def intrusion(
    footprint: np.ndarray,
    normals: np.ndarray,
    radius_m: float,
    local: np.ndarray,
    poses: np.ndarray,
    margin_m: float,
    growth: float,
    enough: float,
) -> float:
    """The largest min(margins[m], d0) - d over the points of `local` (N, 2) and `poses` (M, 3,
    as in `pose_distances`; M >= 1), d a point's distance to the footprint at pose m and d0 at
    the first pose, and 0 at least (`motion.intrusion`); margins[m] is `margin_m` plus `growth`
    times the way the outline has swept up to pose m (its travel plus `radius_m`, the
    footprint's circumscribed radius, times its turn). Only the points within reach of the
    motion are measured, and a point whose distance to pose m's origin less `radius_m` already
    keeps it from raising the largest so far is not measured there. Returns as soon as the
    largest exceeds `enough` (inf: the exact largest)."""
    steps = poses.shape[0]
    margins = np.empty(steps)
    margins[0] = margin_m + growth * 0.0
    swept = 0.0
    farthest = math.hypot(poses[0, 0], poses[0, 1])
    for m in range(1, steps):
        way = math.hypot(poses[m, 0] - poses[m - 1, 0], poses[m, 1] - poses[m - 1, 1]) + radius_m * abs(
            poses[m, 2] - poses[m - 1, 2]
        )
        swept = way if m == 1 else swept + way  # a cumulative sum, as numpy's
        margins[m] = margin_m + growth * swept
        farthest = max(farthest, math.hypot(poses[m, 0], poses[m, 1]))
    reach = farthest + radius_m + margins[steps - 1]
    near = np.empty(local.shape[0], dtype=np.bool_)
    for n in range(local.shape[0]):
        near[n] = math.hypot(local[n, 0], local[n, 1]) < reach
    local = local[near]
    count = local.shape[0]
    if count == 0:
        return 0.0
    first = pose_distances(footprint, normals, local, poses[:1])[0]
    worst = 0.0
    for m in range(1, steps):
        c, s = math.cos(poses[m, 2]), math.sin(poses[m, 2])
        for n in range(count):
            allowed = min(margins[m], first[n])
            dx, dy = local[n, 0] - poses[m, 0], local[n, 1] - poses[m, 1]
            if math.hypot(dx, dy) - radius_m >= allowed - worst:
                continue  # farther than the circumscribed disc allows: cannot intrude more
            gap = _gap(footprint, normals, c * dx + s * dy, -s * dx + c * dy)
            if allowed - gap > worst:
                worst = allowed - gap
                if worst > enough:
                    return worst
    return worst
