"""Khatib's FIRAS attraction and repulsion, compiled (`vplane_mj.planning.motion.fields`)."""

from __future__ import annotations

import math

import numpy as np

from vplane_mj.kernels import njit


@njit
def repulsive_force(
    position: np.ndarray, points: np.ndarray, gain: float, influence: float, min_distance: float
) -> np.ndarray:
    """Eq. 5 summed over `points` (N, 2; m), in their order: eta (1/f - 1/f0) (1/f^2) (x - x_obs)/f
    for f <= f0 = `influence`, f the distance from `position` clamped to `min_distance` (m)."""
    force = np.zeros(2)
    for k in range(points.shape[0]):
        rel_x, rel_y = position[0] - points[k, 0], position[1] - points[k, 1]
        f = max(math.hypot(rel_x, rel_y), min_distance)
        if f <= influence:
            magnitude = gain * (1.0 / f - 1.0 / influence) / (f * f)
            force[0] += magnitude * rel_x / f
            force[1] += magnitude * rel_y / f
    return force


@njit
def attractive_force(
    x: float, y: float, goal_x: float, goal_y: float, gain: float, radius: float
) -> np.ndarray:
    """Eq. 3 at (x, y) (m) toward the goal (m): -2w d inside `radius`, -2wr d/|d| beyond, d the
    offset from the goal; zero at the goal."""
    dx, dy = x - goal_x, y - goal_y
    dist = math.hypot(dx, dy)
    force = np.empty(2)
    if dist <= radius:
        force[0], force[1] = -2.0 * gain * dx, -2.0 * gain * dy
    else:
        scale = -2.0 * gain * radius
        force[0], force[1] = scale * dx / dist, scale * dy / dist
    return force


@njit
def plane_force(
    along: float,
    out: float,
    length: float,
    normal: np.ndarray,
    tangent: np.ndarray,
    slide: float,
    gain: float,
    influence: float,
    step: float,
    slide_gain: float,
    min_distance: float,
) -> np.ndarray:
    """Eqs. 8-10 (`vplane_geometry.plane_force`) for a robot at `along` (m from e1) and `out` (m,
    outward) in the frame of a plane of `length` (m), its `normal` and `tangent` (world, unit):
    the FIRAS repulsion of points p_i at most `step` apart along the plane, both ends included,
    each weighted by the spacing; its outward part, as if the robot stood at least
    `min_distance` outside, plus `slide_gain` times it along `slide` times the tangent."""
    count = max(2, math.ceil(length / step) + 1)
    spacing = length / (count - 1)
    normal_distance = max(out, min_distance)
    outward = 0.0
    for i in range(count):
        position = i * spacing if i < count - 1 else length
        f = math.hypot(along - position, normal_distance)
        if f <= influence:
            magnitude = gain * (1.0 / f - 1.0 / influence) / (f * f) * spacing
            outward += magnitude * normal_distance / f
    force = np.empty(2)
    sliding = slide_gain * outward * slide
    force[0] = outward * normal[0] + sliding * tangent[0]
    force[1] = outward * normal[1] + sliding * tangent[1]
    return force
