"""The travelled path as a simplified polyline, built point by point (numpy, one compiled check)."""

from __future__ import annotations

import numpy as np


def distances_to_segment(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance (m) from each of `points` (N, 2) to the segment a-b (a point when a == b)."""
    ab = b - a
    length2 = float(ab[0] * ab[0] + ab[1] * ab[1])
    along = (points[:, 0] - a[0]) * ab[0] + (points[:, 1] - a[1]) * ab[1]  # not @: no BLAS
    t = np.zeros(len(points)) if length2 == 0.0 else np.clip(along / length2, 0.0, 1.0)
    return np.hypot(*(points - (a + t[:, None] * ab)).T)


class PathSimplifier:
    """A polyline that passes within `tolerance_m` of every position added, with few vertices.

    Online simplification: the positions since the last vertex are held back; a new
    position extends the current edge while every held-back one lies within the tolerance
    of the straight segment from the last vertex to it, otherwise the previous position
    becomes a vertex. A straight run is one edge, a curve of radius r gets a vertex about
    every 2 sqrt(2 r tolerance) metres. At most `max_pending` positions are held back (a
    vertex is made then), which bounds the work per position.

    With `max_vertices`, the polyline drawn never has more vertices: when the fine polyline
    (all the vertices above, kept) grows past it, its older part is drawn simplified again
    (Douglas-Peucker) with the coarse tolerance, doubled until that part takes at most half of
    `max_vertices`; the newest quarter stays fine. Every position then lies within
    `within_m` (the fine tolerance plus the coarse one) of the polyline drawn.
    """

    def __init__(self, tolerance_m: float, max_pending: int = 200, max_vertices: int | None = None):
        self.tolerance_m = float(tolerance_m)
        self.max_pending = int(max_pending)
        self.max_vertices = max_vertices
        self.within_m = self.tolerance_m
        """How far (m) any position added may lie from the polyline drawn."""
        self._vertices: list[tuple[float, float]] = []
        # The drawn polyline's coarse part, in place of the fine vertices before _coarse_end.
        self._coarse: list[tuple[float, float]] = []
        self._coarse_end = 0
        self._coarse_m = 2.0 * self.tolerance_m
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
            if self.max_vertices is not None and self._drawn_count() >= self.max_vertices:
                self._coarsen_older()
        ax, ay = self._vertices[-1]
        self._rel_x[held] = point[0] - ax
        self._rel_y[held] = point[1] - ay
        self._newest = point
        self._held = held + 1

    def _drawn_count(self) -> int:
        """The vertices of the polyline drawn, the newest position held back left out."""
        return len(self._coarse) + len(self._vertices) - self._coarse_end

    def _coarsen_older(self) -> None:
        """Draw all but the newest quarter of `max_vertices` fine vertices coarse: Douglas-Peucker
        with the coarse tolerance, doubled until they take at most half of `max_vertices`."""
        assert self.max_vertices is not None
        end = len(self._vertices) - self.max_vertices // 4
        older = np.array(self._vertices[: end + 1])  # to the first fine vertex after them
        kept = older[douglas_peucker(older, self._coarse_m)]
        while len(kept) > self.max_vertices // 2:
            self._coarse_m *= 2.0
            kept = older[douglas_peucker(older, self._coarse_m)]
        self._coarse = [(float(x), float(y)) for x, y in kept[:-1]]
        self._coarse_end = end
        self.within_m = self.tolerance_m + self._coarse_m

    def _beyond_tolerance(self, held: int, point: tuple[float, float]) -> bool:
        """Whether a held-back position is farther than the tolerance from the edge from the
        last vertex to `point` (`kernels.beyond_tolerance`)."""
        from vplane_mj.kernels import geometry as kernels  # numba: loaded by the first call

        ax, ay = self._vertices[-1]
        dx, dy = point[0] - ax, point[1] - ay
        return kernels.beyond_tolerance(self._rel_x, self._rel_y, held, dx, dy, self.tolerance_m**2)

    def polyline(self) -> list[tuple[float, float]]:
        """The vertices drawn from the first position to the newest one."""
        drawn = [*self._coarse, *self._vertices[self._coarse_end :]]
        return [*drawn, self._newest] if self._held else drawn


def douglas_peucker(points: np.ndarray, tolerance_m: float) -> np.ndarray:
    """Indices of the vertices of `points` (N, 2; m) that Douglas-Peucker keeps: the first, the
    last, and recursively the farthest from the chord between two kept ones while it lies more
    than `tolerance_m` from it. Every dropped point lies within `tolerance_m` of the polyline
    through the kept ones, in the part between the two kept vertices around it."""
    kept = np.zeros(len(points), dtype=bool)
    kept[[0, -1]] = True
    spans = [(0, len(points) - 1)]
    while spans:
        first, last = spans.pop()
        if last - first < 2:
            continue
        gaps = distances_to_segment(points[first + 1 : last], points[first], points[last])
        farthest = int(np.argmax(gaps))
        if gaps[farthest] > tolerance_m:
            middle = first + 1 + farthest
            kept[middle] = True
            spans += [(first, middle), (middle, last)]
    return np.flatnonzero(kept)
