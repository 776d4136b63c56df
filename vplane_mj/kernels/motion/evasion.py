"""Motions checked against moving obstacles in time, compiled (`planning.evasion`).

A candidate is a command (speed m/s, turn rate rad/s) held for a while, after which the robot
makes for the point it is going to as the heading controller drives it (turn rate k_w e,
limited; speed the top one times max(0, cos e), e the heading error): a dodge, then on. Speeds
and turn rates ramp at the drive's accelerations throughout. At every time step the robot's
footprint is set against each tracked obstacle's disc where its constant-velocity prediction
puts it then, the disc grown with time for the prediction's doubt. What comes back per
candidate: the first time (s) a disc comes within the margin of the footprint (inf: none within
the horizon), the least gap (m) (footprint to disc, less the growth; negative: they overlap),
the progress (m) toward the point until then, the command, and the least gap over its first
moments. `arc_hits` does the same for constant commands alone (the dynamic window's arcs).
`threat_rows` picks the tracks a robot can meet within the horizon, `ranking` orders the
candidates by their score.
"""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
def _toward(value: float, target: float, step: float) -> float:
    """`value` moved toward `target` by at most `step`."""
    return value + min(max(target - value, -step), step)


@njit
def _wrap(angle: float) -> float:
    """`angle` (rad) wrapped into [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@njit
def _outline_gap(outline: np.ndarray, px: float, py: float) -> float:
    """Signed distance (m) from the point (px, py) (robot frame) to the convex counter-clockwise
    `outline` (k, 2): negative inside."""
    k = outline.shape[0]
    best = math.inf
    outside = False
    for i in range(k):
        ax, ay = outline[i, 0], outline[i, 1]
        bx, by = outline[(i + 1) % k, 0], outline[(i + 1) % k, 1]
        ex, ey = bx - ax, by - ay
        rx, ry = px - ax, py - ay
        if ex * ry - ey * rx < 0.0:
            outside = True
        t = min(max((rx * ex + ry * ey) / (ex * ex + ey * ey), 0.0), 1.0)
        dx, dy = rx - t * ex, ry - t * ey
        best = min(best, math.sqrt(dx * dx + dy * dy))
    return best if outside else -best


@njit
def threat_rows(
    moving: np.ndarray,
    position: tuple[float, float],
    limits: tuple[float, float, float, float, float],
    doubt_caps: tuple[float, float],
) -> np.ndarray:
    """(N, 6) the tracks of `moving` (M, 7: x, y in m, vx, vy in m/s, radius in m, position
    1-sigma in m, velocity 1-sigma in m/s) that could come within the margin of a robot at
    `position` (m) within the horizon, whatever it does: x, y, vx, vy, radius (m) and its
    growth (m/s), radius and growth wider by their doubts up to `doubt_caps` (m, m/s). `limits`:
    the robot's top speed (m/s), the horizon (s), the robot's circumscribed radius (m), the
    margin (m) and the growth of every track's disc (m/s)."""
    top_speed, horizon_s, radius_m, margin_m, growth_mps = limits
    cap_m, cap_mps = doubt_caps
    rows = np.empty((moving.shape[0], 6))
    count = 0
    for n in range(moving.shape[0]):
        speed = math.hypot(moving[n, 2], moving[n, 3])
        growth = growth_mps + min(moving[n, 6], cap_mps)
        size = moving[n, 4] + min(moving[n, 5], cap_m)
        if math.hypot(moving[n, 0] - position[0], moving[n, 1] - position[1]) < (
            (top_speed + speed + growth) * horizon_s + radius_m + margin_m + size
        ):
            rows[count, :4] = moving[n, :4]
            rows[count, 4], rows[count, 5] = size, growth
            count += 1
    return rows[:count].copy()


@njit
def ranking(
    candidates: np.ndarray,
    risks: np.ndarray,
    scale: tuple[float, float, float],
    weights: tuple[float, float, float, float, float],
    kept: tuple[float, float, bool],
) -> np.ndarray:
    """The indices of `candidates` (C, 3) best first (stable among equals) by their score from
    `risks` (C, 6, as `candidate_risks` gives them): the progress over `scale[0]` (m: a horizon at
    the top speed), plus weights[0] of the least gap up to `scale[2]` (m) over it, less weights[1]
    (1 - t / `scale[1]`)^weights[2] for a first meeting at t (s) within the horizon `scale[1]`,
    less weights[3] per metre of overlap within the first moments, plus weights[4] for the
    command `kept` (m/s, rad/s) when its third item is true."""
    top, horizon, cap = scale
    room_weight, hit_weight, hit_exponent, depth_weight, keep_bonus = weights
    kept_speed, kept_turn, keeping = kept
    score = np.empty(candidates.shape[0])
    for c in range(candidates.shape[0]):
        soon = 1.0 - min(risks[c, 0], horizon) / horizon
        score[c] = (
            risks[c, 2] / top
            + room_weight * min(max(risks[c, 1], 0.0), cap) / cap
            - hit_weight * soon**hit_exponent
            - depth_weight * max(0.0, -risks[c, 5])
        )
        if keeping and candidates[c, 0] == kept_speed and candidates[c, 1] == kept_turn:
            score[c] += keep_bonus
    return np.argsort(-score, kind="stable")


@njit(inline="always")
def _toward_aim(
    x: float, y: float, yaw: float, aim: tuple[float, float], limits: tuple[float, float, float, float]
) -> tuple[float, float]:
    """The heading controller's command (m/s, rad/s) from (x, y, yaw) toward the point `aim`:
    the top speed times max(0, cos e) and k_w e, limited, and no turn faster than one that stops
    where it faces the aim. `limits`: top speed, top turn rate, turn acceleration, k_w."""
    top_speed, top_turn, alpha, gain = limits
    error = _wrap(math.atan2(aim[1] - y, aim[0] - x) - yaw)
    turn = min(max(gain * error, -top_turn), top_turn)
    stop = math.sqrt(2.0 * alpha * abs(error))
    return top_speed * max(0.0, math.cos(error)), min(max(turn, -stop), stop)


@njit(inline="always")
def _track_gaps(
    tracks: np.ndarray, t: float, x: float, y: float, yaw: float, outline: np.ndarray,
    reach_m: float, margin_m: float, counted: float,
) -> tuple[float, float, bool]:  # fmt: skip
    """At time `t` (s), the robot's footprint `outline` at (x, y, yaw) against each track's
    predicted disc (`candidate_risks`, `arc_hits`), skipping a track whose bound below the gap lies beyond
    both `counted` and `margin_m`: the least gap measured (inf: none), `counted` lowered by the
    gaps, and whether a gap lies within the margin."""
    least, within = math.inf, False
    cos_yaw, sin_yaw, turned_to = 0.0, 0.0, False  # the heading's, once a track comes near
    for n in range(tracks.shape[0]):
        ox = tracks[n, 0] + tracks[n, 2] * t - x
        oy = tracks[n, 1] + tracks[n, 3] * t - y
        size = tracks[n, 4] + tracks[n, 5] * t
        bound = math.sqrt(ox * ox + oy * oy) - reach_m - size  # a bound below the gap
        if bound >= counted and bound >= margin_m:
            continue
        if not turned_to:
            cos_yaw, sin_yaw, turned_to = math.cos(yaw), math.sin(yaw), True
        gap = _outline_gap(outline, cos_yaw * ox + sin_yaw * oy, -sin_yaw * ox + cos_yaw * oy) - size
        least = min(least, gap)
        counted = min(counted, gap)
        within = within or gap < margin_m
    return least, counted, within


@njit
def candidate_risks(
    candidates: np.ndarray,
    pose: tuple[float, float, float],
    state: tuple[float, float],
    limits: tuple[float, float, float, float, float, float],
    timing: tuple[float, float],
    outline: np.ndarray,
    reach_m: float,
    tracks: np.ndarray,
    margin_m: float,
    aim: tuple[float, float],
    near_s: float,
    room_cap_m: float,
) -> np.ndarray:
    """(C, 6) per candidate of `candidates` (C, 3: a command's speed in m/s and turn rate in
    rad/s, held for its third column's seconds; then the heading controller makes for `aim`
    at the top speed) followed for `timing[0]` s from the robot's `pose` (x, y in m, yaw in rad;
    world) and its speed and turn rate `state`, ramped within `limits` (top speed m/s, top
    turn rate rad/s, acceleration m/s^2, braking m/s^2, turn acceleration rad/s^2, and the
    heading controller's turn gain k_w, 1/s), checked every `timing[1]` s: the first time (s) a
    track's disc comes within `margin_m` of the footprint `outline` (k, 2; robot frame, within
    `reach_m` of the origin), inf for none; the least gap (m) (of a motion that meets a track,
    up to then or to `near_s`, whichever is later); the progress (m) toward the point `aim`
    (world) up to that time (or the horizon): how much nearer it the robot gets; the command
    (m/s, rad/s); and the least gap (m) within the first `near_s` s. `tracks` (N, 6): x, y
    (m), vx, vy (m/s), radius (m) and its growth (m/s)."""
    horizon, dt = timing
    top_speed, top_turn, accel, brake, alpha, gain = limits
    steps = math.ceil(horizon / dt - 1e-9)
    result = np.empty((candidates.shape[0], 6))
    x0, y0, yaw0 = pose
    away = math.hypot(aim[0] - x0, aim[1] - y0)
    # A motion's state: pose, speed, turn rate, first meeting, least gap, least gap within
    # near_s, the least gap that still counts (min(least, room_cap_m)), and where the robot is
    # at the last step that meets no track. `kept`: the last candidate's at the end of its hold
    # (or where it stopped, `kept_ended`), at step `kept_step`; the next candidate with the same
    # command held as long or longer follows it that far, step for step, and starts from there.
    start = (x0, y0, yaw0, state[0], state[1], math.inf, math.inf, math.inf, room_cap_m, x0, y0)
    kept, kept_step, kept_ended = start, -1, False
    for c in range(candidates.shape[0]):
        v_hold, w_hold, hold_s = candidates[c, 0], candidates[c, 1], candidates[c, 2]
        held = 0  # the steps of the hold: their times within hold_s
        while (held + 1) * dt <= hold_s + 1e-9:
            held += 1
        follows = kept_step >= 0 and v_hold == candidates[c - 1, 0] and w_hold == candidates[c - 1, 1]
        follows = follows and hold_s >= candidates[c - 1, 2]
        x, y, yaw, v, w, hit, least, near, counted, last_x, last_y = kept if follows else start
        s, ended = (kept_step + 1, kept_ended) if follows else (1, False)
        kept_step = -1
        while not ended and s <= steps:
            t = s * dt
            if t <= hold_s + 1e-9:
                v_cmd, w_cmd = v_hold, w_hold
            else:  # resume: the heading controller toward the aim, at the top speed
                v_cmd, w_cmd = _toward_aim(x, y, yaw, aim, (top_speed, top_turn, alpha, gain))
            rate = accel if abs(v_cmd) > abs(v) and v_cmd * v >= 0.0 else brake
            v_next = _toward(v, min(max(v_cmd, -top_speed), top_speed), rate * dt)
            w_next = _toward(w, w_cmd, alpha * dt)
            turned = 0.5 * (w + w_next) * dt
            mid = yaw + 0.5 * turned
            step = 0.5 * (v + v_next) * dt
            x, y, yaw = x + step * math.cos(mid), y + step * math.sin(mid), yaw + turned
            v, w = v_next, w_next
            gap, counted, within = _track_gaps(tracks, t, x, y, yaw, outline, reach_m, margin_m, counted)
            least = min(least, gap)
            near = min(near, gap) if t <= near_s + 1e-9 else near
            hit = t if within and t < hit else hit
            if hit == math.inf:
                last_x, last_y = x, y
            elif t >= near_s:
                ended = True  # what is left to learn of a motion that meets a track: nothing that ranks it
            if s == held or (ended and s < held):
                kept = (x, y, yaw, v, w, hit, least, near, counted, last_x, last_y)
                kept_step, kept_ended = s, ended
            s += 1
        advance = away - math.hypot(aim[0] - last_x, aim[1] - last_y)  # 0 when every step meets a track
        result[c, 0], result[c, 1], result[c, 2] = hit, least, advance
        result[c, 3], result[c, 4], result[c, 5] = v_hold, w_hold, near
    return result


@njit
def arc_hits(
    commands: np.ndarray,
    pose: tuple[float, float, float],
    timing: tuple[float, float],
    outline: np.ndarray,
    reach_m: float,
    tracks: np.ndarray,
    margin_m: float,
) -> np.ndarray:
    """(C,) per command of `commands` (C, 2: m/s, rad/s) driven at once and held from `pose` (x, y
    in m, yaw in rad; world) for `timing[0]` s, checked every `timing[1]` s: the first time (s)
    a track's disc comes within `margin_m` of the footprint `outline` (k, 2; robot frame, within
    `reach_m` of the origin), inf for none (the dynamic window's arcs; `tracks` as
    `candidate_risks` takes them)."""
    horizon, dt = timing
    steps = math.ceil(horizon / dt - 1e-9)
    hits = np.full(commands.shape[0], math.inf)
    x0, y0, yaw0 = pose
    for c in range(commands.shape[0]):
        v, w = commands[c, 0], commands[c, 1]
        for s in range(1, steps + 1):
            t = s * dt
            yaw = yaw0 + w * t
            if abs(w) > 1e-9:
                x = x0 + v / w * (math.sin(yaw) - math.sin(yaw0))
                y = y0 - v / w * (math.cos(yaw) - math.cos(yaw0))
            else:
                x, y = x0 + v * t * math.cos(yaw0), y0 + v * t * math.sin(yaw0)
            if _track_gaps(tracks, t, x, y, yaw, outline, reach_m, margin_m, margin_m)[2]:
                hits[c] = t
                break
    return hits
