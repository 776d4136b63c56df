"""The sonar certainty grid: beam arcs, free-cone carving, clusters and extreme points."""

import math

import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import BEAM, BEARINGS, scan
from vplane_mj.planning.localmap import LocalMap, angular_extremes

WALL = shapes.Footprints(shapes.Wall((2.0, -1.0), (2.0, 1.0), 0.1).footprint())


def mapped(footprints, position, yaw=0.0, scans=3):
    grid = LocalMap(cell_m=0.1, size_m=8.0)
    for _ in range(scans):
        grid.update(np.array(position), yaw, BEARINGS, scan(footprints, position, yaw), BEAM)
    return grid


def test_echoes_mark_the_wall_and_nothing_well_in_front_of_it():
    grid = mapped(WALL, (0.0, 0.0))
    cells, certainty = grid.cells(min_certainty=4)
    assert len(cells) > 5
    # The wall's near face is at x = 1.95. A 20 degree beam places its echo anywhere on its
    # arc, so oblique beams mark cells up to 2 r sin^2(10 deg) ~ 0.3 m in front of the face.
    assert np.median(cells[:, 0]) == pytest.approx(1.95, abs=0.1)
    assert np.all((cells[:, 0] > 1.95 - 0.35) & (cells[:, 0] < 1.95 + 0.15))
    assert certainty.max() <= 15


def test_a_phantom_echo_is_carved_away_by_later_readings():
    grid = LocalMap(cell_m=0.1, size_m=8.0)
    ranges = np.full(16, np.nan)
    ranges[0] = 1.0  # something at 1 m ahead, once
    grid.update(np.zeros(2), 0.0, BEARINGS, ranges, BEAM)
    assert len(grid.cells(3)[0]) > 0
    ranges[0] = 2.5  # then the beam sees past it, again and again
    for _ in range(3):
        grid.update(np.zeros(2), 0.0, BEARINGS, ranges, BEAM)
    cells, _ = grid.cells(1)
    assert not np.any(np.hypot(*cells.T) < 2.3)


def test_no_echo_leaves_the_map_unchanged():
    grid = mapped(WALL, (0.0, 0.0))
    before = grid.grid.copy()
    grid.update(np.zeros(2), 0.0, BEARINGS, np.full(16, np.nan), BEAM)
    np.testing.assert_array_equal(grid.grid, before)


def test_the_grid_follows_the_robot_and_keeps_what_it_saw():
    grid = mapped(WALL, (0.0, 0.0))
    count = len(grid.cells(4)[0])
    grid.update(np.array([2.5, 0.0]) - [1.8, 0.0], 0.0, BEARINGS, np.full(16, np.nan), BEAM)
    grid.update(np.array([-2.0, 0.0]), 0.0, BEARINGS, np.full(16, np.nan), BEAM)
    assert len(grid.cells(4)[0]) == count  # shifted, not lost: the wall is still within 4 m
    grid.update(np.array([-9.0, 0.0]), 0.0, BEARINGS, np.full(16, np.nan), BEAM)
    assert len(grid.cells(1)[0]) == 0  # far away: forgotten


def test_cells_closer_than_the_link_distance_form_one_cluster():
    two_walls = shapes.Footprints(
        [
            *shapes.Wall((2.0, -1.0), (2.0, -0.1), 0.1).footprint(),
            *shapes.Wall((2.0, 1.4), (2.0, 2.5), 0.1).footprint(),
        ]
    )
    grid = mapped(two_walls, (0.0, 0.0), scans=5)
    _, labels_narrow, _ = grid.clusters(4, link_m=0.3)
    _, labels_wide, _ = grid.clusters(4, link_m=2.0)
    # A 1.5 m gap, narrowed by the beams' arcs (a 20 degree beam is 0.7 m wide at 2 m)
    assert len(set(labels_narrow)) == 2
    assert len(set(labels_wide)) == 1


def test_extreme_points_of_a_cup_seen_from_inside_are_the_mouth():
    # A cup opening toward -x around the origin, the robot inside it.
    cup = shapes.Cup((0.0, 0.0), width=1.6, depth=1.2, thickness=0.1)
    points = []
    for piece in cup.footprint():  # sample each wall along its long axis
        long_x = piece.half[0] > piece.half[1]
        for t in np.linspace(-1, 1, 15):
            offset = (t * piece.half[0], 0.0) if long_x else (0.0, t * piece.half[1])
            points.append((piece.center[0] + offset[0], piece.center[1] + offset[1]))
    points = np.array(points)
    i1, i2, span = angular_extremes(np.array([0.0, 0.0]), points)
    assert span > math.pi
    mouth = {tuple(np.round(points[i1], 2)), tuple(np.round(points[i2], 2))}
    assert mouth == {(-0.6, 0.75), (-0.6, -0.75)}


def test_extreme_points_of_an_obstacle_ahead():
    points = np.array([[2.0, y] for y in np.linspace(-1.0, 1.0, 11)])
    i1, i2, span = angular_extremes(np.zeros(2), points)
    assert points[i1] == pytest.approx([2.0, -1.0])  # clockwise end first
    assert points[i2] == pytest.approx([2.0, 1.0])
    assert span == pytest.approx(2 * math.atan(0.5))


def test_a_map_no_scan_has_placed_says_so_where_it_needs_its_origin():
    grid = LocalMap(cell_m=0.1, size_m=8.0)
    assert grid.origin is None and len(grid.cells()[0]) == 0
    with pytest.raises(RuntimeError, match="no origin before its first update or sweep"):
        grid.clearance_field(1, np.zeros(2), reach_m=1.0)
    with pytest.raises(RuntimeError, match="no origin before its first update or sweep"):
        grid.lookup(grid.grid, np.zeros((1, 2)))
    grid.sweep(np.array([1.0, -2.0]), 0.2)
    np.testing.assert_array_equal(grid.origin, [10 - grid.n // 2, -20 - grid.n // 2])
    assert grid.lookup(grid.swept, np.array([[1.0, -2.0], [3.0, -2.0]])).tolist() == [True, False]


def test_the_clearance_field_is_the_distance_to_the_nearest_obstacle_cell():
    rng = np.random.default_rng(0)
    grid = LocalMap(cell_m=0.1, size_m=8.0)
    grid.update(np.zeros(2), 0.0, BEARINGS, np.full(16, np.nan), BEAM)  # places the grid around (0, 0)
    index = rng.integers(25, 55, size=(12, 2))
    grid.grid[index[:, 0], index[:, 1]] = 6
    cells, _ = grid.cells(4)
    field = grid.clearance_field(4, np.zeros(2), reach_m=1.5)

    def exact(points):
        return np.min(np.hypot(*(points[:, None, :] - cells[None]).transpose(2, 0, 1)), axis=1)

    centres = (np.argwhere(np.ones(field.values.shape, bool)) + field.first_cell + 0.5) * 0.1
    seen = np.all(np.abs(centres) < 1.5 - exact(centres)[:, None], axis=1)  # nearest cell in the square
    np.testing.assert_allclose(field.at(centres)[seen], exact(centres)[seen], atol=1e-9)
    points = rng.uniform(-1.2, 1.2, size=(4000, 2))
    near = exact(points) < 0.3  # where a robot's clearance is judged
    assert near.sum() > 100
    error = field.at(points[near]) - exact(points[near])  # bilinear between cell centres
    assert error.min() > -0.05 and error.max() < 0.02  # at most 2 cm above the truth, up to 5 cm below


def test_the_clearance_field_sees_only_its_square():
    grid = mapped(WALL, (0.0, 0.0))  # the wall 1.95 m ahead
    assert grid.clearance_field(4, np.zeros(2), reach_m=3.0).at(np.zeros((1, 2)))[0] < 2.0
    assert grid.clearance_field(4, np.zeros(2), reach_m=1.0).at(np.zeros((1, 2)))[0] > 8.0  # none in it


def dense_update(
    grid: np.ndarray, origin, cell, position, yaw, bearings, ranges, beam, hit=3, miss=1, top=15
):
    """The map's update rule applied to every cell within reach of the longest echo (reference)."""
    if not np.isfinite(ranges).any():
        return
    n = grid.shape[0]
    reach = math.ceil(float(np.nanmax(ranges)) / cell) + 1
    centre = np.floor(np.asarray(position) / cell).astype(int) - origin
    lo, hi = np.maximum(centre - reach, 0), np.minimum(centre + reach + 1, n)
    if np.any(hi <= lo):
        return
    rel_x = (origin[0] + np.arange(lo[0], hi[0]) + 0.5) * cell - position[0]
    rel_y = (origin[1] + np.arange(lo[1], hi[1]) + 0.5) * cell - position[1]
    distance = np.hypot(rel_x[:, None], rel_y[None, :])
    bearing = np.arctan2(rel_y[None, :], rel_x[:, None]) - (yaw + bearings[0])
    spacing = 2 * math.pi / len(bearings)
    sonar = np.round(bearing / spacing).astype(int) % len(bearings)
    offset = (bearing - sonar * spacing + math.pi) % (2 * math.pi) - math.pi
    reading = ranges[sonar]
    in_cone = (np.abs(offset) <= beam / 2) & np.isfinite(reading)
    reading = np.where(in_cone, reading, -1.0)
    window = grid[lo[0] : hi[0], lo[1] : hi[1]]
    window -= miss * (in_cone & (distance < reading - cell))
    window += hit * (np.abs(distance - reading) <= 0.75 * cell)
    np.clip(window, 0, top, out=window)


@pytest.mark.parametrize(
    "count, beam_deg, cell, size, range_max, yaw_scale",
    [
        (16, 20.0, 0.1, 8.0, 3.0, math.pi),  # the defaults
        (7, 60.0, 0.05, 3.0, 2.0, math.pi),  # beams wider than the spacing: cones clipped to sectors
        (128, 1.0, 0.25, 5.0, 6.0, math.pi),
        (4, 40.0, 1.0, 12.0, 9.0, math.pi),  # cells as large as readings
        (16, 20.0, 0.1, 4.0, 3.0, 1e3),  # yaw far outside [-pi, pi]
    ],
)
def test_the_update_equals_a_pass_over_every_cell_within_reach(
    count, beam_deg, cell, size, range_max, yaw_scale
):
    rng = np.random.default_rng(count)
    bearings = np.arange(count) * (2 * math.pi / count)
    beam = math.radians(beam_deg)
    fast = LocalMap(cell_m=cell, size_m=size)
    position = np.array([3.0, -2.0])
    reference = None
    for step in range(150):
        position = position + rng.normal(0.0, 0.4 * cell, 2) if step % 40 else rng.uniform(-9, 9, 2)
        yaw = float(rng.uniform(-yaw_scale, yaw_scale))
        ranges = rng.uniform(0.1, range_max + 0.1, count)
        ranges[rng.random(count) < 0.3] = np.nan
        ranges[rng.random(count) < 0.1] = rng.uniform(0.1, 0.2)  # echoes inside the robot's own cell
        moved_from = None if fast.origin is None else fast.origin.copy()
        fast.update(position, yaw, bearings, ranges, beam)
        if reference is None or not np.array_equal(moved_from, fast.origin):
            # the grid shifted (or started): shift the reference the same way
            shifted = np.zeros_like(fast.grid)
            if reference is not None and np.max(np.abs(fast.origin - moved_from)) < fast.n:
                s = fast.origin - moved_from
                n = fast.n
                src = [slice(max(0, k), n + min(0, k)) for k in s]
                dst = [slice(max(0, -k), n + min(0, -k)) for k in s]
                shifted[dst[0], dst[1]] = reference[src[0], src[1]]
            reference = shifted
            dense_update(reference, fast.origin, cell, position, yaw, bearings, ranges, beam)
        else:
            dense_update(reference, fast.origin, cell, position, yaw, bearings, ranges, beam)
        np.testing.assert_array_equal(fast.grid, reference)
    assert fast.grid.max() > 0  # the scans did mark cells


@pytest.mark.parametrize("seed", range(4))
def test_clusters_are_the_regions_of_the_grown_obstacle_cells(seed):
    ndimage = pytest.importorskip("scipy.ndimage")
    rng = np.random.default_rng(seed)
    grid = LocalMap(cell_m=0.1, size_m=6.0)
    grid.update(np.zeros(2), 0.0, BEARINGS, np.full(16, np.nan), BEAM)  # anchor the grid
    grid.grid[...] = (rng.random(grid.grid.shape) < 0.02 * (seed + 1)) * rng.integers(1, 16, grid.grid.shape)
    link = [0.15, 0.48, 0.9, 2.0][seed]
    occupied = grid.grid >= 4
    reach = max(1, math.ceil(link / 2 / 0.1 - 1e-9))
    disk = np.hypot(*np.mgrid[-reach : reach + 1, -reach : reach + 1]) <= reach
    expected, _ = ndimage.label(ndimage.binary_dilation(occupied, structure=disk))
    cells, labels, label_grid = grid.clusters(4, link)
    assert len(cells) == occupied.sum() > 0
    np.testing.assert_array_equal(label_grid == 0, expected == 0)
    # the same regions: a one-to-one correspondence between the two labellings
    pairs = set(zip(label_grid.ravel().tolist(), expected.ravel().tolist(), strict=True))
    assert len(pairs) == len(set(label_grid.ravel().tolist())) == len(set(expected.ravel().tolist()))
    np.testing.assert_array_equal(labels, label_grid[occupied])
