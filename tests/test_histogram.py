"""The VFH polar histogram: enlargement, valleys (circular), wide-enough gaps."""

import math

import numpy as np
import pytest

from vplane_mj.planning.perception.histogram import (
    Valley,
    find_valleys,
    nearest_wide_valley,
    polar_histogram,
    sector_of,
)

N = 72  # 5 degree sectors
ENLARGE = 0.19  # robot radius 0.11 + clearance 0.08


def blocked_by(cells, window=3.0):
    cells = np.array(cells, float)
    h = polar_histogram(np.zeros(2), cells, np.full(len(cells), 4), N, window, ENLARGE)
    return h > 1.0


def test_a_point_blocks_the_sectors_its_enlarged_disc_covers():
    blocked = blocked_by([[1.0, 0.0]])
    half = math.degrees(math.asin(ENLARGE / 1.0))  # 11 degrees either side
    expected = {k % N for k in range(-math.ceil(half / 5), math.ceil(half / 5))}
    assert set(np.flatnonzero(blocked)) == expected


def test_cells_beyond_the_window_do_not_count():
    assert not blocked_by([[3.5, 0.0]]).any()


def test_valleys_are_circular_runs_of_free_sectors():
    blocked = np.zeros(12, bool)
    blocked[[2, 3, 8]] = True
    valleys = find_valleys(blocked)
    assert {(v.first, v.last, v.count) for v in valleys} == {(4, 7, 4), (9, 1, 5)}
    assert find_valleys(np.zeros(6, bool)) == [Valley(0, 5, 6)]
    assert find_valleys(np.ones(6, bool)) == []


def gap_cells(gap):
    """Two walls 1.5 m ahead, along y, leaving a gap of `gap` metres around y = 0."""
    ys = np.concatenate([np.arange(gap / 2, 1.5, 0.05), -np.arange(gap / 2, 1.5, 0.05)])
    return [[1.5, y] for y in ys]


@pytest.mark.parametrize("gap, passable", [(0.25, False), (0.35, False), (0.9, True), (1.4, True)])
def test_a_gap_is_a_valley_only_when_the_robot_fits(gap, passable):
    blocked = blocked_by(gap_cells(gap))
    valley, distance = nearest_wide_valley(find_valleys(blocked), 0.0, N, min_sectors=2)
    ahead_is_free = not blocked[sector_of(0.0, N)]
    assert ahead_is_free == passable
    if passable:
        assert distance == 0 and valley.count >= 2


def test_nearest_wide_valley_skips_narrow_ones_and_measures_distance():
    blocked = np.ones(36, bool)
    blocked[[5]] = False  # one free sector: too narrow
    blocked[10:14] = False  # four free sectors
    valleys = find_valleys(blocked)
    valley, distance = nearest_wide_valley(valleys, math.radians(5 * 10), 36, min_sectors=3)
    assert (valley.first, valley.count) == (10, 4) and distance == 5
    assert nearest_wide_valley(valleys, 0.0, 36, min_sectors=5) == (None, 36)


def test_an_obstacle_behind_a_gap_closes_the_gap_while_it_is_in_the_window():
    """A 0.9 m gap 1 m ahead, which the enlarged robot (0.38 m) fits through, and a post 0.8 m
    behind it: the way ahead is blocked as long as the window reaches the post, although the
    robot could pass the gap and turn (why VFH stops short in clutter)."""
    walls = [[1.0, y] for y in np.arange(0.45, 1.5, 0.05)] + [[1.0, -y] for y in np.arange(0.45, 1.5, 0.05)]
    post = [[1.8, 0.0]]
    ahead = sector_of(0.0, N)
    assert not blocked_by(walls, window=2.0)[ahead]
    assert blocked_by(walls + post, window=2.0)[ahead]
    assert not blocked_by(walls + post, window=1.5)[ahead]


def reference_histogram(origin, cells, certainty, n_sectors, window_m, enlarge_m):
    """The histogram summed cell by cell into a difference array (np.add.at, in cell order)."""
    h = np.zeros(n_sectors)
    rel = np.asarray(cells, float).reshape(-1, 2) - origin
    d = np.hypot(rel[:, 0], rel[:, 1])
    inside = d < window_m
    if not inside.any():
        return h
    rel, d, c = rel[inside], d[inside], np.asarray(certainty, float)[inside]
    sector = 2 * math.pi / n_sectors
    bearing = np.arctan2(rel[:, 1], rel[:, 0]) % (2 * math.pi)
    half = np.arcsin(np.minimum(1.0, enlarge_m / np.maximum(d, 1e-6)))
    magnitude = c * c * (window_m - d)
    first = np.floor((bearing - half) / sector).astype(int) + n_sectors
    last = np.minimum(np.floor((bearing + half) / sector).astype(int) + n_sectors, first + n_sectors - 1)
    steps = np.zeros(3 * n_sectors + 1)
    np.add.at(steps, first, magnitude)
    np.add.at(steps, last + 1, -magnitude)
    return np.cumsum(steps)[: 3 * n_sectors].reshape(3, n_sectors).sum(axis=0)


def test_the_histogram_equals_the_cell_by_cell_sum_bit_for_bit():
    rng = np.random.default_rng(0)
    for trial in range(500):
        count = int(rng.integers(0, 300))
        # coordinates on a coarse lattice too: cells straight ahead, behind, at sector edges
        cells = np.round(rng.uniform(-3, 3, (count, 2)), int(rng.integers(1, 4)))
        certainty = rng.integers(4, 16, count)
        origin = np.round(rng.uniform(-1, 1, 2), 1) if trial % 2 else np.zeros(2)
        args = (int(rng.choice([8, 36, 72, 720])), float(rng.uniform(0.5, 3)), float(rng.uniform(0, 1)))
        expected = reference_histogram(origin, cells, certainty, *args)
        np.testing.assert_array_equal(polar_histogram(origin, cells, certainty, *args), expected)
