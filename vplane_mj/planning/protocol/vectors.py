"""Angles and plane vectors shared by the planners and the controller."""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

Angle = TypeVar("Angle", float, np.ndarray)


def wrap_angle(angle: Angle) -> Angle:
    """The same angle (rad) in [-pi, pi): a float for a float, element-wise for an array."""
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
    """v / |v| for a plane vector, or zeros for a (near) zero vector."""
    norm = float(np.hypot(v[0], v[1]))
    return v / norm if norm > 1e-12 else np.zeros(2)
