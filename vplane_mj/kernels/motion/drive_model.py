"""The governor's predicted motion, compiled (`motion.DriveModel.poses`): ramped speeds and turn
rates, the fading slide, and the poses they integrate to, kept about a sweep step apart."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
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


@njit
def command_poses(
    command: tuple[float, float],
    hold_s: float,
    start: tuple[float, float, float],
    rates: tuple[float, float, float, float],
    lag_s: float,
    past: tuple[float, np.ndarray, np.ndarray],
    steps: tuple[float, float],
) -> np.ndarray:
    """`predicted_poses` of `command` (m/s, rad/s) given for `hold_s` (s), then a stop: the
    robot's speed (m/s) ramps from `start[0]` toward the command for `hold_s` at `rates[0]`
    (m/s^2; the braking `rates[1]` unless `rates[3]` says it speeds up), then to rest at
    `rates[1]`; its turn rate ramps from `start[1]` likewise at `rates[2]` (rad/s^2), `lag_s`
    late, and over the first `lag_s` is the ramp's of the past (`past`: the time now, s, and
    the past ticks' times and turn rates, interpolated; none without a lag or a past); its
    slide (`start[2]`, m/s) fades at the braking. Poses every `steps[0]` s, kept about
    `steps[1]` apart (`motion.DriveModel.poses`)."""
    accel, brake, alpha, faster = rates
    speeds = np.empty((2, 3))
    speeds[0, 0], speeds[0, 1], speeds[0, 2] = command[0], hold_s, accel if faster > 0.0 else brake
    speeds[1, 0], speeds[1, 1], speeds[1, 2] = 0.0, math.inf, brake
    turns = np.empty((2, 3))
    turns[0, 0], turns[0, 1], turns[0, 2] = command[1], hold_s, alpha
    turns[1, 0], turns[1, 1], turns[1, 2] = 0.0, math.inf, alpha
    v1, w1 = ramp_at(start[0], speeds, hold_s), ramp_at(start[1], turns, hold_s)
    end = lag_s + hold_s + max(abs(v1) / brake, abs(w1) / alpha, abs(start[2]) / brake)
    t = np.arange(0.0, end + steps[0], steps[0])
    now, times, past_rates = past
    late_turns = np.empty(0)
    if lag_s > 0 and times.shape[0] > 0:
        late_turns = np.interp(now + t[t < lag_s] - lag_s, times, past_rates)
    return predicted_poses(t, start[0], speeds, start[1], turns, lag_s, late_turns, start[2], brake, steps[1])


@njit
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
