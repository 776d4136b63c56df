"""The certainty grid from range scans: beam arcs, free-cone carving, any sensor layout (sonar
rings and arrays, lasers), clusters and extreme points."""

import hashlib
import math
import tracemalloc

import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import BEAM, BEARINGS, LAYOUTS, scan
from vplane_mj.kernels.maps import map_update
from vplane_mj.kernels.maps.map_update import nearest_by_search, nearest_in_ring
from vplane_mj.planning.perception import beams
from vplane_mj.planning.perception.localmap import LocalMap, angular_extremes

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
    if seed % 2:  # obstacles in one part of the grid only, as around a robot that has seen little
        kept = grid.grid[12:30, 20:41].copy()
        grid.grid[...] = 0
        grid.grid[12:30, 20:41] = kept
    link = [0.15, 0.48, 0.9, 2.0][seed]
    occupied = grid.grid >= 4
    reach = max(1, math.ceil(link / 2 / 0.1 - 1e-9))
    disk = np.hypot(*np.mgrid[-reach : reach + 1, -reach : reach + 1]) <= reach
    expected, _ = ndimage.label(ndimage.binary_dilation(occupied, structure=disk))
    cells, labels, label_grid = grid.clusters(4, link)
    assert len(cells) == occupied.sum() > 0
    np.testing.assert_array_equal(label_grid, expected)  # the same regions, numbered alike
    np.testing.assert_array_equal(labels, label_grid[occupied])


# -- any scan: sonar rings and arrays, lasers ---------------------------------------------------

RING_WORLD = shapes.Footprints(
    [
        *shapes.Wall((-3.0, -2.5), (5.0, -2.5), 0.1).footprint(),
        *shapes.Wall((-3.0, 2.5), (5.0, 2.5), 0.1).footprint(),
        *shapes.Box((1.5, 0.6), (0.4, 0.8)).footprint(),
        *shapes.Box((3.2, -1.0), (0.3, 0.3), 0.4).footprint(),
    ]
)
RING_MAPS = {
    "vplane_plus": {
        "cell_m": 0.05,
        "size_m": 16.0,
        "hit": 1,
        "miss": 2,
        "hit_range_m": 1.5,
        "track_seen": True,
        "silent_free_m": 1.0,
    },
    "vplane": {"cell_m": 0.1, "size_m": 8.0},
    "small": {"cell_m": 0.1, "size_m": 3.0},  # shifts often
}
RING_DIGESTS = {
    "vplane_plus": "b40a103448aa34bcc556789d76ac9bf5ced5a04179a2ffa7fbc617fc6d161092",
    "vplane": "7f0df0c60cf1dfe25344bf13624f3446cf76f4645712a5b9e0fab8ff240c4c10",
    "small": "07fb678b39e0b5c51819358e630015106a4381cf5ef5ecfcdb9604414b01c757",
}
"""Digests of `ring_sequence`, recorded from the map as it was before it took any scan but the
evenly spaced 16-sonar ring's."""


def ring_sequence(options: dict) -> str:
    """The digest of the grid, the seen mask and the origin after each of 120 ring scans of a
    room, the robot driving and turning through it (some readings lost, some sweeps)."""
    grid = LocalMap(**options)
    rng = np.random.default_rng(7)
    digest = hashlib.sha256()
    for step in range(120):
        t = step / 119
        position = np.array([-2.0 + 6.0 * t, 1.2 * math.sin(3 * t)])
        yaw = 2.5 * math.sin(5 * t)
        ranges = scan(RING_WORLD, position, yaw)
        ranges[rng.random(16) < 0.15] = np.nan
        grid.update(position, yaw, BEARINGS, ranges, BEAM)
        if step % 3 == 0:
            grid.sweep(position, 0.2)
        for layer in (grid.grid, grid.seen, np.asarray(grid.origin)):
            digest.update(layer.tobytes())
    return digest.hexdigest()


@pytest.mark.parametrize("nearest", ["ring arithmetic", "search"])
@pytest.mark.parametrize("name", RING_MAPS)
def test_the_ring_gives_the_grid_it_gave_before_any_other_scan_was_possible(name, nearest, monkeypatch):
    if nearest == "search":  # no ring is even enough for the arithmetic: every cell's beam is searched
        monkeypatch.setattr(beams, "RING_TOLERANCE_RAD", -1.0)
    assert ring_sequence(RING_MAPS[name]) == RING_DIGESTS[name]


@pytest.mark.parametrize("yaw", [0.3, -2.9, 40.0])
@pytest.mark.parametrize("count", [1, 3, 16, 360])
def test_the_ring_arithmetic_and_the_search_give_every_angle_the_same_beam(count, yaw):
    rng = np.random.default_rng(count)
    bearings = rng.uniform(-math.pi, math.pi) + np.arange(count) * (2 * math.pi / count)
    fan = beams.BeamFan(rng.permutation(bearings), math.radians(360.0 / count))
    assert fan.spacing is not None
    axis = yaw + fan.directions[0]
    # As the map asks: a cell centre's world angle (atan2, in [-pi, pi]) less the first axis.
    on_axes = np.repeat(fan.relative, 3) + np.tile([-1e-7, 0.0, 1e-7], count)
    near_bounds = np.repeat(fan.bounds, 2) + np.tile([-1e-9, 1e-9], count)  # either side of a tie
    world = np.concatenate(
        [rng.uniform(-math.pi, math.pi, 50_000), wrapped(np.r_[on_axes, near_bounds] + axis)]
    )
    ring = [nearest_in_ring(angle, axis, fan.spacing, fan.count) for angle in world - axis]
    search = [nearest_by_search(angle, fan.bounds, fan.directions) for angle in world - axis]
    (ring_beam, ring_offset), (search_beam, search_offset) = (np.array(pairs).T for pairs in (ring, search))
    np.testing.assert_array_equal(ring_beam, search_beam)
    np.testing.assert_allclose(ring_offset, search_offset, rtol=0, atol=1e-9)
    assert np.abs(ring_offset).max() <= math.pi / count + 1e-9  # the nearest: at most half the spacing


@pytest.mark.parametrize("name", ["jackal_laser", "turtlebot_laser"])
def test_cells_found_by_the_sides_of_the_bounds_are_those_the_angles_give(name, monkeypatch):
    """A dense fan's cells are given their beam by the side of the bounds they lie on; cells on
    or a hair's breadth off a bound (yaws chosen to put a cell centre there) by the angles: the
    grid is the one the angles alone make."""
    bearings, beam, range_max = SCANS[name]
    assert beams.BeamFan(bearings, beam).quick.sum() > len(bearings) // 2

    def fold() -> tuple[np.ndarray, np.ndarray]:
        fan = beams.BeamFan(bearings, beam)
        rng = np.random.default_rng(7)
        local = LocalMap(cell_m=0.05, size_m=6.0, **RULES["vplane_plus"])
        position = np.array([0.3, -0.2])
        for _ in range(40):
            position = position + rng.normal(0.0, 0.05, 2)
            centre = (np.floor(position / 0.05) + rng.integers(-20, 21, 2) + 0.5) * 0.05
            bound = fan.directions[0] + fan.bounds[rng.integers(fan.count)]
            hair = rng.choice([0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-8])
            yaw = math.atan2(*(centre - position)[::-1]) - bound + hair  # the centre on that bound
            ranges = rng.uniform(0.1, range_max, len(bearings))
            ranges[rng.random(len(bearings)) < 0.2] = np.nan
            local.update(position, yaw, bearings, ranges, beam)
        return local.grid.copy(), local.seen.copy()

    sided = fold()
    monkeypatch.setattr(beams, "QUICK_GAP_RAD", -1.0)  # no direction quick: the angles decide all
    for got, want in zip(sided, fold(), strict=True):
        np.testing.assert_array_equal(got, want)
    assert sided[0].any() and sided[1].any()


def test_the_remainder_of_a_turn_is_pythons_modulo_bit_for_bit():
    turn = 2 * math.pi
    rng = np.random.default_rng(11)
    edges = [a + d for a in (-2 * turn, -turn, 0.0, turn, 2 * turn) for d in (-1e-15, -0.0, 0.0, 1e-15)]
    angles = [*rng.uniform(-3 * turn, 3 * turn, 20_000), *edges, -5e-324, 1e300, -1e300]
    got = np.array([map_update.remainder_of_turn(angle) for angle in angles])
    want = np.array([angle % turn for angle in angles])
    assert np.array_equal(got.view(np.int64), want.view(np.int64))  # the same bits, signed zeros too


def shifted(layer: np.ndarray, old: np.ndarray | None, new: np.ndarray) -> np.ndarray:
    """`layer` (the grid's, at origin `old`; None: not placed yet) moved to origin `new`; what
    falls off is zero."""
    out = np.zeros_like(layer)
    if old is None:
        return out
    n, s = layer.shape[0], new - old
    if np.max(np.abs(s)) < n:
        src = [slice(max(0, k), n + min(0, k)) for k in s]
        dst = [slice(max(0, -k), n + min(0, -k)) for k in s]
        out[dst[0], dst[1]] = layer[src[0], src[1]]
    return out


def wrapped(angle):
    """Angles (rad) wrapped to [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def beam_of_each_cell(centres, position, yaw, bearings, ranges, beam):
    """The map's rule written out plainly, for every cell centre (..., 2): the nearest of the
    scan's distinct bearings (the shortest echo of the beams that share one), whether the centre
    lies within half a beam of it, and that direction's range (NaN: no echo)."""
    directions = np.unique(np.mod(bearings, 2 * math.pi))
    readings = np.full(len(directions), np.nan)
    for k, direction in enumerate(directions):
        echoes = ranges[(np.mod(bearings, 2 * math.pi) == direction) & np.isfinite(ranges)]
        if len(echoes):
            readings[k] = echoes.min()
    rel = centres - position
    gaps = wrapped(np.arctan2(rel[..., 1], rel[..., 0])[..., None] - yaw - directions)
    nearest = np.argmin(np.abs(gaps), axis=-1)
    offset = np.take_along_axis(gaps, nearest[..., None], axis=-1)[..., 0]
    return np.abs(offset) <= beam / 2, readings[nearest], np.hypot(rel[..., 0], rel[..., 1])


def reference_update(grid, seen, origin, cell, position, yaw, bearings, ranges, beam, rule):
    """The grid and seen mask after one scan, the rule applied to every cell of the grid."""
    n = grid.shape[0]
    centres = (np.asarray(origin) + np.stack(np.indices((n, n)), axis=-1) + 0.5) * cell
    in_cone, reading, distance = beam_of_each_cell(centres, position, yaw, bearings, ranges, beam)
    echo = in_cone & np.isfinite(reading)
    marks = (reading <= rule.get("hit_range_m", math.inf)) | (reading <= cell / beam)
    arc = echo & marks & (np.abs(distance - reading) <= 0.75 * cell)
    free = echo & (distance < reading - cell)
    hit, miss = rule.get("hit", 3), rule.get("miss", 1)
    grid = np.clip(grid + hit * arc - miss * free, 0, rule.get("max_certainty", 15)).astype(grid.dtype)
    if rule.get("track_seen"):
        seen = seen | free | (in_cone & np.isnan(reading) & (distance < rule.get("silent_free_m", 0.0)))
    return grid, seen


def uneven_partial_layout(rng):
    """Bearings over 200 degrees, in no order, uneven, some shared; beams wider than some gaps."""
    bearings = np.radians(rng.uniform(-100.0, 100.0, 23))
    return np.concatenate([bearings, bearings[:4]]), math.radians(12.0), 4.0


SCANS = {
    **{name: (layout.bearings, layout.beam, layout.range_max) for name, layout in LAYOUTS.items()},
    "uneven_partial": uneven_partial_layout(np.random.default_rng(5)),
    "one_wide_beam": (np.array([0.7]), math.radians(300.0), 3.0),
}
RULES = {
    "default": {},
    "vplane_plus": {"hit": 1, "miss": 2, "hit_range_m": 1.5, "track_seen": True, "silent_free_m": 1.0},
}


@pytest.mark.parametrize("rule", RULES)
@pytest.mark.parametrize("name", SCANS)
def test_any_scan_updates_the_grid_as_the_rule_says_cell_by_cell(name, rule):
    bearings, beam, range_max = SCANS[name]
    options = RULES[rule]
    rng = np.random.default_rng(len(bearings))
    fast = LocalMap(cell_m=0.1, size_m=5.0, **options)
    position = np.array([1.0, -2.0])
    for step in range(30 if len(bearings) < 100 else 12):
        position = position + rng.normal(0.0, 0.3, 2) if step % 8 else rng.uniform(-9, 9, 2)
        yaw = float(rng.uniform(-math.pi, math.pi)) * (1 if step % 5 else 300)  # now and then far out
        ranges = rng.uniform(0.05, range_max, len(bearings))
        ranges[rng.random(len(bearings)) < 0.25] = np.nan
        ranges[rng.random(len(bearings)) < 0.03] = 30.0  # far beyond the grid
        old_origin = None if fast.origin is None else fast.origin.copy()
        grid, seen = fast.grid.copy(), fast.seen.copy()
        fast.update(position, yaw, bearings, ranges, beam)
        expected = reference_update(
            shifted(grid, old_origin, fast.origin),
            shifted(seen, old_origin, fast.origin),
            fast.origin,
            0.1,
            position,
            yaw,
            bearings,
            ranges,
            beam,
            options,
        )
        np.testing.assert_array_equal(fast.grid, expected[0])
        np.testing.assert_array_equal(fast.seen, expected[1])
    assert fast.grid.max() > 0  # the scans did mark cells


POSTS = ((1.6, 1.0), (0.2, -1.25), (-0.9, 0.25))
"""Post centres (m): ahead and to the left, to the right, and behind the robot."""
POST_RADIUS = 0.075
WALL_ENDS = ((2.3, -1.0), (2.3, 0.9))
"""A thin wall across the way ahead (m)."""
ROBOT, HEADING = np.array([0.1, 0.05]), 0.15


def exact_ranges(position, yaw, bearings, beam, range_max, rays):
    """Each beam's reading (m from `position`): the shortest over `rays` rays spread across the
    beam of the distance to the posts' circles and the wall's segment; NaN beyond `range_max`.
    Also which obstacle (index into POSTS, or len(POSTS) for the wall) each reading comes from."""
    offsets = np.linspace(-0.4 * beam, 0.4 * beam, rays) if rays > 1 else np.zeros(1)
    angles = yaw + np.asarray(bearings)[:, None] + offsets[None, :]
    dx, dy = np.cos(angles), np.sin(angles)
    found = np.full((*angles.shape, len(POSTS) + 1), np.inf)
    for k, centre in enumerate(POSTS):
        cx, cy = centre[0] - position[0], centre[1] - position[1]
        along = cx * dx + cy * dy
        across2 = cx * cx + cy * cy - along * along
        entry = along - np.sqrt(np.maximum(POST_RADIUS**2 - across2, 0.0))
        found[..., k] = np.where((across2 <= POST_RADIUS**2) & (entry > 0), entry, np.inf)
    (ax, ay), (bx, by) = WALL_ENDS
    ex, ey = bx - ax, by - ay
    qx, qy = ax - position[0], ay - position[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        denominator = dx * ey - dy * ex
        t = (qx * ey - qy * ex) / denominator  # along the ray
        s = (qx * dy - qy * dx) / denominator  # along the wall
    found[..., -1] = np.where((t > 0) & (s >= 0) & (s <= 1), t, np.inf)
    nearest = found.min(axis=-1)
    ray = np.argmin(nearest, axis=1)
    reading = nearest[np.arange(len(ray)), ray]
    source = np.argmin(found[np.arange(len(ray)), ray], axis=-1)
    return np.where(reading <= range_max, reading, np.nan), np.where(reading <= range_max, source, -1)


def length(vectors):
    """Lengths of vectors (..., 2)."""
    return np.hypot(vectors[..., 0], vectors[..., 1])


def outline_distance(points):
    """Distance (m) from points (..., 2) to the nearest obstacle's outline (posts and wall)."""
    best = np.full(points.shape[:-1], np.inf)
    for centre in POSTS:
        best = np.minimum(best, np.abs(length(points - centre) - POST_RADIUS))
    a, b = np.array(WALL_ENDS[0]), np.array(WALL_ENDS[1])
    t = np.clip(((points - a) @ (b - a)) / ((b - a) @ (b - a)), 0.0, 1.0)
    return np.minimum(best, length(points - (a + t[..., None] * (b - a))))


def test_the_synthetic_scan_sees_posts_and_walls_where_they_are():
    layout = LAYOUTS["jackal_laser"]
    pieces = [shapes.Disc(centre, POST_RADIUS) for centre in POSTS]
    pieces += shapes.Wall(WALL_ENDS[0], WALL_ENDS[1], 1e-9).footprint()
    cast = layout.scan(shapes.Footprints(pieces), ROBOT, HEADING)
    exact, source = exact_ranges(ROBOT, HEADING, layout.bearings, layout.beam, layout.range_max, 1)
    np.testing.assert_allclose(cast, exact, rtol=0, atol=1e-8)
    assert set(source.tolist()) == {-1, 0, 1, 3}  # two posts and the wall seen; one post behind


@pytest.mark.parametrize("name", LAYOUTS)
def test_a_scan_of_known_obstacles_marks_them_clears_the_way_and_leaves_unseen_cells(name):
    layout = LAYOUTS[name]
    rays = 5 if len(layout.bearings) < 100 else 1  # a sonar's echo: the nearest anywhere in its beam
    ranges, source = exact_ranges(ROBOT, HEADING, layout.bearings, layout.beam, layout.range_max, rays)
    cell = 0.05
    grid = LocalMap(cell_m=cell, size_m=8.0, track_seen=True)
    grid.update(ROBOT, HEADING, layout.bearings, np.full(len(ranges), np.nan), layout.beam)  # places it
    centres = (grid.origin + np.stack(np.indices(grid.grid.shape), axis=-1) + 0.5) * cell
    in_cone, reading, distance = beam_of_each_cell(
        centres, ROBOT, HEADING, layout.bearings, ranges, layout.beam
    )
    stale = (distance > 0.7) & (distance <= 0.8)  # a ring of old marks nearer than every obstacle
    grid.grid[stale] = 5
    for _ in range(6):
        grid.update(ROBOT, HEADING, layout.bearings, ranges, layout.beam)

    in_front = in_cone & (distance < reading - cell)
    assert (stale & in_front).sum() > 20
    assert not grid.grid[stale & in_front].any()  # the way to each echo is cleared
    assert np.all(grid.grid[stale & ~in_cone] == 5)  # between the beams and out of view: untouched
    assert not grid.seen[~in_cone].any()
    assert grid.seen[in_front].all()
    for obstacle in np.unique(source[source >= 0]):  # each obstacle an echo came from is on the map
        if obstacle < len(POSTS):
            near = np.abs(length(centres - POSTS[obstacle]) - POST_RADIUS) <= cell
        else:
            near = outline_distance(centres) <= cell
        assert grid.grid[near].max() >= 4, obstacle
    # What the scans marked lies on the obstacles, give or take the arc's band, a cell's half
    # diagonal and, for a wide beam, how far the arc reaches beside the obstacle.
    marked = (grid.grid > 0) & ~stale
    beside = np.nanmax(ranges) * math.sin(layout.beam / 2) if rays > 1 else 0.0
    assert outline_distance(centres[marked]).max() <= (0.75 + math.sqrt(0.5)) * cell + beside
    if name == "jackal_laser":  # the post behind the robot is out of the laser's view
        assert 2 not in source
        behind = length(centres - POSTS[2]) < 0.5
        assert not grid.grid[behind & ~stale].any() and not grid.seen[behind].any()
    if name == "pioneer_sonars":  # 15 degree beams 20 degrees apart leave gaps, ahead too
        rel = centres - ROBOT
        ahead = np.abs(wrapped(np.arctan2(rel[..., 1], rel[..., 0]) - HEADING)) < 1.0
        assert (stale & ~in_cone & ahead).any()


@pytest.mark.parametrize("name", ["jackal_laser", "sonar_ring"])
def test_a_return_far_beyond_the_grid_clears_its_cone_to_the_edge_and_allocates_little(name):
    layout = LAYOUTS[name]
    warm_up = LocalMap(cell_m=0.1, size_m=8.0)  # numba's kernel loads outside the measurement
    warm_up.update(ROBOT, 0.0, layout.bearings, np.full(len(layout.bearings), 30.0), layout.beam)
    grid = LocalMap(cell_m=0.1, size_m=8.0)
    grid.update(ROBOT, HEADING, layout.bearings, np.full(len(layout.bearings), np.nan), layout.beam)
    grid.grid[...] = 5
    ranges = np.full(len(layout.bearings), np.nan)
    ranges[: len(ranges) // 2] = 30.0  # half the beams echo from 30 m away, the rest hear nothing
    ranges[1] = 1e300
    tracemalloc.start()
    grid.update(ROBOT, HEADING, layout.bearings, ranges, layout.beam)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    # The map as it was before it took any scan but the ring's padded its grid for a cone table
    # out to 30 m: 11 MB for the ring here, 21 MB for the laser.
    assert peak < 1_000_000
    centres = (grid.origin + np.stack(np.indices(grid.grid.shape), axis=-1) + 0.5) * 0.1
    in_cone, reading, _ = beam_of_each_cell(centres, ROBOT, HEADING, layout.bearings, ranges, layout.beam)
    cleared = in_cone & np.isfinite(reading)
    edge = np.zeros_like(cleared)
    edge[[0, -1], :] = edge[:, [0, -1]] = True
    assert (cleared & edge).sum() >= 3  # cleared out to the edge
    np.testing.assert_array_equal(grid.grid, np.where(cleared, 4, 5))  # one miss each; no hit


def test_beams_that_share_a_bearing_act_as_one_with_the_shortest_echo():
    layout = LAYOUTS["pioneer_sonars"]
    ranges, _ = exact_ranges(ROBOT, HEADING, layout.bearings, layout.beam, layout.range_max, 5)
    ranges[[0, 15]] = (1.2, 0.9)  # the front and the rear sonar looking along +90 degrees
    ranges[[7, 8]] = (np.nan, 1.4)  # and the two along -90: one hears nothing
    merged = [k for k in range(16) if k not in (0, 8)]  # one beam per bearing, its shortest echo
    merged_ranges = ranges.copy()
    merged_ranges[7] = 1.4
    grids = []
    for bearings, readings in ((layout.bearings, ranges), (layout.bearings[merged], merged_ranges[merged])):
        grid = LocalMap(cell_m=0.05, size_m=6.0, track_seen=True, silent_free_m=0.5)
        for _ in range(3):
            grid.update(ROBOT, HEADING, bearings, readings, layout.beam)
        grids.append((grid.grid, grid.seen))
    np.testing.assert_array_equal(grids[0][0], grids[1][0])
    np.testing.assert_array_equal(grids[0][1], grids[1][1])
    assert grids[0][0].max() > 0


def test_the_order_of_the_beams_does_not_matter():
    layout = LAYOUTS["jackal_laser"]
    ranges, _ = exact_ranges(ROBOT, HEADING, layout.bearings, layout.beam, layout.range_max, 1)
    order = np.random.default_rng(3).permutation(len(ranges))
    grids = []
    for bearings, readings in ((layout.bearings, ranges), (layout.bearings[order], ranges[order])):
        grid = LocalMap(cell_m=0.05, size_m=6.0)
        grid.update(ROBOT, HEADING, bearings, readings, layout.beam)
        grids.append(grid.grid)
    np.testing.assert_array_equal(*grids)


def test_an_arc_no_wider_than_a_cell_marks_beyond_the_hit_range():
    # A wall 3 m ahead, 0.6 m wide: a laser's 0.375 degree arc there is 2 cm wide and places
    # its echo; a 20 degree sonar arc is a metre wide, and past the hit range it only clears.
    marked = {}
    for name in ("jackal_laser", "sonar_ring"):
        layout = LAYOUTS[name]
        rays = np.linspace(-0.4, 0.4, 5) if name == "sonar_ring" else np.zeros(1)
        angles = layout.bearings[None, :] + rays[:, None] * layout.beam  # the robot facing +x
        across = 3.0 * np.tan(angles)
        hits = np.where((np.cos(angles) > 0) & (np.abs(across) <= 0.3), 3.0 / np.cos(angles), np.inf)
        ranges = np.where(np.isfinite(hits.min(axis=0)), hits.min(axis=0), np.nan)
        grid = LocalMap(cell_m=0.05, size_m=8.0, hit_range_m=1.5)
        grid.update(np.array([0.01, 0.02]), 0.0, layout.bearings, ranges, layout.beam)
        marked[name] = grid.cells(1)[0]
    assert len(marked["sonar_ring"]) == 0
    assert len(marked["jackal_laser"]) >= 8  # the wall's 12 cells, but for its ends
    assert np.all(np.abs(marked["jackal_laser"][:, 0] - 3.0) <= 0.05)
    assert np.all(np.abs(marked["jackal_laser"][:, 1]) <= 0.3 + 0.05)


@pytest.mark.parametrize("seed", range(4))
def test_the_compiled_distance_transform_equals_scipys_bit_for_bit(seed):
    from scipy import ndimage

    from vplane_mj.kernels.maps.edt import distance_transform

    rng = np.random.default_rng(seed)
    for density in (0.002, 0.05, 0.5, 0.95):
        shape = tuple(rng.integers(1, 70, 2))
        free = rng.random(shape) >= density
        free.flat[rng.integers(free.size)] = False  # at least one cell to be near
        np.testing.assert_array_equal(distance_transform(free), ndimage.distance_transform_edt(free))
    assert np.isinf(distance_transform(np.ones((3, 4), bool))).all()  # nothing to be near


def test_mask_cells_are_numpys_nonzero():
    from vplane_mj.planning.perception.localmap import mask_cells

    rng = np.random.default_rng(0)
    for shape in ((1, 1), (3, 5), (64, 64), (7, 1)):
        mask = rng.random(shape) < 0.1
        for got, expected in zip(mask_cells(mask), np.nonzero(mask), strict=True):
            np.testing.assert_array_equal(got, expected)
            assert got.dtype == expected.dtype


def test_the_whole_grids_cells_are_the_squares_with_no_bound():
    """`cells` of the whole grid (numpy) and of an unbounded square around a point (compiled)
    give the same centres and certainties in the same order, swept cells skipped or not."""
    grid = mapped(WALL, (0.0, 0.0))
    grid.sweep(np.array([1.9, 0.0]), 0.2)  # sweep some of the wall's cells
    for skip in (False, True):
        whole = grid.cells(4, skip_swept=skip)
        square = grid.cells(4, near=np.zeros(2), within_m=math.inf, skip_swept=skip)
        assert len(whole[0]) > 5
        for got, expected in zip(whole, square, strict=True):
            np.testing.assert_array_equal(got, expected)
            assert got.dtype == expected.dtype
    assert len(grid.cells(4, skip_swept=True)[0]) < len(grid.cells(4)[0])


def test_the_nearest_cell_is_the_first_nearest_of_the_cells_near_a_point():
    rng = np.random.default_rng(4)
    grid = LocalMap(cell_m=0.1, size_m=6.0)
    grid.update(np.zeros(2), 0.0, BEARINGS, np.full(16, np.nan), BEAM)  # anchor the grid
    grid.grid[...] = (rng.random(grid.grid.shape) < 0.03) * rng.integers(1, 16, grid.grid.shape)
    grid.sweep(np.array([0.5, 0.0]), 0.4)
    for _ in range(200):
        point = np.round(rng.uniform(-3.5, 3.5, 2), 2)  # on cell edges and centres too: ties
        within, skip = float(rng.uniform(0.05, 1.0)), bool(rng.integers(2))
        cells, _ = grid.cells(4, near=point, within_m=within, skip_swept=skip)
        nearest = grid.nearest_cell(4, point, within, skip_swept=skip)
        if not len(cells):
            assert nearest is None
        else:
            np.testing.assert_array_equal(nearest, cells[np.argmin(np.hypot(*(cells - point).T))])


def test_the_map_forgets_the_cells_under_a_moving_track_and_keeps_the_rest():
    from vplane_mj.planning.perception.tracker import Track

    grid = mapped(WALL, (0.0, 0.0))
    before = {tuple(c) for c in grid.cells(min_certainty=1)[0].round(3)}
    assert before

    def track(moving: bool) -> Track:
        return Track(
            track_id=1,
            position=np.array([2.0, 0.5]),
            velocity=np.array([0.0, 1.0]),
            radius_m=0.2,
            position_std_m=0.01,
            velocity_std_mps=0.01,
            first_seen_s=0.0,
            last_seen_s=0.0,
            moving=moving,
            stamp_s=0.0,
        )

    grid.forget((track(False),), 0.0)
    assert {tuple(c) for c in grid.cells(min_certainty=1)[0].round(3)} == before  # a fixed track stays
    grid.forget((track(True),), 0.5, margin_m=0.1)  # predicted at (2.0, 1.0), cleared 0.3 m round it
    after = grid.cells(min_certainty=1)[0]
    assert np.all(np.hypot(after[:, 0] - 2.0, after[:, 1] - 1.0) > 0.3)
    kept = [c for c in before if math.hypot(c[0] - 2.0, c[1] - 1.0) > 0.3 + 1e-9]
    assert {tuple(c) for c in after.round(3)} == set(kept) and len(kept) < len(before)
