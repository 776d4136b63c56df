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
echoes. A cell within ARC_HALF_WIDTH (0.75) cell of the range, along its beam, is on the
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
an update visits just those and classifies each by the rule above, computed exactly as a pass
over every cell within reach of the longest echo would: the grid is the same, bit for bit.
They are found from a table of grid offsets by beam direction and range (`_ConeTable`) for a
scan of few beams reaching a few metres (a sonar's), and otherwise, for a laser's hundreds of
beams or an echo far beyond the grid, by a compiled walk through each cone
(`cone_walk.cone_cells`, numba, imported only then: its start-up, about 0.3 s a process, is
more than a sonar run's map ever costs).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.beams import BeamFan


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
        track_seen: bool = False,
        silent_free_m: float = 0.0,
    ):
        self.cell_m = cell_m
        self.n = max(8, math.ceil(size_m / cell_m))
        self.hit, self.miss, self.max_certainty = hit, miss, max_certainty
        self.hit_range_m = hit_range_m
        self.track_seen = track_seen
        self.silent_free_m = silent_free_m if track_seen else 0.0
        self.origin: np.ndarray | None = None  # world cell index of grid[0, 0]
        self._cones: _ConeTable | None = None
        self._fan: BeamFan | None = None
        self._stamps: np.ndarray | None = None  # per padded cell: the last walk that listed it
        self._stamp = 0
        empty = np.zeros((self.n, self.n), dtype=bool)
        self._allocate(np.zeros((self.n, self.n), dtype=np.int16), empty, empty, 0)

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
        ranges = fan.readings(ranges)  # one per direction
        echoes = ranges == ranges  # not NaN
        silent = self.silent_free_m if not echoes.all() else 0.0
        looked = np.flatnonzero(echoes) if silent <= 0 else np.arange(fan.count)
        if not len(looked):
            return
        px, py = float(position[0]), float(position[1])
        cell = self.cell_m
        reach = np.where(echoes, ranges, silent)[looked]  # a silent beam: its cone to `silent`
        farthest = float(reach.max())
        # An arc at most a cell wide (range x beam <= cell) places its echo as precisely as the
        # grid can hold it, at any range.
        marks = ranges <= max(self.hit_range_m, cell / beam if beam > 0 else math.inf)
        if fan.count <= TABLE_MAX_BEAMS and farthest / cell + 3.0 <= TABLE_MAX_RADIUS:
            cand = self._table_cells(fan, yaw, px, py, origin, looked, reach, farthest)
        else:
            cand = self._walked_cells(fan, yaw, px, py, origin, looked, ranges, marks, silent)
        rel_x = self._centre_x[cand] - px
        rel_y = self._centre_y[cand] - py
        distance = np.hypot(rel_x, rel_y)
        axis = yaw + fan.directions[0]
        nearest, offset = fan.nearest(np.arctan2(rel_y, rel_x) - axis, axis)
        in_beam = np.abs(offset) <= beam / 2
        reading = np.where(echoes, ranges, -1.0)[nearest]  # -1: no echo
        reading = np.where(in_beam, reading, -1.0)  # -1: not in a cone with an echo
        shown_free = distance < reading - cell
        delta = self.hit * ((np.abs(distance - reading) <= ARC_HALF_WIDTH * cell) & marks[nearest])
        delta -= self.miss * shown_free
        flat = self._padded.reshape(-1)
        value = np.minimum(np.maximum(flat[cand] + delta, 0), self.max_certainty)  # a cheaper np.clip
        flat[cand] = value
        self._marked[cand] = value > 0
        if self.track_seen:
            if silent > 0:
                shown_free |= in_beam & ~echoes[nearest] & (distance < silent)
            self._seen_flat[cand[shown_free]] = True

    def _fan_of(self, bearings: np.ndarray, beam: float) -> BeamFan:
        """The scan's directions (kept while the bearings and the beam stay the same)."""
        fan = self._fan
        if (
            fan is None
            or fan.beam != beam
            or fan.bearings.shape != np.shape(bearings)
            or not (fan.bearings == bearings).all()
        ):
            fan = self._fan = BeamFan(bearings, beam)
        return fan

    def _table_cells(
        self,
        fan: BeamFan,
        yaw: float,
        px: float,
        py: float,
        origin: np.ndarray,
        looked: np.ndarray,
        reach: np.ndarray,
        farthest: float,
    ) -> np.ndarray:
        """Flat indices of the cells the scan may change, from the cone table (some repeated)."""
        cell = self.cell_m
        cones = self._cones
        half_beam = fan.beam / 2
        bands = farthest / cell + 3.0  # the arc's last band, and a margin
        if cones is None or cones.half_beam != half_beam or bands > cones.radius:
            radius = TABLE_RADIUS_STEP * math.ceil(bands / TABLE_RADIUS_STEP)  # few distinct tables
            if radius > self._pad + self.n // 4:
                self._allocate(
                    self._grid.copy(), self._seen.copy(), self._swept.copy(), radius - self.n // 4 + 1
                )
            cones = self._cones = _cone_table(cell, half_beam, radius, self._stride)
        robot = (math.floor(px / cell) - origin[0] + self._pad) * self._stride
        robot += math.floor(py / cell) - origin[1] + self._pad
        offsets, cone_only = cones.near(yaw + fan.directions[looked], reach)
        cand = offsets + robot
        # Before its arc, a cone only empties marked cells, and shows unseen ones free: an
        # unmarked cell already seen stays as it is.
        changes = self._marked[cand] if not self.track_seen else self._marked[cand] | ~self._seen_flat[cand]
        return cand[~cone_only | changes]

    def _walked_cells(
        self,
        fan: BeamFan,
        yaw: float,
        px: float,
        py: float,
        origin: np.ndarray,
        looked: np.ndarray,
        ranges: np.ndarray,
        marks: np.ndarray,
        silent: float,
    ) -> np.ndarray:
        """Flat indices of the cells the scan may change, from a walk through each cone."""
        from vplane_mj.planning.cone_walk import cone_cells  # numba: only scans that need it pay

        axes = yaw + fan.directions[looked]
        if self._stamps is None or self._stamp >= np.iinfo(np.int32).max:
            self._stamps = np.zeros(self._stride * self._stride, dtype=np.int32)
            self._stamp = 0
        self._stamp += 1
        out = np.empty(self.n * self.n, dtype=np.int64)
        count = cone_cells(
            np.array((px, py)),
            np.asarray(origin, dtype=np.int64),
            np.array((self.n, self._pad, self._stride), dtype=np.int64),
            self.cell_m,
            ARC_HALF_WIDTH * self.cell_m,
            axes - fan.half_before[looked],
            axes + fan.half_after[looked],
            ranges[looked],
            marks[looked],
            silent,
            self._padded.reshape(-1),
            self._seen_flat,
            self.track_seen,
            self._stamps,
            self._stamp,
            out,
        )
        return out[:count]

    def sweep(self, position: np.ndarray, radius_m: float) -> None:
        """Mark swept (and seen) the cells whose centre lies within `radius_m` of a point (m):
        the robot's own disc stands there, so no obstacle does."""
        origin = self._follow(position)
        reach = math.ceil(radius_m / self.cell_m) + 1
        centre = np.floor(np.asarray(position) / self.cell_m).astype(int) - origin
        lo, hi = np.maximum(centre - reach, 0), np.minimum(centre + reach + 1, self.n)
        if np.any(hi <= lo):
            return
        rel_x = (origin[0] + np.arange(lo[0], hi[0]) + 0.5) * self.cell_m - position[0]
        rel_y = (origin[1] + np.arange(lo[1], hi[1]) + 0.5) * self.cell_m - position[1]
        inside = np.hypot(rel_x[:, None], rel_y[None, :]) <= radius_m
        self._swept[lo[0] : hi[0], lo[1] : hi[1]] |= inside
        self._seen[lo[0] : hi[0], lo[1] : hi[1]] |= inside

    def cells(
        self, min_certainty: int = 1, near: np.ndarray | None = None, within_m: float = math.inf
    ) -> tuple[np.ndarray, np.ndarray]:
        """Centres (N, 2) in metres and certainties (N,) of cells at or above a certainty, row-major.

        With `near` (a point, m), only the cells of the square around it that holds the disc
        of radius `within_m`: every such cell closer than `within_m`, and some farther ones.
        """
        grid, first_row, first_col = self._grid, 0, 0
        if near is not None and self.origin is not None and math.isfinite(within_m):
            reach = math.ceil(within_m / self.cell_m) + 1
            row = math.floor(near[0] / self.cell_m) - int(self.origin[0])
            col = math.floor(near[1] / self.cell_m) - int(self.origin[1])
            first_row, first_col = max(0, row - reach), max(0, col - reach)
            grid = grid[first_row : max(0, row + reach + 1), first_col : max(0, col + reach + 1)]
        occupied = grid >= min_certainty
        i, j = np.divmod(np.flatnonzero(occupied), occupied.shape[1])
        if self.origin is None or len(i) == 0:
            return np.empty((0, 2)), np.empty(0, dtype=int)
        certainty = grid[i, j].astype(int)
        centres = np.empty((len(i), 2))
        centres[:, 0] = i + (first_row + int(self.origin[0]))
        centres[:, 1] = j + (first_col + int(self.origin[1]))
        centres += 0.5
        centres *= self.cell_m
        return centres, certainty

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
        grid_labels = _label_regions(_dilate(occupied, _disk(link_m / 2, self.cell_m)))
        i, j = np.nonzero(occupied)
        if self.origin is None or len(i) == 0:
            return np.empty((0, 2)), np.empty(0, dtype=int), grid_labels
        centres = (np.column_stack((i, j)) + self.origin + 0.5) * self.cell_m
        return centres, grid_labels[i, j], grid_labels

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
            from scipy import ndimage  # only the planners that need it pay for scipy's import

            values = ndimage.distance_transform_edt(free) * self.cell_m
        return ClearanceField(values, origin + np.array(lo), self.cell_m)

    @property
    def _placed_origin(self) -> np.ndarray:
        """The origin, which the first `update` or `sweep` places (RuntimeError before that)."""
        if self.origin is None:
            raise RuntimeError("the local map has no origin before its first update or sweep")
        return self.origin

    # -- storage ---------------------------------------------------------------------------
    def _allocate(self, grid: np.ndarray, seen: np.ndarray, swept: np.ndarray, pad: int) -> None:
        """Hold `grid` (n, n) and the `seen` and `swept` masks inside a margin of `pad` cells, so
        that the cells near an echo are looked up without bounds checks. Updates in the margin
        are never read: the grid is the middle, and a shift starts the margin afresh."""
        self._pad = pad
        self._stride = self.n + 2 * pad
        middle = (slice(pad, pad + self.n), slice(pad, pad + self.n))
        self._padded = np.zeros((self._stride, self._stride), dtype=np.int16)
        self._grid = self._padded[middle]
        self._grid[...] = grid
        self._marked = self._padded.reshape(-1) > 0
        padded_seen = np.zeros((self._stride, self._stride), dtype=bool)
        self._seen_flat = padded_seen.reshape(-1)
        self._seen = padded_seen[middle]
        self._seen[...] = seen
        self._swept = swept.copy()
        self._stamps = None
        self._anchor()

    def _anchor(self) -> None:
        """World coordinates (m) of the centre of every padded cell, as (origin + i + 1/2) * cell_m."""
        origin = (0, 0) if self.origin is None else self.origin
        index = np.arange(self._stride) - self._pad
        rows = (origin[0] + index + 0.5) * self.cell_m
        cols = (origin[1] + index + 0.5) * self.cell_m
        self._centre_x = np.repeat(rows, self._stride)
        self._centre_y = np.tile(cols, self._stride)

    def _follow(self, position: np.ndarray) -> np.ndarray:
        """Keep the robot in the grid's middle half, shifting the grid by whole cells; the origin."""
        half = self.n // 2
        centre = (math.floor(position[0] / self.cell_m) - half, math.floor(position[1] / self.cell_m) - half)
        if self.origin is None:
            self.origin = np.array(centre)
            self._anchor()
            return self.origin
        if max(abs(centre[0] - self.origin[0]), abs(centre[1] - self.origin[1])) < self.n // 4:
            return self.origin
        centre_cell = np.array(centre)
        shift = centre_cell - self.origin
        layers = (self._grid, self._seen, self._swept)
        grid, seen, swept = (np.zeros_like(layer) for layer in layers)
        if np.max(np.abs(shift)) < self.n:  # else nothing of the old grid remains in the new one
            src = [slice(max(0, s), self.n + min(0, s)) for s in shift]
            dst = [slice(max(0, -s), self.n + min(0, -s)) for s in shift]
            for moved, layer in zip((grid, seen, swept), layers, strict=True):
                moved[dst[0], dst[1]] = layer[src[0], src[1]]
        self.origin = centre_cell
        self._allocate(grid, seen, swept, self._pad)
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


DIRECTIONS = 256
"""Bins of beam axis direction in the cone table."""
TABLE_RADIUS_STEP = 16
"""The cone table reaches a multiple of this many cells, so that few tables are ever built."""
TABLE_MAX_BEAMS = 64
"""A scan of more beam directions than this walks its cones instead of using the cone table."""
TABLE_MAX_RADIUS = 128
"""A scan that reaches farther than this many cells (its longest reach plus a 3-cell margin)
walks its cones: the cone table, and the margin around the grid that it needs, stay this size."""
ARC_HALF_WIDTH = 0.75
"""An echo's arc holds the cells within this many cells of its range (along the beam)."""


@functools.lru_cache(maxsize=16)
def _cone_table(cell_m: float, half_beam: float, radius: int, stride: int) -> _ConeTable:
    return _ConeTable(cell_m, half_beam, radius, stride)


class _ConeTable:
    """The grid cells an echo can change, by direction of the beam's axis and range band.

    For each of DIRECTIONS bins of axis direction: the grid offsets (in cells, from the
    robot's cell) within `radius` whose bearing lies within the beam of an axis in the bin,
    widened by the most a cell centre's bearing can differ from its offset's (the robot is
    anywhere in its cell, at most `slack` = sqrt(2) / 2 cells from the centre), sorted by
    distance. For a range in band b (b <= range / cell_m < b + 1), the arc cells (within
    0.75 cell of the range) lie at offset distances in [b - 0.75 - slack, b + 1.75 + slack],
    and the cone cells nearer than range - cell_m below b + slack: together, the run of the
    bin's list up to the arc's end, whose part before the arc only matters where a cell is
    marked. A superset of the cells the update changes; each is classified exactly afterwards.
    """

    def __init__(self, cell_m: float, half_beam: float, radius: int, stride: int):
        self.cell_m, self.half_beam, self.radius = cell_m, half_beam, radius
        slack = math.sqrt(0.5) + 1e-6
        span = np.arange(-radius, radius + 1)
        di, dj = (a.ravel() for a in np.meshgrid(span, span, indexing="ij"))
        length = np.hypot(di, dj)
        keep = length <= radius
        di, dj, length = di[keep], dj[keep], length[keep]
        # Each offset belongs to the direction bins whose centre lies within its reach.
        width = 2 * math.pi / DIRECTIONS
        widen = np.arcsin(np.minimum(1.0, slack / np.maximum(length, slack)))
        reach = np.where(length > slack, half_beam + widen + width / 2 + 1e-6, math.pi)
        angle = np.arctan2(dj, di) % (2 * math.pi)
        first = np.ceil((angle - reach) / width - 0.5).astype(int)
        count = np.minimum(np.floor((angle + reach) / width - 0.5).astype(int) - first + 1, DIRECTIONS)
        member = np.repeat(np.arange(len(di)), count)
        runs = np.arange(len(member)) - np.repeat(np.cumsum(count) - count, count)
        direction = (np.repeat(first, count) + runs) % DIRECTIONS
        order = np.lexsort((length[member], direction))  # by direction, then distance
        member, direction = member[order], direction[order]
        self.offsets = (di * stride + dj)[member]
        self.bin_start = np.searchsorted(direction, np.arange(DIRECTIONS))
        keys = direction * (2.0 * radius + 8.0) + length[member]  # ascending
        base = np.arange(DIRECTIONS)[:, None] * (2.0 * radius + 8.0)
        bands = np.arange(radius + 1.0)[None, :]
        self.arc_first = np.searchsorted(keys, base + bands - ARC_HALF_WIDTH - slack, "left")
        self.arc_stop = np.searchsorted(keys, base + bands + 1.0 + ARC_HALF_WIDTH + slack, "right")
        self._bin = DIRECTIONS / (2 * math.pi)
        self._runs: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}

    def near(self, axes: np.ndarray, ranges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Offsets of the cells that echoes along `axes` (rad) at `ranges` (m) may change, and
        whether each lies before its arc (in the cone only: it changes only if marked)."""
        bins = np.minimum((axes % (2 * math.pi) * self._bin).astype(int), DIRECTIONS - 1).tolist()
        bands = (ranges / self.cell_m).astype(int).tolist()
        runs, cone_only = [], []
        for key in zip(bins, bands, strict=True):
            run = self._runs.get(key)
            if run is None:
                run = self._runs[key] = self._run(*key)
            runs.append(run[0])
            cone_only.append(run[1])
        return np.concatenate(runs), np.concatenate(cone_only)

    def _run(self, direction: int, band: int) -> tuple[np.ndarray, np.ndarray]:
        """The bin's offsets up to the end of the band's arc, and which lie before the arc."""
        start = self.bin_start[direction]
        offsets = self.offsets[start : self.arc_stop[direction, band]]
        return offsets, np.arange(len(offsets)) < self.arc_first[direction, band] - start


@functools.cache
def _disk(radius_m: float, cell_m: float) -> np.ndarray:
    """A disc-shaped structuring element of `radius_m` in cells (at least one cell)."""
    reach = max(1, math.ceil(radius_m / cell_m - 1e-9))
    return np.hypot(*np.mgrid[-reach : reach + 1, -reach : reach + 1]) <= reach


def _dilate(mask: np.ndarray, disk: np.ndarray) -> np.ndarray:
    """Binary dilation of `mask` by the centred structuring element `disk` (cells beyond the edge are off)."""
    reach = disk.shape[0] // 2
    out = np.zeros_like(mask)
    i, j = np.nonzero(mask)
    if not len(i):
        return out
    di, dj = np.nonzero(disk)
    rows, cols = (i[:, None] + di - reach).ravel(), (j[:, None] + dj - reach).ravel()
    inside = (rows >= 0) & (rows < mask.shape[0]) & (cols >= 0) & (cols < mask.shape[1])
    out[rows[inside], cols[inside]] = True
    return out


def _label_regions(mask: np.ndarray) -> np.ndarray:
    """Labels (1, 2, ...) of the 4-connected regions of `mask`, 0 elsewhere.

    Runs of set cells along each row are the nodes; runs on neighbouring rows that share a
    column are joined (union-find), and the regions are numbered in row-major order of their
    first cell, as scipy.ndimage.label numbers them.
    """
    n_rows, n_cols = mask.shape
    padded = np.zeros((n_rows, n_cols + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    edges = np.diff(padded, axis=1)
    run_row, run_start = np.nonzero(edges == 1)
    _, run_end = np.nonzero(edges == -1)  # exclusive; same row-major order as the starts
    labels = np.zeros(mask.shape, dtype=np.int32)
    if not len(run_row):
        return labels
    parent = list(range(len(run_row)))

    def root(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    rows_first = np.searchsorted(run_row, np.arange(n_rows + 1))
    for r in range(n_rows - 1):
        above, below = range(rows_first[r], rows_first[r + 1]), range(rows_first[r + 1], rows_first[r + 2])
        a, b = iter(above), iter(below)
        ka, kb = next(a, None), next(b, None)
        while ka is not None and kb is not None:
            if run_start[ka] < run_end[kb] and run_start[kb] < run_end[ka]:  # they share a column
                ra, rb = root(ka), root(kb)
                if ra != rb:
                    parent[max(ra, rb)] = min(ra, rb)
            if run_end[ka] <= run_end[kb]:
                ka = next(a, None)
            else:
                kb = next(b, None)
    roots = np.array([root(k) for k in range(len(run_row))])
    number = np.zeros(len(run_row), dtype=np.int32)
    firsts = np.flatnonzero(roots == np.arange(len(run_row)))
    number[firsts] = np.arange(1, len(firsts) + 1)
    run_label = number[roots]
    lengths = run_end - run_start
    flat = labels.reshape(-1)
    cell = np.repeat(run_row * n_cols + run_start - np.cumsum(lengths) + lengths, lengths)
    flat[cell + np.arange(len(cell))] = np.repeat(run_label, lengths)
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
