"""A small local map accumulated from sonar echoes (a VFH-style certainty grid).

The grid is a square of `size_m` around the robot with cells of `cell_m`, anchored to
the world (it shifts by whole cells when the robot nears its edge; cells that fall off
are forgotten). Each sonar reading is treated as a real sonar's: the echo lies somewhere
on the arc of the beam at the measured range, and the cone in front of the arc is free.
Arc cells gain `hit` certainty (up to `max_certainty`), cone cells lose `miss`; so
phantom echoes (a wide beam grazing a corridor wall) are erased by later readings while
real surfaces accumulate (Borenstein and Koren's histogramic in-motion mapping, HIMM).
A reading with no echo carries no information here: it may be a lost reading. The map
is the planner's only memory of obstacles, built from the sonar ring and the pose alone.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage


class LocalMap:
    """Certainty grid of obstacle cells around the robot (see the module docstring)."""

    def __init__(
        self,
        cell_m: float,
        size_m: float,
        hit: int = 3,
        miss: int = 1,
        max_certainty: int = 15,
        hit_range_m: float = math.inf,
        silent_free_m: float = 0.0,
    ):
        self.cell_m = cell_m
        self.n = max(8, math.ceil(size_m / cell_m))
        self.hit, self.miss, self.max_certainty = hit, miss, max_certainty
        self.hit_range_m = hit_range_m
        """Echoes beyond this range (m) only clear their cone: their arc is too wide to place them."""
        self.silent_free_m = silent_free_m
        """A reading without an echo marks its cone `seen` free this far (m); it changes no
        certainty, since it may be a lost reading."""
        self.grid = np.zeros((self.n, self.n), dtype=np.int16)
        self.seen = np.zeros((self.n, self.n), dtype=bool)
        """Cells some reading has shown free (inside a cone, short of its echo) or the robot's disc
        has covered; the others were never seen free (obstacles, or unknown)."""
        self.swept = np.zeros((self.n, self.n), dtype=bool)
        """Cells the robot's disc has covered (`sweep`): in a static world, never an obstacle."""
        self.origin: np.ndarray | None = None  # world cell index of grid[0, 0]

    def update(
        self, position: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray, beam: float
    ) -> None:
        """Fold one scan of the sonar ring (ranges in m from the robot's centre) into the grid."""
        self._follow(position)
        echoes = np.isfinite(ranges)
        silent = self.silent_free_m if not echoes.all() else 0.0
        if not echoes.any() and silent <= 0:
            return
        # Only the cells within the longest reading can change: work on that window.
        longest = max(float(np.max(ranges[echoes])) if echoes.any() else 0.0, silent)
        reach = math.ceil(longest / self.cell_m) + 1
        centre = np.floor(np.asarray(position) / self.cell_m).astype(int) - self.origin
        lo = np.maximum(centre - reach, 0)
        hi = np.minimum(centre + reach + 1, self.n)
        if np.any(hi <= lo):
            return
        rel_x = (self.origin[0] + np.arange(lo[0], hi[0]) + 0.5) * self.cell_m - position[0]
        rel_y = (self.origin[1] + np.arange(lo[1], hi[1]) + 0.5) * self.cell_m - position[1]
        distance = np.hypot(rel_x[:, None], rel_y[None, :])
        bearing = np.arctan2(rel_y[None, :], rel_x[:, None]) - (yaw + bearings[0])
        spacing = 2 * math.pi / len(bearings)
        sonar = np.round(bearing / spacing).astype(int) % len(bearings)
        offset = (bearing - sonar * spacing + math.pi) % (2 * math.pi) - math.pi
        reading = ranges[sonar]
        in_beam = np.abs(offset) <= beam / 2
        in_cone = in_beam & np.isfinite(reading)
        if silent > 0:
            self.seen[lo[0] : hi[0], lo[1] : hi[1]] |= in_beam & np.isnan(reading) & (distance < silent)
        reading = np.where(in_cone, reading, -1.0)
        window = self.grid[lo[0] : hi[0], lo[1] : hi[1]]  # a view: updated in place
        shown_free = in_cone & (distance < reading - self.cell_m)
        self.seen[lo[0] : hi[0], lo[1] : hi[1]] |= shown_free
        window -= self.miss * shown_free
        window += self.hit * (
            (np.abs(distance - reading) <= 0.75 * self.cell_m) & (reading <= self.hit_range_m)
        )
        np.clip(window, 0, self.max_certainty, out=window)

    def sweep(self, position: np.ndarray, radius_m: float) -> None:
        """Mark swept (and seen free) the cells whose centre lies within `radius_m` of a point (m):
        the robot's own disc stands there, so no obstacle does."""
        self._follow(position)
        reach = math.ceil(radius_m / self.cell_m) + 1
        centre = np.floor(np.asarray(position) / self.cell_m).astype(int) - self.origin
        lo, hi = np.maximum(centre - reach, 0), np.minimum(centre + reach + 1, self.n)
        if np.any(hi <= lo):
            return
        rel_x = (self.origin[0] + np.arange(lo[0], hi[0]) + 0.5) * self.cell_m - position[0]
        rel_y = (self.origin[1] + np.arange(lo[1], hi[1]) + 0.5) * self.cell_m - position[1]
        inside = np.hypot(rel_x[:, None], rel_y[None, :]) <= radius_m
        self.swept[lo[0] : hi[0], lo[1] : hi[1]] |= inside
        self.seen[lo[0] : hi[0], lo[1] : hi[1]] |= inside

    def cells(self, min_certainty: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """Centres (N, 2) in metres and certainties (N,) of cells at or above a certainty."""
        i, j = np.nonzero(self.grid >= min_certainty)
        if self.origin is None or len(i) == 0:
            return np.empty((0, 2)), np.empty(0, dtype=int)
        centres = (np.column_stack((i, j)) + self.origin + 0.5) * self.cell_m
        return centres, self.grid[i, j].astype(int)

    def clusters(self, min_certainty: int, link_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cell centres (N, 2), their cluster labels (N,) and the label grid (n, n).

        Cells closer than about `link_m` (rounded up to whole cells) share a label; label 0
        is free space. Two obstacle cells
        closer than the robot's width form one barrier, so `link_m` is normally the robot's
        diameter plus a clearance.
        """
        occupied = self.grid >= min_certainty
        grid_labels, _ = ndimage.label(
            ndimage.binary_dilation(occupied, structure=_disk(link_m / 2, self.cell_m))
        )
        i, j = np.nonzero(occupied)
        if self.origin is None or len(i) == 0:
            return np.empty((0, 2)), np.empty(0, dtype=int), grid_labels
        centres = (np.column_stack((i, j)) + self.origin + 0.5) * self.cell_m
        return centres, grid_labels[i, j], grid_labels

    def lookup(self, grid_values: np.ndarray, points: np.ndarray) -> np.ndarray:
        """The value of a grid-shaped array at world points (N, 2); 0 outside the grid."""
        index = np.floor(np.asarray(points, float) / self.cell_m).astype(int) - self.origin
        inside = np.all((index >= 0) & (index < self.n), axis=1)
        values = np.zeros(len(index), dtype=grid_values.dtype)
        values[inside] = grid_values[index[inside, 0], index[inside, 1]]
        return values

    def clearance_field(self, min_certainty: int, centre: np.ndarray, reach_m: float) -> ClearanceField:
        """The distance (m) from each cell's centre to the nearest obstacle cell's centre (at
        `min_certainty`), over the square of cells within `reach_m` of `centre`: a Euclidean
        distance transform of that square alone. Obstacle cells outside it are not seen, so a
        distance d is exact for points at least d inside the square."""
        reach = math.ceil(reach_m / self.cell_m)
        lo, hi = [], []
        for axis in range(2):
            middle = math.floor(centre[axis] / self.cell_m) - int(self.origin[axis])
            lo.append(min(max(middle - reach, 0), self.n - 2))
            hi.append(min(max(middle + reach + 1, lo[axis] + 2), self.n))
        free = self.grid[lo[0] : hi[0], lo[1] : hi[1]] < min_certainty
        if free.all():  # farther than any cell of the map could be
            values = np.full(free.shape, 2.0 * self.n * self.cell_m)
        else:
            values = ndimage.distance_transform_edt(free) * self.cell_m
        return ClearanceField(values, self.origin + np.array(lo), self.cell_m)

    def _follow(self, position: np.ndarray) -> None:
        """Keep the robot in the grid's middle half, shifting the grid by whole cells."""
        centre_cell = np.floor(np.asarray(position) / self.cell_m).astype(int) - self.n // 2
        if self.origin is None:
            self.origin = centre_cell
            return
        shift = centre_cell - self.origin
        if np.max(np.abs(shift)) < self.n // 4:
            return
        src = [slice(max(0, s), self.n + min(0, s)) for s in shift]
        dst = [slice(max(0, -s), self.n + min(0, -s)) for s in shift]
        for name in ("grid", "seen", "swept"):
            moved = np.zeros_like(getattr(self, name))
            moved[dst[0], dst[1]] = getattr(self, name)[src[0], src[1]]
            setattr(self, name, moved)
        self.origin = centre_cell


@dataclass(frozen=True)
class ClearanceField:
    """Distances (m) to the nearest obstacle cell, at the centres of a block of map cells."""

    values: np.ndarray
    first_cell: np.ndarray
    """World cell index (i, j) of values[0, 0]."""
    cell_m: float

    def at(self, points: np.ndarray) -> np.ndarray:
        """The distance at world points (N, 2), bilinear between the cell centres; points beyond
        the outermost centres take the border's values."""
        rows, cols = self.values.shape
        u = np.asarray(points, float) / self.cell_m - self.first_cell - 0.5
        i = np.minimum(np.maximum(np.floor(u[:, 0]).astype(int), 0), rows - 2)
        j = np.minimum(np.maximum(np.floor(u[:, 1]).astype(int), 0), cols - 2)
        fx = np.minimum(np.maximum(u[:, 0] - i, 0.0), 1.0)
        fy = np.minimum(np.maximum(u[:, 1] - j, 0.0), 1.0)
        flat = self.values.ravel()
        index = i * cols + j
        below = flat[index] + (flat[index + cols] - flat[index]) * fx
        above = flat[index + 1] + (flat[index + cols + 1] - flat[index + 1]) * fx
        return below + (above - below) * fy


@functools.cache
def _disk(radius_m: float, cell_m: float) -> np.ndarray:
    """A disc-shaped structuring element of `radius_m` in cells (at least one cell)."""
    reach = max(1, math.ceil(radius_m / cell_m - 1e-9))
    return np.hypot(*np.mgrid[-reach : reach + 1, -reach : reach + 1]) <= reach


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
