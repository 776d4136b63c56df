"""The moving-obstacle tracker (`planning.perception.tracker`): accuracy on discs moving past a
robot's 270 degree laser, identities through a crossing, no motion in a static world, coasting
out of view, the beams of moving tracks, odd scans, and its kernels against plain references."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import least_squares, linear_sum_assignment

from vplane_mj.geometry.shapes import Disc, Rect
from vplane_mj.kernels import tracking
from vplane_mj.planning.perception.tracker import Track, Tracker, TrackerParams, tracks_of
from vplane_mj.sim.laser import RayCaster, laser_bearings

BEARINGS, STEP = laser_bearings(270.0, 720)
"""The Jackal's laser: 720 beams over 270 degrees."""
RATE_HZ = 20.0
NOISE_M = 0.01
RANGE_MAX_M = 30.0
RADIUS_M = 0.5
"""DynaBARN's obstacles: discs of 0.5 m radius."""


def cast(pieces, pose, rng=None):
    """Ranges (m; NaN: none) of a 720-beam 270 degree laser at pose (x, y, yaw), with 0.01 m of
    noise drawn from `rng` (none without)."""
    x, y, yaw = pose
    ranges = RayCaster(pieces).cast((x, y), yaw + BEARINGS[0], STEP, BEARINGS.size, RANGE_MAX_M)
    if rng is not None:
        ranges = ranges + rng.normal(0.0, NOISE_M, ranges.size)
    ranges[~((ranges >= 0.1) & (ranges <= RANGE_MAX_M))] = np.nan
    return ranges


def simulate(movers, robot, duration_s, static=(), seed=0):
    """Scans at 20 Hz of discs moving along `movers` (t -> centre) among `static` pieces, from a
    robot at `robot(t)` = (x, y, yaw); each tick: time, robot pose, true centres, tracks, the
    tracker's moving beams, and the beams that hit each mover."""
    rng = np.random.default_rng(seed)
    tracker = Tracker()
    ticks = []
    for k in range(round(duration_s * RATE_HZ) + 1):
        t = k / RATE_HZ
        pose = robot(t)
        centres = [np.array(mover(t)) for mover in movers]
        discs = [Disc(tuple(c), RADIUS_M) for c in centres]
        ranges = cast(list(static) + discs, pose, rng)
        tracks = tracker.update(t, np.array(pose[:2]), pose[2], BEARINGS, ranges)
        own = [np.abs(cast([disc], pose) - ranges) < 0.05 for disc in discs]  # the disc is the nearest
        ticks.append((t, pose, centres, tracks, tracker.moving_beams.copy(), own))
    return tracker, ticks


def nearest(tracks, centre):
    """The track nearest `centre`, or None."""
    return min(tracks, key=lambda track: np.linalg.norm(track.position - centre), default=None)


def errors_after_sight(ticks, velocity, sight_s=0.5):
    """Per tick from `sight_s` after the first track appeared: the position (m) and velocity (m/s)
    errors of the track nearest the first mover."""
    first = next(track.first_seen_s for _, _, _, tracks, _, _ in ticks for track in tracks)
    out = []
    for t, _, centres, tracks, _, _ in ticks:
        if t >= first + sight_s:
            track = nearest(tracks, centres[0])
            out.append(
                (np.linalg.norm(track.position - centres[0]), np.linalg.norm(track.velocity - velocity(t)))
            )
    return np.array(out)


def at_origin(t):
    """A robot standing at the origin, heading along +x."""
    return (0.0, 0.0, 0.0)


def test_a_disc_on_a_line_is_tracked_within_0_1_m_and_0_15_m_per_s_after_half_a_second():
    _, ticks = simulate([lambda t: (-1.0 + 1.5 * t, 3.0)], at_origin, 5.0)
    errors = errors_after_sight(ticks, lambda t: np.array((1.5, 0.0)))
    assert len(errors) > 80
    assert errors[:, 0].max() < 0.1
    assert errors[:, 1].max() < 0.15
    assert all(track.moving for _, _, _, tracks, _, _ in ticks[-60:] for track in tracks)


def test_a_disc_on_a_circle_is_tracked_within_the_same_bounds_in_median():
    omega = 1.2 / 4.0

    def mover(t):
        return (6.0 + 4.0 * math.cos(omega * t), 4.0 * math.sin(omega * t))

    _, ticks = simulate([mover], at_origin, 10.0)
    errors = errors_after_sight(ticks, lambda t: 1.2 * np.array((-math.sin(omega * t), math.cos(omega * t))))
    assert np.median(errors[:, 0]) < 0.1
    assert np.median(errors[:, 1]) < 0.15
    assert errors[:, 0].max() < 0.1  # the lag of a constant-velocity model on a 0.36 m/s^2 turn is small


def test_two_discs_crossing_paths_keep_their_identities():
    # A along y = 4 to +x, B along x = 4 to -y, B a second behind A at the crossing (1.06 m apart
    # at their closest); from the origin A hides B for 0.7 s, and B's track coasts through it.
    movers = [lambda t: (1.5 * t, 4.0), lambda t: (4.0, 9.5 - 1.5 * t)]
    _, ticks = simulate(movers, at_origin, 5.0)
    owners = [set(), set()]
    for t, _, centres, tracks, _, _ in ticks:
        for owner, centre in zip(owners, centres, strict=True):
            track = nearest(tracks, centre)
            if t > 1.0 and track is not None and np.linalg.norm(track.position - centre) < 0.3:
                owner.add(track.track_id)
    assert len(owners[0]) == len(owners[1]) == 1
    assert owners[0] != owners[1]


def test_two_discs_side_by_side_give_two_tracks():
    # Centres 0.85 m apart: their outlines overlap, one cluster of 1.8 m, too large for one object,
    # until it is cut where the two arcs meet.
    movers = [lambda t, side=side: (2.5 + 0.8 * t, -1.5 + 0.425 * side + 0.5 * t) for side in (-1, 1)]
    for seed in range(2):
        _, ticks = simulate(movers, at_origin, 2.0, seed=seed)
        for t, _, centres, tracks, _, _ in ticks:
            if t >= 0.3:
                matched = [nearest(tracks, centre) for centre in centres]
                assert None not in matched
                assert all(
                    np.linalg.norm(track.position - c) < 0.1
                    for track, c in zip(matched, centres, strict=True)
                )
                assert matched[0].track_id != matched[1].track_id
                assert all(track.moving for track in matched)


def scan_clusters(pieces, pose=(0.0, 0.0, 0.0)):
    """`tracking.scan_clusters` of a noiseless scan of `pieces` from `pose`: bounds, ends, usable,
    fitted, centres."""
    tracker = Tracker()
    bearings, cos_b, sin_b, _, cyclic = tracker._fan_of(BEARINGS).packed
    _, segmentation, features, *_ = tracker._settings
    ranges = cast(pieces, pose)
    out = tracking.scan_clusters(
        bearings, cos_b, sin_b, ranges, cyclic, np.array(pose), segmentation, features
    )
    bounds, _, ends, _, usable, fitted, centres, _, _ = out
    return bounds, ends, usable, fitted, centres


@pytest.mark.parametrize(
    "discs",
    [
        [(2.5, -0.45), (2.5, 0.45)],  # side by side, overlapping
        [(3.0, -0.9), (3.0, 0.0), (3.0, 0.9)],  # three in a row
        [(2.3, -0.4), (2.6, 0.45)],  # one a little behind the other
    ],
)
def test_round_objects_in_one_cluster_are_cut_apart(discs):
    pieces = [Disc(centre, RADIUS_M) for centre in discs]
    segmented = tracking.segment(
        BEARINGS, cast(pieces, (0.0, 0.0, 0.0)), False, math.radians(10.0), 0.01, 0.1, 1, 0.2
    )
    assert len(segmented[1]) - 1 == 1  # one cluster as Borges and Aldon cut the scan
    bounds, ends, usable, fitted, centres = scan_clusters(pieces)
    assert len(bounds) - 1 == len(discs)
    assert usable.all() and fitted.all()
    for centre in discs:
        assert np.min(np.linalg.norm(centres - centre, axis=1)) < 0.01
    assert (ends[1:, 0] == tracking.END_BLOCKED).all() and (ends[:-1, 1] == tracking.END_BLOCKED).all()


def test_a_disc_against_a_wall_is_cut_from_it_and_bent_walls_stay_whole():
    wall = Rect((3.0, 0.0), (0.05, 3.0))  # x = 3 from y = -3 to 3
    bounds, _, usable, fitted, centres = scan_clusters([wall, Disc((2.45, 0.5), RADIUS_M)])
    assert np.sum(usable & fitted) == 1
    assert np.linalg.norm(centres[usable & fitted][0] - (2.45, 0.5)) < 0.01
    assert np.sum(~usable) >= 1  # the wall is still fixed structure
    corner = [wall, Rect((1.5, 3.0), (1.5, 0.05))]  # an L, its inner corner toward the sensor
    bounds, _, usable, _, _ = scan_clusters(corner)
    assert len(bounds) - 1 == 1 and not usable.any()


@pytest.mark.parametrize(
    ("mover", "static", "scans"),
    [
        (lambda t: (3.0, -2.0 + 1.5 * t), (), 2),  # in view from the first scan
        (lambda t: (2.5, -1.6 + 1.5 * t), (Rect((1.5, -1.5), (0.05, 1.0)),), 8),  # past a wall's end
    ],
)
def test_a_disc_at_1_5_m_per_s_is_moving_soon_after_its_first_sight(mover, static, scans):
    # From a scan 0.1 s old, it has moved 0.15 m; its third measurement (second, its motion plain)
    # tells it moves. Coming out past a wall, it first shows a few echoes: its circle fit waits for
    # an arc of 45 degrees that places its centre within 5 cm.
    for seed in range(3):
        _, ticks = simulate([mover], at_origin, 3.0, static, seed)
        seen = next(i for i, tick in enumerate(ticks) if tick[5][0].sum() >= 3)
        moving = next(
            i
            for i, (_, _, centres, tracks, _, _) in enumerate(ticks)
            if any(track.moving and np.linalg.norm(track.position - centres[0]) < 0.2 for track in tracks)
        )
        assert moving - seen <= scans


def test_nothing_moves_in_a_static_world_the_robot_drives_past():
    static = [
        Rect((5.0, 4.0), (6.0, 0.05)),  # a wall along y = 4
        Disc((2.0, -2.0), 0.5),
        Disc((6.0, -1.5), 0.3),
        Disc((8.0, 2.0), 0.15),
        Disc((4.0, 1.5), 0.075),
        Disc((10.0, -2.5), 0.5),
        Disc((10.6, -2.5), 0.2),  # a blob with the one before it
    ]
    for seed in range(2):
        _, ticks = simulate([], lambda t: (1.0 * t, 0.0, 0.0), 10.0, static, seed)
        assert not any(track.moving for _, _, _, tracks, _, _ in ticks for track in tracks)
        assert not any(moving.any() for _, _, _, _, moving, _ in ticks)


def test_a_disc_moving_straight_away_is_told_moving_by_the_place_it_left():
    # Along the beams it stands where it hid before; the place it left is free space now.
    _, ticks = simulate([lambda t: (2.0 + 1.0 * t, 2.0 + 1.0 * t)], at_origin, 3.0)
    assert all(track.moving for _, _, _, tracks, _, _ in ticks[30:] for track in tracks)
    assert all(len(tracks) == 1 for _, _, _, tracks, _, _ in ticks[30:])


def test_a_static_disc_is_left_to_the_map_once_judged_fixed():
    tracker, ticks = simulate([], lambda t: (0.5 * t, 0.0, 0.0), 4.0, static=[Disc((4.0, 1.5), 0.3)])
    seen = [t for t, _, _, tracks, _, _ in ticks if tracks]
    assert seen and seen[0] < 0.5  # confirmed, not moving
    assert max(seen) < tracker.params.slow_reference_age_s + tracker.params.static_drop_s + 0.2
    assert not any(track.moving for _, _, _, tracks, _, _ in ticks for track in tracks)


def test_a_drifting_pose_makes_nothing_move_while_fixed_structure_is_in_view():
    static = [Rect((5.0, 4.0), (6.0, 0.05)), Disc((4.0, 1.5), 0.075), Disc((6.0, -1.5), 0.3)]
    rng = np.random.default_rng(0)
    tracker = Tracker()
    for k in range(200):
        t = k / RATE_HZ
        ranges = cast(static, (1.0 * t, 0.0, 0.0), rng)
        believed_yaw = 0.1 * t  # the belief drifts 0.1 rad/s off the truth, 0
        tracks = tracker.update(t, np.array((1.0 * t, 0.0)), believed_yaw, BEARINGS, ranges)
        assert not any(track.moving for track in tracks)


def test_a_disc_leaving_the_view_behind_the_robot_coasts_then_is_dropped():
    tracker, ticks = simulate([lambda t: (4.0 - 1.5 * t, 2.0)], at_origin, 8.0)
    coast_s = tracker.params.coast_s
    ids = {track.track_id for _, _, _, tracks, _, _ in ticks for track in tracks}
    assert len(ids) == 1
    last_seen = max(track.last_seen_s for _, _, _, tracks, _, _ in ticks for track in tracks)
    assert 3.0 < last_seen < 4.5  # it leaves the 270 degree view near x = -2
    for t, _, centres, tracks, _, _ in ticks:
        if last_seen + 0.1 < t < last_seen + coast_s - 0.1:
            (track,) = tracks
            assert track.last_seen_s == last_seen
            assert np.linalg.norm(track.position - centres[0]) < 0.2  # on its prediction
        if t > last_seen + coast_s + 0.06:
            assert tracks == ()


def test_moving_beams_are_those_of_the_moving_disc_and_never_the_walls():
    wall = Rect((4.0, 5.0), (6.0, 0.05))
    _, ticks = simulate([lambda t: (-1.0 + 1.5 * t, 3.0)], at_origin, 5.0, static=[wall])
    marked = 0
    for _, _, _, tracks, moving, own in ticks:
        assert not (moving & ~own[0]).any()  # only the disc's beams
        if any(track.moving for track in tracks):
            assert moving.sum() >= 0.9 * own[0].sum()
            marked += 1
    assert marked > 60


def test_the_beams_are_taken_in_any_order():
    rng = np.random.default_rng(3)
    shuffle = rng.permutation(BEARINGS.size)
    tracker, shuffled = Tracker(), Tracker()
    for k in range(30):
        t = k / RATE_HZ
        ranges = cast([Disc((2.0 + 1.5 * t, 1.0), RADIUS_M), Disc((5.0, -2.0), 0.2)], (0.0, 0.0, 0.0), rng)
        tracks = tracker.update(t, np.zeros(2), 0.0, BEARINGS, ranges)
        again = shuffled.update(t, np.zeros(2), 0.0, BEARINGS[shuffle], ranges[shuffle])
        assert [track.track_id for track in tracks] == [track.track_id for track in again]
        for one, other in zip(tracks, again, strict=True):
            assert np.array_equal(one.position, other.position)
        assert np.array_equal(tracker.moving_beams[shuffle], shuffled.moving_beams)
        assert np.array_equal(tracker.beam_track_ids[shuffle], shuffled.beam_track_ids)


def test_the_same_scans_give_the_same_tracks():
    runs = [simulate([lambda t: (-1.0 + 1.5 * t, 3.0)], at_origin, 2.0, seed=5)[1] for _ in range(2)]
    for one, other in zip(*runs, strict=True):
        assert [dataclasses.astuple(track)[3:] for track in one[3]] == [
            dataclasses.astuple(track)[3:] for track in other[3]
        ]
        assert [track.position.tolist() for track in one[3]] == [
            track.position.tolist() for track in other[3]
        ]


def test_a_scan_all_round_keeps_a_disc_on_its_seam_whole():
    bearings, step = laser_bearings(360.0, 720)  # the seam at the back, +-180 degrees
    ranges = RayCaster([Disc((-3.0, 0.0), RADIUS_M)]).cast((0.0, 0.0), bearings[0], step, 720, 30.0)
    ranges[~np.isfinite(ranges)] = np.nan
    tracker = Tracker()
    for k in range(5):
        tracks = tracker.update(k / RATE_HZ, np.zeros(2), 0.0, bearings, ranges)
    (track,) = tracks
    assert np.linalg.norm(track.position - (-3.0, 0.0)) < 0.02
    assert track.radius_m == pytest.approx(RADIUS_M, abs=0.03)
    assert len(set(tracker.beam_track_ids[np.isfinite(ranges)])) == 1


@pytest.mark.parametrize(
    "ranges",
    [
        np.zeros(0),
        np.full(720, np.nan),
        np.where(np.arange(720) % 2 == 0, 3.0, np.nan),  # one-beam clusters
        np.where(np.arange(720) % 7 == 0, 3.0, np.inf),  # inf: no echo either
        np.full(720, 2.0),  # a ring of wall all round the view
        np.full(720, 0.0),  # zero ranges: no echo
    ],
)
def test_odd_scans_give_no_tracks_and_no_errors(ranges):
    tracker = Tracker()
    bearings = BEARINGS if ranges.size else np.zeros(0)
    for k in range(5):
        assert tracker.update(k / RATE_HZ, np.zeros(2), 0.0, bearings, ranges) == ()
        assert tracker.moving_beams.shape == ranges.shape and not tracker.moving_beams.any()
        assert (tracker.beam_track_ids == -1).all()


def test_one_beam_and_bad_input():
    tracker = Tracker()
    assert tracker.update(0.0, np.zeros(2), 0.0, np.zeros(1), np.ones(1)) == ()
    with pytest.raises(ValueError, match="one length"):
        tracker.update(0.1, np.zeros(2), 0.0, BEARINGS, np.ones(3))
    with pytest.raises(ValueError, match="time order"):
        tracker.update(-1.0, np.zeros(2), 0.0, np.zeros(1), np.ones(1))


def test_a_track_predicts_at_constant_velocity():
    track = Track(1, np.array((1.0, 2.0)), np.array((0.5, -1.0)), 0.5, 0.1, 0.1, 0.0, 1.0, True, 1.0)
    assert track.predicted(3.0) == pytest.approx((2.0, 0.0))


def test_tracks_are_built_as_the_dataclass_builds_them():
    states = np.array(((1.0, 2.0, 0.5, -1.0), (3.0, 4.0, 0.0, 0.0)))
    values = np.array(((7, 0.5, 0.1, 0.2, 0.0, 1.0, 1), (9, 0.3, 0.4, 0.5, 0.5, 1.5, 0)), dtype=float)
    for built, row, v in zip(tracks_of(states, values, 2.0), states, values, strict=True):
        expected = Track(int(v[0]), row[:2], row[2:], *v[1:6].tolist(), bool(v[6]), 2.0)
        assert dataclasses.asdict(built).keys() == dataclasses.asdict(expected).keys()
        for name, value in dataclasses.asdict(expected).items():
            assert np.array_equal(getattr(built, name), value) and type(getattr(built, name)) is type(value)


def test_every_parameter_has_a_unit_and_a_meaning():
    for name, spec in TrackerParams.table().items():
        assert spec.doc, name
        assert spec.check(spec.default) is None, name


def reference_segments(bearings, ranges, cyclic, lam, sigma, min_gap, max_missing):
    """Plain numpy: whether each echo (by bearing) starts a cluster, by Borges and Aldon's rule."""
    echoes = np.flatnonzero(np.isfinite(ranges) & (ranges > 0))
    starts = []
    for j, b in enumerate(echoes):
        if j == 0 and not (cyclic and echoes.size > 1):
            starts.append(True)
            continue
        a = echoes[j - 1]
        dphi = bearings[b] - bearings[a] + (2 * np.pi if j == 0 else 0.0)
        missing = b - a - 1 + (ranges.size if j == 0 else 0)
        gap = np.hypot(*(ranges[b] * np.array((np.cos(dphi), np.sin(dphi))) - (ranges[a], 0.0)))
        threshold = max(min_gap, min(ranges[a], ranges[b]) * np.sin(dphi) / np.sin(lam - dphi) + 3 * sigma)
        starts.append(missing > max_missing or dphi >= lam or gap > threshold)
    return echoes, np.array(starts, dtype=bool)


@pytest.mark.parametrize("fov_deg", [270.0, 360.0])
def test_segmentation_agrees_with_a_numpy_reference(fov_deg):
    bearings, _ = laser_bearings(fov_deg, 720)
    rng = np.random.default_rng(7)
    lam, sigma, min_gap, max_missing = math.radians(10.0), 0.01, 0.1, 1
    for _ in range(40):
        pieces = [Disc(tuple(rng.uniform(-8, 8, 2)), float(rng.uniform(0.05, 1.0))) for _ in range(25)]
        pieces.append(Rect(tuple(rng.uniform(-8, 8, 2)), (3.0, 0.05), float(rng.uniform(0, np.pi))))
        ranges = RayCaster(pieces).cast((0.0, 0.0), bearings[0], bearings[1] - bearings[0], 720, 12.0)
        ranges += rng.normal(0.0, 0.01, 720)
        ranges[rng.random(720) < 0.05] = np.nan
        ranges[~(ranges <= 12.0)] = np.nan
        cyclic = fov_deg == 360.0
        order, bounds, labels, _ = tracking.segment(
            bearings, ranges, cyclic, lam, sigma, min_gap, max_missing, 0.2
        )
        echoes, starts = reference_segments(bearings, ranges, cyclic, lam, sigma, min_gap, max_missing)
        assert np.array_equal(np.sort(order), echoes)
        kernel_starts = np.r_[True, labels[echoes][1:] != labels[echoes][:-1]]
        if cyclic and starts.any():  # the kernel starts its numbering at a break
            kernel_starts[0] = labels[echoes[0]] != labels[echoes[-1]]
        assert np.array_equal(kernel_starts, starts)
        assert bounds[-1] == echoes.size and np.all(np.diff(bounds) > 0)


def test_the_circle_fit_finds_an_arc_exactly():
    angles = np.linspace(-1.2, 1.2, 15)
    points = np.c_[2.0 + 0.5 * np.cos(angles + np.pi), 1.0 + 0.5 * np.sin(angles + np.pi)]
    cx, cy, radius, rms = tracking.kasa_fit(points, 0, 15)
    assert (cx, cy, radius) == pytest.approx((2.0, 1.0, 0.5))
    assert rms < 1e-9


def test_the_geometric_fit_refines_kasas_on_a_short_noisy_arc():
    rng = np.random.default_rng(4)
    kasa, refined = [], []
    for _ in range(200):
        angles = np.linspace(-0.5, 0.5, 30)  # 57 degrees
        points = np.c_[0.5 * np.cos(angles), 0.5 * np.sin(angles)] + rng.normal(0.0, 0.01, (30, 2))
        optimum = least_squares(lambda q, p=points: np.hypot(*(p - q[:2]).T) - q[2], (0.0, 0.0, 0.5)).x
        kasa.append(np.linalg.norm(tracking.kasa_fit(points, 0, 30)[:2] - optimum[:2]))
        refined.append(np.linalg.norm(tracking.circle_fit(points, 0, 30, 2)[:2] - optimum[:2]))
    assert np.median(refined) < 0.01 * np.median(kasa)


@pytest.mark.parametrize("fov_deg", [270.0, 360.0])
def test_the_window_of_beams_agrees_with_a_plain_search(fov_deg):
    rng = np.random.default_rng(9)
    fans = [laser_bearings(fov_deg, 720)[0], np.sort(rng.uniform(-np.pi, np.pi, 40))]
    cyclic = fov_deg == 360.0
    for bearings in fans:
        for _ in range(3000):
            lo = rng.uniform(-8.0, 8.0)
            hi = lo + rng.choice([0.0, rng.uniform(0.0, 0.2), rng.uniform(0.0, 7.0)])
            shift = 2 * np.pi * np.floor((lo - bearings[0]) / (2 * np.pi))
            start = int(np.searchsorted(bearings, lo - shift))
            if not cyclic and hi - shift > bearings[-1]:
                expected = (start, 0)
            else:
                unrolled = np.r_[bearings, bearings + 2 * np.pi]
                count = int(np.sum(unrolled[start : start + bearings.size] <= hi - shift))
                expected = (start, count)
            assert tracking._window(bearings, cyclic, lo, hi) == expected


def test_the_assignment_is_scipys_optimum():
    rng = np.random.default_rng(11)
    for trial in range(300):
        costs = rng.random(rng.integers(1, 9, 2)) * 10.0
        costs[rng.random(costs.shape) < rng.random()] = np.inf
        if trial % 2:
            costs = np.round(costs)  # ties
        rows, columns = tracking.assign(costs)
        finite = np.where(np.isfinite(costs), costs, 1e9)
        best_rows, best_columns = linear_sum_assignment(finite)
        kept = finite[best_rows, best_columns] < 1e9
        assert len(rows) == kept.sum() and len(set(rows)) == len(rows) and len(set(columns)) == len(columns)
        assert costs[rows, columns].sum() == pytest.approx(finite[best_rows[kept], best_columns[kept]].sum())
