"""Dijkstra over an 8-connected grid of step costs, the descent along its costs and whether a
cell is joined to the targets at all, compiled (`gridsearch.cost_to_go`, `descend`,
`way_exists`).

The queue is a binary heap of cells, each cell in it at most once (its key lowered in place
when a cheaper way reaches it), so the heap stays as small as the search's frontier.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_STEPS = np.array([[-1, -1], [-1, 0], [-1, 1], [0, -1], [0, 1], [1, -1], [1, 0], [1, 1]])
_NEVER_QUEUED = -1
_SETTLED = -2


@njit(cache=True)
def cost_to_go(
    cost: np.ndarray, targets: np.ndarray, target_costs: np.ndarray, cell_m: float, stop: int
) -> np.ndarray:
    """Least cost (m) from every cell of `cost` (nx, ny; step costs, inf blocked) to the
    `targets` (flat indices of free cells, each starting at its `target_costs`, m, at least
    1e-9); inf where none is reachable. With a `stop` cell (a flat index; -1 for none) the
    search ends once that cell is settled: every cell cheaper than it has its least cost, the
    others keep an upper bound (or inf). A move to one of the 8 neighbours costs its length
    (`cell_m`, or `cell_m` sqrt 2 diagonally, only between two free orthogonal neighbours)
    times the mean of the two cells' step costs. Each cell's cost is the least over its
    neighbours of theirs plus the move, whatever the order cells are settled in, so it is the
    same, bit for bit, as any other correct Dijkstra's over the same weights."""
    nx, ny = cost.shape
    dist = np.full(nx * ny, np.inf)
    slot = np.full(nx * ny, _NEVER_QUEUED)  # each cell's place in the heap, or a state
    keys = np.empty(nx * ny)
    cells = np.empty(nx * ny, dtype=np.int64)
    size = 0
    for k in range(targets.shape[0]):
        start = max(target_costs[k], 1e-9)
        if start < dist[targets[k]]:
            dist[targets[k]] = start
            size = _queue(keys, cells, slot, size, targets[k], start)
    diagonal_m = cell_m * math.sqrt(2)
    while size:
        d, u = keys[0], cells[0]
        slot[u] = _SETTLED
        size -= 1
        if size:
            keys[0], cells[0] = keys[size], cells[size]
            _sift_down(keys, cells, slot, size)
        if u == stop:
            break
        i, j = u // ny, u % ny
        for s in range(8):
            a, b = i + _STEPS[s, 0], j + _STEPS[s, 1]
            if a < 0 or a >= nx or b < 0 or b >= ny or not math.isfinite(cost[a, b]):
                continue
            v = a * ny + b
            if slot[v] == _SETTLED:
                continue
            length = cell_m
            if a != i and b != j:  # diagonal: both orthogonal neighbours free, no corner cut
                if not (math.isfinite(cost[a, j]) and math.isfinite(cost[i, b])):
                    continue
                length = diagonal_m
            candidate = d + length * 0.5 * (cost[i, j] + cost[a, b])
            if candidate < dist[v]:
                dist[v] = candidate
                size = _queue(keys, cells, slot, size, v, candidate)
    return dist.reshape(nx, ny)


@njit(cache=True)
def _queue(keys, cells, slot, size, cell, key):
    """Queue `cell` with `key`, or lower its key if it is queued already; the heap's new size."""
    at = slot[cell]
    if at < 0:
        at = size
        size += 1
    while at > 0:  # sift up
        parent = (at - 1) >> 1
        if keys[parent] <= key:
            break
        keys[at], cells[at] = keys[parent], cells[parent]
        slot[cells[at]] = at
        at = parent
    keys[at], cells[at] = key, cell
    slot[cell] = at
    return size


@njit(cache=True)
def _sift_down(keys, cells, slot, size):
    """Move the heap's first entry down to its place."""
    key, cell = keys[0], cells[0]
    at = 0
    while True:
        child = 2 * at + 1
        if child >= size:
            break
        if child + 1 < size and keys[child + 1] < keys[child]:
            child += 1
        if key <= keys[child]:
            break
        keys[at], cells[at] = keys[child], cells[child]
        slot[cells[at]] = at
        at = child
    keys[at], cells[at] = key, cell
    slot[cell] = at


@njit(cache=True)
def descend(costs: np.ndarray, i: int, j: int, max_cells: int) -> np.ndarray:
    """The cells (K, 2) from (i, j) down `costs` to the target: from each cell to its cheapest
    neighbour (the first of the 8 in `_STEPS`' order among equals) while that one is cheaper,
    at most `max_cells` steps; just (i, j) when its cost is not finite."""
    nx, ny = costs.shape
    path = np.empty((min(max_cells, nx * ny) + 1, 2), dtype=np.int64)
    path[0, 0], path[0, 1] = i, j
    count = 1
    if not math.isfinite(costs[i, j]):
        return path[:1]
    for _ in range(max_cells):
        best_cost = costs[i, j]
        best = -1
        for s in range(8):
            a, b = i + _STEPS[s, 0], j + _STEPS[s, 1]
            if 0 <= a < nx and 0 <= b < ny and costs[a, b] < best_cost:
                best, best_cost = s, costs[a, b]
        if best < 0:
            break
        i, j = i + _STEPS[best, 0], j + _STEPS[best, 1]
        path[count, 0], path[count, 1] = i, j
        count += 1
    return path[:count]


@njit(cache=True)
def reaches(cost: np.ndarray, targets: np.ndarray, start: int) -> bool:
    """Whether the cell `start` (a flat index of a free cell of `cost`, nx x ny, inf blocked) is
    joined to one of the free `targets` (flat indices) by `cost_to_go`'s moves: its cost there
    is finite. Moves are the same both ways, so a flood fill from the start decides."""
    nx, ny = cost.shape
    wanted = np.zeros(nx * ny, dtype=np.bool_)
    for k in range(targets.shape[0]):
        wanted[targets[k]] = True
    seen = np.zeros(nx * ny, dtype=np.bool_)
    stack = np.empty(nx * ny, dtype=np.int64)
    stack[0] = start
    seen[start] = True
    top = 1
    while top:
        top -= 1
        u = stack[top]
        if wanted[u]:
            return True
        i, j = u // ny, u % ny
        for s in range(8):
            a, b = i + _STEPS[s, 0], j + _STEPS[s, 1]
            if a < 0 or a >= nx or b < 0 or b >= ny or not math.isfinite(cost[a, b]):
                continue
            v = a * ny + b
            if seen[v]:
                continue
            if a != i and b != j and not (math.isfinite(cost[a, j]) and math.isfinite(cost[i, b])):
                continue  # a diagonal only between two free orthogonal neighbours
            seen[v] = True
            stack[top] = v
            top += 1
    return False
