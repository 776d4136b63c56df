"""The local map's update, compiled: the beams' cones walked, and the cells they may change judged.

A scan changes only the cells near its echo arcs (hits), the marked cells inside its cones
(misses: an empty cell stays empty) and, with `seen`, the cells of its cones not yet seen. The
walk visits the cells of each wedge: the cones of neighbouring beams that adjoin and reach about
as far, walked as one (a laser's cones are far narrower than a cell: walked one by one, most
grid lines of a cone held a cell or none, and a cell was visited by several cones). A wedge is
split into pieces at most a quarter turn wide; a piece is held by the quadrilateral of the
robot, the arc's two ends and the point where the tangents at those ends meet, so the cells of
one grid line (a row or a column, whichever crosses fewer lines) that lie inside it form one
run, computed from the four edges. Only cells of the grid are visited, so an echo beyond the
grid costs no more than one at its edge.

Of the cells of a wedge, a cell is taken when it lies in the arc band of its own beam (the
nearest direction), or nearer than the band and marked (an echo clears it), or nearer and not
yet seen (with `seen`); the bounds are wider than the rule by a margin, so rounding never drops
a cell. The wedge's own bounds (the widest of its cones') are tested first: a cell no cone of
the wedge can change is passed over before its direction is sought. Each cell taken is then
judged by the map's rule (`vplane_mj.planning.perception.localmap`), in the walk of the wedge that holds
its own beam's cone alone (the wedges overlap at their margins; its own holds every cell the
beam can change), so once: its beam is the nearest direction, and it must lie within half a
beam width of that direction's axis; a cell within ARC_HALF_WIDTH cell of the range, along its
beam, is on the arc and gains `hit`; a cell nearer than the range less one cell is in the free
cone and loses `miss`. So the grid is what a pass over every cell would make of it.

The nearest direction is found by arithmetic for an evenly spaced ring (`nearest_in_ring`), by
a search among the bounds half-way between neighbouring directions for any directions
(`nearest_by_search`): one rule, two ways, which agree wherever rounding does not decide. A
dense fan's directions (`beams.BeamFan.quick`: a laser's, whose beams cover their share) are
found without an arctangent, by the side of the bounds (their unit vectors, turned once a scan)
the cell lies on, wherever it lies more than SURE_RAD off each; on a bound, by the angles.
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit

ARC_HALF_WIDTH = 0.75
"""An echo's arc holds the cells within this many cells of its range (along the beam)."""
ANGLE_MARGIN_RAD = 1e-9
DISTANCE_MARGIN_M = 1e-6
"""How much wider than the map's rule the walk looks (rad, m), so that rounding drops no cell."""
QUARTER_TURN = math.pi / 2
WEDGE_SPAN_RAD = 0.2
WEDGE_SPREAD_CELLS = 2.0
"""A wedge of neighbouring cones walked as one spans at most this (rad), and their reaches
differ by at most this many cells (`_wedge`)."""
TURN = 2 * math.pi
SURE_RAD = 1e-9
"""A point whose direction lies more than this (rad) off a line through the robot is surely on its
side of it (a bound between beams here, an edge of the view in `memory`): the angles' own
rounding (an arctangent, differences of angles) is some 1e-14 rad."""


@njit
def fold_scan(
    x: float,
    y: float,
    yaw: float,
    first_cell: np.ndarray,
    cell_m: float,
    beam: float,
    directions: np.ndarray,
    half_before: np.ndarray,
    half_after: np.ndarray,
    spacing: float,
    bounds: np.ndarray,
    bound_units: np.ndarray,
    quick: np.ndarray,
    ranges: np.ndarray,
    mark_range_m: float,
    silent_free_m: float,
    rule: np.ndarray,
    track_seen: bool,
    grid: np.ndarray,
    seen: np.ndarray,
) -> None:
    """Fold one scan into `grid` (n, n certainties) and `seen` (n, n), in place.

    The robot at `x`, `y` (m) heading `yaw` (rad); `first_cell` the world cell index (i, j) of
    grid cell (0, 0), cells of `cell_m`. The scan's distinct directions (rad, robot frame,
    ascending) are `directions`, each beam `beam` wide (rad) and its cone clipped to
    `half_before` and `half_after` of its axis; `spacing` (rad) is the even ring's, 0 for any
    directions, then searched among `bounds`; `bound_units` are the bounds' unit vectors and
    `quick` the directions whose cells are found by the side of the bounds they lie on
    (`beams.BeamFan`). `ranges[k]` (m, NaN: no echo) is direction k's;
    an echo marks its arc when it is at most `mark_range_m` away. When some direction has no
    echo, its cone shows free for `silent_free_m` (m, with `track_seen`). `rule` is (hit,
    miss, max_certainty).
    """
    n = grid.shape[0]
    marks = np.empty(directions.shape[0], dtype=np.bool_)
    silent_m = 0.0
    for c in range(directions.shape[0]):
        marks[c] = ranges[c] <= mark_range_m
        if ranges[c] != ranges[c]:
            silent_m = silent_free_m
    # No cone needs to reach past the grid's farthest corner (with a cell to spare).
    far_x = max(abs(x - first_cell[0] * cell_m), abs((first_cell[0] + n) * cell_m - x))
    far_y = max(abs(y - first_cell[1] * cell_m), abs((first_cell[1] + n) * cell_m - y))
    extent2 = far_x * far_x + far_y * far_y + cell_m * cell_m
    _fold_cones(
        (x, y, yaw, cell_m, beam, spacing, silent_m, extent2, track_seen),
        (first_cell[0], first_cell[1], n),
        (
            directions,
            half_before,
            half_after,
            bounds,
            ranges,
            marks,
            _turned(bound_units, yaw + directions[0]),
            quick,
        ),
        (rule[0], rule[1], rule[2]),
        grid.reshape(-1),
        seen.reshape(-1),
    )


@njit
def _fold_cones(scan, cells, fan, rule, flat, seen_flat):
    """`fold_scan`'s walk through the scan's wedges (`_wedge`: the cones of neighbouring beams
    that reach about as far, walked as one) and its judgement of the cells it takes: one loop
    nest, its helpers given numbers alone (an array handed to a compiled function costs two
    atomic reference counts a call, which took 40% of the update when the walk and the
    judgement were helpers of their own). `flat` and `seen_flat` are the grid and the seen
    mask, flat."""
    x, y, yaw, cell_m, beam, spacing, silent_m, extent2, track_seen = scan
    first_i, first_j, n = cells
    directions, half_before, half_after, bounds, ranges, marks, bound_units, quick = fan
    per_cell = 1.0 / cell_m
    axis0 = yaw + directions[0]
    judging = (beam, cell_m, ARC_HALF_WIDTH * cell_m, silent_m, rule[0], rule[1], rule[2])
    reach = _cone_bounds(ranges, marks, judging[2], cell_m, silent_m, track_seen, extent2)
    c = 0
    while c < directions.shape[0]:
        if reach[c, 4] <= 0.0:
            c += 1  # nothing to walk: a silent beam, or an echo inside the robot
            continue
        last, band_lo2, band_hi2, clear2, show2, reach2 = _wedge(
            c, reach, directions, half_before, half_after, cell_m
        )
        sided = quick[c : last + 1].all()  # its cells' directions found by the bounds' sides
        start = yaw + directions[c] - half_before[c] - ANGLE_MARGIN_RAD
        span = directions[last] - directions[c] + half_after[last] + half_before[c] + 2 * ANGLE_MARGIN_RAD
        pieces = max(1, math.ceil(span / QUARTER_TURN))
        width = span / pieces
        for k in range(pieces):  # overlapping a little: rounding drops no cell
            low = start + k * width - ANGLE_MARGIN_RAD
            high = low + width + 2 * ANGLE_MARGIN_RAD
            sight = (math.cos(low), math.sin(low), math.cos(high), math.sin(high))
            us, vs, edges, lines, first_v, step_u, step_v = _piece_lines(
                n, sight, reach2, x, y, cell_m, first_i, first_j
            )
            for line in range(lines[0], lines[1] + 1):
                u = (lines[2] + line + 0.5) * cell_m
                run_first, run_last = _run(u, us, vs, edges, per_cell, first_v, n)
                du2 = (u - us[0]) * (u - us[0])
                for along in range(run_first, run_last + 1):
                    dv = (first_v + along + 0.5) * cell_m - vs[0]
                    d2 = du2 + dv * dv
                    index = line * step_u + along * step_v
                    if not _may_change(
                        d2, band_lo2, band_hi2, clear2, show2, flat[index], seen_flat[index], track_seen
                    ):
                        continue
                    # The map's rule for this cell, by its nearest direction: judged only in
                    # the walk of the wedge that holds it (which holds every cell it can change).
                    i, j = (line, along) if step_u == n else (along, line)
                    rel_x = (first_i + i + 0.5) * cell_m - x
                    rel_y = (first_j + j + 0.5) * cell_m - y
                    nearest, offset = _by_sides(rel_x, rel_y, c, last, bound_units) if sided else (-2, 0.0)
                    if nearest == -2:  # unsure (or not sided): by the angles themselves
                        angle = math.atan2(rel_y, rel_x) - axis0
                        if spacing > 0.0:
                            nearest, offset = nearest_in_ring(angle, axis0, spacing, directions.shape[0])
                        else:
                            nearest, offset = nearest_by_search(angle, bounds, directions)
                    if not (
                        c <= nearest <= last
                        and _may_change_by(d2, reach, nearest, flat[index], seen_flat[index], track_seen)
                    ):
                        continue
                    distance = math.hypot(rel_x, rel_y)
                    value, shown = _judged(
                        flat[index], distance, offset, ranges[nearest], marks[nearest], judging
                    )
                    flat[index] = value
                    if track_seen and shown:
                        seen_flat[index] = True
        c = last + 1


@njit(inline="always")
def _by_sides(rel_x, rel_y, c, last, units):
    """The nearest direction of the cell at (`rel_x`, `rel_y`) (m from the robot) among the
    wedge's `c` to `last`, all `quick`, and its angle from that direction's axis where the
    cell lies within its beam (given as 0): found by the side of the bounds (`units`, world unit
    vectors) the cell lies on, -1 when it surely lies beyond the wedge's bounds, -2 when it lies
    within SURE_RAD of a bound (then only the angles decide)."""
    sure = sure_off_line(rel_x, rel_y)
    before = c - 1 if c > 0 else units.shape[0] - 1
    side = side_of(units[before, 0], units[before, 1], rel_x, rel_y, sure)
    if side <= 0:
        return (-1 if side < 0 else -2), 0.0
    for k in range(c, last + 1):
        side = side_of(units[k, 0], units[k, 1], rel_x, rel_y, sure)
        if side <= 0:
            return (k if side < 0 else -2), 0.0
    return -1, 0.0


@njit(inline="always")
def sure_off_line(x: float, y: float) -> float:
    """How far (in the units of `side_of`'s cross product) the point (x, y) (m from the robot)
    must lie off a line through the robot to lie surely on one side: SURE_RAD times a bound on
    its distance."""
    return SURE_RAD * (abs(x) + abs(y))


@njit(inline="always")
def side_of(ux: float, uy: float, x: float, y: float, sure: float) -> int:
    """Which side of the line through the robot along the unit vector (ux, uy) the point (x, y)
    (m from the robot) lies on: 1 counter-clockwise of it, -1 clockwise, 0 within `sure`
    (`sure_off_line`) of it, where only the angles decide."""
    side = ux * y - uy * x
    return 1 if side > sure else -1 if side < -sure else 0


@njit
def _turned(units, angle):
    """The unit vectors (K, 2) turned counter-clockwise by `angle` (rad)."""
    c, s = math.cos(angle), math.sin(angle)
    out = np.empty_like(units)
    for k in range(units.shape[0]):
        out[k, 0] = c * units[k, 0] - s * units[k, 1]
        out[k, 1] = s * units[k, 0] + c * units[k, 1]
    return out


@njit(inline="always")
def _may_change(d2, band_lo2, band_hi2, clear2, show2, value, seen, track_seen):
    """Whether a cell `d2` (m^2) from the robot, of certainty `value`, may change under a cone
    (or a wedge) with these squared bounds (`_cone_bounds`): in the arc band, or nearer and
    marked (an echo clears it), or nearer and not yet seen (with `seen`)."""
    return (
        band_lo2 <= d2 <= band_hi2 or (d2 < clear2 and value > 0) or (track_seen and d2 < show2 and not seen)
    )


@njit(inline="always")
def _may_change_by(d2, reach, k, value, seen, track_seen):
    """`_may_change` under direction `k`'s cone, its bounds `reach[k]` (`_cone_bounds`)."""
    return _may_change(d2, reach[k, 0], reach[k, 1], reach[k, 2], reach[k, 3], value, seen, track_seen)


@njit
def _cone_bounds(ranges, marks, arc_m, cell_m, silent_m, track_seen, extent2):
    """Each direction's squared bounds (m^2, `_cone_reach`): the arc band's low and high, how
    far it clears marked cells, how far it shows unseen ones, and how far its cone is walked (at
    most `extent2`; 0: not walked)."""
    reach = np.empty((ranges.shape[0], 5))
    for c in range(ranges.shape[0]):
        band_lo2, band_hi2, clear, show = _cone_reach(
            ranges[c], marks[c], arc_m, cell_m, silent_m, track_seen
        )
        clear2, show2 = clear * clear, show * show
        reach[c, 0], reach[c, 1], reach[c, 2], reach[c, 3] = band_lo2, band_hi2, clear2, show2
        reach[c, 4] = min(max(band_hi2, clear2, show2), extent2)
    return reach


@njit
def _wedge(c, reach, directions, half_before, half_after, cell_m):
    """The wedge walked from direction `c`: it and the next directions whose cones adjoin it,
    while it spans at most WEDGE_SPAN_RAD and their walked reaches differ by at most
    WEDGE_SPREAD_CELLS cells (a laser's cones are far narrower than a cell: walked one by one,
    each grid line of each cone costs a run of a cell or none). The last direction, and the
    wedge's bounds (m^2): the lowest band's low, the highest band's high, the farthest clear,
    show and walk."""
    low = high = math.sqrt(reach[c, 4])
    lo2, hi2, clear2, show2, reach2 = reach[c, 0], reach[c, 1], reach[c, 2], reach[c, 3], reach[c, 4]
    last = c
    while last + 1 < directions.shape[0]:
        d = last + 1
        far = math.sqrt(reach[d, 4]) if reach[d, 4] > 0.0 else -math.inf
        adjoins = directions[d] - half_before[d] <= directions[last] + half_after[last] + ANGLE_MARGIN_RAD
        span = directions[d] + half_after[d] - (directions[c] - half_before[c])
        spread = max(high, far) - min(low, far)
        if not (adjoins and span <= WEDGE_SPAN_RAD and spread <= WEDGE_SPREAD_CELLS * cell_m):
            break
        low, high, last = min(low, far), max(high, far), d
        lo2, hi2 = min(lo2, reach[d, 0]), max(hi2, reach[d, 1])
        clear2, show2, reach2 = max(clear2, reach[d, 2]), max(show2, reach[d, 3]), max(reach2, reach[d, 4])
    return last, lo2, hi2, clear2, show2, reach2


@njit
def _judged(value, distance, offset, reading, marking, judging):
    """A cell's certainty after one scan, from `value`, and whether the scan shows it free: the
    cell `distance` (m) from the robot and `offset` (rad) from the axis of its nearest
    direction, whose range is `reading` (m, NaN: no echo) and whose arc marks when `marking`;
    `judging` is (beam, cell_m, arc_m, silent_m, hit, miss, max_certainty)."""
    beam, cell_m, arc_m, silent_m, hit, miss, most = judging
    in_beam = abs(offset) <= beam / 2
    echo = reading == reading  # not NaN
    shown_range = reading if echo and in_beam else -1.0
    shown_free = distance < shown_range - cell_m
    delta = 0
    if abs(distance - shown_range) <= arc_m and marking:
        delta += hit
    if shown_free:
        delta -= miss
    silent_free = silent_m > 0.0 and in_beam and not echo and distance < silent_m
    return min(max(value + delta, 0), most), shown_free or silent_free


@njit
def nearest_in_ring(angle: float, axis: float, spacing: float, count: int) -> tuple[int, float]:
    """The nearest direction (index) of an angle (rad from the first direction's world axis,
    `axis`) on an evenly spaced ring of `count` directions `spacing` apart, and the angle from
    its axis, in [-pi, pi), by arithmetic."""
    beam = int(np.rint(angle / spacing)) % count  # halves to even, as np.round
    offset = angle - beam * spacing + math.pi  # wrapped below: the angle from its axis
    if abs(axis) <= math.pi:  # offset in (-2 pi, 4 pi): the modulo is one conditional turn
        if offset < 0.0:
            offset += TURN
        elif offset >= TURN:
            offset -= TURN
        return beam, offset - math.pi
    return beam, offset % TURN - math.pi


@njit
def nearest_by_search(angle: float, bounds: np.ndarray, directions: np.ndarray) -> tuple[int, float]:
    """`nearest_in_ring` for any directions (rad, ascending): a search among the `bounds` half-way
    between neighbouring directions (each relative to the first direction)."""
    angle = remainder_of_turn(angle)
    beam = np.searchsorted(bounds, angle, side="right") % directions.shape[0]
    return beam, remainder_of_turn(angle - (directions[beam] - directions[0]) + math.pi) - math.pi


@njit
def remainder_of_turn(angle: float) -> float:
    """`angle % TURN` (rad) as Python's float modulo gives it, by one conditional turn when the
    angle lies within a turn of [0, TURN) (the modulo is then that turn added or taken away,
    rounded alike)."""
    if 0.0 <= angle < TURN:
        return angle
    if -TURN <= angle < 0.0:
        return angle + TURN
    if TURN <= angle < 2 * TURN:
        return angle - TURN
    return angle % TURN


@njit
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


@njit(inline="always")
def _run(u, us, vs, edges, per_cell, first_v, n):
    """The first and last cell (indices along the line, within the grid) of the run of a piece's
    quadrilateral (see `_piece_lines`) on the grid line at `u` (m), cells `1 / per_cell` m
    wide; first > last: none. Inlined: a call a grid line, its twenty numbers on the stack,
    took a twentieth of the update."""
    lo, hi = -math.inf, math.inf
    for k in range(4):
        lo, hi = _bound(lo, hi, u, edges[k][0], edges[k][1], us[k], vs[k])
    if lo > hi:
        return 1, 0
    return (
        max(0, math.ceil((lo - 1e-9) * per_cell - first_v - 0.5)),
        min(n - 1, math.floor((hi + 1e-9) * per_cell - first_v - 0.5)),
    )


@njit
def _piece_lines(n, sight, reach2, x0, y0, cell_m, first_i, first_j):
    """How to walk one piece of a cone (see `fold_scan`): the corners (u, v) of the
    quadrilateral that holds it (the robot, the arc's start, the corner where the tangents at
    the arc's ends meet, the arc's end), its four edges (`_edge`), the first and last grid
    line it crosses and the first line's world cell, the first cell along a line, and the flat
    index steps between lines and along one. Lines are rows (u = x) or columns (u = y),
    whichever are fewer."""
    ax, ay, bx, by = sight
    far_m = math.sqrt(reach2)
    sx, sy = ax + bx, ay + by
    far = 2.0 * far_m / (sx * sx + sy * sy)
    xs = (x0, x0 + far_m * ax, x0 + far * sx, x0 + far_m * bx)
    ys = (y0, y0 + far_m * ay, y0 + far * sy, y0 + far_m * by)
    if max(xs) - min(xs) <= max(ys) - min(ys):
        us, vs, first_u, first_v, step_u, step_v, orient = xs, ys, first_i, first_j, n, 1, 1.0
    else:
        us, vs, first_u, first_v, step_u, step_v, orient = ys, xs, first_j, first_i, 1, n, -1.0
    # Each edge bounds a line's run from below or above (or, parallel to the lines, keeps or
    # drops whole lines); its inner side is the left one in x, y.
    edges = (
        _edge(us[0], vs[0], us[1], vs[1], orient),
        _edge(us[1], vs[1], us[2], vs[2], orient),
        _edge(us[2], vs[2], us[3], vs[3], orient),
        _edge(us[3], vs[3], us[0], vs[0], orient),
    )
    line_first = max(0, math.ceil((min(us) - 1e-9) / cell_m - first_u - 0.5))
    line_last = min(n - 1, math.floor((max(us) + 1e-9) / cell_m - first_u - 0.5))
    return us, vs, edges, (line_first, line_last, first_u), first_v, step_u, step_v


@njit
def _edge(ua, va, ub, vb, orient):
    """How the edge a -> b bounds the run of a line of constant u: (1, slope) from below,
    (-1, slope) from above, (0, s) parallel to the lines (a line at u is outside when
    s (u - ua) > 0). Its inner side is the left one when `orient` is 1, the right when -1."""
    du, dv = ub - ua, vb - va
    if du == 0.0:
        return 0, orient * dv
    return (1 if orient * du > 0.0 else -1), dv / du


@njit
def _bound(lo, hi, u, kind, slope, ua, va):
    """The run [lo, hi] of the line at `u` cut by one edge (see `_edge`) through (ua, va)."""
    if kind > 0:
        return max(lo, va + slope * (u - ua)), hi
    if kind < 0:
        return lo, min(hi, va + slope * (u - ua))
    if slope * (u - ua) > 0.0:
        return math.inf, -math.inf
    return lo, hi
