"""The clutter extension `vplane_plus` on synthetic sonar scans (pure numpy), and its map search."""

import itertools
import math

import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.geometry.synthetic import BEAM, BEARINGS, scan
from vplane_mj.planning.motion import gridsearch
from vplane_mj.planning.planners.vplane_geometry import make_plane
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.scenario import parse_scenario

RADIUS = 0.11

CUP = """
format = 1
name = "cup"
[world]
size = [10.0, 10.0]
[[world.obstacles]]
kind = "u"
center = [5.0, 5.0]
width = 1.6
depth = 1.2
thickness = 0.1
{extra}
[robot]
start = [5.2, 5.0]
goal = [9.0, 5.0]
"""


def world(extra: str = ""):
    scenario = parse_scenario(CUP.format(extra=extra), "cup.toml")
    return scenario, shapes.scene_footprints(scenario.world.obstacles, scenario.world.size)


def hold(planner, footprints, position, goal, seconds, yaw=0.0, start_s=0.0, turn_rad_per_s=0.0):
    """Keep the robot in place at 20 Hz, turning at `turn_rad_per_s`; return every decision."""
    decisions = []
    for k in range(round(seconds * 20)):
        heading = yaw + turn_rad_per_s * k * 0.05
        obs = Observation(
            start_s + k * 0.05,
            np.asarray(position, float),
            heading,
            np.asarray(goal, float),
            0.15,
            BEARINGS,
            scan(footprints, position, heading),
            BEAM,
        )
        decisions.append(planner.step(obs))
    return decisions


def drive(planner, footprints, waypoints, goal):
    """Move the robot along straight legs at 0.5 m/s (20 Hz), facing its way; return the time."""
    time_s = 0.0
    for a, b in itertools.pairwise(waypoints):
        a, b = np.asarray(a, float), np.asarray(b, float)
        yaw = math.atan2(b[1] - a[1], b[0] - a[0])
        steps = max(1, round(float(np.hypot(*(b - a))) / 0.025))
        for k in range(steps):
            position = a + (b - a) * k / steps
            ranges = scan(footprints, position, yaw)
            obs = Observation(time_s, position, yaw, np.asarray(goal, float), 0.15, BEARINGS, ranges, BEAM)
            planner.step(obs)
            time_s += 0.05
    return time_s


BOX_BESIDE_MOUTH = """
[[world.obstacles]]
kind = "box"
center = [4.5, 6.325]
size = [0.2, 0.35]
"""


def test_a_plane_never_spans_a_gap_the_robot_fits_through():
    """A box 0.35 m beyond the end of the cup's upper arm, in line with the mouth: the robot
    (0.22 m) fits between them, so the plane that closes the cup must end before the box."""
    scenario, footprints = world(BOX_BESIDE_MOUTH)
    box = shapes.Footprints(scenario.world.obstacles[1].footprint())
    planner = make_planner("vplane_plus", {}, RADIUS)
    start_s = drive(planner, footprints, [(2.0, 5.0), (5.2, 5.0)], scenario.robot.goal)
    decisions = hold(planner, footprints, (5.2, 5.0), scenario.robot.goal, 8.0, start_s=start_s)
    assert any(e.kind == EventKind.ESCAPE_STARTED for d in decisions for e in d.events)
    plane = planner.pending_plane
    assert plane is not None
    span = np.linspace(plane.e1, plane.e2, 50)
    assert np.all(np.abs(span[:, 0] - 4.45) < 0.2)  # across the mouth (x = 4.4 to 4.5)
    assert span[:, 1].min() < 4.5 and span[:, 1].max() > 5.5  # from arm to arm
    assert float(box.distance(span).min()) > 2 * RADIUS  # and not on to the box


@pytest.mark.slow
def test_no_giving_up_while_the_map_shows_a_way():
    """Held still in the cup, escape after escape fails: the planner follows the map's way
    instead of giving up, and its way leaves through the mouth."""
    scenario, footprints = world()
    planner = make_planner("vplane_plus", {}, RADIUS)
    start_s = drive(planner, footprints, [(2.0, 5.0), (5.2, 5.0)], scenario.robot.goal)
    decisions = hold(planner, footprints, (5.2, 5.0), scenario.robot.goal, 60.0, start_s=start_s)
    assert not any(d.gave_up for d in decisions)
    assert planner.following and decisions[-1].mode == "following"
    assert min(point[0] for point in planner.follow_way) < 4.4 - RADIUS  # out through the mouth


@pytest.mark.slow
def test_it_gives_up_when_the_map_holds_no_way():
    closed = """
[[world.obstacles]]
kind = "box"
center = [4.35, 5.0]
size = [0.1, 1.8]
"""
    scenario, footprints = world(closed)
    planner = make_planner("vplane_plus", {"no_way_patience_s": 4.0}, RADIUS)
    # A trapped robot turns on the spot: scans from new headings are folded into the map.
    decisions = hold(planner, footprints, (5.0, 5.0), scenario.robot.goal, 40.0, turn_rad_per_s=1.0)
    assert any(d.gave_up for d in decisions)
    assert any("gave up: the map has held no way" in e.text for d in decisions for e in d.events)


def test_a_scan_is_folded_into_the_map_once():
    """A sensor slower than the control rate hands one scan to several ticks: folded again at
    the pose of a later tick it would show the cup displaced, so the map takes it once."""
    scenario, footprints = world()
    planner = make_planner("vplane_plus", {}, RADIUS)
    goal = np.asarray(scenario.robot.goal, float)

    def observation(time_s, x, ranges, scan_time_s):
        position = np.array([x, 5.0])
        return Observation(time_s, position, 0.0, goal, 0.15, BEARINGS, ranges, BEAM, scan_time_s=scan_time_s)

    first_scan = scan(footprints, (3.5, 5.0), 0.0)
    planner.step(observation(0.0, 3.5, first_scan, 0.0))
    mapped = planner.map.grid.copy()
    planner.step(observation(0.05, 3.8, first_scan, 0.0))  # the same scan, the robot 0.3 m on
    np.testing.assert_array_equal(planner.map.grid, mapped)
    planner.step(observation(0.1, 3.8, scan(footprints, (3.8, 5.0), 0.0), 0.1))  # a new scan
    assert not np.array_equal(planner.map.grid, mapped)


def test_a_plane_that_closes_the_only_way_is_retired():
    """The goal lies before the cup's mouth and the robot inside: a plane across the mouth
    closes the only way, so following the map retires it."""
    _, footprints = world()
    goal = np.array([1.0, 5.0])
    planner = make_planner("vplane_plus", {"fallback_after": 0}, RADIUS)
    start_s = drive(planner, footprints, [(2.0, 5.0), (5.2, 5.0)], goal)
    mouth = make_plane(
        np.array([4.45, 4.1]), np.array([4.45, 5.9]), np.array([[5.5, 5.0]]), np.array([3.0, 5.0]), goal
    )
    planner.planes.append(mouth)
    decisions = hold(planner, footprints, (5.2, 5.0), goal, 8.0, start_s=start_s)
    events = [e.text for d in decisions for e in d.events]
    assert "virtual plane retired: it closed the only known way to the goal" in events
    assert mouth not in planner.planes


def test_costs_block_the_disc_and_charge_for_closeness():
    occupied = np.zeros((40, 40), dtype=bool)
    occupied[20, :] = True
    doubtful = np.zeros_like(occupied)
    cost = gridsearch.step_costs(occupied, doubtful, 0.05, 0.11, 0.3, 4.0, 20.0)
    assert np.isinf(cost[18:23, 5]).all() and np.isfinite(cost[17, 5])  # 0.10 m blocked, 0.15 m not
    assert cost[17, 5] > cost[14, 5] > cost[5, 5] == 1.0
    soft = gridsearch.step_costs(doubtful, occupied, 0.05, 0.11, 0.3, 4.0, 20.0)
    assert np.isfinite(soft).all() and soft[20, 5] > 20  # doubtful: passable at a price


def _step_costs_by_numpy(sure, doubtful, cell_m, lethal_m, inflation_m, weight, doubt_cost):
    """`gridsearch.step_costs`' rule in numpy's element-wise arithmetic, on scipy's distances."""
    from scipy import ndimage

    cost = np.ones(sure.shape)
    occupied = sure | doubtful
    if not occupied.any():
        return cost
    d = ndimage.distance_transform_edt(~occupied) * cell_m
    closeness = np.clip((lethal_m + inflation_m - d) / inflation_m, 0.0, 1.0)
    cost += weight * closeness**2 + np.where(d < lethal_m, doubt_cost, 0.0)
    if sure.any():
        sure_d = d if not doubtful.any() else ndimage.distance_transform_edt(~sure) * cell_m
        cost[sure_d < lethal_m] = np.inf
    return cost


def test_the_compiled_step_costs_are_numpys_arithmetic_bit_for_bit():
    rng = np.random.default_rng(1)
    for _ in range(300):
        shape = tuple(int(k) for k in rng.integers(1, 50, 2))
        sure = rng.random(shape) < rng.choice([0.0, 0.01, 0.05, 0.2])
        doubtful = (rng.random(shape) < rng.choice([0.0, 0.01, 0.05])) & ~sure
        cell, lethal, inflation = (
            float(rng.choice([0.05, 0.1])),
            rng.choice([rng.uniform(0.05, 0.4), 0.1 * rng.integers(1, 5)]),  # and whole cells
            rng.choice([rng.uniform(0.05, 0.5), 0.1 * rng.integers(1, 5), rng.uniform(1.0, 3.0)]),
        )
        args = (
            cell,
            float(lethal),
            float(inflation),
            float(rng.uniform(0, 8)),
            float(rng.choice([0.0, 20.0])),
        )
        got = gridsearch.step_costs(sure, doubtful, *args)
        np.testing.assert_array_equal(got, _step_costs_by_numpy(sure, doubtful, *args))


def test_the_squared_distances_within_the_band_are_a_distance_transforms():
    """Within the band, the squared distance to the nearest blocked cell, as scipy's transform
    gives it; beyond, some larger value below the bound."""
    from scipy import ndimage

    from vplane_mj.kernels.maps.step_costs import near_squares, near_squares_bound

    rng = np.random.default_rng(6)
    for _ in range(200):
        shape = tuple(int(k) for k in rng.integers(1, 60, 2))
        blocked = rng.random(shape) < rng.choice([0.002, 0.01, 0.05, 0.3])
        blocked.flat[rng.integers(blocked.size)] = True
        band = int(rng.integers(1, 20))
        near = near_squares(blocked.view(np.uint8), band)
        exact = np.rint(ndimage.distance_transform_edt(~blocked) ** 2).astype(int)
        within = exact <= band * band
        np.testing.assert_array_equal(near[within], exact[within])
        assert (near[~within] > band * band).all() and (near < near_squares_bound(band)).all()


def descend(costs: np.ndarray, start: tuple[int, int], max_cells: int) -> list[tuple[int, int]]:
    """`gridsearch.descend`'s cells as a list of (i, j)."""
    return [(int(i), int(j)) for i, j in gridsearch.descend(costs, start, max_cells).tolist()]


def scipy_cost_to_go(cost: np.ndarray, targets: np.ndarray, target_costs: np.ndarray, cell_m: float):
    """`gridsearch.cost_to_go` by scipy's Dijkstra over the explicit grid graph: every move
    between free cells, a diagonal only across a free 2 x 2 square, weighted by its length times
    the mean step cost of its cells, and a source joined to each free target at its cost."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    nx, ny = cost.shape
    free, index = np.isfinite(cost), np.arange(nx * ny).reshape(nx, ny)
    rows, cols, weights = [], [], []
    every, head, tail = slice(None), slice(None, -1), slice(1, None)
    square = free[:-1, :-1] & free[:-1, 1:] & free[1:, :-1] & free[1:, 1:]
    for a, b, mask, length in (
        ((every, head), (every, tail), free[:, :-1] & free[:, 1:], cell_m),
        ((head, every), (tail, every), free[:-1, :] & free[1:, :], cell_m),
        ((head, head), (tail, tail), square, cell_m * math.sqrt(2)),
        ((head, tail), (tail, head), square, cell_m * math.sqrt(2)),
    ):
        rows.append(index[a][mask])
        cols.append(index[b][mask])
        weights.append(length * 0.5 * (cost[a][mask] + cost[b][mask]))
    keep = free.ravel()[targets]
    rows.append(np.full(keep.sum(), nx * ny))
    cols.append(targets[keep])
    weights.append(np.maximum(target_costs[keep], 1e-9))
    graph = coo_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(nx * ny + 1,) * 2
    ).tocsr()
    return dijkstra(graph, directed=False, indices=nx * ny)[:-1].reshape(nx, ny)


@pytest.mark.parametrize(
    ("seed", "least", "spread", "start_span"),
    [(seed, 1.0, 4.0, 3.0) for seed in range(6)] + [(7, 0.3, 40.0, 30.0), (9, 2.0, 400.0, 300.0)],
)
def test_the_compiled_search_equals_scipys_dijkstra_bit_for_bit(seed, least, spread, start_span):
    """Step costs from `least` to `least + spread`; targets on the edge start up to `start_span`
    (m) apart, so the bucket queue wraps round its ring and waits for targets far dearer."""
    rng = np.random.default_rng(seed)
    cost = least + spread * rng.random((37, 53)) ** 3
    cost[rng.random(cost.shape) < 0.3] = np.inf  # walls and islands, some cells cut off
    edge = np.flatnonzero(np.pad(np.zeros((35, 51), bool), 1, constant_values=True))
    targets = edge if seed % 2 else rng.choice(np.flatnonzero(np.isfinite(cost)), 1)
    starts = rng.uniform(0.0, start_span, len(targets)) if seed % 2 else np.zeros(1)
    got = gridsearch.cost_to_go(cost, targets, starts, 0.05)
    expected = scipy_cost_to_go(cost, targets, starts, 0.05)
    assert np.isfinite(got).sum() > 100 and np.isinf(got).any()
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("seed", range(4))
def test_a_search_stopped_at_the_start_gives_the_same_costs_below_it_and_the_same_way(seed):
    rng = np.random.default_rng(seed)
    cost = 1.0 + 4.0 * rng.random((41, 47)) ** 3
    cost[rng.random(cost.shape) < 0.25] = np.inf
    free = np.flatnonzero(np.isfinite(cost))
    target, start = rng.choice(free, 2, replace=False)
    full = gridsearch.cost_to_go(cost, np.array([target]), np.zeros(1), 0.05)
    start_cell = np.unravel_index(start, cost.shape)
    stopped = gridsearch.cost_to_go(cost, np.array([target]), np.zeros(1), 0.05, stop=start_cell)
    below = full < full[start_cell]
    np.testing.assert_array_equal(stopped[below], full[below])
    assert stopped[start_cell] == full[start_cell]
    assert (stopped[~below] >= full[~below]).all()
    if np.isfinite(full[start_cell]):
        assert np.isinf(stopped).sum() > np.isinf(full).sum()  # it stopped early
    assert descend(stopped, start_cell, 10_000) == descend(full, start_cell, 10_000)


def test_the_way_ahead_is_blocked_where_numpys_distances_say():
    from vplane_mj.kernels.motion import way as way_kernels

    rng = np.random.default_rng(11)
    found = 0
    for _ in range(3000):
        way = np.cumsum(rng.normal(0.0, 0.1, (int(rng.integers(0, 30)), 2)), axis=0)
        cells = rng.uniform(-1.0, 1.0, (int(rng.integers(0, 40)), 2))
        near = way[np.hypot(*way.T) <= 0.6]
        gaps = np.hypot(*(cells[:, None, :] - near[None, :, :]).transpose(2, 0, 1))
        expected = bool(gaps.size and gaps.min() < 0.2)
        assert way_kernels.blocked(0.0, 0.0, way, 0.6, cells, 0.2) == expected
        found += expected
    assert 300 < found < 2700


def test_the_search_refuses_step_costs_that_are_not_positive():
    cost = np.ones((5, 5))
    cost[2, 2] = 0.0
    with pytest.raises(ValueError, match="positive"):
        gridsearch.cost_to_go(cost, np.array([0]), np.zeros(1), 0.05)


def test_line_of_sight_checks_linspaces_points_every_half_cell():
    """The compiled check against its definition: np.linspace's points, each on a free cell or
    outside the window; segments along a row, a column, and of no length among them."""
    from vplane_mj.kernels.motion import way as way_kernels

    rng = np.random.default_rng(3)
    for trial in range(3000):
        cost = np.ones((30, 20))
        cost[rng.random(cost.shape) < 0.03] = np.inf
        window = gridsearch.Window(cost, rng.uniform(-1, 1, 2), 0.05, np.zeros(cost.shape, bool))
        a, b = rng.uniform(-1.5, 2.0, 2), rng.uniform(-1.5, 2.0, 2)
        if trial % 3 == 0:
            b[0] = a[0]
        if trial % 5 == 0:
            b[1] = a[1]
        steps = max(2, math.ceil(2 * float(np.hypot(*(b - a))) / 0.05) + 1)
        i, j = np.floor((np.linspace(a, b, steps) - window.corner) / 0.05).astype(int).T
        inside = (i >= 0) & (i < 30) & (j >= 0) & (j < 20)
        seen = way_kernels.segment_free(window.packed(), float(a[0]), float(a[1]), float(b[0]), float(b[1]))
        assert seen == bool(np.isfinite(cost[i[inside], j[inside]]).all())


def test_the_next_waypoint_is_the_farthest_in_sight_of_the_run_within_reach_past_the_nearest():
    """The compiled choice against its definition: the nearest point (the first of equally near
    ones), the run of points after it within reach, the farthest of them the robot sees in a
    straight line (the nearest when none); every one seen without a window."""
    from vplane_mj.kernels.motion import way as way_kernels
    from vplane_mj.planning.planners import vplane_plus

    rng = np.random.default_rng(11)
    for trial in range(2000):
        cost = np.ones((40, 40))
        cost[rng.random(cost.shape) < 0.05] = np.inf
        window = gridsearch.Window(cost, np.zeros(2), 0.05, np.zeros(cost.shape, bool))
        way = np.cumsum(rng.uniform(-0.3, 0.4, (int(rng.integers(1, 12)), 2)), axis=0) + 0.5
        if trial % 4 == 0:
            way = np.repeat(way, 2, axis=0)  # equally near points
        position, reach = rng.uniform(0.0, 2.0, 2), float(rng.uniform(0.2, 1.5))
        distances = np.hypot(*(way - position).T)
        nearest = int(np.argmin(distances))
        last = nearest
        while last + 1 < len(way) and distances[last + 1] <= reach:
            last += 1
        x, y = float(position[0]), float(position[1])
        sight = window.packed()
        seen = [k for k in range(last, nearest, -1) if way_kernels.segment_free(sight, x, y, *way[k])]
        farthest_seen = seen[0] if seen else nearest
        assert way_kernels.next_waypoint(x, y, way, reach, sight) == (nearest, farthest_seen)
        assert way_kernels.next_waypoint(x, y, way, reach, vplane_plus.NO_SIGHT) == (nearest, last)


def test_descent_steps_to_the_first_cheapest_neighbour_until_none_is_cheaper():
    """The compiled descent against its definition, on cost fields with ties and walls."""
    neighbours = ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))
    rng = np.random.default_rng(5)
    for _ in range(20):
        cost = np.round(rng.random((23, 31)) * 4) + 1.0  # many equal step costs
        cost[rng.random(cost.shape) < 0.2] = np.inf
        target = rng.choice(np.flatnonzero(np.isfinite(cost)), 1)
        costs = gridsearch.cost_to_go(cost, target, np.zeros(1), 0.05)
        start = tuple(int(v) for v in np.unravel_index(rng.integers(cost.size), cost.shape))
        expected, (i, j) = [start], start
        while np.isfinite(costs[i, j]):
            steps = [(i + di, j + dj) for di, dj in neighbours if 0 <= i + di < 23 and 0 <= j + dj < 31]
            best = min(steps, key=lambda cell: costs[cell])  # the first of the cheapest
            if not costs[best] < costs[i, j]:
                break
            expected.append(best)
            i, j = best
        assert descend(costs, start, 10_000) == expected
        assert descend(costs, start, 2) == expected[:3]


def test_a_way_exists_exactly_when_the_search_finds_one():
    """The flood fill against the search, ends inside the window and beyond it, walls that cut
    the window in two and diagonal gaps no way may slip through."""
    rng = np.random.default_rng(11)
    found = {True: 0, False: 0}
    for trial in range(300):
        cost = 1.0 + rng.random((30, 40))
        cost[rng.random(cost.shape) < rng.uniform(0.1, 0.5)] = np.inf
        if trial % 3 == 0:
            cost[:, 20] = np.inf  # a wall across the window
            cost[rng.integers(30), 20] = 1.0 if trial % 2 else np.inf
        start, end = rng.uniform(0.0, 1.5, 2), rng.uniform(-0.5, 2.5, 2)
        unseen = np.zeros(cost.shape, bool)
        windows = [gridsearch.Window(cost.copy(), np.zeros(2), 0.05, unseen) for _ in range(2)]
        exists = gridsearch.way_exists(windows[0], start, end, 0.1)
        assert exists == (gridsearch.way_to(windows[1], start, end, 0.1) is not None)
        found[exists] += 1
    assert min(found.values()) > 30  # both answers, many times


def test_the_way_goes_round_a_wall_through_its_gap():
    cost = np.ones((60, 60))
    cost[30, :] = np.inf
    cost[30, 45:50] = 1.0  # a gap at j = 45..49
    target = np.array([np.ravel_multi_index((50, 10), cost.shape)])
    costs = gridsearch.cost_to_go(cost, target, np.zeros(1), 0.05)
    way = descend(costs, (10, 10), 10_000)
    assert way[-1] == (50, 10)
    crossing = [j for i, j in way if i == 30]
    assert crossing and all(45 <= j <= 49 for j in crossing)
    assert costs[10, 10] == pytest.approx(0.05 * (2 * math.hypot(20, 35)), rel=0.1)
