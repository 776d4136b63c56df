"""How far a motion of a convex footprint intrudes on points, and how far it turns in place
before it does, compiled (`motion.intrusion`, `motion.free_turn`), from the points' distances
to the footprint at the motion's poses.

A distance is the C library's `hypot`, as numpy's; it costs some twenty times a product, so
it is taken only where a squared distance cannot decide: a squared distance carries a
rounding error of a few parts in 1e16, and a comparison it decides with a margin of SURE (a
relative 1e-9, and 1e-9 m) comes out as the distance's would (`_surely_beyond`, `closer`,
`_gap`): the same numbers as `hypot` everywhere.
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit

SURE = 1e-9
SURE_M = 1e-9
"""The relative and absolute (m) margins by which a comparison of squares decides one of
distances."""


@njit
def _gap(footprint: np.ndarray, normals: np.ndarray, x: float, y: float) -> float:
    """Distance (m) from the point (x, y), in the footprint's frame, to the convex `footprint`
    (k, 2; counter-clockwise, each edge's outward unit normal in `normals`); 0 inside: the
    least `hypot` to an edge, taken only for the edges whose squared distance may be least."""
    sides = footprint.shape[0]
    outside = False
    least = math.inf
    for k in range(sides):
        nxt = (k + 1) % sides
        if (x - footprint[k, 0]) * normals[k, 0] + (y - footprint[k, 1]) * normals[k, 1] > 0.0:
            outside = True
        gx, gy = _to_edge(footprint[k, 0], footprint[k, 1], footprint[nxt, 0], footprint[nxt, 1], x, y)
        least = min(least, gx * gx + gy * gy)
    if not outside:
        return 0.0
    gap = math.inf
    for k in range(sides):
        nxt = (k + 1) % sides
        gx, gy = _to_edge(footprint[k, 0], footprint[k, 1], footprint[nxt, 0], footprint[nxt, 1], x, y)
        if gx * gx + gy * gy <= least * (1.0 + SURE):
            gap = min(gap, math.hypot(gx, gy))
    return gap


@njit
def _to_edge(ax: float, ay: float, bx: float, by: float, x: float, y: float) -> tuple[float, float]:
    """The vector (m) from the nearest point of the edge a -> b to the point (x, y)."""
    ex, ey = bx - ax, by - ay
    px, py = x - ax, y - ay
    t = min(max((px * ex + py * ey) / (ex * ex + ey * ey), 0.0), 1.0)
    return px - t * ex, py - t * ey


@njit
def _surely_beyond(dx: float, dy: float, bound: float) -> bool:
    """Whether hypot(dx, dy) (m) exceeds `bound` (m) by more than any rounding, judged by the
    square alone (False: maybe not)."""
    limit = bound * (1.0 + SURE) + SURE_M
    return bound > 0.0 and dx * dx + dy * dy > limit * limit


@njit(inline="always")
def closer(dx: float, dy: float, bound: float) -> bool:
    """hypot(dx, dy) < `bound` (m), the C library's `hypot` (numpy's) taken only where the square
    does not decide: a squared distance carries a rounding error of a few parts in 1e16, and a
    comparison it decides with a margin of SURE (relative) and SURE_M comes out as the
    distance's would."""
    if _surely_beyond(dx, dy, bound):
        return False
    within = bound * (1.0 - SURE) - SURE_M
    if within > 0.0 and dx * dx + dy * dy < within * within:
        return True
    return math.hypot(dx, dy) < bound


@njit(inline="always")
def _beyond_box(x: float, y: float, box: tuple[float, float, float, float], bound: float) -> bool:
    """Whether the point (x, y) lies more than `bound` (m) and SURE_M beyond the box (x low, x
    high, y low, y high; m) that holds the footprint, along x or y: then farther than `bound`
    from the footprint itself, surely (the footprint's distance, `_gap`, is at least that)."""
    return max(box[0] - x, x - box[1], box[2] - y, y - box[3]) > bound + SURE_M


@njit
def first_blocked_turn(
    footprint: np.ndarray,
    normals: np.ndarray,
    local: np.ndarray,
    near_m: float,
    angles: np.ndarray,
    margin_m: float,
) -> int:
    """The first of `angles` (rad; the first 0, ascending in size) at which the footprint,
    turned in place, comes closer to a point of `local` (N, 2) than both `margin_m` and the
    point's distance at the first angle less 1e-9 m (`motion.free_turn`); -1 at none. Only the
    points nearer than `near_m` to the origin count."""
    count = 0
    near = np.empty(local.shape[0], dtype=np.int64)
    for n in range(local.shape[0]):
        if closer(local[n, 0], local[n, 1], near_m):
            near[count] = n
            count += 1
    limits = np.empty(count)
    c, s = math.cos(angles[0]), math.sin(angles[0])
    for k in range(count):
        x, y = local[near[k], 0], local[near[k], 1]
        limits[k] = min(margin_m, _gap(footprint, normals, c * x + s * y, -s * x + c * y) - 1e-9)
    for m in range(1, angles.shape[0]):
        c, s = math.cos(angles[m]), math.sin(angles[m])
        for k in range(count):
            x, y = local[near[k], 0], local[near[k], 1]
            if _gap(footprint, normals, c * x + s * y, -s * x + c * y) < limits[k]:
                return m
    return -1


@njit
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
    """The largest min(margins[m], d0) - d over the points of `local` (N, 2) and `poses` (M >= 1,
    3: x, y in m, yaw in rad, in the frame of `local`), d a point's distance to the convex
    `footprint` (k, 2; counter-clockwise, each edge's outward unit normal in `normals`; 0
    inside) at pose m and d0 at the first pose, and 0 at least (`motion.intrusion`); margins[m]
    is `margin_m` plus `growth` times the way the outline has swept up to pose m (its travel
    plus `radius_m`, the footprint's circumscribed radius, times its turn). Only the points
    within reach of the motion are measured (those in the box around the poses' origins that
    holds every point within `radius_m` and the last margin, the largest, of one), and a point
    whose distance to pose m's origin less `radius_m`, or to the box that holds the footprint
    at pose m, already keeps it from raising the largest so far is not measured there. Returns
    as soon as the largest exceeds `enough` (inf: the exact largest)."""
    steps = poses.shape[0]
    margins = np.empty(steps)
    margins[0] = margin_m + growth * 0.0
    swept = 0.0
    low_x, high_x, low_y, high_y = poses[0, 0], poses[0, 0], poses[0, 1], poses[0, 1]
    for m in range(1, steps):
        way = math.hypot(poses[m, 0] - poses[m - 1, 0], poses[m, 1] - poses[m - 1, 1]) + radius_m * abs(
            poses[m, 2] - poses[m - 1, 2]
        )
        swept = way if m == 1 else swept + way  # a cumulative sum, as numpy's
        margins[m] = margin_m + growth * swept
        low_x, high_x = min(low_x, poses[m, 0]), max(high_x, poses[m, 0])
        low_y, high_y = min(low_y, poses[m, 1]), max(high_y, poses[m, 1])
    reach = (radius_m + margins[steps - 1]) * (1.0 + SURE) + SURE_M
    near = np.empty(local.shape[0], dtype=np.bool_)
    for n in range(local.shape[0]):
        x, y = local[n, 0], local[n, 1]
        near[n] = low_x - reach <= x <= high_x + reach and low_y - reach <= y <= high_y + reach
    local = local[near]
    count = local.shape[0]
    if count == 0:
        return 0.0
    box = (footprint[:, 0].min(), footprint[:, 0].max(), footprint[:, 1].min(), footprint[:, 1].max())
    # A point surely the largest margin away from the footprint at the first pose (its distance
    # from that pose's origin less radius_m is, or from the footprint's box) is allowed the
    # margins themselves: its own distance is not needed.
    first = np.empty(count)
    widest = margins[steps - 1]
    c, s = math.cos(poses[0, 2]), math.sin(poses[0, 2])
    for n in range(count):
        dx, dy = local[n, 0] - poses[0, 0], local[n, 1] - poses[0, 1]
        x, y = c * dx + s * dy, -s * dx + c * dy
        if _surely_beyond(dx, dy, widest + radius_m) or _beyond_box(x, y, box, widest):
            first[n] = math.inf
        else:
            first[n] = _gap(footprint, normals, x, y)
    worst = 0.0
    for m in range(1, steps):
        c, s = math.cos(poses[m, 2]), math.sin(poses[m, 2])
        for n in range(count):
            allowed = min(margins[m], first[n])
            dx, dy = local[n, 0] - poses[m, 0], local[n, 1] - poses[m, 1]
            if _surely_beyond(dx, dy, allowed - worst + radius_m):
                continue  # farther than the circumscribed disc allows: cannot intrude more
            x, y = c * dx + s * dy, -s * dx + c * dy
            if _beyond_box(x, y, box, allowed - worst):
                continue  # as far from the footprint's box: cannot intrude more either
            gap = _gap(footprint, normals, x, y)
            if allowed - gap > worst:
                worst = allowed - gap
                if worst > enough:
                    return worst
    return worst
