"""A small local map accumulated from range scans (a VFH-style certainty grid).

The grid is a square of `size_m` around the robot with cells of `cell_m`, anchored to
the world (it shifts by whole cells when the robot nears its edge; cells that fall off
are forgotten). A scan is any set of beams: bearings (robot frame, in any order, unevenly
spaced, over any field of view; several beams may share a bearing), one range per beam
(from the robot's centre) and one beam width: a sonar ring, a front and a rear sonar array,
or a laser (its beam width is its angle step). Each reading is treated as a real sonar's:
the echo lies somewhere on the arc of the beam at the measured range, and the cone in front
of the arc is free. Arc cells gain `hit` certainty (up to `max_certainty`), cone cells lose
`miss`; so phantom echoes (a wide beam grazing a corridor wall) are erased by later readings
while real surfaces accumulate (Borenstein and Koren's histogramic in-motion mapping, HIMM).
A reading with no echo carries no information here: it may be a lost reading. The map
is the planner's only memory of obstacles, built from the scans and the pose alone.

Which beam speaks for a cell: the one whose bearing is nearest to the cell centre's, and
only when the centre lies within half a beam width of that bearing (`beams.BeamFan`). So
beams wider than their spacing are clipped to their share of the circle, a cell between two
narrow beams or outside the field of view is left as it is, and a laser's cell is judged by
the ray through it. Beams that share a bearing act as one, with the shortest of their
echoes. A cell within 0.75 cell (`map_update.ARC_HALF_WIDTH`) of the range, along its beam, is on the
arc; a cell nearer than the range less one cell is in the free cone.

Options for planners that plan ways on the map: `hit_range_m` (an echo farther than this
only clears its cone: its arc is too wide to place it; an arc at most one cell wide,
range x beam <= cell_m, as a laser's, marks at any range), `seen` (the cells some reading
has shown free, as opposed to merely unknown; with `silent_free_m`, a reading without an echo
shows its cone free that far) and `sweep` (the cells the robot's own disc has covered, never
obstacles in a static world).

An echo beyond the grid clears its cone up to the grid's edge and marks nothing there: the
grid holds no cells beyond its edge, and its storage does not grow with an echo's range.

A scan changes only the cells near its echo arcs (hits), the marked cells inside its cones
(misses: an empty cell stays empty) and, with `seen`, the cells of its cones not yet seen. So
an update walks the cones (neighbouring ones together) and judges just those cells, by the rule
above, in compiled code
(`kernels.map_update`, numba, imported by the map's constructor): the grid is what a pass over
every cell within reach of the longest echo would make of it.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.perception.beams import BeamFan
from vplane_mj.planning.perception.tracker import Track, moving_tracks

FORGET_MARGIN_M = 0.2
"""`forget` clears this far (m) beyond a moving track's disc: the trail its echoes left in the
scans before it was known to move (a scan or two, at up to 2 m/s)."""
_NONE = np.zeros((0, 0), dtype=bool)
"""An empty mask: no cell skipped."""


class LocalMap:
    """Certainty grid of obstacle cells around the robot (see the module docstring).

    Attributes:
        cell_m (float): Side of a cell (m).
        n (int): Cells along each side of the grid.
        hit (int): Certainty an arc cell gains from a reading.
        miss (int): Certainty a cone cell loses to a reading.
        max_certainty (int): The most certainty a cell holds.
        hit_range_m (float): Echoes farther than this only clear their cone (m).
        track_seen (bool): Whether the map keeps `seen`.
        silent_free_m (float): How far a reading without an echo shows its cone free (m; 0
            without `track_seen`).
        origin (numpy.ndarray | None): World cell index (i, j) of grid[0, 0]; None before the
            first `update` or `sweep` places the grid.
    """

    def __init__(
        self,
        cell_m: float,
        size_m: float,
        hit: int = 3,
        miss: int = 1,
        max_certainty: int = 15,
        hit_range_m: float = math.inf,
        track_seen: bool = False,
        silent_free_m: float = 0.0,
    ):
        """An empty grid; the first `update` or `sweep` places it about the robot.

        Args:
            cell_m: Side of a cell (m).
            size_m: Side of the square grid (m), at least 8 cells.
            hit: Certainty an arc cell gains from a reading.
            miss: Certainty a cone cell loses to a reading.
            max_certainty: The most certainty a cell holds.
            hit_range_m: Echoes farther than this only clear their cone (m); an arc at most a
                cell wide (a laser's) marks at any range.
            track_seen: Keep `seen`: the cells a reading has shown free or the robot's disc
                has covered.
            silent_free_m: With `track_seen`, how far a reading without an echo shows its cone
                free (m).
        """
        from vplane_mj.kernels.maps import grid, map_update  # numba: loaded by the first map a run makes

        self._fold_scan = map_update.fold_scan
        self._cells_near, self._nearest_cell = grid.cells_near, grid.nearest_cell
        self._mark_disc, self._clear_discs = grid.mark_disc, grid.clear_discs
        self._dilate, self._label_regions = grid.dilate, grid.label_regions
        self.cell_m = cell_m
        self.n = max(8, math.ceil(size_m / cell_m))
        self.hit, self.miss, self.max_certainty = hit, miss, max_certainty
        self._rule = np.array((hit, miss, max_certainty), dtype=np.int64)
        self.hit_range_m = hit_range_m
        self.track_seen = track_seen
        self.silent_free_m = silent_free_m if track_seen else 0.0
        self.origin: np.ndarray | None = None  # world cell index of grid[0, 0]
        self._fan: BeamFan | None = None
        self._grid = np.zeros((self.n, self.n), dtype=np.int16)
        self._seen = np.zeros((self.n, self.n), dtype=bool)
        self._swept = np.zeros((self.n, self.n), dtype=bool)

    @property
    def grid(self) -> np.ndarray:
        """Certainties (n, n) int16; grid[i, j] is the world cell origin + (i, j)."""
        return self._grid

    @property
    def seen(self) -> np.ndarray:
        """(n, n) bool: cells a reading has shown free or the robot's disc has covered (with
        `track_seen`; else all False)."""
        return self._seen

    @property
    def swept(self) -> np.ndarray:
        """(n, n) bool: cells the robot's disc has covered (`sweep`)."""
        return self._swept

    def update(
        self, position: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray, beam: float
    ) -> None:
        """Fold one scan into the grid: `ranges` (m from the robot's centre, NaN: no echo) along
        `bearings` (rad, robot frame; any order, duplicates allowed), each beam `beam` wide (rad)."""
        origin = self._follow(position)
        fan = self._fan_of(bearings, beam)
        # An arc at most a cell wide (range x beam <= cell) places its echo as precisely as the
        # grid can hold it, at any range.
        mark_range = max(self.hit_range_m, self.cell_m / beam if beam > 0 else math.inf)
        self._fold_scan(
            float(position[0]),
            float(position[1]),
            float(yaw),
            origin,
            self.cell_m,
            float(beam),
            fan.directions,
            fan.half_before,
            fan.half_after,
            fan.spacing or 0.0,
            fan.bounds,
            fan.bound_units,
            fan.quick,
            fan.readings(ranges),
            mark_range,
            self.silent_free_m,
            self._rule,
            self.track_seen,
            self._grid,
            self._seen,
        )

    def _fan_of(self, bearings: np.ndarray, beam: float) -> BeamFan:
        """The scan's directions (kept while the bearings and the beam stay the same)."""
        fan = self._fan
        if fan is not None and fan.source is bearings and fan.beam == beam:
            return fan  # a sensor's bearings, the same array at every scan
        if (
            fan is None
            or fan.beam != beam
            or fan.bearings.shape != np.shape(bearings)
            or not (fan.bearings == bearings).all()
        ):
            fan = self._fan = BeamFan(bearings, beam)
        return fan

    def sweep(self, position: np.ndarray, radius_m: float) -> None:
        """Mark swept (and seen) the cells whose centre lies within `radius_m` of a point (m):
        the robot's own disc stands there, so no obstacle does."""
        origin = self._follow(position)
        self._mark_disc(
            self._swept, self._seen, origin, self.cell_m, float(position[0]), float(position[1]), radius_m
        )

    def forget(self, tracks: tuple[Track, ...], time_s: float, margin_m: float = FORGET_MARGIN_M) -> None:
        """Clear the cells under each moving track's disc, its radius plus `margin_m` (m), where
        it is predicted at `time_s` (s): what echoed there is the track itself, or the trail of
        echoes it left before it was known to move."""
        if self.origin is None:
            return
        moving = moving_tracks(tracks, time_s)
        if len(moving):
            discs = np.column_stack((moving[:, :2], moving[:, 4] + margin_m))
            self._clear_discs(self._grid, self.origin, self.cell_m, discs)

    def cells(
        self,
        min_certainty: int = 1,
        near: np.ndarray | None = None,
        within_m: float = math.inf,
        skip_swept: bool = False,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Centres (N, 2) in metres and certainties (N,) of cells at or above a certainty, row-major.

        With `near` (a point, m), only the cells of the square around it that holds the disc
        of radius `within_m`: every such cell closer than `within_m`, and some farther ones.
        With `skip_swept`, not the cells the robot's disc has covered.
        """
        if self.origin is None:
            return np.empty((0, 2)), np.empty(0, dtype=np.int64)
        if near is None:  # the whole grid: numpy's passes over it are the quicker
            chosen = self._grid >= min_certainty
            if skip_swept:
                chosen &= ~self._swept
            i, j = mask_cells(chosen)
            return self.centres_of(i, j), self._grid[i, j].astype(np.int64)
        return self._cells_near(*self._square(min_certainty, near, within_m, skip_swept))

    def nearest_cell(
        self, min_certainty: int, near: np.ndarray, within_m: float, skip_swept: bool = False
    ) -> np.ndarray | None:
        """The centre (m) of the cell of `cells(min_certainty, near, within_m, skip_swept)`
        nearest `near` (the first of equally near ones), None when there is none."""
        if self.origin is None:
            return None
        centre = self._nearest_cell(*self._square(min_certainty, near, within_m, skip_swept))
        return centre if len(centre) else None

    def _square(self, min_certainty: int, near: np.ndarray, within_m: float, skip_swept: bool) -> tuple:
        """The arguments of the compiled reads of the cells around `near` (`kernels.grid`)."""
        swept = self._swept if skip_swept else _NONE
        x, y = float(near[0]), float(near[1])
        return self._grid, self.origin, self.cell_m, min_certainty, x, y, float(within_m), swept

    def any_cells(self, min_certainty: int = 1) -> bool:
        """Whether any cell is at or above a certainty."""
        return bool((self._grid >= min_certainty).any())

    def clusters(self, min_certainty: int, link_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cell centres (N, 2), their cluster labels (N,) and the label grid (n, n).

        Cells closer than about `link_m` (rounded up to whole cells) share a label; label 0
        is free space. Two obstacle cells closer than the robot's width form one barrier, so
        `link_m` is normally the robot's diameter plus a clearance. The labels are those of
        the 4-connected regions of the obstacle cells grown by a disc of `link_m` / 2.
        """
        occupied = self._grid >= min_certainty
        grid_labels = np.zeros(occupied.shape, dtype=np.int32)
        i, j = mask_cells(occupied)
        if self.origin is None or len(i) == 0:
            return np.empty((0, 2)), np.empty(0, dtype=int), grid_labels
        # Only the box of the grown cells can hold a label: labelled there alone, the regions
        # are the same, numbered in the same (row-major) order.
        disk = _disk(link_m / 2, self.cell_m)
        reach = disk.shape[0] // 2
        box = (
            slice(max(int(i.min()) - reach, 0), int(i.max()) + reach + 1),
            slice(max(int(j.min()) - reach, 0), int(j.max()) + reach + 1),
        )
        grid_labels[box] = self._label_regions(self._dilate(np.ascontiguousarray(occupied[box]), disk))
        return self.centres_of(i, j), grid_labels[i, j], grid_labels

    def centres_of(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """The centres (N, 2; m) of grid cells (i, j)."""
        return (np.column_stack((i, j)) + self._placed_origin + 0.5) * self.cell_m

    def lookup(self, grid_values: np.ndarray, points: np.ndarray) -> np.ndarray:
        """The value of a grid-shaped array at world points (N, 2); 0 outside the grid."""
        index = np.floor(np.asarray(points, float) / self.cell_m).astype(int) - self._placed_origin
        inside = np.all((index >= 0) & (index < self.n), axis=1)
        values = np.zeros(len(index), dtype=grid_values.dtype)
        values[inside] = grid_values[index[inside, 0], index[inside, 1]]
        return values

    def clearance_field(self, min_certainty: int, centre: np.ndarray, reach_m: float) -> ClearanceField:
        """The distance (m) from each cell's centre to the nearest obstacle cell's centre (at
        `min_certainty`), over the square of cells within `reach_m` of `centre`: a Euclidean
        distance transform of that square alone. Obstacle cells outside it are not seen, so a
        distance d is exact for points at least d inside the square."""
        origin = self._placed_origin
        reach = math.ceil(reach_m / self.cell_m)
        lo, hi = [], []
        for axis in range(2):
            middle = math.floor(centre[axis] / self.cell_m) - int(origin[axis])
            lo.append(min(max(middle - reach, 0), self.n - 2))
            hi.append(min(max(middle + reach + 1, lo[axis] + 2), self.n))
        free = self.grid[lo[0] : hi[0], lo[1] : hi[1]] < min_certainty
        if free.all():  # farther than any cell of the map could be
            values = np.full(free.shape, 2.0 * self.n * self.cell_m)
        else:
            from vplane_mj.kernels.maps.edt import distance_transform  # numba: loaded by the first call

            values = distance_transform(free) * self.cell_m
        return ClearanceField(values, origin + np.array(lo), self.cell_m)

    @property
    def _placed_origin(self) -> np.ndarray:
        """The origin, which the first `update` or `sweep` places (RuntimeError before that)."""
        if self.origin is None:
            raise RuntimeError("the local map has no origin before its first update or sweep")
        return self.origin

    def _follow(self, position: np.ndarray) -> np.ndarray:
        """Keep the robot in the grid's middle half, shifting the grid by whole cells; the origin."""
        half = self.n // 2
        centre = (math.floor(position[0] / self.cell_m) - half, math.floor(position[1] / self.cell_m) - half)
        if self.origin is None:
            self.origin = np.array(centre, dtype=np.int64)
            return self.origin
        if max(abs(centre[0] - self.origin[0]), abs(centre[1] - self.origin[1])) < self.n // 4:
            return self.origin
        centre_cell = np.array(centre, dtype=np.int64)
        shift = centre_cell - self.origin
        for layer in (self._grid, self._seen, self._swept):
            moved = np.zeros_like(layer)
            if np.max(np.abs(shift)) < self.n:  # else nothing of the old grid remains in the new one
                src = [slice(max(0, s), self.n + min(0, s)) for s in shift]
                dst = [slice(max(0, -s), self.n + min(0, -s)) for s in shift]
                moved[dst[0], dst[1]] = layer[src[0], src[1]]
            layer[...] = moved
        self.origin = centre_cell
        return self.origin


@dataclass(frozen=True)
class ClearanceField:
    """Distances (m) to the nearest obstacle cell, at the centres of a block of map cells."""

    values: np.ndarray
    first_cell: np.ndarray
    """World cell index (i, j) of values[0, 0]."""
    cell_m: float

    def at(self, points: np.ndarray) -> np.ndarray:
        """The distance at world points (N, 2), bilinear between the cell centres; points beyond
        the outermost centres take the border's values (`kernels.arcs`)."""
        from vplane_mj.kernels.motion import arcs  # numba: loaded by the first call

        points = np.ascontiguousarray(points, float).reshape(-1, 2)
        first_i, first_j = float(self.first_cell[0]), float(self.first_cell[1])
        return arcs.bilinear(np.ascontiguousarray(self.values, float), first_i, first_j, self.cell_m, points)


@functools.cache
def _disk(radius_m: float, cell_m: float) -> np.ndarray:
    """A disc-shaped structuring element of `radius_m` in cells (at least one cell)."""
    reach = max(1, math.ceil(radius_m / cell_m - 1e-9))
    return np.hypot(*np.mgrid[-reach : reach + 1, -reach : reach + 1]) <= reach


def mask_cells(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows and columns of a 2-D mask's true cells, row-major: `np.nonzero(mask)`, through the
    flat indices (numpy's 2-D nonzero takes some twenty times as long on the map)."""
    return np.divmod(np.flatnonzero(mask), mask.shape[1])


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
