"""Dijkstra over an 8-connected grid of step costs, compiled (`gridsearch.cost_to_go`)."""

from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

_STEPS = np.array([[-1, -1], [-1, 0], [-1, 1], [0, -1], [0, 1], [1, -1], [1, 0], [1, 1]])


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
    heap = [(0.0, 0)]
    heap.pop()
    for k in range(targets.shape[0]):
        start = max(target_costs[k], 1e-9)
        if start < dist[targets[k]]:
            dist[targets[k]] = start
            heapq.heappush(heap, (start, targets[k]))
    diagonal_m = cell_m * math.sqrt(2)
    while heap:
        d, u = heapq.heappop(heap)
        if d > dist[u]:
            continue
        if u == stop:
            break
        i, j = u // ny, u % ny
        for s in range(8):
            a, b = i + _STEPS[s, 0], j + _STEPS[s, 1]
            if a < 0 or a >= nx or b < 0 or b >= ny or not math.isfinite(cost[a, b]):
                continue
            length = cell_m
            if a != i and b != j:  # diagonal: both orthogonal neighbours free, no corner cut
                if not (math.isfinite(cost[a, j]) and math.isfinite(cost[i, b])):
                    continue
                length = diagonal_m
            candidate = d + length * 0.5 * (cost[i, j] + cost[a, b])
            v = a * ny + b
            if candidate < dist[v]:
                dist[v] = candidate
                heapq.heappush(heap, (candidate, v))
    return dist.reshape(nx, ny)
