"""The way search's step costs, compiled (`gridsearch.step_costs`): each cell's from its distance
to the nearest obstacle cell, in one pass over the distance transforms' output."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def obstacles(sure: np.ndarray, doubtful: np.ndarray) -> tuple[np.ndarray, bool, bool]:
    """The cells that are no obstacle of either kind (nx, ny bool), and whether there are sure
    obstacle cells and doubtful ones."""
    nx, ny = sure.shape
    free = np.empty((nx, ny), dtype=np.bool_)
    any_sure = any_doubtful = False
    for i in range(nx):
        for j in range(ny):
            free[i, j] = not (sure[i, j] or doubtful[i, j])
            any_sure |= sure[i, j]
            any_doubtful |= doubtful[i, j]
    return free, any_sure, any_doubtful


@njit(cache=True)
def step_costs(
    d: np.ndarray, sure_d: np.ndarray, rule: tuple[float, float, float, float, float]
) -> np.ndarray:
    """`gridsearch.step_costs` (see there for the rule) from the distances (cells; nx, ny) to
    the nearest obstacle cell of either kind, `d`, and to the nearest sure one, `sure_d` (0 x 0:
    there is none), as numpy's element-wise arithmetic gives it, bit for bit: distances (m) are
    the cells' times the cell size. `rule` is (cell_m, lethal_m, inflation_m, inflation_weight,
    doubt_cost)."""
    cell_m, lethal_m, inflation_m, inflation_weight, doubt_cost = rule
    nx, ny = d.shape
    cost = np.ones((nx, ny))
    reach = lethal_m + inflation_m
    for i in range(nx):
        for j in range(ny):
            d_m = d[i, j] * cell_m
            closeness = min(max((reach - d_m) / inflation_m, 0.0), 1.0)
            cost[i, j] += inflation_weight * (closeness * closeness) + (doubt_cost if d_m < lethal_m else 0.0)
            if sure_d.size and sure_d[i, j] * cell_m < lethal_m:
                cost[i, j] = np.inf
    return cost
