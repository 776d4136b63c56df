"""The moving-obstacle tracker's per-beam and per-track loops, compiled (`perception.tracker`).

`track_scan` folds one scan into a table of tracks; `Tracker` holds the table and sorts each
scan's beams by bearing once per fan of bearings, as every kernel here takes them. A scan is cut
into clusters of neighbouring echoes by Borges and Aldon's adaptive breakpoint (G. A. Borges and
M.-J. Aldon, "Line extraction in 2D range images for mobile robotics", J. Intelligent and
Robotic Systems 40, 2004), and a cluster of round objects side by side is cut where their
outlines meet (`split`); each small cluster's centre comes from Kasa's algebraic circle fit (I.
Kasa, "A circle fitting procedure and its error analysis", IEEE Trans. Instrum. Meas. 25, 1976),
refined toward the geometric fit (N. Chernov, "Circular and Linear Regression", CRC Press 2010),
or, failing that, from its chord; tracks take clusters by the Hungarian method (H. W.
Kuhn, Naval Research Logistics Quarterly 2, 1955) within a Mahalanobis gate; each track is a
constant-velocity Kalman filter with white-noise acceleration (Y. Bar-Shalom, X. R. Li and
T. Kirubarajan, "Estimation with Applications to Tracking and Navigation", Wiley 2001,
section 6.2.2); a track moves when its echoes stand where earlier scans saw free space, or
leave free where it stood (C.-C. Wang, C. Thorpe and S. Thrun, "Online simultaneous
localization and mapping with detection and tracking of moving objects", ICRA 2003).
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit

END_CLEAR = 0
"""A cluster's end is a silhouette: beyond it nothing echoes, or only what lies well behind."""
END_BLOCKED = 1
"""A cluster's end meets a nearer echo, or one about as near: the object may go on unseen there."""
END_EDGE = 2
"""A cluster's end is the edge of the sensor's field of view."""
MOTION_UNKNOWN = -1
"""No earlier scan tells whether a track moved (none, a wrong pose, or what it shows was hidden)."""
MOTION_STATIC = 0
"""A track's echoes stand where an earlier scan's echoes stood: a fixed surface."""
MOTION_MOVED = 1
"""A track's echoes stand where an earlier scan saw free space, or leave free where it stood."""
LOOK_AWAY = 0
"""A track out of the field of view, hidden behind nearer echoes, or too small to look for."""
LOOK_THROUGH = 1
"""The beams toward a track's predicted centre pass beyond it: it is not where predicted."""
LOOK_SOMETHING = 2
"""Something echoes where a track is predicted, though no cluster was given to it."""
TWO_PI = 2.0 * math.pi
ID, RADIUS, FIRST_SEEN, LAST_SEEN, HITS, MISSES, CONFIRMED, MOVING, MOTION, STATIC_SINCE, ECHOES = range(11)
"""The columns of a track table's `info` (rows: tracks): its id; the radius (m) of the disc that
holds what was seen; the times (s) of its first and last measurement; its measurements; the
scans in a row whose beams passed through its predicted disc; whether it is confirmed, and
moving (0 or 1); the last verdict of the free-space test (`MOTION_*`), and since when (s) its
verdicts have been `MOTION_STATIC` (-1: the last was not); the echoes of the last cluster it
took."""
INFO_COLUMNS = 11


@njit
def _echo(r: float) -> bool:
    """Whether a range (m) is an echo: finite and positive (NaN: none)."""
    return math.isfinite(r) and r > 0.0


@njit
def joined(
    range_a: float,
    range_b: float,
    cos_dphi: float,
    spread: float,
    missing: int,
    sigma_m: float,
    min_gap_m: float,
    max_missing: int,
) -> bool:
    """Whether two echoes at `range_a` and `range_b` (m), at bearings dphi apart (`cos_dphi` its
    cosine, `spread` = sin(dphi) / sin(lambda - dphi), inf when dphi >= lambda) with `missing`
    beams without echo between, lie on one object: Borges and Aldon's breakpoint, the gap at most
    max(min_gap, r sin(dphi) / sin(lambda - dphi) + 3 sigma), r the nearer range."""
    if missing > max_missing or spread == math.inf:
        return False
    gap2 = range_a * range_a + range_b * range_b - 2.0 * range_a * range_b * cos_dphi
    limit = max(min_gap_m, min(range_a, range_b) * spread + 3.0 * sigma_m)
    return gap2 <= limit * limit


@njit
def _breaks(
    bearings: np.ndarray,
    ranges: np.ndarray,
    echoes: np.ndarray,
    cyclic: bool,
    lambda_rad: float,
    sigma_m: float,
    min_gap_m: float,
    max_missing: int,
) -> np.ndarray:
    """breaks[j]: whether a cluster starts at echo j (`echoes` the beams with an echo, by
    bearing), apart from echo j - 1 (the last for j = 0 in a scan all round). The sines and
    cosine are computed again only when the angle between the beams changes by over 1e-9 rad."""
    n, m = ranges.shape[0], echoes.shape[0]
    breaks = np.ones(m, dtype=np.bool_)
    last_dphi, cos_dphi, spread = math.nan, 1.0, math.inf
    for j in range(m):
        if j == 0 and not (cyclic and m > 1):
            continue
        i = j - 1 if j > 0 else m - 1
        a, b = echoes[i], echoes[j]
        dphi = bearings[b] - bearings[a] + (TWO_PI if j == 0 else 0.0)
        if not abs(dphi - last_dphi) <= 1e-9:
            last_dphi, cos_dphi = dphi, math.cos(dphi)
            spread = math.sin(dphi) / math.sin(lambda_rad - dphi) if dphi < lambda_rad else math.inf
        missing = b - a - 1 + (n if j == 0 else 0)
        breaks[j] = not joined(
            ranges[a], ranges[b], cos_dphi, spread, missing, sigma_m, min_gap_m, max_missing
        )
    return breaks


@njit
def _end_code(
    ranges: np.ndarray, end: int, other: int, missing: int, max_missing: int, depth_m: float
) -> int:
    """How a cluster's end beam `end` meets the neighbouring echo `other` (-1: the scan's edge)
    across `missing` beams without echo: `END_EDGE`, `END_CLEAR` or `END_BLOCKED`."""
    if missing > max_missing:
        return END_CLEAR
    if other < 0:
        return END_EDGE
    return END_CLEAR if ranges[other] > ranges[end] + depth_m else END_BLOCKED


@njit
def _ends(
    ranges: np.ndarray,
    echoes: np.ndarray,
    start: int,
    bounds: np.ndarray,
    cyclic: bool,
    max_missing: int,
    depth_m: float,
) -> np.ndarray:
    """The `END_*` code (C, 2) of each cluster's first and last echo (`segment`)."""
    n, m = ranges.shape[0], echoes.shape[0]
    clusters = bounds.shape[0] - 1
    ends = np.full((clusters, 2), END_BLOCKED, dtype=np.int64)
    if clusters == 1 and cyclic:
        return ends  # one cluster all round: no end at all
    for c in range(clusters):
        first, last = echoes[(start + bounds[c]) % m], echoes[(start + bounds[c + 1] - 1) % m]
        before, after = echoes[(start + bounds[c] - 1) % m], echoes[(start + bounds[c + 1]) % m]
        if cyclic:
            gap_before, gap_after = (first - before - 1) % n, (after - last - 1) % n
        else:
            if first == echoes[0]:
                before = -1
            if last == echoes[m - 1]:
                after = -1
            gap_before = first - before - 1 if before >= 0 else first
            gap_after = after - last - 1 if after >= 0 else n - 1 - last
        ends[c, 0] = _end_code(ranges, first, before, gap_before, max_missing, depth_m)
        ends[c, 1] = _end_code(ranges, last, after, gap_after, max_missing, depth_m)
    return ends


@njit
def segment(
    bearings: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    lambda_rad: float,
    sigma_m: float,
    min_gap_m: float,
    max_missing: int,
    clear_depth_m: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cut a scan (`bearings` rad, increasing; `ranges` m, NaN, inf or <= 0: no echo; `cyclic`:
    the beams go all round) into clusters of neighbouring echoes that `joined` holds together,
    lambda `lambda_rad`.

    Returns `order` (M,), the beams with an echo cluster by cluster, each cluster's by bearing (a
    scan all round starts at a break, so no cluster straddles its seam); `bounds` (C + 1,),
    cluster c being order[bounds[c]:bounds[c + 1]]; `labels` (N,), each beam's cluster or -1;
    and `ends` (C, 2), how each cluster's first and last echo meet the next echo beyond
    (`END_*`; clear when that lies more than `clear_depth_m` m farther).
    """
    n = ranges.shape[0]
    echoes = np.empty(n, dtype=np.int64)
    m = 0
    for k in range(n):
        if _echo(ranges[k]):
            echoes[m] = k
            m += 1
    echoes = echoes[:m]
    breaks = _breaks(bearings, ranges, echoes, cyclic, lambda_rad, sigma_m, min_gap_m, max_missing)
    start = 0
    while start < m and not breaks[start]:
        start += 1
    start = start % max(m, 1)
    order = np.empty(m, dtype=np.int64)
    bounds = np.zeros(m + 1, dtype=np.int64)
    labels = np.full(n, -1, dtype=np.int64)
    clusters = 0
    for i in range(m):
        j = (start + i) % m
        if i == 0 or breaks[j]:
            bounds[clusters] = i
            clusters += 1
        order[i] = echoes[j]
        labels[order[i]] = clusters - 1
    bounds[clusters] = m
    bounds = bounds[: clusters + 1]
    return order, bounds, labels, _ends(ranges, echoes, start, bounds, cyclic, max_missing, clear_depth_m)


@njit
def _larger_than(points: np.ndarray, lo: int, hi: int, size_m: float) -> bool:
    """Whether the cluster points[lo:hi] is larger than `size_m` (m): a point farther than that
    from either end (stops at the first)."""
    limit = size_m * size_m
    for k in range(lo, hi):
        for end in (lo, hi - 1):
            dx, dy = points[k, 0] - points[end, 0], points[k, 1] - points[end, 1]
            if dx * dx + dy * dy > limit:
                return True
    return False


@njit
def kasa_fit(points: np.ndarray, lo: int, hi: int) -> tuple[float, float, float, float]:
    """Kasa's algebraic circle fit to points[lo:hi] (m), in coordinates centred on their mean:
    centre x, y, radius and the RMS distance of the points from the circle (m); NaN when the
    points are collinear."""
    n = hi - lo
    mx, my = 0.0, 0.0
    for k in range(lo, hi):
        mx += points[k, 0]
        my += points[k, 1]
    mx, my = mx / n, my / n
    suu = suv = svv = suuu = svvv = suvv = svuu = 0.0
    for k in range(lo, hi):
        u, v = points[k, 0] - mx, points[k, 1] - my
        suu += u * u
        suv += u * v
        svv += v * v
        suuu += u * u * u
        svvv += v * v * v
        suvv += u * v * v
        svuu += v * u * u
    det = suu * svv - suv * suv
    if not det > 1e-12 * (suu + svv) ** 2:
        return math.nan, math.nan, math.nan, math.nan
    bu, bv = 0.5 * (suuu + suvv), 0.5 * (svvv + svuu)
    uc, vc = (svv * bu - suv * bv) / det, (suu * bv - suv * bu) / det
    radius = math.sqrt(uc * uc + vc * vc + (suu + svv) / n)
    square = 0.0
    for k in range(lo, hi):
        du, dv = points[k, 0] - mx - uc, points[k, 1] - my - vc
        residual = math.sqrt(du * du + dv * dv) - radius
        square += residual * residual
    return mx + uc, my + vc, radius, math.sqrt(square / n)


@njit
def refine(
    points: np.ndarray, lo: int, hi: int, fit: tuple[float, float, float, float], iterations: int
) -> tuple[float, float, float, float]:
    """A circle fit (centre x, y, radius, RMS; m) to points[lo:hi] (m) refined by `iterations`
    Gauss-Newton steps on the points' distances from it, toward the geometric fit: centre x, y,
    radius and the RMS distance of the points from the circle (m)."""
    cx, cy, radius, _ = fit
    for _ in range(iterations):
        if not math.isfinite(radius):
            return fit
        # J^T J (symmetric, a b c / b d e / c e f) and J^T r for the unknowns (cx, cy, radius)
        a = b = c = d = e = f = ga = gb = gc = 0.0
        for k in range(lo, hi):
            dx, dy = points[k, 0] - cx, points[k, 1] - cy
            dist = math.sqrt(dx * dx + dy * dy)
            if dist == 0.0:
                continue
            ux, uy, residual = -dx / dist, -dy / dist, dist - radius
            a, b, c = a + ux * ux, b + ux * uy, c - ux
            d, e, f = d + uy * uy, e - uy, f + 1.0
            ga, gb, gc = ga + ux * residual, gb + uy * residual, gc - residual
        det = a * (d * f - e * e) - b * (b * f - c * e) + c * (b * e - c * d)
        if not abs(det) > 1e-12:
            break
        # the step solves (J^T J) step = -J^T r, by Cramer's rule
        sa = -(ga * (d * f - e * e) - b * (gb * f - e * gc) + c * (gb * e - d * gc)) / det
        sb = -(a * (gb * f - e * gc) - ga * (b * f - c * e) + c * (b * gc - gb * c)) / det
        sc = -(a * (d * gc - gb * e) - b * (b * gc - gb * c) + ga * (b * e - c * d)) / det
        cx, cy, radius = cx + sa, cy + sb, radius + sc
    square = 0.0
    for k in range(lo, hi):
        dx, dy = points[k, 0] - cx, points[k, 1] - cy
        residual = math.sqrt(dx * dx + dy * dy) - radius
        square += residual * residual
    return cx, cy, radius, math.sqrt(square / (hi - lo))


@njit
def circle_fit(points: np.ndarray, lo: int, hi: int, iterations: int) -> tuple[float, float, float, float]:
    """The geometric circle fit to points[lo:hi] (m): `kasa_fit`'s circle refined by `iterations`
    Gauss-Newton steps (`refine`; Kasa's algebraic fit draws the circle of a short noisy arc too
    small, its centre toward the points: N. Chernov, "Circular and Linear Regression", CRC Press
    2010, ch. 5); centre x, y, radius and the RMS distance of the points from the circle (m);
    NaN when the points are collinear."""
    return refine(points, lo, hi, kasa_fit(points, lo, hi), iterations)


@njit
def fit_sigma(rms: float, n: int, arc: float) -> float:
    """The 1-sigma (m) of the centre of a circle fitted to `n` echoes over an `arc` (rad) with
    `rms` (m) about it: sqrt(45 / n) sigma / (arc / 2)^2, sigma the echoes' noise (their RMS
    over sqrt((n - 3) / n), for the 3 fitted values), the 1-sigma of the radius of a parabola
    fitted to n echoes evenly spread over a short arc (more than the centre's over a long one)."""
    noise = rms * math.sqrt(n / max(n - 3, 1))
    return math.sqrt(45.0 / n) * noise / max(0.5 * arc, 1e-9) ** 2


@njit
def _fit_sane(
    points: np.ndarray, lo: int, hi: int, fit: tuple, x: float, y: float, settings: np.ndarray
) -> bool:
    """Whether a circle fit (centre, radius, RMS; m) to points[lo:hi] is believable (`settings`:
    `cluster_features`'): a radius in [min radius, half the max object size], an RMS at most the
    max RMS, an arc of at least the min arc (rad) from the first point to the last about its
    centre, a centre known to the max 1-sigma (`fit_sigma`: a short arc of noisy echoes places
    it poorly), and its centre farther from the sensor at (x, y) than the points' mean (the
    points are the near side of a convex outline)."""
    cx, cy, radius, rms = fit
    if not (settings[4] <= radius <= 0.5 * settings[1] and rms <= settings[3]):
        return False
    arc = _arc(points, lo, hi, cx, cy)
    if not (arc >= settings[5] and fit_sigma(rms, hi - lo, arc) <= settings[11]):
        return False
    mx = my = 0.0
    for k in range(lo, hi):
        mx, my = mx + points[k, 0] / (hi - lo), my + points[k, 1] / (hi - lo)
    return math.hypot(cx - x, cy - y) > math.hypot(mx - x, my - y)


@njit
def _arc(points: np.ndarray, lo: int, hi: int, cx: float, cy: float) -> float:
    """The angle (rad) between the first and last of points[lo:hi] seen from (cx, cy)."""
    ax, ay = points[lo, 0] - cx, points[lo, 1] - cy
    bx, by = points[hi - 1, 0] - cx, points[hi - 1, 1] - cy
    return abs(math.atan2(ax * by - ay * bx, ax * bx + ay * by))


@njit
def _chord_centre(points: np.ndarray, lo: int, hi: int, x: float, y: float) -> tuple[float, float, float]:
    """The chord's midpoint of points[lo:hi] pushed away from the sensor at (x, y) by half the
    chord: the centre (m) of a disc whose near side the chord spans; and the chord (m)."""
    mx, my = 0.5 * (points[lo, 0] + points[hi - 1, 0]), 0.5 * (points[lo, 1] + points[hi - 1, 1])
    chord = math.hypot(points[hi - 1, 0] - points[lo, 0], points[hi - 1, 1] - points[lo, 1])
    away = math.hypot(mx - x, my - y)
    if away == 0.0:
        return mx, my, chord
    return mx + 0.5 * chord * (mx - x) / away, my + 0.5 * chord * (my - y) / away, chord


@njit
def world_points(
    order: np.ndarray,
    cos_b: np.ndarray,
    sin_b: np.ndarray,
    ranges: np.ndarray,
    x: float,
    y: float,
    yaw: float,
) -> np.ndarray:
    """The echoes of the beams `order` (M,) as world points (M, 2; m) from the sensor at (x, y)
    (m) heading `yaw` (rad), the beams' bearings given by their cosines `cos_b` and sines `sin_b`."""
    points = np.empty((order.shape[0], 2))
    cos_yaw, sin_yaw = math.cos(yaw), math.sin(yaw)
    for i in range(order.shape[0]):
        k = order[i]
        points[i, 0] = x + ranges[k] * (cos_yaw * cos_b[k] - sin_yaw * sin_b[k])
        points[i, 1] = y + ranges[k] * (sin_yaw * cos_b[k] + cos_yaw * sin_b[k])
    return points


FIT_NONE = -1
"""No circle fit was tried on a cluster (too few echoes, or too large)."""
FIT_FAILED = 0
"""A cluster's circle fit is not sane (`_fit_sane`)."""
FIT_SANE = 1
"""A cluster's circle fit is sane."""


@njit
def _sane_fit(
    points: np.ndarray, lo: int, hi: int, x: float, y: float, settings: np.ndarray
) -> tuple[int, tuple[float, float, float, float]]:
    """Kasa's circle fit to points[lo:hi] (m, `kasa_fit`) seen from the sensor at (x, y) (m), and
    whether it is sane (`FIT_*`, `_fit_sane`; `settings` as `cluster_features`', the radius at
    most half the max object size): `FIT_NONE` with fewer than `fit_points` echoes. The
    geometric fit (`refine`) has at most Kasa's RMS: the cheaper fit judges."""
    if hi - lo < settings[2]:
        return FIT_NONE, (math.nan, math.nan, math.nan, math.nan)
    fit = kasa_fit(points, lo, hi)
    sane = _fit_sane(points, lo, hi, fit, x, y, settings)
    return FIT_SANE if sane else FIT_FAILED, fit


@njit(inline="always")
def concavity(points: np.ndarray, lo: int, hi: int, j: int, w: int, x: float, y: float) -> float:
    """How far (m) the echo points[j] lies behind its neighbours in points[lo:hi] as seen from
    the sensor at (x, y) (m): its distance beyond the line through the echoes `w` before and
    after it (fewer at the ends), negative in front of it. A round object's echoes are convex
    toward the sensor, a straight wall's flat; where the outlines of two round objects meet,
    the outline turns away from the sensor."""
    a, b = max(lo, j - w), min(hi - 1, j + w)
    ex, ey = points[b, 0] - points[a, 0], points[b, 1] - points[a, 1]
    side = ex * (points[j, 1] - points[a, 1]) - ey * (points[j, 0] - points[a, 0])
    sensor = ex * (y - points[a, 1]) - ey * (x - points[a, 0])
    behind = -side if sensor > 0.0 else side
    return behind / math.sqrt(ex * ex + ey * ey) if behind > 0.0 else behind


@njit
def _cuts(
    points: np.ndarray,
    lo: int,
    hi: int,
    distances: np.ndarray,
    x: float,
    y: float,
    beams_per_m: float,
    settings: np.ndarray,
    cuts: np.ndarray,
    spans: np.ndarray,
) -> int:
    """The echoes after which to cut points[lo:hi] (`split`; `distances`, m, theirs from the
    sensor at (x, y)), into `cuts`; how many. Each run of echoes more than `depth_m` deep
    (`concavity`, over the echoes that span `reach_m` at their range, `beams_per_m` / range, at
    least 2, each way) gives its deepest, while `min_points` remain on either side of every cut.
    A bend spans its reach each way, so the echoes are looked at half a reach apart first, and
    one by one only about those more than half as deep (`spans`: scratch, (M, 2))."""
    least, depth_m = int(settings[0]), settings[8]
    first, last = lo + least - 1, hi - least  # the echoes a cut may follow
    hot = 0  # spans[:hot]: the stretches to look at one by one, in order, apart
    j = first
    while j < last:
        w = max(2, int(beams_per_m / distances[j]))
        step = w // 2
        if concavity(points, lo, hi, j, w, x, y) > 0.5 * depth_m:
            a, b = max(first, j - step), min(last, j + step + 1)
            if hot > 0 and a <= spans[hot - 1, 1]:
                spans[hot - 1, 1] = b
            else:
                spans[hot, 0], spans[hot, 1] = a, b
                hot += 1
        j += step
    count = 0
    for k in range(hot):
        best, deepest = -1, -math.inf
        for j in range(spans[k, 0], spans[k, 1] + 1):
            deep = -math.inf
            if j < spans[k, 1]:
                w = max(2, int(beams_per_m / distances[j]))
                deep = concavity(points, lo, hi, j, w, x, y)
            if deep > depth_m:
                if deep > deepest:
                    best, deepest = j, deep
                continue
            previous = cuts[count - 1] if count > 0 else lo - 1
            if best >= 0 and best - previous >= least:
                cuts[count] = best
                count += 1
            best, deepest = -1, -math.inf
    return count


@njit
def split(
    points: np.ndarray,
    distances: np.ndarray,
    bounds: np.ndarray,
    ends: np.ndarray,
    x: float,
    y: float,
    step_rad: float,
    settings: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cut the clusters of points (m, world; `distances` m from the sensor at (x, y)) that cannot
    be one round object (too large, or a circle fit that fails: `_sane_fit`) where their outline
    turns away from the sensor by more than `depth_m` (`concavity` over `reach_m` each way,
    beams `step_rad` apart; `_cuts`), so that round objects side by side, or a round object
    against a wall, give a cluster each. A cut is kept only when a part beside it is a round
    object (a sane circle fit of a radius at least `min_round_m`, at most the max object size):
    the other parts stay together, and a wall with bends stays whole. A cut end meets the other
    part: `END_BLOCKED`. `settings`: `cluster_features`'.

    Returns the new bounds (C' + 1,) and ends (C', 2), and each new cluster's circle fit
    (C', 4) and its `FIT_*` (C',) when one was made (`FIT_NONE` when not yet)."""
    least, max_size, fit_points, min_round = int(settings[0]), settings[1], settings[2], settings[10]
    beams_per_m = settings[7] / step_rad
    count = bounds.shape[0] - 1
    room = count + points.shape[0] // max(least, 1) + 1  # each cut leaves `least` echoes before it
    new_bounds = np.empty(room, dtype=np.int64)
    new_ends = np.empty((room, 2), dtype=np.int64)
    fits = np.full((room, 4), np.nan)
    states = np.full(room, FIT_NONE, dtype=np.int64)
    cuts = np.empty(room, dtype=np.int64)
    spans = np.empty((points.shape[0] + 1, 2), dtype=np.int64)
    part_fits = np.empty((room, 4))
    part_states = np.empty(room, dtype=np.int64)
    total = 0
    for c in range(count):
        lo, hi = bounds[c], bounds[c + 1]
        state, fit = FIT_NONE, (math.nan, math.nan, math.nan, math.nan)
        large = _larger_than(points, lo, hi, max_size)
        if hi - lo >= least and not large:
            state, fit = _sane_fit(points, lo, hi, x, y, settings)
        made = 0
        if hi - lo >= 2 * least and (large or state == FIT_FAILED):
            made = _cuts(points, lo, hi, distances, x, y, beams_per_m, settings, cuts, spans)
        for i in range(made + 1 if made > 0 else 0):  # the parts between the cuts
            a = lo if i == 0 else cuts[i - 1] + 1
            b = hi if i == made else cuts[i] + 1
            part_states[i] = FIT_NONE
            if b - a >= fit_points and not _larger_than(points, a, b, max_size):
                part_states[i], part_fit = _sane_fit(points, a, b, x, y, settings)
                part_fits[i, 0], part_fits[i, 1], part_fits[i, 2], part_fits[i, 3] = part_fit
                if part_fit[2] < min_round:
                    part_states[i] = FIT_FAILED
        start, first = lo, 0  # the new cluster that starts at echo `start`, part `first`
        new_ends[total, 0] = ends[c, 0]
        for i in range(made + 1):
            last = i == made
            if not last and part_states[i] != FIT_SANE and part_states[i + 1] != FIT_SANE:
                continue  # no cut between parts i and i + 1
            new_bounds[total] = start
            new_ends[total, 1] = ends[c, 1] if last else END_BLOCKED
            if first == 0 and last:  # the cluster as it came
                states[total] = state
                fits[total, 0], fits[total, 1], fits[total, 2], fits[total, 3] = fit
            elif first == i:  # one part
                states[total] = part_states[i]
                fits[total] = part_fits[i]
            total += 1
            if not last:
                start, first = cuts[i] + 1, i + 1
                new_ends[total, 0] = END_BLOCKED
    new_bounds[total] = bounds[count]
    return new_bounds[: total + 1], new_ends[:total], fits[:total], states[:total]


@njit
def cluster_features(
    points: np.ndarray,
    bounds: np.ndarray,
    ends: np.ndarray,
    fits: np.ndarray,
    states: np.ndarray,
    x: float,
    y: float,
    settings: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each cluster points[bounds[c]:bounds[c + 1]] (m, world; `split`'s, with its circle fits
    and their `FIT_*` where made) measured from the sensor at (x, y) (m).

    `settings`: min points, max object size (m), min points for a circle fit, the fit's max RMS
    (m), its min radius (m) and arc (rad), the floor of a centre's 1-sigma (m), `split`'s
    reach_m, depth_m, the fit's iterations (`refine`), `split`'s min_round_m, and the fit's
    max 1-sigma (m, `_fit_sane`). Returns per cluster whether it is at most the max
    object size (its largest distance of a point from either end) and has points enough to
    track (C,), whether its centre came from a sane circle fit (C,; `_sane_fit`), and, for
    those to track, the centre (C, 2; m, world), the radius of the disc about it that holds the
    points (C,; m), and the centre's 1-sigma along and across the line of sight (C, 2; m), each
    at least the floor: of a fit (refined by `refine` when its RMS is over a tenth of the floor),
    `fit_sigma` both ways; of a chord, a quarter of it along the line of sight (the depth rests
    on the guess of the radius) and an eighth across, and when an end is not a silhouette, a
    quarter of what a hidden part may add to the chord, both ways.
    """
    min_points, max_size, floor, iterations = settings[0], settings[1], settings[6], int(settings[9])
    count = bounds.shape[0] - 1
    usable = np.zeros(count, dtype=np.bool_)
    fitted = np.zeros(count, dtype=np.bool_)
    centres = np.full((count, 2), np.nan)
    radii = np.full(count, np.nan)
    sigmas = np.full((count, 2), np.nan)
    for c in range(count):
        lo, hi = bounds[c], bounds[c + 1]
        if hi - lo < min_points or _larger_than(points, lo, hi, max_size):
            continue
        usable[c] = True
        state, fit = states[c], (fits[c, 0], fits[c, 1], fits[c, 2], fits[c, 3])
        if state == FIT_NONE:
            state, fit = _sane_fit(points, lo, hi, x, y, settings)
        cx, cy, chord = _chord_centre(points, lo, hi, x, y)
        if state == FIT_SANE:
            fitted[c] = True
            if fit[3] > 0.1 * floor:  # Kasa's bias grows with the noise squared: nil below that
                refined = refine(points, lo, hi, fit, iterations)
                if _fit_sane(points, lo, hi, refined, x, y, settings):
                    fit = refined
            cx, cy = fit[0], fit[1]
            arc = _arc(points, lo, hi, cx, cy)
            sigmas[c, :] = max(floor, fit_sigma(fit[3], hi - lo, arc))
        else:
            hidden = 0.25 * (max_size - chord) if ends[c, 0] != END_CLEAR or ends[c, 1] != END_CLEAR else 0.0
            sigmas[c, 0] = max(floor, 0.25 * chord, hidden)
            sigmas[c, 1] = max(floor, 0.125 * chord, hidden)
        centres[c, 0], centres[c, 1] = cx, cy
        hold2 = 0.0
        for k in range(lo, hi):
            hold2 = max(hold2, (points[k, 0] - cx) ** 2 + (points[k, 1] - cy) ** 2)
        radii[c] = math.sqrt(hold2)
    return usable, fitted, centres, radii, sigmas


@njit
def predict(state: np.ndarray, cov: np.ndarray, count: int, dt: float, accel_psd: float) -> None:
    """Move the first `count` tracks' states (x, y, vx, vy; m, m/s) and covariances `dt` s ahead,
    constant velocity with white-noise acceleration of spectral density `accel_psd` (m^2/s^3):
    Q = q [dt^3/3, dt^2/2; dt^2/2, dt] per axis (Bar-Shalom et al. 2001, eq. 6.2.2-12)."""
    q11, q12, q22 = accel_psd * dt**3 / 3.0, accel_psd * dt**2 / 2.0, accel_psd * dt
    for t in range(count):
        state[t, 0] += dt * state[t, 2]
        state[t, 1] += dt * state[t, 3]
        p = cov[t]
        for i in range(4):  # P F^T: columns 0 and 1 take dt times columns 2 and 3
            p[i, 0] += dt * p[i, 2]
            p[i, 1] += dt * p[i, 3]
        for j in range(4):  # F (P F^T): rows 0 and 1 take dt times rows 2 and 3
            p[0, j] += dt * p[2, j]
            p[1, j] += dt * p[3, j]
        for axis in range(2):
            p[axis, axis] += q11
            p[axis, axis + 2] += q12
            p[axis + 2, axis] += q12
            p[axis + 2, axis + 2] += q22


@njit(inline="always")
def _innovation_cov(
    cov: np.ndarray, sigma_r: float, sigma_t: float, ux: float, uy: float
) -> tuple[float, float, float]:
    """S = H P H^T + R (2 x 2, m^2) as (s_xx, s_xy, s_yy): R has 1-sigma `sigma_r` along the
    unit line of sight (ux, uy) and `sigma_t` across it."""
    rr, tt = sigma_r * sigma_r, sigma_t * sigma_t
    return (
        cov[0, 0] + rr * ux * ux + tt * uy * uy,
        cov[0, 1] + (rr - tt) * ux * uy,
        cov[1, 1] + rr * uy * uy + tt * ux * ux,
    )


@njit(inline="always")
def _unit_from(x: float, y: float, tx: float, ty: float) -> tuple[float, float]:
    """The unit vector from (x, y) toward (tx, ty); (1, 0) when they coincide."""
    d = math.sqrt((tx - x) ** 2 + (ty - y) ** 2)
    return ((tx - x) / d, (ty - y) / d) if d > 0.0 else (1.0, 0.0)


@njit
def gate_costs(
    state: np.ndarray,
    cov: np.ndarray,
    count: int,
    candidates: np.ndarray,
    centres: np.ndarray,
    sigmas: np.ndarray,
    pose: np.ndarray,
    gate_chi2: float,
    max_gate_m: float,
) -> np.ndarray:
    """The squared Mahalanobis distance (count, K) of the innovation between each of the first
    `count` tracks' predicted centre and each `candidates` cluster's centre (m; its noise about
    the line of sight from `pose`), inf beyond the gate: above `gate_chi2`, or farther than
    `max_gate_m` m. Pairs farther than the gate could hold even along the covariance's largest
    axis (its trace bounds it) are not computed."""
    costs = np.full((count, candidates.shape[0]), np.inf)
    for t in range(count):
        trace = cov[t, 0, 0] + cov[t, 1, 1]
        for j in range(candidates.shape[0]):
            c = candidates[j]
            dx, dy = centres[c, 0] - state[t, 0], centres[c, 1] - state[t, 1]
            d2 = dx * dx + dy * dy
            widest = trace + max(sigmas[c, 0], sigmas[c, 1]) ** 2
            if d2 > max_gate_m * max_gate_m or d2 > gate_chi2 * widest:
                continue
            ux, uy = _unit_from(pose[0], pose[1], centres[c, 0], centres[c, 1])
            sxx, sxy, syy = _innovation_cov(cov[t], sigmas[c, 0], sigmas[c, 1], ux, uy)
            m2 = (syy * dx * dx - 2.0 * sxy * dx * dy + sxx * dy * dy) / (sxx * syy - sxy * sxy)
            if m2 <= gate_chi2:
                costs[t, j] = m2
    return costs


@njit
def _hungarian(costs: np.ndarray) -> np.ndarray:
    """The column of each row in the assignment of rows to distinct columns of least total cost,
    for no more rows than columns: Kuhn's Hungarian method in its O(n^2 m) form by
    shortest augmenting paths with potentials (H. W. Kuhn, "The Hungarian method for the
    assignment problem", Naval Research Logistics Quarterly 2, 1955; R. Jonker and A. Volgenant,
    Computing 38, 1987). Ties go to the lower column, so the answer is deterministic."""
    n, m = costs.shape
    u, v = np.zeros(n + 1), np.zeros(m + 1)  # potentials of rows and columns
    owner = np.zeros(m + 1, dtype=np.int64)  # owner[j]: the row (1-based) holding column j, 0: none
    way = np.zeros(m + 1, dtype=np.int64)
    for i in range(1, n + 1):
        owner[0], j0 = i, 0
        slack = np.full(m + 1, np.inf)
        used = np.zeros(m + 1, dtype=np.bool_)
        while owner[j0] != 0:
            used[j0] = True
            i0, delta, j1 = owner[j0], np.inf, 0
            for j in range(1, m + 1):
                if not used[j]:
                    reduced = costs[i0 - 1, j - 1] - u[i0] - v[j]
                    if reduced < slack[j]:
                        slack[j], way[j] = reduced, j0
                    if slack[j] < delta:
                        delta, j1 = slack[j], j
            for j in range(m + 1):
                if used[j]:
                    u[owner[j]] += delta
                    v[j] -= delta
                else:
                    slack[j] -= delta
            j0 = j1
        while j0 != 0:  # flip the augmenting path
            j1 = way[j0]
            owner[j0] = owner[j1]
            j0 = j1
    columns = np.empty(n, dtype=np.int64)
    for j in range(1, m + 1):
        if owner[j] > 0:
            columns[owner[j] - 1] = j - 1
    return columns


@njit
def _solve(costs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (rows, columns) of the least-cost assignment (`_hungarian`, either way round)."""
    n, m = costs.shape
    if n <= m:
        return np.arange(n), _hungarian(costs)
    return _hungarian(costs.T.copy()), np.arange(m)


@njit
def _components(gated: np.ndarray) -> np.ndarray:
    """The connected component (labelled by its least member) of each row and then each column
    (n + m,) of the bipartite graph whose edges are the `gated` (n, m) pairs."""
    n, m = gated.shape
    parent = np.arange(n + m)
    for i in range(n):
        for j in range(m):
            if gated[i, j]:
                a, b = i, n + j
                while parent[a] != a:
                    a = parent[a]
                while parent[b] != b:
                    b = parent[b]
                parent[max(a, b)] = min(a, b)
    for k in range(n + m):
        root = k
        while parent[root] != root:
            root = parent[root]
        parent[k] = root
    return parent


@njit
def _members(flags: np.ndarray, lo: int, hi: int, value: float) -> np.ndarray:
    """The indices k - lo of the entries of flags[lo:hi] equal to `value`."""
    out = np.empty(hi - lo, dtype=np.int64)
    count = 0
    for k in range(lo, hi):
        if flags[k] == value:
            out[count] = k - lo
            count += 1
    return out[:count]


@njit
def assign(costs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (rows, columns) of finite cost of the assignment of least total cost that pairs
    as many as it can (`_hungarian`, inf as a cost larger than any sum of finite ones), solved
    per connected component of the finite pairs: a pair alone in its component is taken as it is."""
    n, m = costs.shape
    gated = np.isfinite(costs)
    component = _components(gated)
    big = 1.0  # above any sum of finite costs
    for i in range(n):
        for j in range(m):
            big += costs[i, j] if gated[i, j] else 0.0
    rows = np.empty(min(n, m), dtype=np.int64)
    columns = np.empty(min(n, m), dtype=np.int64)
    pairs = 0
    for root in range(n):
        if component[root] != root:
            continue
        members_r, members_c = _members(component, 0, n, root), _members(component, n, n + m, root)
        block = np.empty((members_r.shape[0], members_c.shape[0]))
        for i in range(members_r.shape[0]):
            for j in range(members_c.shape[0]):
                r, c = members_r[i], members_c[j]
                block[i, j] = costs[r, c] if gated[r, c] else big
        if block.size == 0:
            continue
        block_rows, block_columns = _solve(block)
        for i in range(block_rows.shape[0]):
            r, c = block_rows[i], block_columns[i]
            if block[r, c] < big:
                rows[pairs], columns[pairs] = members_r[r], members_c[c]
                pairs += 1
    return rows[:pairs], columns[:pairs]


@njit
def associate(
    state: np.ndarray,
    cov: np.ndarray,
    count: int,
    usable: np.ndarray,
    centres: np.ndarray,
    sigmas: np.ndarray,
    pose: np.ndarray,
    gate_chi2: float,
    max_gate_m: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (track rows, cluster indices) of the global nearest neighbour: the optimal
    assignment (`assign`) of the first `count` tracks to the `usable` clusters within the gate
    (`gate_costs`)."""
    candidates = _members(usable, 0, usable.shape[0], True)
    rows, columns = assign(
        gate_costs(state, cov, count, candidates, centres, sigmas, pose, gate_chi2, max_gate_m)
    )
    clusters = np.empty(columns.shape[0], dtype=np.int64)
    for i in range(columns.shape[0]):
        clusters[i] = candidates[columns[i]]
    return rows, clusters


@njit(inline="always")
def _search(bearings: np.ndarray, angle: float, right: bool) -> int:
    """The first index of `bearings` (N,; rad, increasing) at least `angle` (rad), or, `right`,
    beyond it (N: none), as `np.searchsorted` finds it (side "left" or "right"), from a guess as
    though they were evenly spread (exact for a laser's fan, a few steps off for others)."""
    n = bearings.shape[0]
    span = bearings[n - 1] - bearings[0]
    k = n if angle > bearings[n - 1] else 0
    if span > 0.0 and bearings[0] < angle <= bearings[n - 1]:
        k = min(n - 1, max(0, int((angle - bearings[0]) / span * (n - 1))))
    if right:
        while k > 0 and bearings[k - 1] > angle:
            k -= 1
        while k < n and bearings[k] <= angle:
            k += 1
    else:
        while k > 0 and bearings[k - 1] >= angle:
            k -= 1
        while k < n and bearings[k] < angle:
            k += 1
    return k


@njit
def _window(bearings: np.ndarray, cyclic: bool, lo: float, hi: float) -> tuple[int, int]:
    """The beams whose bearings (rad, increasing) lie in [lo, hi] (rad, robot frame, taken a
    whole number of turns on so that lo lies within a turn past the first bearing): the first,
    and how many from it (the next after the last being the first in a scan all round); none
    when the window is not wholly within the field of view."""
    n = bearings.shape[0]
    while lo < bearings[0]:
        lo, hi = lo + TWO_PI, hi + TWO_PI
    while lo >= bearings[0] + TWO_PI:
        lo, hi = lo - TWO_PI, hi - TWO_PI
    start = _search(bearings, lo, False)
    if hi <= bearings[n - 1]:
        return start, max(0, _search(bearings, hi, True) - start)
    if not cyclic:
        return start, 0
    return start, min(n, n - start + _search(bearings, hi - TWO_PI, True))  # on past the last


@njit
def _stands(
    x: float,
    y: float,
    pose: np.ndarray,
    bearings: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    margin_m: float,
    tolerance_m: float,
) -> int:
    """Where an echo at (x, y) (m, world) stands in an earlier scan (`ranges`, m, along
    `bearings`, rad, increasing; from `pose`: x, y in m, yaw in rad), by the beams that pass
    within `tolerance_m` of it sideways: 1 (free) when every one passed more than `margin_m`
    beyond it or had no echo, -1 (held) when one ended within `tolerance_m` of it, else 0
    (hidden then, or out of view)."""
    dx, dy = x - pose[0], y - pose[1]
    d = math.sqrt(dx * dx + dy * dy)
    angle, half = math.atan2(dy, dx) - pose[2], tolerance_m / d  # at most tolerance_m sideways
    start, count = _window(bearings, cyclic, angle - half, angle + half)
    beyond = 0
    for i in range(count):
        r = ranges[(start + i) % bearings.shape[0]]
        r = r if _echo(r) else math.inf
        if abs(r - d) <= tolerance_m:
            return -1
        beyond += r > d + margin_m
    return 1 if count > 0 and beyond == count else 0


@njit
def free_and_held(
    points: np.ndarray,
    lo: int,
    hi: int,
    stride: int,
    pose: np.ndarray,
    bearings: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    margin_m: float,
    tolerance_m: float,
) -> tuple[int, int, int]:
    """Of every `stride`-th echo of points[lo:hi] (m, world): how many stand where an earlier
    scan saw free space, how many where it echoed (`_stands`), and how many it looked at."""
    free = held = looked = 0
    for k in range(lo, hi, stride):
        looked += 1
        stands = _stands(points[k, 0], points[k, 1], pose, bearings, ranges, cyclic, margin_m, tolerance_m)
        free += stands == 1
        held += stands == -1
    return free, held, looked


@njit
def _verdict(free: int, held: int, looked: int, fraction: float, min_free: float) -> int:
    """What `looked` echoes tell of their object, `free` of them standing in an earlier scan's
    free space and `held` where it echoed: `MOTION_MOVED` when at least `min_free` and a
    `fraction` are free (a fixed surface cannot stand where a beam passed); `MOTION_STATIC` when
    fewer than `min_free` are free and at least half are held (a moving object overlaps where it
    stood, so being held is the weaker evidence); else `MOTION_UNKNOWN`."""
    if free >= max(min_free, fraction * looked):
        return MOTION_MOVED
    if free < min_free and 2 * held >= looked:
        return MOTION_STATIC
    return MOTION_UNKNOWN


@njit
def structure(
    points: np.ndarray, bounds: np.ndarray, usable: np.ndarray, min_points: int, most: int
) -> np.ndarray:
    """At most `most` echoes (K, 2; m, world), evenly spread, of the scan's fixed structure: the
    clusters of `min_points` echoes or more too large to track (not `usable`)."""
    total = 0
    for c in range(usable.shape[0]):
        if not usable[c] and bounds[c + 1] - bounds[c] >= min_points:
            total += bounds[c + 1] - bounds[c]
    stride = max(1, math.ceil(total / max(most, 1)))
    out = np.empty((math.ceil(total / stride), 2))
    seen = kept = 0
    for c in range(usable.shape[0]):
        if usable[c] or bounds[c + 1] - bounds[c] < min_points:
            continue
        for k in range(bounds[c], bounds[c + 1]):
            if seen % stride == 0:
                out[kept, 0], out[kept, 1] = points[k, 0], points[k, 1]
                kept += 1
            seen += 1
    return out


@njit
def structure_stays(
    now: np.ndarray,
    then: np.ndarray,
    pose: np.ndarray,
    ranges: np.ndarray,
    reference: tuple[np.ndarray, np.ndarray],
    bearings: np.ndarray,
    cyclic: bool,
    settings: np.ndarray,
) -> bool:
    """Whether the fixed structure stands where it stood: at most `pose_share` of the echoes of
    its sample `now` (m, world) in the free space of the earlier scan (`reference`: its pose and
    ranges by bearing) and of its sample `then` in the free space of this one (`ranges` from
    `pose`), by `_stands`. When more are, the pose of one of the scans is off (odometry that
    drifts, wheels that slip) and every object would seem to move: the free space of the one
    scan holds the other's surfaces shifted, whichever way. `settings`: margin_m, tolerance_m,
    and, at 6, pose_share."""
    margin_m, tolerance_m, pose_share = settings[0], settings[1], settings[6]
    free = held = 0
    for k in range(now.shape[0] + then.shape[0]):
        if k < now.shape[0]:
            stands = _stands(
                now[k, 0], now[k, 1], reference[0], bearings, reference[1], cyclic, margin_m, tolerance_m
            )
        else:
            x, y = then[k - now.shape[0], 0], then[k - now.shape[0], 1]
            stands = _stands(x, y, pose, bearings, ranges, cyclic, margin_m, tolerance_m)
        free += stands == 1
        held += stands == -1
    return free <= pose_share * (free + held)


@njit
def judge(
    points: np.ndarray,
    bounds: np.ndarray,
    wanted: np.ndarray,
    pose: np.ndarray,
    bearings: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    settings: np.ndarray,
) -> np.ndarray:
    """Each `wanted` cluster's verdict (C,; `_verdict`, the others unknown) against an earlier
    scan (`ranges`, m, along `bearings`; from `pose`), from at most `max_points` of its echoes
    evenly spread (`free_and_held`). `settings`: margin_m, tolerance_m, fraction, min_free,
    max_points."""
    margin_m, tolerance_m, fraction, min_free, max_points = settings[:5]
    verdicts = np.full(wanted.shape[0], MOTION_UNKNOWN, dtype=np.int64)
    for c in range(wanted.shape[0]):
        if not wanted[c]:
            continue
        lo, hi = bounds[c], bounds[c + 1]
        stride = max(1, math.ceil((hi - lo) / max_points))
        free, held, looked = free_and_held(
            points, lo, hi, stride, pose, bearings, ranges, cyclic, margin_m, tolerance_m
        )
        verdicts[c] = _verdict(free, held, looked, fraction, min_free)
    return verdicts


@njit
def scan_clusters(
    bearings: np.ndarray,
    cos_b: np.ndarray,
    sin_b: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    pose: np.ndarray,
    segmentation: np.ndarray,
    features: np.ndarray,
) -> tuple:
    """A scan (by bearing: `bearings`, rad, their cosines and sines; `ranges`, m) taken at `pose`
    (x, y in m, yaw in rad): `segment`'s bounds, labels and ends (`segmentation`: lambda
    (rad), sigma_m, min_gap_m, max_missing, clear_depth_m), cut apart where round objects meet
    (`split`: its bounds, ends and labels then), the points (`world_points`), and
    `cluster_features`' usable, fitted, centres, radii and sigmas (`features`); the points are
    the echoes cluster by cluster, as `segment` orders them."""
    lambda_rad, sigma_m, min_gap_m, max_missing, clear_depth_m = segmentation
    order, bounds, labels, ends = segment(
        bearings, ranges, cyclic, lambda_rad, sigma_m, min_gap_m, int(max_missing), clear_depth_m
    )
    x, y = pose[0], pose[1]
    points = world_points(order, cos_b, sin_b, ranges, x, y, pose[2])
    distances = np.empty(order.shape[0])
    for i in range(order.shape[0]):
        distances[i] = ranges[order[i]]
    n = bearings.shape[0]
    step = (bearings[n - 1] - bearings[0]) / (n - 1) if n > 1 else TWO_PI
    cut, ends, fits, states = split(points, distances, bounds, ends, x, y, step, features)
    if cut.shape[0] != bounds.shape[0]:
        bounds = cut
        for c in range(bounds.shape[0] - 1):
            for i in range(bounds[c], bounds[c + 1]):
                labels[order[i]] = c
    usable, fitted, centres, radii, sigmas = cluster_features(
        points, bounds, ends, fits, states, x, y, features
    )
    return bounds, labels, ends, points, usable, fitted, centres, radii, sigmas


@njit(inline="always")
def _whole(ends: np.ndarray, fitted: np.ndarray, c: int) -> bool:
    """Whether cluster c shows enough of its object to place it: silhouettes at both ends, or an
    arc whose circle fit is sane (a part that meets a nearer echo, another object's outline or
    the edge of the view places its centre only when the arc that shows fits a circle)."""
    return fitted[c] or (ends[c, 0] == END_CLEAR and ends[c, 1] == END_CLEAR)


@njit
def _kalman_update(
    x: np.ndarray, p: np.ndarray, zx: float, zy: float, sigma_r: float, sigma_t: float, ux: float, uy: float
) -> None:
    """Update the state `x` (4,) and covariance `p` (4, 4) with the centre (zx, zy) (m) measured
    with 1-sigma `sigma_r` along the unit line of sight (ux, uy) and `sigma_t` across it: x
    gains K (z - H x), p becomes (I - K H) P, symmetrised (K = P H^T S^-1, H picking x and y)."""
    sxx, sxy, syy = _innovation_cov(p, sigma_r, sigma_t, ux, uy)
    det = sxx * syy - sxy * sxy
    ixx, ixy, iyy = syy / det, -sxy / det, sxx / det
    dx, dy = zx - x[0], zy - x[1]
    gain = np.empty((4, 2))
    for j in range(4):
        gain[j, 0] = p[j, 0] * ixx + p[j, 1] * ixy
        gain[j, 1] = p[j, 0] * ixy + p[j, 1] * iyy
        x[j] += gain[j, 0] * dx + gain[j, 1] * dy
    top = p[:2].copy()
    for a in range(4):
        for b in range(4):
            p[a, b] -= gain[a, 0] * top[0, b] + gain[a, 1] * top[1, b]
    for a in range(4):
        for b in range(a + 1, 4):
            p[a, b] = p[b, a] = 0.5 * (p[a, b] + p[b, a])


@njit(inline="always")
def _largest_sd(cov: np.ndarray, first: int) -> float:
    """The square root of the larger eigenvalue of cov[first:first + 2, first:first + 2]."""
    a, b, d = cov[first, first], cov[first, first + 1], cov[first + 1, first + 1]
    return math.sqrt(max(0.5 * (a + d) + math.sqrt(0.25 * (a - d) ** 2 + b * b), 0.0))


@njit
def _classify(state: np.ndarray, cov: np.ndarray, info: np.ndarray, count: int, settings: np.ndarray) -> None:
    """Set MOVING for the first `count` tracks. A track starts moving when measured `min_hits`
    times, seen for `min_age_s`, its motion `MOTION_MOVED`, and its speed above `floor_mps` and
    `sigmas` times its velocity's 1-sigma, `young_sigmas` times while it is not confirmed (a
    young track whose motion is plain and fast need not wait for `confirm_hits`: it is confirmed
    then); it stops when its motion turns `MOTION_STATIC` or its speed falls to `hold_mps`.
    `settings`: floor_mps, sigmas, min_age_s, hold_mps, min_hits, young_sigmas."""
    floor_mps, sigmas, min_age_s, hold_mps, min_hits, young_sigmas = settings
    for t in range(count):
        speed = math.hypot(state[t, 2], state[t, 3])
        if info[t, MOVING]:
            moving = info[t, MOTION] != MOTION_STATIC and speed > hold_mps
        else:
            young = info[t, CONFIRMED] == 0.0
            moving = (
                info[t, HITS] >= min_hits
                and info[t, MOTION] == MOTION_MOVED
                and info[t, LAST_SEEN] - info[t, FIRST_SEEN] >= min_age_s - 1e-9
                and speed > floor_mps
                and speed > (young_sigmas if young else sigmas) * _largest_sd(cov[t], 2)
            )
        info[t, MOVING] = 1.0 if moving else 0.0
        info[t, CONFIRMED] = 1.0 if moving else info[t, CONFIRMED]


@njit
def left_free(
    x: float,
    y: float,
    radius: float,
    fan: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool],
    reference: tuple[np.ndarray, np.ndarray],
    pose: np.ndarray,
    ranges: np.ndarray,
    settings: np.ndarray,
) -> tuple[int, int]:
    """How many of an earlier scan's echoes within `radius` (m, plus `tolerance_m`) of (x, y) (m,
    where a track stood then) now stand in free space (`_stands` against the scan `ranges` from
    `pose`), and how many it looked at (at most `max_points`, evenly spread): an object that
    moved away leaves the place it stood free, which the echoes of now cannot show when it
    recedes along the beams. `fan`: the bearings (rad, increasing), cosines, sines, order and
    whether all round; `reference`: the earlier scan's pose and ranges (m, by bearing).
    `settings`: margin_m, tolerance_m, fraction, min_free, max_points."""
    bearings, cos_b, sin_b, _, cyclic = fan
    ref_pose, ref_ranges = reference
    margin_m, tolerance_m, max_points = settings[0], settings[1], settings[4]
    dx, dy = x - ref_pose[0], y - ref_pose[1]
    d, reach = math.sqrt(dx * dx + dy * dy), radius + tolerance_m
    if ref_ranges.shape[0] == 0 or d <= reach:
        return 0, 0
    angle, half = math.atan2(dy, dx) - ref_pose[2], math.asin(reach / d)
    start, count = _window(bearings, cyclic, angle - half, angle + half)
    cos_yaw, sin_yaw = math.cos(ref_pose[2]), math.sin(ref_pose[2])
    free = looked = 0
    for i in range(0, count, max(1, math.ceil(count / max_points))):
        k = (start + i) % bearings.shape[0]
        r = ref_ranges[k]
        px = ref_pose[0] + r * (cos_yaw * cos_b[k] - sin_yaw * sin_b[k])
        py = ref_pose[1] + r * (sin_yaw * cos_b[k] + cos_yaw * sin_b[k])
        if _echo(r) and (px - x) ** 2 + (py - y) ** 2 <= reach * reach:
            looked += 1
            free += _stands(px, py, pose, bearings, ranges, cyclic, margin_m, tolerance_m) == 1
    return free, looked


@njit
def _fold_one(
    state: np.ndarray,
    cov: np.ndarray,
    info: np.ndarray,
    t: int,
    c: int,
    scan: tuple,
    time_s: float,
    confirm_hits: float,
    smoothing: float,
) -> None:
    """Fold cluster c (`scan`: `fold`'s) into track t: its Kalman filter with the centre
    (`_kalman_update`), its radius (taken when larger, else smoothed by `smoothing`), its last
    sight (`time_s`), hits and misses, its confirmation (`confirm_hits`) and its echoes."""
    pose, _, _, _, centres, sigmas, radii, _, bounds, _ = scan
    ux, uy = _unit_from(pose[0], pose[1], centres[c, 0], centres[c, 1])
    _kalman_update(state[t], cov[t], centres[c, 0], centres[c, 1], sigmas[c, 0], sigmas[c, 1], ux, uy)
    radius = info[t, RADIUS]
    info[t, RADIUS] = radii[c] if radii[c] > radius else radius + smoothing * (radii[c] - radius)
    info[t, LAST_SEEN] = time_s
    info[t, HITS] += 1.0
    info[t, MISSES] = 0.0
    info[t, CONFIRMED] = 1.0 if info[t, HITS] >= confirm_hits else info[t, CONFIRMED]
    info[t, ECHOES] = bounds[c + 1] - bounds[c]


@njit
def _verdicts(
    references: tuple[tuple[np.ndarray, np.ndarray, float, np.ndarray], ...],
    scan: tuple,
    wanted: np.ndarray,
    young: np.ndarray,
    ranges: np.ndarray,
    fan: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool],
    evidence: np.ndarray,
) -> tuple[bool, np.ndarray]:
    """Whether the pose can be trusted, and the `wanted` clusters' verdicts (C,; `judge`) against
    earlier scans (`references`, oldest first, each its pose, ranges, time and structure's
    sample; no ranges: none yet). The oldest there judges first: a slow object has moved
    enough in its time, and a fixed one stays where it stood (`MOTION_STATIC` comes from the
    first, `slow_reference_age_s` old, alone); each younger one then judges what the older
    ones could not tell of the `young` clusters (those of no track, or of a track first seen
    after the oldest: hidden or out of view then, or no such old scan yet), and only whether it
    moved, so that a new object is told as soon as it has moved far enough. The pose is trusted
    when the fixed structure stands where it stood in the oldest (`structure_stays`); nothing
    is judged when it does not, or there is no earlier scan."""
    pose, _, _, _, _, _, _, points, bounds, now = scan
    bearings, _, _, _, cyclic = fan
    verdicts = np.full(wanted.shape[0], MOTION_UNKNOWN, dtype=np.int64)
    oldest = 0
    while oldest < len(references) and references[oldest][1].shape[0] == 0:
        oldest += 1
    if oldest == len(references):
        return False, verdicts
    ref_pose, ref_ranges, _, then = references[oldest]
    if not structure_stays(now, then, pose, ranges, (ref_pose, ref_ranges), bearings, cyclic, evidence):
        return False, verdicts
    verdicts = judge(points, bounds, wanted, ref_pose, bearings, ref_ranges, cyclic, evidence)
    if oldest > 0:
        for c in range(verdicts.shape[0]):  # only the first, slow reference tells one is fixed
            verdicts[c] = MOTION_MOVED if verdicts[c] == MOTION_MOVED else MOTION_UNKNOWN
    for which in range(oldest + 1, len(references)):
        untold = wanted & young & (verdicts == MOTION_UNKNOWN)
        if not untold.any():
            break
        ref_pose, ref_ranges, _, _ = references[which]
        again = judge(points, bounds, untold, ref_pose, bearings, ref_ranges, cyclic, evidence)
        for c in range(verdicts.shape[0]):
            verdicts[c] = MOTION_MOVED if again[c] == MOTION_MOVED else verdicts[c]
    return True, verdicts


@njit
def fold(
    state: np.ndarray,
    cov: np.ndarray,
    info: np.ndarray,
    count: int,
    rows: np.ndarray,
    clusters: np.ndarray,
    scan: tuple,
    ranges: np.ndarray,
    fan: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool],
    references: tuple[tuple[np.ndarray, np.ndarray, float, np.ndarray], ...],
    time_s: float,
    settings: np.ndarray,
    evidence: np.ndarray,
) -> np.ndarray:
    """Fold each cluster clusters[i] into track rows[i] (`_fold_one`), then set every track's
    MOVING (`_classify`); return the clusters' verdicts (C,).

    `scan` holds the scan's pose, ends, usable, fitted, centres, sigmas, radii, points, bounds and
    its fixed structure's sample (`scan_clusters`, `structure`), `ranges` its ranges (m) along
    the `fan`. Only a whole cluster (`_whole`) updates its track or is judged (`_verdicts`,
    `evidence`, against `references`: earlier scans, oldest first, each its pose, ranges, time
    and structure's sample); a confirmed track leaving the view (its part cut by the edge of the
    view shows fewer echoes than the last cluster it took) coasts on the velocity of its whole
    views, as does a track that takes a part that does not place its object. A track faster
    than `floor_mps` whose cluster does not tell it moved is asked whether it left the place it
    stood at an earlier scan free (`left_free`): the oldest, and the oldest taken since the
    track's first sight. Nothing is judged, and every verdict is forgotten (so no track moves),
    when there is no earlier scan or the fixed structure seems to have moved
    (`structure_stays`). `settings`: confirm_hits, radius_smoothing, and `_classify`'s
    (floor_mps, ...).
    """
    pose, ends, usable, fitted, _, _, _, _, bounds, _ = scan
    fraction, min_free = evidence[2], evidence[3]
    wanted = np.zeros(usable.shape[0], dtype=np.bool_)
    for c in range(usable.shape[0]):
        wanted[c] = usable[c] and _whole(ends, fitted, c)
    young = np.ones(usable.shape[0], dtype=np.bool_)
    for i in range(rows.shape[0]):
        young[clusters[i]] = info[rows[i], FIRST_SEEN] > references[0][2] or references[0][1].shape[0] == 0
    trusted, verdicts = _verdicts(references, scan, wanted, young, ranges, fan, evidence)
    for i in range(rows.shape[0]):
        t, c = rows[i], clusters[i]
        leaving = ends[c, 0] == END_EDGE or ends[c, 1] == END_EDGE
        leaving = leaving and info[t, CONFIRMED] > 0.0 and bounds[c + 1] - bounds[c] < info[t, ECHOES]
        if not wanted[c] or leaving:
            continue  # a track leaving the view coasts on the velocity of its whole views
        verdict = verdicts[c]
        _fold_one(state, cov, info, t, c, scan, time_s, settings[0], settings[1])
        if trusted and verdict != MOTION_MOVED and math.hypot(state[t, 2], state[t, 3]) > settings[2]:
            tries = 0  # the oldest earlier scan, and the oldest since the track's first sight
            for which in range(len(references)):
                ref_pose, ref_ranges, ref_time, _ = references[which]
                if ref_ranges.shape[0] == 0 or verdict == MOTION_MOVED or tries == 2:
                    continue
                if tries == 1 and ref_time < info[t, FIRST_SEEN]:
                    continue
                tries += 1
                age = time_s - ref_time
                x, y = state[t, 0] - state[t, 2] * age, state[t, 1] - state[t, 3] * age
                free, looked = left_free(
                    x, y, info[t, RADIUS], fan, (ref_pose, ref_ranges), pose, ranges, evidence
                )
                verdict = MOTION_MOVED if free >= max(min_free, fraction * looked) else verdict
        _judged(info, t, verdict, time_s)
    for t in range(0 if trusted else count):  # what was judged before may rest on a wrong pose
        info[t, MOTION], info[t, STATIC_SINCE] = MOTION_UNKNOWN, -1.0
    _classify(state, cov, info, count, settings[2:])
    return verdicts


@njit
def _judged(info: np.ndarray, t: int, verdict: int, time_s: float) -> None:
    """Set track t's MOTION and STATIC_SINCE by a `verdict` at `time_s` (an unknown one changes
    nothing)."""
    if verdict == MOTION_MOVED:
        info[t, MOTION], info[t, STATIC_SINCE] = MOTION_MOVED, -1.0
    elif verdict == MOTION_STATIC:
        info[t, MOTION] = MOTION_STATIC
        info[t, STATIC_SINCE] = info[t, STATIC_SINCE] if info[t, STATIC_SINCE] >= 0.0 else time_s


@njit
def _beam_labels(
    labels: np.ndarray,
    by_bearing: np.ndarray,
    clusters_count: int,
    rows: np.ndarray,
    clusters: np.ndarray,
    info: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Per beam (N,; in the order `by_bearing` sorted them from, none: already by bearing), the
    id of the confirmed track its cluster (`labels`, by bearing; -1: none) went to (-1: none),
    and whether that track is moving."""
    cluster_ids = np.full(clusters_count, -1, dtype=np.int64)
    cluster_moving = np.zeros(clusters_count, dtype=np.bool_)
    for i in range(rows.shape[0]):
        if info[rows[i], CONFIRMED] > 0.0:
            cluster_ids[clusters[i]] = int(info[rows[i], ID])
            cluster_moving[clusters[i]] = info[rows[i], MOVING] > 0.0
    n = labels.shape[0]
    ids = np.full(n, -1, dtype=np.int64)
    moving = np.zeros(n, dtype=np.bool_)
    for k in range(n):
        if labels[k] >= 0:
            beam = by_bearing[k] if by_bearing.shape[0] == n else k
            ids[beam] = cluster_ids[labels[k]]
            moving[beam] = cluster_moving[labels[k]]
    return ids, moving


@njit
def _near_a_track(x: float, y: float, state: np.ndarray, info: np.ndarray, rows: np.ndarray) -> bool:
    """Whether (x, y) (m) lies within the radius of one of the tracks `rows`."""
    inside = math.inf  # the least distance from a track's disc
    for t in rows:
        inside = min(inside, math.hypot(x - state[t, 0], y - state[t, 1]) - info[t, RADIUS])
    return inside <= 0.0


@njit
def _fresh(
    usable: np.ndarray,
    fitted: np.ndarray,
    ends: np.ndarray,
    centres: np.ndarray,
    verdicts: np.ndarray,
    clusters: np.ndarray,
    state: np.ndarray,
    info: np.ndarray,
    rows: np.ndarray,
) -> np.ndarray:
    """The clusters that start tracks: usable, not taken (`clusters`), whole (no end at the edge
    of the view, and silhouettes at both ends unless `fitted`), not judged static, and not
    centred within the radius of a track just seen (`rows`)."""
    taken = np.zeros(usable.shape[0], dtype=np.bool_)
    for c in clusters:
        taken[c] = True
    fresh = np.empty(usable.shape[0], dtype=np.int64)
    count = 0
    for c in range(usable.shape[0]):
        if not usable[c] or taken[c] or verdicts[c] == MOTION_STATIC or not _whole(ends, fitted, c):
            continue
        if not _near_a_track(centres[c, 0], centres[c, 1], state, info, rows):
            fresh[count] = c
            count += 1
    return fresh[:count]


@njit
def look_for(
    x: float,
    y: float,
    radius: float,
    pose: np.ndarray,
    bearings: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    margin_m: float,
) -> int:
    """What the scan (`ranges`, m, along `bearings`, rad, increasing; from `pose`: x, y in m, yaw
    in rad) says of a disc of `radius` (m) predicted at (x, y) (m) where no cluster was seen
    (`LOOK_*`), from the beams within half its angular radius of its centre: away when it is
    not wholly within the field of view, when one of them ends more than `margin_m` m before it
    (hidden) or none falls within; through when more of them pass beyond its centre (or have
    no echo) than not; else something."""
    n = bearings.shape[0]
    d = math.sqrt((x - pose[0]) ** 2 + (y - pose[1]) ** 2)
    if n == 0 or d <= radius:
        return LOOK_AWAY
    half = math.asin(radius / d)
    low = bearings[0]
    centre = low + (math.atan2(y - pose[1], x - pose[0]) - pose[2] - low) % TWO_PI  # in [low, low + 2 pi)
    if not cyclic and centre + half > bearings[n - 1]:
        return LOOK_AWAY  # also when the disc reaches below low: its centre then lies a turn on
    start, count = _window(bearings, cyclic, centre - 0.5 * half, centre + 0.5 * half)
    through = before = 0
    for i in range(count):
        r = ranges[(start + i) % n]
        if not _echo(r) or r > d:
            through += 1
        elif r < d - radius - margin_m:
            return LOOK_AWAY  # hidden behind something nearer
        else:
            before += 1
    if count == 0:
        return LOOK_AWAY
    return LOOK_THROUGH if through > before else LOOK_SOMETHING


@njit
def _duplicate(t: int, state: np.ndarray, info: np.ndarray, seen: np.ndarray, max_dv: float) -> bool:
    """Whether track t is centred within the radius of a track of `seen` and its velocity within
    `max_dv` (m/s) of that track's: one object tracked twice."""
    for s in seen:
        near = math.hypot(state[t, 0] - state[s, 0], state[t, 1] - state[s, 1]) <= info[s, RADIUS]
        if near and math.hypot(state[t, 2] - state[s, 2], state[t, 3] - state[s, 3]) <= max_dv:
            return True
    return False


@njit
def _gone(
    state: np.ndarray,
    info: np.ndarray,
    count: int,
    rows: np.ndarray,
    pose: np.ndarray,
    bearings: np.ndarray,
    ranges: np.ndarray,
    cyclic: bool,
    time_s: float,
    settings: np.ndarray,
) -> np.ndarray:
    """Which of the first `count` tracks to drop (count,) after a scan in which the tracks `rows`
    took clusters. Each other track counts a miss when the scan looks through it (`look_for`,
    `hidden_margin_m`) and is dropped after `max_misses` in a row, or when it duplicates a track
    of `rows` (`_duplicate`, `duplicate_mps`). Any track unseen for `coast_s` (unconfirmed:
    `tentative_coast_s`), or not moving and judged static for `static_s`, is dropped: fixed
    structure is the planner's map's. `settings`: coast_s, tentative_coast_s, max_misses,
    hidden_margin_m, duplicate_mps, static_s."""
    coast_s, tentative_coast_s, max_misses, margin_m, duplicate_mps, static_s = settings
    seen = np.zeros(count, dtype=np.bool_)
    for t in rows:
        seen[t] = True
    drop = np.zeros(count, dtype=np.bool_)
    for t in range(count):
        if not seen[t]:
            look = look_for(
                state[t, 0], state[t, 1], info[t, RADIUS], pose, bearings, ranges, cyclic, margin_m
            )
            if look == LOOK_THROUGH:
                info[t, MISSES] += 1.0
            drop[t] = info[t, MISSES] >= max_misses or _duplicate(t, state, info, rows, duplicate_mps)
        quiet = time_s - info[t, LAST_SEEN]
        coast = coast_s if info[t, CONFIRMED] > 0.0 else tentative_coast_s
        static = info[t, MOVING] == 0.0 and 0.0 <= info[t, STATIC_SINCE] <= time_s - static_s
        drop[t] = drop[t] or quiet > coast or static
    return drop


@njit
def start_tracks(
    state: np.ndarray,
    cov: np.ndarray,
    info: np.ndarray,
    first: int,
    fresh: np.ndarray,
    centres: np.ndarray,
    sigmas: np.ndarray,
    radii: np.ndarray,
    bounds: np.ndarray,
    pose: np.ndarray,
    time_s: float,
    first_id: int,
    settings: np.ndarray,
) -> None:
    """Start a tentative track in rows first, first + 1, ... at each cluster of `fresh`, ids from
    `first_id`: at its centre, at rest, the position's covariance its measurement noise (seen
    from `pose`), the velocity's 1-sigma `speed_std_mps`, its cluster's echoes (`bounds`).
    `settings`: speed_std_mps, confirm_hits."""
    speed_std_mps, confirm_hits = settings
    for i in range(fresh.shape[0]):
        t, c = first + i, fresh[i]
        state[t, 0], state[t, 1], state[t, 2], state[t, 3] = centres[c, 0], centres[c, 1], 0.0, 0.0
        ux, uy = _unit_from(pose[0], pose[1], centres[c, 0], centres[c, 1])
        sxx, sxy, syy = _innovation_cov(np.zeros((2, 2)), sigmas[c, 0], sigmas[c, 1], ux, uy)
        cov[t] = 0.0
        cov[t, 0, 0], cov[t, 0, 1], cov[t, 1, 0], cov[t, 1, 1] = sxx, sxy, sxy, syy
        cov[t, 2, 2] = cov[t, 3, 3] = speed_std_mps * speed_std_mps
        info[t] = 0.0
        info[t, ID] = first_id + i
        info[t, RADIUS] = radii[c]
        info[t, FIRST_SEEN] = info[t, LAST_SEEN] = time_s
        info[t, HITS] = 1.0
        info[t, CONFIRMED] = 1.0 if confirm_hits <= 1 else 0.0
        info[t, MOTION] = MOTION_UNKNOWN
        info[t, STATIC_SINCE] = -1.0
        info[t, ECHOES] = bounds[c + 1] - bounds[c]


@njit
def _compact(state: np.ndarray, cov: np.ndarray, info: np.ndarray, count: int, drop: np.ndarray) -> int:
    """Remove the rows where `drop` holds from the first `count` of the track table, keeping the
    others' order; the number kept."""
    kept = 0
    for t in range(count):
        if not drop[t]:
            for j in range(info.shape[1]):
                info[kept, j] = info[t, j]
            for j in range(16):
                state[kept, j % 4] = state[t, j % 4]
                cov[kept, j // 4, j % 4] = cov[t, j // 4, j % 4]
            kept += 1
    return kept


@njit
def track_scan(
    table: tuple[np.ndarray, np.ndarray, np.ndarray],
    count: int,
    next_id: int,
    fan: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool],
    ranges: np.ndarray,
    pose: np.ndarray,
    time_s: float,
    dt: float,
    references: tuple[tuple[np.ndarray, np.ndarray, float, np.ndarray], ...],
    settings: tuple[np.ndarray, ...],
) -> tuple[int, int, np.ndarray, np.ndarray, np.ndarray]:
    """Fold one scan into the track table and return its new count and next id, per beam the id
    of the confirmed track its echo belongs to (-1: none) and whether that track moves, and the
    sample of the scan's fixed structure (`structure`, for the scans after it).

    `table`: the tracks' states, covariances and info (rows; room for a track per cluster more
    than `count`); `fan`: the bearings (rad, increasing), their cosines and sines, the beams by
    bearing (none: given so) and whether they go all round; `ranges` (m, by bearing) taken at
    `pose` (x, y in m, yaw in rad) at `time_s`, `dt` s after the last scan; `references`:
    earlier scans, oldest first, each its pose, ranges, time and structure's sample (`fold`).
    The steps: `predict` (settings[0]: accel_psd, gate_chi2, max_gate_m), `scan_clusters`
    (settings[1], settings[2]), `associate`, `structure`, `fold` (settings[3], and settings[4]
    for `judge`, `left_free` and `structure_stays`, whose 7th is structure_points),
    `_beam_labels`, `_fresh`, `_gone` (settings[5]), `_compact` and `start_tracks`
    (settings[6]).
    """
    state, cov, info = table
    bearings, cos_b, sin_b, by_bearing, cyclic = fan
    motion, segmentation, features, folding, evidence, settling, starting = settings
    predict(state, cov, count, dt, motion[0])
    bounds, labels, ends, points, usable, fitted, centres, radii, sigmas = scan_clusters(
        bearings, cos_b, sin_b, ranges, cyclic, pose, segmentation, features
    )
    rows, clusters = associate(state, cov, count, usable, centres, sigmas, pose, motion[1], motion[2])
    fixed = structure(points, bounds, usable, int(features[0]), int(evidence[7]))
    measured = (pose, ends, usable, fitted, centres, sigmas, radii, points, bounds, fixed)
    verdicts = fold(
        state, cov, info, count, rows, clusters, measured, ranges, fan, references, time_s, folding, evidence
    )
    ids, moving = _beam_labels(labels, by_bearing, usable.shape[0], rows, clusters, info)
    fresh = _fresh(usable, fitted, ends, centres, verdicts, clusters, state, info, rows)
    drop = _gone(state, info, count, rows, pose, bearings, ranges, cyclic, time_s, settling)
    count = _compact(state, cov, info, count, drop)
    start_tracks(
        state, cov, info, count, fresh, centres, sigmas, radii, bounds, pose, time_s, next_id, starting
    )
    return count + fresh.shape[0], next_id + fresh.shape[0], ids, moving, fixed


@njit
def confirmed(
    state: np.ndarray, cov: np.ndarray, info: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """The confirmed ones of the first `count` tracks, by row: their states (K, 4; x, y in m, vx,
    vy in m/s), and (K, 7) their id, radius (m), the 1-sigma of position (m) and velocity (m/s)
    (the square roots of the larger eigenvalues of their blocks of the covariance), first and
    last sight (s), and whether moving (0 or 1)."""
    rows = _members(info[:, CONFIRMED], 0, count, 1.0)
    states = np.empty((rows.shape[0], 4))
    values = np.empty((rows.shape[0], 7))
    for i in range(rows.shape[0]):
        t = rows[i]
        for j in range(4):
            states[i, j] = state[t, j]
        values[i, 0], values[i, 1] = info[t, ID], info[t, RADIUS]
        values[i, 2], values[i, 3] = _largest_sd(cov[t], 0), _largest_sd(cov[t], 2)
        values[i, 4], values[i, 5], values[i, 6] = info[t, FIRST_SEEN], info[t, LAST_SEEN], info[t, MOVING]
    return states, values


@njit
def same(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the arrays (N,) hold the same values."""
    if a.shape[0] != b.shape[0]:
        return False
    differ = 0
    for k in range(a.shape[0]):
        differ += a[k] != b[k]
    return differ == 0
