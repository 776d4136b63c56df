"""The signed clearance of a polygon footprint from a grid's occupied cells, against brute force."""

import math

import numpy as np
import pytest

from vplane_mj.kernels.motion.footprint_clearance import footprint_clearance
from vplane_mj.robots.facts import robot_body


def signed_distance(polygon, points):
    """Signed distance (m) from points (N, 2) to a convex counter-clockwise polygon: negative inside."""
    start, edge = polygon[None], (np.roll(polygon, -1, axis=0) - polygon)[None]
    rel = points[:, None, :] - start
    t = np.clip((rel * edge).sum(-1) / (edge * edge).sum(-1), 0.0, 1.0)
    gap = np.hypot(*np.moveaxis(rel - t[..., None] * edge, -1, 0)).min(axis=1)
    outside = (edge[..., 0] * rel[..., 1] - edge[..., 1] * rel[..., 0] < 0).any(axis=1)
    return np.where(outside, gap, -gap)


def brute_force(occupied, first_cell, cell_m, footprint, poses, cap_m):
    i, j = np.nonzero(occupied)
    centres = (np.column_stack((i, j)) + first_cell + 0.5) * cell_m
    result = []
    for x, y, yaw in poses:
        c, s = math.cos(yaw), math.sin(yaw)
        rel = centres - (x, y)
        body = np.column_stack((c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]))
        result.append(min(cap_m, signed_distance(footprint, body).min(initial=math.inf)))
    return np.array(result)


@pytest.mark.parametrize("profile", ["jackal", "pioneer3dx", "turtlebot3_burger"])
@pytest.mark.parametrize("cap_m", [0.0, 0.05, 0.3])
def test_it_agrees_with_brute_force_inside_and_outside(profile, cap_m):
    rng = np.random.default_rng(3)
    footprint = robot_body(profile).footprint
    occupied = rng.random((40, 50)) < 0.05
    first_cell, cell_m = (-7, 3), 0.1
    poses = np.column_stack((rng.uniform(-1, 3.5, 400), rng.uniform(0, 8.5, 400), rng.uniform(-4, 4, 400)))
    got = footprint_clearance(occupied, first_cell, cell_m, footprint, poses, cap_m)
    want = brute_force(occupied, first_cell, cell_m, footprint, poses, cap_m)
    assert got == pytest.approx(want, abs=1e-12)
    assert (want < 0).sum() > 20 and (want == cap_m).sum() > 20  # inside, and far, both tried


def test_a_cell_off_the_grid_or_beyond_the_cap_is_not_seen():
    footprint = robot_body("jackal").footprint
    occupied = np.zeros((10, 10), dtype=bool)
    occupied[5, 5] = True  # centre (0.55, 0.55) m
    poses = np.array([[0.55, 0.0, 0.0], [0.55, 0.0, math.pi / 2], [5.0, 5.0, 0.0], [-3.0, 0.55, 0.0]])
    got = footprint_clearance(occupied, (0, 0), 0.1, footprint, poses, 0.5)
    assert got == pytest.approx([0.55 - 0.215, 0.55 - 0.254, 0.5, 0.5])


def test_points_count_where_they_are_and_off_the_grid_not_at_all():
    footprint = robot_body("jackal").footprint
    occupied = np.zeros((10, 10), dtype=bool)
    points = np.array([[0.6, 0.5], [0.62, -0.3], [1.5, 0.0]])  # the last is off the grid
    poses = np.array([[0.0, 0.5, 0.0], [0.0, 0.5, math.pi / 2], [1.5, 0.3, 0.0]])
    got = footprint_clearance(occupied, (0, 0), 0.1, footprint, poses, 0.5, points)
    want = brute_force_points(points[:2], footprint, poses, 0.5)
    assert got == pytest.approx(want) and got[0] == pytest.approx(0.6 - 0.254)
    assert got[2] == 0.5  # (1.5, 0.0) lies beyond the grid's 1 m


def brute_force_points(points, footprint, poses, cap_m):
    result = []
    for x, y, yaw in poses:
        c, s = math.cos(yaw), math.sin(yaw)
        rel = points - (x, y)
        body = np.column_stack((c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]))
        result.append(min(cap_m, signed_distance(footprint, body).min()))
    return np.array(result)


def test_cells_and_points_together_agree_with_brute_force():
    rng = np.random.default_rng(5)
    footprint = robot_body("pioneer3dx").footprint
    occupied = rng.random((30, 30)) < 0.03
    points = rng.uniform(-1.0, 4.0, (300, 2))
    poses = np.column_stack((rng.uniform(0, 3, 300), rng.uniform(0, 3, 300), rng.uniform(-4, 4, 300)))
    got = footprint_clearance(occupied, (0, 0), 0.1, footprint, poses, 0.3, points)
    on_grid = points[np.all((points >= 0) & (points < 3.0), axis=1)]
    want = np.minimum(
        brute_force(occupied, (0, 0), 0.1, footprint, poses, 0.3),
        brute_force_points(on_grid, footprint, poses, 0.3),
    )
    assert got == pytest.approx(want, abs=1e-12)
    assert (want < 0).sum() > 10 and (want < 0.3).sum() > 100
