"""Angles and plane vectors shared by the planners and the controller."""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

Angle = TypeVar("Angle", float, np.ndarray)


def wrap_angle(angle: Angle) -> Angle:
    """The same angle in [-pi, pi).

    Args:
        angle: An angle (rad), a float or an array.

    Returns:
        The angle wrapped (rad): a float for a float, element-wise for an array.
    """
    return (angle + math.pi) % (2 * math.pi) - math.pi


def evenly_spaced(start: float, stop: float, count: int) -> np.ndarray:
    """`np.linspace(start, stop, count)` for two floats, bit for bit (its arithmetic: k times
    the step, plus the start; the stop last), without its overhead (it runs at every tick)."""
    if count < 2:
        return np.linspace(start, stop, count)
    div = count - 1
    delta = stop - start
    step = delta / div
    if step == 0:  # linspace scales by the difference then (a difference below div's subnormal)
        values = [k / div * delta + start for k in range(count)]
    else:
        values = [k * step + start for k in range(count)]
    values[-1] = stop
    return np.array(values)


def unit(v: np.ndarray) -> np.ndarray:
    """The unit vector along a plane vector.

    Args:
        v: A plane vector (2,).

    Returns:
        v / |v|, or zeros for a vector shorter than 1e-12.
    """
    norm = float(np.hypot(v[0], v[1]))
    return v / norm if norm > 1e-12 else np.zeros(2)


def dot(points: np.ndarray, v: np.ndarray) -> np.ndarray:
    """x vx + y vy of each plane vector of `points` (..., 2) with `v` (2,), rounded as written.

    Not `points @ v`: numpy hands a product to BLAS, whose kernels for the CPU at hand (with
    fused multiply-adds or without) decide its last bit, and a trajectory's with it."""
    points = np.asarray(points, float)
    return points[..., 0] * v[0] + points[..., 1] * v[1]


def rotated(points: np.ndarray, yaw: float) -> np.ndarray:
    """Plane vectors `points` (..., 2) turned by `yaw` (rad) counter-clockwise (no BLAS, as `dot`)."""
    points = np.asarray(points, float)
    c, s = math.cos(yaw), math.sin(yaw)
    x, y = points[..., 0], points[..., 1]
    return np.stack((x * c - y * s, x * s + y * c), axis=-1)
