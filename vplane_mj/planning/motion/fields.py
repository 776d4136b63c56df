"""Khatib's FIRAS potentials and forces (paper eqs. 2-6), as read in docs/method.md.

Positions in metres; potentials and forces are in the planner's own force units
(the controller maps a force of magnitude 1 to its cruise speed).
"""

from __future__ import annotations

import numpy as np

MIN_DISTANCE_M = 1e-3
"""Distances are clamped to at least this, so no force is ever inf or NaN."""


def attractive_potential(position: np.ndarray, goal: np.ndarray, gain: float, radius: float) -> float:
    """Eq. 2: w|d|^2 for |d| <= r, w(2r|d| - r^2) beyond (continuous at r); d = x - x_goal."""
    d = float(np.hypot(*(np.asarray(position, float) - goal)))
    if d <= radius:
        return gain * d * d
    return gain * (2.0 * radius * d - radius * radius)


def attractive_force(position: np.ndarray, goal: np.ndarray, gain: float, radius: float) -> np.ndarray:
    """Eq. 3: -grad of eq. 2: -2w d inside r, -2wr d/|d| beyond; zero at the goal."""
    from vplane_mj.kernels.motion import fields  # numba: loaded by the first call

    return fields.attractive_force(
        float(position[0]), float(position[1]), float(goal[0]), float(goal[1]), float(gain), float(radius)
    )


def repulsive_potential(position: np.ndarray, points: np.ndarray, gain: float, influence: float) -> float:
    """Eq. 4 summed over obstacle points: 1/2 eta (1/f - 1/f0)^2 for f <= f0, else 0.

    `points` (N, 2) are obstacle points (sonar echoes); f is clamped to MIN_DISTANCE_M.
    """
    _, f = _offsets(position, points)
    near = f <= influence
    return float(0.5 * gain * np.sum((1.0 / f[near] - 1.0 / influence) ** 2))


def repulsive_force(position: np.ndarray, points: np.ndarray, gain: float, influence: float) -> np.ndarray:
    """Eq. 5 summed over obstacle points: eta (1/f - 1/f0) (1/f^2) (x - x_obs)/f for f <= f0.

    Each sonar echo is one obstacle point, so the force is the negative gradient of
    `repulsive_potential`; it points away from every point within the influence distance.
    At a clamped distance the direction (x - x_obs)/f is still a unit vector or zero.
    """
    from vplane_mj.kernels.motion import fields  # numba: loaded by the first call

    return fields.repulsive_force(
        np.asarray(position, float),
        np.asarray(points, float).reshape(-1, 2),
        float(gain),
        float(influence),
        MIN_DISTANCE_M,
    )


def _offsets(position: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x - x_obs for each point (N, 2), and its length f clamped to MIN_DISTANCE_M (N,)."""
    rel = np.asarray(position, float) - np.asarray(points, float).reshape(-1, 2)
    return rel, np.maximum(np.hypot(rel[:, 0], rel[:, 1]), MIN_DISTANCE_M)
