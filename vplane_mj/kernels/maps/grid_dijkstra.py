"""Dijkstra over an 8-connected grid of step costs, the descent along its costs and whether a
cell is joined to the targets at all, compiled (`gridsearch.cost_to_go`, `descend`,
`way_exists`).

The queue is a ring of buckets (Dial's), each holding the keys of one span of half the cheapest
move's cost: a cell in the lowest bucket cannot be made cheaper by any other queued cell (each
of those costs at least the bucket's low, and a move at least two spans), so its cost is final,
whatever the order a bucket's cells are settled in. Queueing and settling a cell cost O(1),
where a binary heap's sift moved an entry up and down a dozen levels of the frontier. A cell
lowered while queued is queued again; its stale entries are passed over.
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit

_STEPS = np.array([[-1, -1], [-1, 0], [-1, 1], [0, -1], [0, 1], [1, -1], [1, 0], [1, 1]])


@njit
def cost_to_go(
    cost: np.ndarray, targets: np.ndarray, target_costs: np.ndarray, cell_m: float, stop: int
) -> np.ndarray:
    """Least cost (m) from every cell of `cost` (nx, ny; step costs, positive, inf blocked) to
    the `targets` (flat indices of free cells, each starting at its `target_costs`, m, at least
    1e-9); inf where none is reachable. With a `stop` cell (a flat index; -1 for none) the
    search ends once that cell is settled: every cell cheaper than it has its least cost, the
    others keep an upper bound (or inf). A move to one of the 8 neighbours costs its length
    (`cell_m`, or `cell_m` sqrt 2 diagonally, only between two free orthogonal neighbours)
    times the mean of the two cells' step costs. Each cell's cost is the least over its
    neighbours of theirs plus the move, whatever the order cells are settled in, so it is the
    same, bit for bit, as any other correct Dijkstra's over the same weights."""
    nx, ny = cost.shape
    wide = ny + 2
    step, least, most = _framed(cost)
    if not least > 0.0:
        raise ValueError("step costs must be positive")
    diagonal_m = cell_m * math.sqrt(2)
    half_cell, half_diagonal = cell_m * 0.5, diagonal_m * 0.5  # a move: its length times the mean
    width = cell_m * least / 2  # each move costs at least twice a bucket's width
    rings = math.ceil(diagonal_m * most / width) + 2  # a move's cost spans fewer buckets
    order = np.argsort(target_costs, kind="mergesort")
    starts = np.maximum(target_costs[order], 1e-9)
    firsts = ((targets[order] // ny + 1) * wide + targets[order] % ny + 1).astype(np.int64)
    stop = -1 if stop < 0 else (stop // ny + 1) * wide + stop % ny + 1
    dist = np.full(step.shape[0], np.inf)
    head = np.full(rings, -1)  # each bucket's last entry, -1: empty
    entries = targets.shape[0] + 8 * nx * ny  # a cell is queued by a target, or by a neighbour as it settles
    after, cells, keys = (
        np.empty(entries, dtype=np.int64),
        np.empty(entries, dtype=np.int64),
        np.empty(entries),
    )
    used = size = released = 0
    current = int(starts[0] / width) if starts.shape[0] else 0
    while True:
        while released < starts.shape[0] and int(starts[released] / width) < current + rings:
            if starts[released] < dist[firsts[released]]:
                dist[firsts[released]] = starts[released]
                used = _push(head, after, cells, keys, used, firsts[released], starts[released], width)
                size += 1
            released += 1
        if size == 0:
            if released == starts.shape[0]:
                break
            current = max(current + 1, int(starts[released] / width) - rings + 1)
            continue
        e = head[current % rings]
        if e < 0:
            current += 1
            continue
        head[current % rings], u, d = after[e], cells[e], keys[e]
        size -= 1
        if d > dist[u]:
            continue  # queued again cheaper since: a stale entry (a cell's last entry settles it)
        if u == stop:
            break
        here = step[u]
        free_up, free_down = math.isfinite(step[u - wide]), math.isfinite(step[u + wide])
        free_left, free_right = math.isfinite(step[u - 1]), math.isfinite(step[u + 1])
        for s in range(8):
            di, dj = _STEPS[s, 0], _STEPS[s, 1]
            half_length = half_cell
            if di != 0 and dj != 0:  # diagonal: both orthogonal neighbours free, no corner cut
                if not ((free_up if di < 0 else free_down) and (free_left if dj < 0 else free_right)):
                    continue
                half_length = half_diagonal
            v = u + di * wide + dj
            there = step[v]
            if not math.isfinite(there):
                continue  # blocked (a settled neighbour is passed over below: no move lowers it)
            candidate = d + half_length * (here + there)  # half the length, exactly: times 0.5
            if candidate < dist[v]:
                dist[v] = candidate
                used = _push(head, after, cells, keys, used, v, candidate, width)
                size += 1
    return dist.reshape(nx + 2, wide)[1:-1, 1:-1].copy()


@njit
def _framed(cost):
    """The step costs (nx, ny) framed by a blocked cell each side, flat ((nx + 2) (ny + 2)), so
    that no move needs a bounds check; and the least and the largest finite step cost."""
    nx, ny = cost.shape
    step = np.full((nx + 2) * (ny + 2), np.inf)
    least, most = np.inf, 0.0
    for i in range(nx):
        for j in range(ny):
            c = cost[i, j]
            step[(i + 1) * (ny + 2) + j + 1] = c
            if c < np.inf:
                least, most = min(least, c), max(most, c)
    return step, least, most


@njit(inline="always")
def _push(head, after, cells, keys, used, cell, key, width):
    """Queue `cell` at `key` in its bucket (entry `used`, put before the bucket's others); the
    entries used now."""
    bucket = int(key / width) % head.shape[0]
    after[used], cells[used], keys[used] = head[bucket], cell, key
    head[bucket] = used
    return used + 1


@njit
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


@njit
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
