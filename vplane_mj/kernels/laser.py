"""The laser's ray cast (`vplane_mj.sim.laser.RayCaster`), compiled: a fan of horizontal beams
against discs and rectangles, each beam tested only against the pieces within its angular
extent."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit

SPAN_PAD_RAD = 1e-7
"""Margin (rad) added on each side of a piece's angular extent before choosing the beams to
test: a beam outside the padded extent misses the piece by far more than rounding."""
TWO_PI = 2.0 * math.pi


@njit
def _beam_spans(lo: float, width: float, first: float, step: float, beams: int) -> tuple[int, int, int]:
    """The beams whose angle lies in [lo, lo + width] (rad, width < 2 pi), as (a, m, w): the m
    beams a .. a + m - 1, then the w beams 0 .. w - 1 where the interval wraps past the fan's
    start a full turn later."""
    start = (lo - first) % TWO_PI
    # Clamped before rounding to integers, so a tiny step cannot overflow them.
    a = math.ceil(min(start / step, beams))
    m = max(0, math.floor(min((start + width) / step, beams - 1)) - a + 1)
    w = 0
    if start + width >= TWO_PI:
        w = math.floor(min((start + width - TWO_PI) / step, beams - 1)) + 1
    return a, m, w


@njit
def _disc_hit(dx: float, dy: float, outside: float, ux: float, uy: float) -> float:
    """Distance along the unit direction (ux, uy) to a disc whose centre is at (dx, dy) from
    the origin, which lies outside it (`outside` = |d|^2 - r^2 > 0); inf on a miss."""
    along = dx * ux + dy * uy
    if along <= 0.0:
        return math.inf
    discriminant = along * along - outside
    if discriminant < 0.0:
        return math.inf
    return outside / (along + math.sqrt(discriminant))  # the nearer root, without cancellation


@njit
def _slab(p: float, v: float, half: float, lo: float, hi: float) -> tuple[float, float]:
    """Narrow the ray's parameter interval [lo, hi] to the slab |p + t v| <= half."""
    if v == 0.0:
        if abs(p) > half:
            return math.inf, -math.inf
        return lo, hi
    t1 = (-half - p) / v
    t2 = (half - p) / v
    return max(lo, min(t1, t2)), min(hi, max(t1, t2))


@njit
def _rect_hit(px: float, py: float, hx: float, hy: float, vx: float, vy: float) -> float:
    """Distance along the unit direction (vx, vy) from (px, py) to the rectangle |x| <= hx,
    |y| <= hy, everything in the rectangle's frame; inf on a miss."""
    lo, hi = _slab(px, vx, hx, -math.inf, math.inf)
    lo, hi = _slab(py, vy, hy, lo, hi)
    if lo > hi or hi < 0.0:
        return math.inf
    return max(lo, 0.0)


@njit
def cast_fan(
    discs: np.ndarray,
    rects: np.ndarray,
    ox: float,
    oy: float,
    first: float,
    step: float,
    fan: np.ndarray,
    range_max: float,
    ranges: np.ndarray,
) -> None:
    """Fill `ranges` (beams,) with each beam's distance (m) to the nearest piece, inf beyond
    `range_max`; all 0 when the origin lies inside or on a piece (see `RayCaster.cast`)."""
    beams = ranges.shape[0]
    cos_first, sin_first = math.cos(first), math.sin(first)
    ux = cos_first * fan[0] - sin_first * fan[1]
    uy = sin_first * fan[0] + cos_first * fan[1]
    ranges[:] = math.inf
    for i in range(discs.shape[0]):
        dx, dy, radius = discs[i, 0] - ox, discs[i, 1] - oy, discs[i, 2]
        distance = math.sqrt(dx * dx + dy * dy)
        if distance - radius > range_max:
            continue
        if distance <= radius:
            ranges[:] = 0.0
            return
        outside = dx * dx + dy * dy - radius * radius
        half = math.asin(radius / distance) + SPAN_PAD_RAD
        a, m, w = _beam_spans(math.atan2(dy, dx) - half, 2.0 * half, first, step, beams)
        for j in range(m + w):
            k = a + j if j < m else j - m
            t = _disc_hit(dx, dy, outside, ux[k], uy[k])
            if t <= range_max and t < ranges[k]:
                ranges[k] = t
    for i in range(rects.shape[0]):
        cx, cy, hx, hy, cos_yaw, sin_yaw = rects[i]
        # The origin in the rectangle's frame, and its distance to the rectangle.
        px = cos_yaw * (ox - cx) + sin_yaw * (oy - cy)
        py = -sin_yaw * (ox - cx) + cos_yaw * (oy - cy)
        qx, qy = abs(px) - hx, abs(py) - hy
        if qx <= 0.0 and qy <= 0.0:
            ranges[:] = 0.0
            return
        if math.hypot(max(qx, 0.0), max(qy, 0.0)) > range_max:
            continue
        # Angular extent: the corners' angles about the direction to the centre (< pi apart).
        lo, hi = math.inf, -math.inf
        for sx in (-1.0, 1.0):
            for sy in (-1.0, 1.0):
                ex, ey = sx * hx - px, sy * hy - py
                angle = math.atan2(-px * ey + py * ex, -px * ex - py * ey)
                lo, hi = min(lo, angle), max(hi, angle)
        centre = math.atan2(cy - oy, cx - ox)
        a, m, w = _beam_spans(centre + lo - SPAN_PAD_RAD, hi - lo + 2.0 * SPAN_PAD_RAD, first, step, beams)
        for j in range(m + w):
            k = a + j if j < m else j - m
            vx = cos_yaw * ux[k] + sin_yaw * uy[k]
            vy = -sin_yaw * ux[k] + cos_yaw * uy[k]
            t = _rect_hit(px, py, hx, hy, vx, vy)
            if t <= range_max and t < ranges[k]:
                ranges[k] = t
