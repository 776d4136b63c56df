"""The simplified travelled path: within its tolerance of every position, with few vertices."""

import itertools
import math

import numpy as np
import pytest

from vplane_mj.geometry.polyline import PathSimplifier, distances_to_segment, douglas_peucker


def simplify(points: np.ndarray, tolerance_m: float = 0.01, max_pending: int = 200) -> np.ndarray:
    simplifier = PathSimplifier(tolerance_m, max_pending)
    for x, y in points:
        simplifier.add(x, y)
    return np.array(simplifier.polyline())


def deviation(points: np.ndarray, polyline: np.ndarray) -> float:
    """The largest distance from a point to the polyline."""
    if len(polyline) == 1:
        return float(np.hypot(*(points - polyline[0]).T).max())
    edges = [distances_to_segment(points, a, b) for a, b in itertools.pairwise(polyline)]
    return float(np.min(edges, axis=0).max())


def test_distance_to_a_segment_and_to_a_degenerate_one():
    points = np.array([[0.5, 1.0], [-1.0, 0.0], [3.0, 4.0]])
    a, b = np.array([0.0, 0.0]), np.array([1.0, 0.0])
    np.testing.assert_allclose(distances_to_segment(points, a, b), [1.0, 1.0, math.hypot(2, 4)])
    np.testing.assert_allclose(distances_to_segment(points, a, a), np.hypot(*points.T))


def test_a_straight_run_is_one_edge():
    points = np.column_stack([np.linspace(0, 5, 120), np.linspace(1, 2, 120)])
    polyline = simplify(points)
    np.testing.assert_array_equal(polyline, points[[0, -1]])


def test_a_circle_keeps_a_vertex_about_every_chord_of_the_tolerance():
    radius, tolerance = 0.5, 0.01
    angles = np.linspace(0, 2 * math.pi, 2000)
    points = radius * np.column_stack([np.cos(angles), np.sin(angles)])
    polyline = simplify(points, tolerance, max_pending=10_000)
    assert deviation(points, polyline) <= tolerance
    chord = 2 * math.sqrt(2 * radius * tolerance)  # 0.2 m: the sagitta equals the tolerance
    expected = 2 * math.pi * radius / chord
    assert expected <= len(polyline) - 1 <= 1.5 * expected + 2


def test_going_back_on_the_same_line_keeps_the_turning_point():
    out = np.column_stack([np.linspace(0, 2, 50), np.zeros(50)])
    points = np.vstack([out, out[-2::-1]])
    polyline = simplify(points)
    assert deviation(points, polyline) <= 0.01
    assert any(np.allclose(vertex, (2.0, 0.0)) for vertex in polyline)
    np.testing.assert_array_equal(polyline[-1], (0.0, 0.0))


@pytest.mark.parametrize("seed", range(5))
def test_a_random_walk_stays_within_the_tolerance(seed):
    rng = np.random.default_rng(seed)
    headings = np.cumsum(rng.normal(0, 0.3, 3000))
    steps = 0.02 * np.column_stack([np.cos(headings), np.sin(headings)])
    points = np.cumsum(steps, axis=0)
    polyline = simplify(points)
    assert deviation(points, polyline) <= 0.01 + 1e-12
    np.testing.assert_array_equal(polyline[[0, -1]], points[[0, -1]])
    assert len(polyline) < len(points) / 2


def test_the_held_back_positions_are_bounded():
    points = np.column_stack([np.linspace(0, 10, 1001), np.zeros(1001)])
    polyline = simplify(points, max_pending=100)
    assert len(polyline) == 11  # a vertex every 100 positions on a straight line
    assert deviation(points, polyline) <= 1e-12


def test_one_or_no_position():
    assert PathSimplifier(0.01).polyline() == []
    simplifier = PathSimplifier(0.01)
    simplifier.add(1.0, 2.0)
    assert simplifier.polyline() == [(1.0, 2.0)]


def test_a_capped_polyline_keeps_its_vertex_count_and_its_bound_on_a_long_winding_path():
    """A random walk of 20,000 positions (about 600 m of turns) under a cap of 300 vertices."""
    rng = np.random.default_rng(3)
    heading = np.cumsum(rng.normal(0.0, 0.15, 20_000))
    points = np.cumsum(0.03 * np.column_stack((np.cos(heading), np.sin(heading))), axis=0)
    simplifier = PathSimplifier(0.01, max_vertices=300)
    most = 0
    for x, y in points:
        simplifier.add(x, y)
        most = max(most, len(simplifier.polyline()))
    polyline = np.array(simplifier.polyline())
    assert len(simplify(points)) > 2500  # uncapped, the path needs eight times the cap
    assert most <= 301  # the vertices, and the newest position held back
    assert 0.01 < simplifier.within_m < 2.0
    assert deviation(points, polyline) <= simplifier.within_m + 1e-12
    assert polyline[0] == pytest.approx(points[0]) and polyline[-1] == pytest.approx(points[-1])
    newest = points[-100:]  # the latest stretch keeps the fine tolerance
    assert deviation(newest, polyline[-(len(polyline) // 4) :]) <= 0.01 + 1e-12


def test_douglas_peucker_keeps_the_ends_and_the_corners_beyond_its_tolerance():
    points = np.array([[0, 0], [1, 0.004], [2, 0], [2, 1], [2.003, 2], [2, 3]], dtype=float)
    np.testing.assert_array_equal(douglas_peucker(points, 0.01), [0, 2, 5])
    np.testing.assert_array_equal(douglas_peucker(points, 0.001), [0, 1, 2, 3, 4, 5])
