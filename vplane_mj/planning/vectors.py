"""Angles and plane vectors shared by the planners and the controller."""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

Angle = TypeVar("Angle", float, np.ndarray)


def wrap_angle(angle: Angle) -> Angle:
    """The same angle (rad) in [-pi, pi): a float for a float, element-wise for an array."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def unit(v: np.ndarray) -> np.ndarray:
    """v / |v| for a plane vector, or zeros for a (near) zero vector."""
    norm = float(np.hypot(v[0], v[1]))
    return v / norm if norm > 1e-12 else np.zeros(2)
