"""Geometry compiled: the path simplifier's tolerance check (`polyline.PathSimplifier`) and the
moving obstacles' positions (`motion.MotionTable`)."""

from __future__ import annotations

import numpy as np

from vplane_mj.kernels import njit


@njit
def beyond_tolerance(
    rel_x: np.ndarray, rel_y: np.ndarray, held: int, dx: float, dy: float, tolerance2: float
) -> bool:
    """Whether a point (rel_x[k], rel_y[k]), k < held (m, from the last vertex), lies farther than
    sqrt(`tolerance2`) from the segment from the last vertex to (dx, dy) (the arithmetic of
    `polyline.distances_to_segment`, squared)."""
    length2 = dx * dx + dy * dy
    for k in range(held):
        t = 0.0
        if length2 > 0:
            t = min(max((rel_x[k] * dx + rel_y[k] * dy) / length2, 0.0), 1.0)
        ex, ey = rel_x[k] - t * dx, rel_y[k] - t * dy
        if ex * ex + ey * ey > tolerance2:
            return True
    return False


@njit
def motion_positions(
    run_time_s: float,
    starts: np.ndarray,
    times: np.ndarray,
    points: np.ndarray,
    tangents: np.ndarray,
    loops: np.ndarray,
    kinds: np.ndarray,
    phases: np.ndarray,
    out: np.ndarray,
) -> None:
    """Write each motion's position (m) at run time `run_time_s` (s) into out[m, :2]: the
    arithmetic of `motion.Motion.position` for the packed motions of a `motion.MotionTable`
    (kinds: 0 spline, 1 linear)."""
    for m in range(starts.shape[0] - 1):
        first, last = starts[m], starts[m + 1] - 1
        duration = times[last]
        t = run_time_s + phases[m]
        t = t % duration if loops[m] else min(max(t, 0.0), duration)
        segment = first
        while segment < last - 1 and times[segment + 1] <= t:
            segment += 1
        f = (t - times[segment]) / (times[segment + 1] - times[segment])
        for axis in range(2):
            p0, p1 = points[segment, axis], points[segment + 1, axis]
            if kinds[m] == 1:
                out[m, axis] = p0 + f * (p1 - p0)
            else:
                f2, f3 = f * f, f * f * f
                out[m, axis] = (
                    (2 * f3 - 3 * f2 + 1) * p0
                    + (-2 * f3 + 3 * f2) * p1
                    + (f3 - 2 * f2 + f) * tangents[segment, axis]
                    + (f3 - f2) * tangents[segment + 1, axis]
                )
