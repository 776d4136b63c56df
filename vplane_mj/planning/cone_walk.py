"""The grid cells a scan may change, found by walking each beam's cone (a compiled kernel).

A laser's hundreds of narrow beams, or an echo far beyond the grid, make the local map's
table of cone cells (`localmap._ConeTable`) too slow or too large; this kernel visits the
cells of each cone directly instead. Each beam's cone is split into pieces at most a quarter
turn wide; a piece is held by the quadrilateral of the robot, the arc's two ends and the
point where the tangents at those ends meet, so the cells of one grid line (a row or a
column, whichever crosses fewer lines) that lie inside it form one run, computed from the
four edges. Only cells of the grid (not its margin) are visited, so an echo beyond the grid
costs no more than one at its edge.

Of the cells of a cone, a cell is listed when it lies in the beam's arc band, or nearer
than the band and marked (an echo clears it), or nearer and not yet seen (with `seen`);
every listed cell is then classified exactly by the map (`LocalMap.update`). The bounds
passed in are wider than the exact rule by a margin, so rounding never drops a cell.
Each cell is listed once per call (a stamp per cell).

numba is imported here only: the map imports this module the first time it needs it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

ANGLE_MARGIN_RAD = 1e-9
DISTANCE_MARGIN_M = 1e-6
"""How much wider than the map's rule the walk looks (rad, m), so that rounding drops no cell."""
QUARTER_TURN = math.pi / 2


@njit(cache=True)
def cone_cells(
    robot: np.ndarray,
    first_cell: np.ndarray,
    shape: np.ndarray,
    cell_m: float,
    arc_m: float,
    start: np.ndarray,
    stop: np.ndarray,
    ranges: np.ndarray,
    marks: np.ndarray,
    silent_m: float,
    grid: np.ndarray,
    seen: np.ndarray,
    track_seen: bool,
    stamps: np.ndarray,
    stamp: int,
    out: np.ndarray,
) -> int:
    """List into `out` the flat indices of the cells the scan may change; their number.

    `robot` (x, y) in m; `first_cell` the world cell index (i, j) of grid cell (0, 0);
    `shape` (n, pad, stride): the grid's side, its margin and the padded row length, so that
    grid cell (i, j) is element (i + pad) * stride + j + pad of the flat `grid` (certainties),
    `seen` and `stamps`. Cone c spans the world angles `start[c]` to `stop[c]` (rad,
    counter-clockwise); its range is `ranges[c]` (m, NaN: no echo) and `marks[c]` says whether
    its echo marks its arc (the cells within `arc_m` of the range; the free cone ends a cell
    short of it). A beam without an echo shows its cone to `silent_m` (m, with `track_seen`).
    A cell is listed once: its stamp becomes `stamp`.
    """
    # No cone needs to reach past the grid's farthest corner (with a cell to spare).
    n = shape[0]
    far_x = max(abs(robot[0] - first_cell[0] * cell_m), abs((first_cell[0] + n) * cell_m - robot[0]))
    far_y = max(abs(robot[1] - first_cell[1] * cell_m), abs((first_cell[1] + n) * cell_m - robot[1]))
    extent2 = far_x * far_x + far_y * far_y + cell_m * cell_m
    count = 0
    for c in range(start.shape[0]):
        band_lo2, band_hi2, clear, show = _cone_reach(
            ranges[c], marks[c], arc_m, cell_m, silent_m, track_seen
        )
        reach2 = min(max(band_hi2, clear * clear, show * show), extent2)
        if reach2 <= 0.0:
            continue
        span = stop[c] - start[c] + 2 * ANGLE_MARGIN_RAD
        pieces = max(1, math.ceil(span / QUARTER_TURN))
        width = span / pieces
        for k in range(pieces):  # overlapping a little: rounding drops no cell
            low = start[c] - ANGLE_MARGIN_RAD + k * width - ANGLE_MARGIN_RAD
            high = low + width + 2 * ANGLE_MARGIN_RAD
            count = _walk_piece(
                robot,
                first_cell,
                shape,
                cell_m,
                math.cos(low),
                math.sin(low),
                math.cos(high),
                math.sin(high),
                reach2,
                band_lo2,
                band_hi2,
                clear * clear,
                show * show,
                grid,
                seen,
                track_seen,
                stamps,
                stamp,
                out,
                count,
            )
    return count


@njit(cache=True)
def _cone_reach(
    r: float, marks: bool, arc_m: float, cell_m: float, silent_m: float, track_seen: bool
) -> tuple[float, float, float, float]:
    """For a cone with the range `r` (m, NaN: no echo): the squared bounds (m^2) of the arc band
    it marks (inf and -1 when it marks none), and how far (m) it clears marked cells and shows
    unseen ones (0 without `track_seen`)."""
    band_lo2, band_hi2, clear, show = math.inf, -1.0, 0.0, 0.0
    if r == r:  # an echo
        band_hi = r + arc_m + DISTANCE_MARGIN_M
        if marks and band_hi > 0.0:
            band_lo = max(r - arc_m - DISTANCE_MARGIN_M, 0.0)
            band_lo2, band_hi2 = band_lo * band_lo, band_hi * band_hi
            clear = max(r - arc_m + DISTANCE_MARGIN_M, 0.0)
        else:
            clear = max(r - cell_m + DISTANCE_MARGIN_M, 0.0)
        show = clear
    elif silent_m > 0.0:
        show = silent_m + DISTANCE_MARGIN_M
    if not track_seen:
        show = 0.0
    return band_lo2, band_hi2, clear, show


@njit(cache=True)
def _walk_piece(
    robot,
    first_cell,
    shape,
    cell_m,
    ax,
    ay,
    bx,
    by,
    reach2,
    band_lo2,
    band_hi2,
    clear2,
    show2,
    grid,
    seen,
    track_seen,
    stamps,
    stamp,
    out,
    count,
):
    """List the cells of one piece of a cone: from the direction (ax, ay) counter-clockwise to
    (bx, by), at most a quarter turn; squared distances (m^2) as in `cone_cells`."""
    n, pad, stride = shape[0], shape[1], shape[2]
    x0, y0 = robot[0], robot[1]
    reach = math.sqrt(reach2)
    # The quadrilateral robot, arc's start, corner (where the tangents at the arc's ends
    # meet), arc's end: counter-clockwise in x, y, and it holds the piece.
    sx, sy = ax + bx, ay + by
    far = 2.0 * reach / (sx * sx + sy * sy)
    x1, y1 = x0 + reach * ax, y0 + reach * ay
    x2, y2 = x0 + far * sx, y0 + far * sy
    x3, y3 = x0 + reach * bx, y0 + reach * by
    x_lo, x_hi = min(x0, x1, x2, x3), max(x0, x1, x2, x3)
    y_lo, y_hi = min(y0, y1, y2, y3), max(y0, y1, y2, y3)
    # Lines of constant u, runs along v: rows (u = x) or columns (u = y), whichever are fewer.
    if x_hi - x_lo <= y_hi - y_lo:
        us, vs = (x0, x1, x2, x3), (y0, y1, y2, y3)
        u_lo, u_hi, first_u, first_v = x_lo, x_hi, first_cell[0], first_cell[1]
        step_u, step_v, orient = stride, 1, 1.0
    else:
        us, vs = (y0, y1, y2, y3), (x0, x1, x2, x3)
        u_lo, u_hi, first_u, first_v = y_lo, y_hi, first_cell[1], first_cell[0]
        step_u, step_v, orient = 1, stride, -1.0
    # Each edge bounds a line's run from below or above (or, parallel to the lines, keeps or
    # drops whole lines); its inner side is the left one in x, y.
    k0, m0 = _edge(us[0], vs[0], us[1], vs[1], orient)
    k1, m1 = _edge(us[1], vs[1], us[2], vs[2], orient)
    k2, m2 = _edge(us[2], vs[2], us[3], vs[3], orient)
    k3, m3 = _edge(us[3], vs[3], us[0], vs[0], orient)
    line_first = max(0, math.ceil((u_lo - 1e-9) / cell_m - first_u - 0.5))
    line_last = min(n - 1, math.floor((u_hi + 1e-9) / cell_m - first_u - 0.5))
    for line in range(line_first, line_last + 1):
        u = (first_u + line + 0.5) * cell_m
        lo, hi = _bound(-math.inf, math.inf, u, k0, m0, us[0], vs[0])
        lo, hi = _bound(lo, hi, u, k1, m1, us[1], vs[1])
        lo, hi = _bound(lo, hi, u, k2, m2, us[2], vs[2])
        lo, hi = _bound(lo, hi, u, k3, m3, us[3], vs[3])
        if lo > hi:
            continue
        run_first = max(0, math.ceil((lo - 1e-9) / cell_m - first_v - 0.5))
        run_last = min(n - 1, math.floor((hi + 1e-9) / cell_m - first_v - 0.5))
        du2 = (u - us[0]) * (u - us[0])
        base = (line + pad) * step_u + pad * step_v
        for along in range(run_first, run_last + 1):
            dv = (first_v + along + 0.5) * cell_m - vs[0]
            d2 = du2 + dv * dv
            index = base + along * step_v
            listed = (
                band_lo2 <= d2 <= band_hi2
                or (d2 < clear2 and grid[index] > 0)
                or (track_seen and d2 < show2 and not seen[index])
            )
            if listed and stamps[index] != stamp:
                stamps[index] = stamp
                out[count] = index
                count += 1
    return count


@njit(cache=True)
def _edge(ua, va, ub, vb, orient):
    """How the edge a -> b bounds the run of a line of constant u: (1, slope) from below,
    (-1, slope) from above, (0, s) parallel to the lines (a line at u is outside when
    s (u - ua) > 0). Its inner side is the left one when `orient` is 1, the right when -1."""
    du, dv = ub - ua, vb - va
    if du == 0.0:
        return 0, orient * dv
    return (1 if orient * du > 0.0 else -1), dv / du


@njit(cache=True)
def _bound(lo, hi, u, kind, slope, ua, va):
    """The run [lo, hi] of the line at `u` cut by one edge (see `_edge`) through (ua, va)."""
    if kind > 0:
        return max(lo, va + slope * (u - ua)), hi
    if kind < 0:
        return lo, min(hi, va + slope * (u - ua))
    if slope * (u - ua) > 0.0:
        return math.inf, -math.inf
    return lo, hi
