"""The governor's predicted motion, compiled (`motion.DriveModel.poses`): ramped speeds and turn
rates, the fading slide, and the poses they integrate to, kept about a sweep step apart."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def ramp_at(start: float, phases: np.ndarray, time_s: float) -> float:
    """A ramped drive's speed (or turn rate) at `time_s` (s from now): from `start` it moves
    toward each phase's target at the phase's rate (per s) for its duration (s), in turn
    (`phases`, P x 3: target, duration, rate); after the last phase it holds."""
    value = start
    begin = 0.0
    for p in range(phases.shape[0]):
        target, duration, rate = phases[p, 0], phases[p, 1], phases[p, 2]
        if time_s > begin:
            step = min(max(time_s - begin, 0.0), duration) * rate
            value = start + min(max(target - start, -step), step)
        start += min(max(target - start, -rate * duration), rate * duration)
        begin += duration
    return value


@njit(cache=True)
def predicted_poses(
    t: np.ndarray,
    speed: float,
    speed_phases: np.ndarray,
    turn: float,
    turn_phases: np.ndarray,
    lag_s: float,
    late_turns: np.ndarray,
    slide: float,
    brake: float,
    sweep_step_m: float,
) -> np.ndarray:
    """The poses (K, 3: x, y in m, yaw in rad; from the origin heading +x) at times `t` (s,
    from 0, ascending) of a robot whose speed ramps from `speed` (`ramp_at`, `speed_phases`)
    and whose turn rate is `late_turns` (rad/s) at the first times, then ramps from `turn` as
    `turn_phases` `lag_s` late; its slide to its left (`slide`, m/s) fades at `brake` (m/s^2):
    v t - a t^2 / 2 up to v / a, v^2 / 2a after. Speeds and turn rates are integrated by the
    trapezoid rule, cumulated in order. Poses are kept where the travel plus the slide plus
    the turn (rad) since the start first reaches each multiple of `sweep_step_m`; the last is
    always kept."""
    n = t.shape[0]
    v, w, slid = np.empty(n), np.empty(n), np.empty(n)
    fade_s = abs(slide) / brake
    signed_brake = math.copysign(brake, slide)
    for k in range(n):
        v[k] = ramp_at(speed, speed_phases, t[k])
        w[k] = late_turns[k] if k < late_turns.shape[0] else ramp_at(turn, turn_phases, t[k] - lag_s)
        s = min(t[k], fade_s)
        slid[k] = slide * s - signed_brake * s * s / 2
    x, y, yaw, moved = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    x[0], y[0], yaw[0], moved[0] = 0.0, 0.0 + slid[0], 0.0, 0.0
    sum_yaw = sum_x = sum_y = sum_moved = 0.0
    for k in range(n - 1):
        dt = t[k + 1] - t[k]
        turned = 0.5 * (w[k + 1] + w[k]) * dt
        sum_yaw = turned if k == 0 else sum_yaw + turned  # a cumulative sum, as numpy's
        yaw[k + 1] = sum_yaw
        mid = 0.5 * (yaw[k + 1] + yaw[k])
        ds = 0.5 * (v[k + 1] + v[k]) * dt
        step_x, step_y = ds * math.cos(mid), ds * math.sin(mid)
        step_moved = abs(ds) + abs(slid[k + 1] - slid[k]) + abs(yaw[k + 1] - yaw[k])
        if k == 0:
            sum_x, sum_y, sum_moved = step_x, step_y, step_moved
        else:
            sum_x, sum_y, sum_moved = sum_x + step_x, sum_y + step_y, sum_moved + step_moved
        x[k + 1], y[k + 1], moved[k + 1] = sum_x, sum_y + slid[k + 1], sum_moved
    keep = np.empty(n, dtype=np.int64)
    count = 0
    previous = -1.0
    for k in range(n):
        level = math.floor(moved[k] / sweep_step_m)
        if level - previous > 0 or k == n - 1:
            keep[count] = k
            count += 1
        previous = level
    poses = np.empty((count, 3))
    for c in range(count):
        poses[c, 0], poses[c, 1], poses[c, 2] = x[keep[c]], y[keep[c]], yaw[keep[c]]
    return poses
