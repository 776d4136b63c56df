"""The travelled path as a simplified polyline, built point by point (pure numpy)."""

from __future__ import annotations

import numpy as np


def distances_to_segment(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (m) from each of `points` (N, 2) to the segment a-b (a point when a == b)."""
    ab = b - a
    length2 = float(ab @ ab)
    t = np.zeros(len(points)) if length2 == 0.0 else np.clip((points - a) @ ab / length2, 0.0, 1.0)
    return np.hypot(*(points - (a + t[:, None] * ab)).T)


class PathSimplifier:
    """A polyline that passes within `tolerance_m` of every position added, with few vertices.

    Online simplification: the positions since the last vertex are held back; a new
    position extends the current edge while every held-back one lies within the tolerance
    of the straight segment from the last vertex to it, otherwise the previous position
    becomes a vertex. A straight run is one edge, a curve of radius r gets a vertex about
    every 2 sqrt(2 r tolerance) metres. At most `max_pending` positions are held back (a
    vertex is made then), which bounds the work per position.
    """

    def __init__(self, tolerance_m: float, max_pending: int = 200):
        self.tolerance_m = float(tolerance_m)
        self.max_pending = int(max_pending)
        self._vertices: list[tuple[float, float]] = []
        self._pending: list[tuple[float, float]] = []

    def add(self, x: float, y: float) -> None:
        """Append the position (x, y) (m)."""
        point = (float(x), float(y))
        if not self._vertices:
            self._vertices.append(point)
            return
        if self._pending:
            distances = distances_to_segment(
                np.array(self._pending), np.array(self._vertices[-1]), np.array(point)
            )
            if distances.max() > self.tolerance_m or len(self._pending) >= self.max_pending:
                self._vertices.append(self._pending[-1])
                self._pending = []
        self._pending.append(point)

    def polyline(self) -> list[tuple[float, float]]:
        """The vertices from the first position to the newest one."""
        return self._vertices + self._pending[-1:]
