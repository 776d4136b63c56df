"""The travelled path as a simplified polyline, built point by point (numpy, one compiled check)."""

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
        # The positions held back, relative to the last vertex: _rel_x[:_held], _rel_y[:_held].
        self._rel_x = np.empty(self.max_pending)
        self._rel_y = np.empty(self.max_pending)
        self._held = 0
        self._newest = (0.0, 0.0)

    def add(self, x: float, y: float) -> None:
        """Append the position (x, y) (m)."""
        point = (float(x), float(y))
        if not self._vertices:
            self._vertices.append(point)
            return
        held = self._held
        if held and (held >= self.max_pending or self._beyond_tolerance(held, point)):
            self._vertices.append(self._newest)
            held = 0
        ax, ay = self._vertices[-1]
        self._rel_x[held] = point[0] - ax
        self._rel_y[held] = point[1] - ay
        self._newest = point
        self._held = held + 1

    def _beyond_tolerance(self, held: int, point: tuple[float, float]) -> bool:
        """Whether a held-back position is farther than the tolerance from the edge from the
        last vertex to `point` (`kernels.beyond_tolerance`)."""
        from vplane_mj.geometry import kernels  # numba: loaded by the first call

        ax, ay = self._vertices[-1]
        dx, dy = point[0] - ax, point[1] - ay
        return kernels.beyond_tolerance(self._rel_x, self._rel_y, held, dx, dy, self.tolerance_m**2)

    def polyline(self) -> list[tuple[float, float]]:
        """The vertices from the first position to the newest one."""
        if not self._held:
            return list(self._vertices)
        return [*self._vertices, self._newest]
