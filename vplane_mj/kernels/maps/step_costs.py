"""The way search's step costs, compiled (`gridsearch.step_costs`).

A cell's step cost depends on its distance to the nearest obstacle cell only within the lethal
distance plus the inflation: farther, it is 1 whatever the distance. So the distances are
taken within that band alone (`near_squares`): along each column to the nearest obstacle cell,
then along each row the least of (column distance)^2 + (cells apart)^2 over the columns within
the band, each loop one the compiler runs on many cells at once. Within the band this is the
exact squared distance (a distance transform's); beyond it, some larger value. The costs of the
few whole-number squared distances are computed once (`_cost_of_square`), as numpy's
element-wise arithmetic on scipy's distances gives them, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
def step_costs(
    sure: np.ndarray, doubtful: np.ndarray, rule: tuple[float, float, float, float, float]
) -> np.ndarray:
    """`gridsearch.step_costs` (see there for the rule) of the cells of `sure` and `doubtful`
    obstacle cells (nx, ny bool); `rule` is (cell_m, lethal_m, inflation_m, inflation_weight,
    doubt_cost)."""
    cell_m, lethal_m, inflation_m = rule[0], rule[1], rule[2]
    nx, ny = sure.shape
    sure_cells, doubtful_cells = sure.view(np.uint8), doubtful.view(np.uint8)
    blocked = np.empty((nx, ny), dtype=np.uint8)
    any_sure = any_doubtful = 0
    for i in range(nx):
        any_sure |= _either(blocked[i], sure_cells[i], doubtful_cells[i])
        any_doubtful |= _any(doubtful_cells[i])
    if not (any_sure or any_doubtful):
        return np.ones((nx, ny))
    band = math.floor((lethal_m + inflation_m) / cell_m) + 1  # beyond band cells: cost 1
    near = near_squares(blocked, band)
    costs = np.empty(near_squares_bound(band))
    for square in range(costs.size):
        costs[square] = _cost_of_square(square, rule)
    lethal_square = 0  # sqrt(square) cells lie closer than lethal_m below it (sqrt is monotone)
    while any_sure and math.sqrt(float(lethal_square)) * cell_m < lethal_m:
        lethal_square += 1
    near_sure = near
    if any_sure and any_doubtful:  # the same cells but for the doubtful ones: their own distances
        near_sure = near_squares(sure_cells, math.floor(lethal_m / cell_m) + 1)
    cost = np.empty((nx, ny))
    for i in range(nx):
        _row_costs(cost[i], near[i], near_sure[i], costs, lethal_square)
    return cost


@njit
def _cost_of_square(square: int, rule: tuple[float, float, float, float, float]) -> float:
    """The step cost of a cell `square` squared cells from the nearest obstacle cell (of either
    kind): numpy's element-wise arithmetic on scipy's distance, bit for bit."""
    cell_m, lethal_m, inflation_m, inflation_weight, doubt_cost = rule
    d_m = math.sqrt(float(square)) * cell_m
    closeness = min(max((lethal_m + inflation_m - d_m) / inflation_m, 0.0), 1.0)
    return 1.0 + (inflation_weight * (closeness * closeness) + (doubt_cost if d_m < lethal_m else 0.0))


@njit
def _row_costs(cost, near, near_sure, costs, lethal_square):
    """One row of step costs from its squared distances to the nearest obstacle cell (`near`)
    and sure one (`near_sure`): `costs` of the first, inf below `lethal_square` of the second."""
    for j in range(cost.size):
        cost[j] = costs[near[j]]
    for j in range(cost.size):
        if near_sure[j] < lethal_square:
            cost[j] = np.inf


@njit
def near_squares(blocked: np.ndarray, band: int) -> np.ndarray:
    """Squared distance (cells^2; nx, ny int32) from each cell to the nearest `blocked` cell (nx,
    ny uint8, 1: blocked), exact where it is at most band^2, some larger value below
    `near_squares_bound(band)` where it is not."""
    nx, ny = blocked.shape
    beyond = np.int32(band + 1)
    column = np.empty((nx, ny), dtype=np.int32)  # cells along axis 0 to the nearest, at most beyond
    _column_start(column[0], blocked[0], beyond)
    for i in range(1, nx):
        _column_down(column[i], column[i - 1], blocked[i], beyond)
    for i in range(nx - 2, -1, -1):
        _column_up(column[i], column[i + 1])
    near = np.empty((nx, ny), dtype=np.int32)
    squares = np.empty(ny, dtype=np.int32)
    for i in range(nx):
        _squared(squares, column[i])
        _row_least(near[i], squares, min(band, ny - 1))
    return near


@njit
def near_squares_bound(band: int) -> int:
    """One more than the largest value of `near_squares` for `band`."""
    return (band + 1) ** 2 + band * band + 1


@njit
def _either(out, a, b):
    """out = a | b (uint8 rows); whether `a` holds a 1."""
    found = 0
    for j in range(out.size):
        out[j] = a[j] | b[j]
        found |= a[j]
    return found


@njit
def _any(row):
    """Whether a uint8 row holds a 1."""
    found = 0
    for j in range(row.size):
        found |= row[j]
    return found


@njit
def _column_start(column, blocked, beyond):
    """The first row of the column distances: 0 on blocked cells, `beyond` elsewhere."""
    for j in range(column.size):
        column[j] = beyond * (blocked[j] ^ 1)


@njit
def _column_down(column, above, blocked, beyond):
    """A row of the column distances from the row above (looking up the columns only)."""
    for j in range(column.size):
        column[j] = min(above[j] + 1, beyond) * (blocked[j] ^ 1)


@njit
def _column_up(column, below):
    """A row of the column distances, the row below taken into account."""
    for j in range(column.size):
        column[j] = min(column[j], below[j] + 1)


@njit
def _squared(out, values):
    """out = values^2."""
    for j in range(out.size):
        out[j] = values[j] * values[j]


@njit
def _row_least(near, squares, band):
    """near[j] = the least squares[j + k] + k^2 over |k| <= `band`, one shift k at a time."""
    count = near.size
    near[:] = squares
    for k in range(1, band + 1):
        extra = k * k
        ahead, behind = near[k:], squares[: count - k]
        for j in range(ahead.size):
            ahead[j] = min(ahead[j], behind[j] + extra)
        ahead, behind = near[: count - k], squares[k:]
        for j in range(ahead.size):
            ahead[j] = min(ahead[j], behind[j] + extra)
