"""Shortest ways over the sonar map: where the robot's disc fits, and the cost to go to a target.

Compiled step costs and Dijkstra, numpy between them. Each cell gets a step cost from its
distance to the nearest obstacle cell (`step_costs`): infinite (blocked) closer than the
robot's radius plus a clearance, 1 far from obstacles, and rising in between, so ways keep
their distance where there is room and still pass a narrow gap when it is the only one (a
costmap's inflation layer). An 8-connected grid graph over the finite cells (diagonal moves
only between two free orthogonal neighbours, so no corner is cut; each move costs its length
times the mean of its two cells' costs) gives, by Dijkstra, each cell's cost to go to a set of
target cells (`cost_to_go`). Cells the sonar has never seen count as free: the search is
optimistic about the unknown, so a way that is not known to be blocked is worth trying, and
the map corrects it when the sonar sees more.
Steepest descent of the cost gives the way itself (`descend`).

Grids are indexed [i, j] with i along world x and j along world y, like the sonar map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

INFLATED_STEP_COST = 10.0
"""Step cost of blocked cells made passable (under the robot's own disc, at the goal)."""


def step_costs(
    sure: np.ndarray,
    doubtful: np.ndarray,
    cell_m: float,
    lethal_m: float,
    inflation_m: float,
    inflation_weight: float,
    doubt_cost: float,
) -> np.ndarray:
    """Step cost of each cell from the distances (m) between its centre and the nearest obstacle
    cell's centre: inf closer than `lethal_m` to a `sure` obstacle cell; `doubt_cost` more closer
    than that to a `doubtful` one (a way through it is tried only when no other is known, and
    the sonar settles the doubt on the way); 1 + w ((lethal + inflation - d) / inflation)^2
    within `inflation_m` beyond the lethal distance of either kind; 1 farther."""
    from vplane_mj.kernels.maps import step_costs as kernels  # numba: loaded by the first call

    sure, doubtful = np.ascontiguousarray(sure, bool), np.ascontiguousarray(doubtful, bool)
    rule = (float(cell_m), float(lethal_m), float(inflation_m), float(inflation_weight), float(doubt_cost))
    return kernels.step_costs(sure, doubtful, rule)


def clear_step_cost(beyond_lethal_m: float, inflation_m: float, inflation_weight: float) -> float:
    """The largest step cost of a cell at least `beyond_lethal_m` (m) farther than the lethal
    distance from every obstacle cell, sure or doubtful (see `step_costs`)."""
    closeness = max(0.0, (inflation_m - beyond_lethal_m) / inflation_m)
    return 1.0 + inflation_weight * closeness**2


@dataclass
class Window:
    """A rectangle of grid cells in the world: the step cost `cost[i, j]` of the robot's centre
    in each (inf: blocked), cells of `cell_m` whose cell (0, 0) has its lower-left corner at
    `corner` (m)."""

    cost: np.ndarray
    corner: np.ndarray
    cell_m: float
    seen: np.ndarray
    """Cells known to be free (seen so by the sensors), as opposed to merely unknown."""

    @property
    def free(self) -> np.ndarray:
        return np.isfinite(self.cost)

    def cell_of(self, point: np.ndarray) -> tuple[int, int] | None:
        """The cell that holds a world point (m), None outside the window."""
        i, j = np.floor((np.asarray(point, float) - self.corner) / self.cell_m).astype(int)
        if 0 <= i < self.cost.shape[0] and 0 <= j < self.cost.shape[1]:
            return int(i), int(j)
        return None

    def free_cell_near(self, point: np.ndarray, radius_m: float) -> tuple[int, int] | None:
        """The free cell nearest a point (m) within `radius_m`, None when there is none."""
        block, distance = self._disc(point, radius_m)
        distance[~np.isfinite(self.cost[block]) | (distance > radius_m)] = np.inf
        if not distance.size or not np.isfinite(distance.min()):
            return None
        i, j = np.unravel_index(int(np.argmin(distance)), distance.shape)
        return int(i + block[0].start), int(j + block[1].start)

    def centre(self, cell: tuple[int, int]) -> np.ndarray:
        """The world point (m) at a cell's centre."""
        return self.corner + (np.asarray(cell, float) + 0.5) * self.cell_m

    def centres_of(self, cells: np.ndarray | list[tuple[int, int]]) -> np.ndarray:
        """The world points (N, 2; m) at the centres of `cells` (N, 2: i, j)."""
        return self.corner + (np.asarray(cells, float).reshape(-1, 2) + 0.5) * self.cell_m

    def centres(self) -> np.ndarray:
        """Every cell's centre (m), shaped like `cost` plus a last axis of 2."""
        i, j = np.meshgrid(np.arange(self.cost.shape[0]), np.arange(self.cost.shape[1]), indexing="ij")
        return self.corner + (np.stack([i, j], axis=-1) + 0.5) * self.cell_m

    def clear_disc(self, point: np.ndarray, radius_m: float) -> None:
        """Make passable the blocked cells whose centre lies within `radius_m` of a point (m)."""
        block, distance = self._disc(point, radius_m)
        near = distance <= radius_m
        cell = self.cell_of(point)
        if cell is not None:
            near[cell[0] - block[0].start, cell[1] - block[1].start] = True
        cost = self.cost[block]  # a view
        cost[near & ~np.isfinite(cost)] = INFLATED_STEP_COST

    def charge_disc(self, point: np.ndarray, radius_m: float, extra: float) -> None:
        """Add `extra` to the step cost of the cells whose centre lies within `radius_m` of a
        point (m)."""
        block, distance = self._disc(point, radius_m)
        self.cost[block][distance <= radius_m] += extra

    def _disc(self, point: np.ndarray, radius_m: float) -> tuple[tuple[slice, slice], np.ndarray]:
        """The block of cells around a point (m) that holds the disc of `radius_m`, and the
        distance (m) from the point to each of their centres."""
        low = np.floor((np.asarray(point, float) - radius_m - self.corner) / self.cell_m).astype(int)
        high = np.floor((np.asarray(point, float) + radius_m - self.corner) / self.cell_m).astype(int) + 1
        low = np.clip(low, 0, self.cost.shape)
        high = np.clip(high, low, self.cost.shape)
        block = (slice(int(low[0]), int(high[0])), slice(int(low[1]), int(high[1])))
        x = self.corner[0] + (np.arange(low[0], high[0]) + 0.5) * self.cell_m - point[0]
        y = self.corner[1] + (np.arange(low[1], high[1]) + 0.5) * self.cell_m - point[1]
        return block, np.hypot(x[:, None], y[None, :])

    def block_segment(self, a: np.ndarray, b: np.ndarray) -> None:
        """Mark blocked the cells a segment (m) passes through, thickened so no diagonal step
        slips between them."""
        steps = max(2, math.ceil(2 * float(np.hypot(*(b - a))) / self.cell_m) + 1)
        points = np.linspace(a, b, steps)
        cells = np.floor((points - self.corner) / self.cell_m).astype(int)
        for di, dj in ((0, 0), (1, 0), (0, 1), (1, 1)):
            i, j = cells[:, 0] + di, cells[:, 1] + dj
            inside = (i >= 0) & (i < self.cost.shape[0]) & (j >= 0) & (j < self.cost.shape[1])
            self.cost[i[inside], j[inside]] = np.inf

    def path_cost(self, points: np.ndarray) -> float:
        """The cost of a polyline of world points (m): each segment's length times the mean step
        cost of its ends (1 outside the window); inf when a point lies on a blocked cell."""
        points = np.asarray(points, float).reshape(-1, 2)
        cells = np.floor((points - self.corner) / self.cell_m).astype(int)
        inside = np.all((cells >= 0) & (cells < self.cost.shape), axis=1)
        step = np.ones(len(points))
        step[inside] = self.cost[cells[inside, 0], cells[inside, 1]]
        lengths = np.hypot(*np.diff(points, axis=0).T)
        return float(np.sum(lengths * 0.5 * (step[:-1] + step[1:])))

    def packed(self) -> tuple[np.ndarray, float, float, float]:
        """The window as `kernels.way` reads it (its sight lines, `segment_free`): its step
        costs, its corner's x and y and its cell size (m)."""
        return self.cost, float(self.corner[0]), float(self.corner[1]), float(self.cell_m)


def cost_to_go(
    cost: np.ndarray,
    targets: np.ndarray,
    target_costs: np.ndarray,
    cell_m: float,
    stop: tuple[int, int] | None = None,
) -> np.ndarray:
    """Least cost (m, weighted by the step costs) from every cell to the targets; inf where no
    target is reachable (Dijkstra over the 8-connected grid, `kernels.grid_dijkstra`).

    `targets` are flat indices of cells, each starting at its `target_costs` (m): a target
    outside the grid is represented by the border cells with their straight distance to it.
    Targets on blocked cells are dropped. With a `stop` cell, the search ends once it has that
    cell's cost: the cells cheaper than it have theirs (all that a descent from it reads),
    the others an upper bound or inf.
    """
    from vplane_mj.kernels.maps import grid_dijkstra  # numba: loaded by the first call

    targets = np.asarray(targets, dtype=np.int64).ravel()
    keep = np.isfinite(np.ravel(cost)[targets])
    return grid_dijkstra.cost_to_go(
        np.ascontiguousarray(cost, float),
        targets[keep],
        np.asarray(target_costs, float).ravel()[keep],
        float(cell_m),
        -1 if stop is None else int(np.ravel_multi_index(stop, np.shape(cost))),
    )


def way_to(window: Window, start: np.ndarray, end: np.ndarray, radius_m: float) -> np.ndarray | None:
    """The cells (K, 2: i, j) of the window's shortest way from `start` toward `end` (m), the
    start's first: to the end's cell when the window holds it (made passable within `radius_m`
    of the end), else to the window's edge, each edge cell starting at its straight distance to
    the end. The start is the free cell nearest it within 2 `radius_m`; None when there is
    none, or no way from it (`descend`'s cells)."""
    ends = _ends(window, start, end, radius_m)
    if ends is None:
        return None
    targets, target_costs, start_cell = ends
    costs = cost_to_go(window.cost, targets, target_costs, window.cell_m, stop=start_cell)
    if not np.isfinite(costs[start_cell]):
        return None
    return descend(costs, start_cell, costs.size)


def way_exists(window: Window, start: np.ndarray, end: np.ndarray, radius_m: float) -> bool:
    """Whether `way_to` finds a way (the window made passable around the end as it does): the
    start's cell joined to a target by the same moves, found by a flood fill instead of the
    search for the cheapest."""
    from vplane_mj.kernels.maps import grid_dijkstra  # numba: loaded by the first call

    ends = _ends(window, start, end, radius_m)
    if ends is None:
        return False
    targets, _, start_cell = ends
    targets = targets[np.isfinite(window.cost).ravel()[targets]]
    start_index = int(np.ravel_multi_index(start_cell, window.cost.shape))
    return bool(grid_dijkstra.reaches(np.ascontiguousarray(window.cost, float), targets, start_index))


def _ends(
    window: Window, start: np.ndarray, end: np.ndarray, radius_m: float
) -> tuple[np.ndarray, np.ndarray, tuple[int, int]] | None:
    """What a way from `start` toward `end` (m) joins (see `way_to`): the target cells (flat
    indices) and their starting costs (m), and the start's cell; None without a start cell.
    The window is made passable within `radius_m` of the end when it holds the end."""
    shape = window.cost.shape
    end_cell = window.cell_of(end)
    if end_cell is not None:
        window.clear_disc(end, radius_m)
        targets, target_costs = np.array([np.ravel_multi_index(end_cell, shape)]), np.zeros(1)
    else:
        edge = np.zeros(shape, dtype=bool)
        edge[[0, -1], :] = edge[:, [0, -1]] = True
        targets = np.flatnonzero(edge)
        centres = window.centres_of(np.column_stack(np.unravel_index(targets, shape)))
        target_costs = np.hypot(*(centres - end).T)
    start_cell = window.free_cell_near(start, 2 * radius_m)
    if start_cell is None:
        return None
    return targets, target_costs, start_cell


def descend(costs: np.ndarray, start: tuple[int, int], max_cells: int) -> np.ndarray:
    """The cells (K, 2: i, j) from `start` down the cost to the target (steepest descent over 8
    neighbours), at most `max_cells` steps; just `start` when it has no finite cost
    (`kernels.grid_dijkstra`)."""
    from vplane_mj.kernels.maps import grid_dijkstra  # numba: loaded by the first call

    costs = np.ascontiguousarray(costs, float)
    return grid_dijkstra.descend(costs, int(start[0]), int(start[1]), int(max_cells))
