"""The path simplifier's tolerance check, compiled (`polyline.PathSimplifier`)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
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
