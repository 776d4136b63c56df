"""A small local map accumulated from sonar echoes (a VFH-style certainty grid).

Cells are `cell_m` squares in the world frame, keyed by integer indices; each echo adds
one unit of certainty to the cell it falls in, up to `max_certainty`. Cells farther
than `keep_radius_m` from the robot are forgotten, so memory stays bounded however
long the run. The map is the planner's only memory of obstacles: it is built from the
sonar ring and the robot's pose alone.
"""

from __future__ import annotations

import math

import numpy as np


class LocalMap:
    """Certainty grid of obstacle cells around the robot (see the module docstring)."""

    def __init__(self, cell_m: float, keep_radius_m: float, max_certainty: int = 15):
        self.cell_m = cell_m
        self.keep_radius_m = keep_radius_m
        self.max_certainty = max_certainty
        self._cells: dict[tuple[int, int], int] = {}

    def __len__(self) -> int:
        return len(self._cells)

    def add_echoes(self, points: np.ndarray) -> None:
        """Raise the certainty of the cells that hold the echo points (N, 2) (m)."""
        for i, j in np.floor(np.asarray(points, float).reshape(-1, 2) / self.cell_m).astype(int):
            key = (int(i), int(j))
            self._cells[key] = min(self.max_certainty, self._cells.get(key, 0) + 1)

    def forget_far(self, position: np.ndarray) -> None:
        """Drop cells whose centre is farther than keep_radius_m from `position`."""
        limit = (self.keep_radius_m / self.cell_m) ** 2
        ci, cj = position[0] / self.cell_m - 0.5, position[1] / self.cell_m - 0.5
        far = [key for key in self._cells if (key[0] - ci) ** 2 + (key[1] - cj) ** 2 > limit]
        for key in far:
            del self._cells[key]

    def cells(self, min_certainty: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """Centres (N, 2) in metres and certainties (N,) of the cells at or above a certainty."""
        kept = [(key, c) for key, c in self._cells.items() if c >= min_certainty]
        if not kept:
            return np.empty((0, 2)), np.empty(0, dtype=int)
        keys = np.array([key for key, _ in kept], dtype=float)
        return (keys + 0.5) * self.cell_m, np.array([c for _, c in kept])


def cluster_points(points: np.ndarray, link_m: float) -> np.ndarray:
    """Label points (N, 2) so that points closer than `link_m` share a cluster (single linkage).

    Two obstacle points closer than the robot's width form one barrier, so `link_m` is
    normally the robot's diameter plus a clearance. Returns labels 0..K-1 (N,).
    """
    n = len(points)
    labels = np.full(n, -1)
    if n == 0:
        return labels
    near = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1)) < link_m
    current = 0
    for seed in range(n):
        if labels[seed] >= 0:
            continue
        labels[seed] = current
        frontier = [seed]
        while frontier:
            members = np.flatnonzero(near[frontier].any(axis=0) & (labels < 0))
            labels[members] = current
            frontier = list(members)
        current += 1
    return labels


def angular_extremes(origin: np.ndarray, points: np.ndarray) -> tuple[int, int, float]:
    """Indices of the two angular ends of `points` seen from `origin`, and the span (rad).

    The ends border the largest empty angular gap around `origin`, so a cluster that
    wraps around the robot (the robot inside a cup) gives the two sides of the mouth.
    The first index is the clockwise end (e1), the second the counter-clockwise end (e2).
    """
    rel = np.asarray(points, float) - origin
    bearings = np.arctan2(rel[:, 1], rel[:, 0])
    order = np.argsort(bearings)
    sorted_b = bearings[order]
    gaps = np.diff(np.concatenate([sorted_b, sorted_b[:1] + 2 * math.pi]))
    widest = int(np.argmax(gaps))
    ccw_end = order[widest]  # the gap starts after this one, going counter-clockwise
    cw_end = order[(widest + 1) % len(order)]
    span = 2 * math.pi - float(gaps[widest])
    return int(cw_end), int(ccw_end), span
