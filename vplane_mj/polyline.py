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
        self._pending = np.empty((self.max_pending, 2))
        self._held = 0  # positions held back, in _pending[:_held]

    def add(self, x: float, y: float) -> None:
        """Append the position (x, y) (m)."""
        point = (float(x), float(y))
        if not self._vertices:
            self._vertices.append(point)
            return
        held = self._held
        if held:
            pending = self._pending[:held]
            if held >= self.max_pending or self._beyond_tolerance(pending, point):
                self._vertices.append((float(pending[-1, 0]), float(pending[-1, 1])))
                held = 0
        self._pending[held] = point
        self._held = held + 1

    def _beyond_tolerance(self, pending: np.ndarray, point: tuple[float, float]) -> bool:
        """Whether a held-back position is farther than the tolerance from the edge from the
        last vertex to `point` (the arithmetic of `distances_to_segment`, squared, in scalars)."""
        ax, ay = self._vertices[-1]
        dx, dy = point[0] - ax, point[1] - ay
        px, py = pending[:, 0] - ax, pending[:, 1] - ay
        length2 = dx * dx + dy * dy
        t = np.clip((px * dx + py * dy) / length2, 0.0, 1.0) if length2 > 0 else 0.0
        ex, ey = px - t * dx, py - t * dy
        return bool((ex * ex + ey * ey).max() > self.tolerance_m**2)

    def polyline(self) -> list[tuple[float, float]]:
        """The vertices from the first position to the newest one."""
        if not self._held:
            return list(self._vertices)
        newest = self._pending[self._held - 1]
        return [*self._vertices, (float(newest[0]), float(newest[1]))]
