"""The way search's step costs, compiled (`gridsearch.step_costs`): each cell's from its distance
to the nearest obstacle cell, in one pass after the distance transforms."""

from __future__ import annotations

import numpy as np
from numba import njit

from vplane_mj.planning.kernels.edt import distance_transform


@njit(cache=True)
def step_costs(
    sure: np.ndarray,
    doubtful: np.ndarray,
    cell_m: float,
    lethal_m: float,
    inflation_m: float,
    inflation_weight: float,
    doubt_cost: float,
) -> np.ndarray:
    """`gridsearch.step_costs` (see there for the rule), as numpy's element-wise arithmetic
    gives it, bit for bit: distances (m) are the transform's (cells) times `cell_m`."""
    nx, ny = sure.shape
    cost = np.ones((nx, ny))
    free = np.empty((nx, ny), dtype=np.bool_)
    any_sure = any_doubtful = False
    for i in range(nx):
        for j in range(ny):
            free[i, j] = not (sure[i, j] or doubtful[i, j])
            any_sure |= sure[i, j]
            any_doubtful |= doubtful[i, j]
    if not (any_sure or any_doubtful):
        return cost
    d = distance_transform(free)
    sure_d = d
    if any_sure and any_doubtful:  # the same cells but for the doubtful ones: their own distances
        sure_d = distance_transform(~sure)
    reach = lethal_m + inflation_m
    for i in range(nx):
        for j in range(ny):
            d_m = d[i, j] * cell_m
            closeness = min(max((reach - d_m) / inflation_m, 0.0), 1.0)
            cost[i, j] += inflation_weight * (closeness * closeness) + (doubt_cost if d_m < lethal_m else 0.0)
            if any_sure and sure_d[i, j] * cell_m < lethal_m:
                cost[i, j] = np.inf
    return cost
