"""The laser: its 2D cast against MuJoCo's own ray caster on the compiled worlds, its edge cases,
and the sensor's beams, range rules, noise, dropout and determinism."""

import math
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from vplane_mj.geometry import shapes
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import box, build_scenario, cup, cylinder, h_shape, wall
from vplane_mj.sim.laser import MOUNT_HEIGHT_M, LaserScanner, RayCaster
from vplane_mj.sim.world import OBSTACLE_HEIGHT_M, OBSTACLES_BODY, build_model

JACKAL_STEP = math.radians(270) / 719
"""The Jackal's laser: 720 beams over 270 degrees."""
OBSTACLES_ONLY = np.array([1, 1, 1, 1, 1, 0], dtype=np.uint8)
"""Geom groups MuJoCo's ray sees: every group but 5, where `MujocoRays` moves the robot and floor."""


class MujocoRays:
    """MuJoCo's ray caster on a scenario's compiled world, seeing only the obstacles and border."""

    def __init__(self, scenario):
        self.model = build_model(scenario, rangefinders=False)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_kinematics(self.model, self.data)
        obstacles = self.model.body(OBSTACLES_BODY).id
        self.model.geom_group[self.model.geom_bodyid != obstacles] = 5

    def cast(self, origin, first_angle, step, beams, range_max):
        """Like `RayCaster.cast`, at the laser's mount height: inf for a miss or beyond range_max."""
        angles = first_angle + step * np.arange(beams)
        vec = np.zeros((beams, 3))
        vec[:, 0], vec[:, 1] = np.cos(angles), np.sin(angles)
        geom, dist = np.zeros(beams, np.int32), np.zeros(beams)
        point = np.array([origin[0], origin[1], MOUNT_HEIGHT_M])
        mujoco.mj_multiRay(
            self.model, self.data, point, vec.ravel(), OBSTACLES_ONLY, 1, -1, geom, dist, None, beams, np.inf
        )
        return np.where((dist < 0) | (dist > range_max), np.inf, dist)


def scenario_of(obstacles, size=(10.0, 10.0), border=True, start=None, goal=None):
    """A world of `obstacles` (scenario dicts); start and goal default to free points far apart."""
    if start is None or goal is None:
        start, goal = free_points(obstacles, size, 2, np.random.default_rng(0), robot_radius_m() + 0.01)
    return build_scenario("laser", size=size, start=start, goal=goal, obstacles=obstacles, border=border)


def footprints(scenario):
    world = scenario.world
    return shapes.scene_footprints(world.obstacles, world.size if world.border else None)


def free_points(obstacles, size, count, rng, clearance):
    """`count` random points of the arena at least `clearance` (m) from the obstacles and its edges."""
    scene = obstacle_footprints(obstacles, size)
    points = rng.uniform((clearance, clearance), (size[0] - clearance, size[1] - clearance), (4000, 2))
    free = points[scene.distance(points) > clearance] if len(scene) else points
    assert len(free) >= count, "the test's world is too full"
    return [tuple(map(float, p)) for p in free[:count]]


def obstacle_footprints(obstacles, size):
    """The footprints of `obstacles` (scenario dicts inside an arena of `size`), parsed as a
    scenario parses them, in a larger arena whose start and goal lie clear of them."""
    w, h = size
    probe = build_scenario(
        "probe", size=(w + 20, h + 20), start=(w + 10, h + 5), goal=(w + 10, h + 15), obstacles=obstacles
    )
    return shapes.scene_footprints(probe.world.obstacles)


def random_world(rng):
    """Random boxes at random yaw, walls, cylinders, U and H shapes, usually inside a border."""
    size = (float(rng.uniform(4.0, 10.0)), float(rng.uniform(4.0, 10.0)))

    def point():
        return [float(rng.uniform(0.0, size[0])), float(rng.uniform(0.0, size[1]))]

    def yaw():
        return float(rng.uniform(-180.0, 180.0))

    obstacles = [box(point(), list(rng.uniform(0.05, 1.5, 2)), yaw()) for _ in range(rng.integers(0, 8))]
    obstacles += [wall(point(), point(), float(rng.uniform(0.02, 0.2))) for _ in range(rng.integers(0, 3))]
    obstacles += [cylinder(point(), float(rng.uniform(0.03, 0.6))) for _ in range(rng.integers(0, 40))]
    obstacles += [
        cup(point(), float(rng.uniform(0.6, 2)), float(rng.uniform(0.6, 2)), yaw()) for _ in range(2)
    ]
    obstacles += [h_shape(point(), float(rng.uniform(0.6, 2)), float(rng.uniform(0.6, 2)), yaw())]
    return scenario_of(obstacles, size, border=bool(rng.random() < 0.8))


def assert_same_ranges(ours, theirs):
    """Within 1 mm on every beam, misses (inf) included."""
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-3)


@pytest.mark.parametrize("seed", range(30))
def test_the_cast_equals_mujocos_ray_on_random_worlds(seed):
    rng = np.random.default_rng(seed)
    scenario = random_world(rng)
    caster, mujoco_rays = RayCaster(footprints(scenario)), MujocoRays(scenario)
    size = scenario.world.size
    scene = footprints(scenario)
    origins = rng.uniform((0, 0), size, (60, 2))
    origins = origins[scene.distance(origins) > 0][:8]
    fans = [(JACKAL_STEP, 720), (2 * math.pi / 360, 360), (float(rng.uniform(1e-3, 0.1)), 50)]
    hits = 0
    for origin in origins:
        for step, beams in fans:
            first, range_max = float(rng.uniform(-10, 10)), float(rng.uniform(0.5, 30))
            ours = caster.cast(tuple(origin), first, step, beams, range_max)
            assert_same_ranges(ours, mujoco_rays.cast(origin, first, step, beams, range_max))
            hits += np.isfinite(ours).sum()
    assert hits > 0


def test_pieces_beyond_range_max_are_not_seen():
    scenario = scenario_of([cylinder([5.0, 5.0], 0.5), box([2.0, 8.0], [1.0, 0.5], 30.0)])
    caster, mujoco_rays = RayCaster(footprints(scenario)), MujocoRays(scenario)
    origin = (3.0, 5.0)  # 1.5 m from the cylinder, 2.04 m from the box, 3 m from the border
    near = caster.cast(origin, -math.pi, 2 * math.pi / 720, 720, 1.2)
    assert np.isinf(near).all()
    for range_max in (1.2, 1.6, 2.5, 3.5, 30.0):
        assert_same_ranges(
            caster.cast(origin, -math.pi, 2 * math.pi / 720, 720, range_max),
            mujoco_rays.cast(origin, -math.pi, 2 * math.pi / 720, 720, range_max),
        )


def test_range_max_cuts_a_piece_between_its_beams():
    # A long wall at x in [1.95, 2.05]: the beams further off the x axis reach it further away.
    caster = RayCaster([shapes.Rect(center=(2.0, 0.0), half=(0.05, 10.0))])
    angles = np.linspace(-1.2, 1.2, 241)
    ranges = caster.cast((0.0, 0.0), -1.2, 0.01, 241, 3.0)
    exact = 1.95 / np.cos(angles)
    np.testing.assert_allclose(ranges[exact <= 3.0], exact[exact <= 3.0], rtol=0, atol=1e-12)
    assert np.isinf(ranges[exact > 3.0]).all() and (exact > 3.0).sum() > 40


def test_beams_grazing_a_disc():
    caster = RayCaster([shapes.Disc(center=(5.0, 0.0), radius=1.0)])
    tangent = math.asin(1.0 / 5.0)
    touch = math.sqrt(24.0)  # the distance to the tangent point
    inside, outside = caster.cast((0.0, 0.0), tangent - 1e-9, 2e-9, 2, 10.0)
    assert inside == pytest.approx(touch, abs=1e-3) and outside == math.inf
    inside, outside = caster.cast((0.0, 0.0), -tangent + 1e-9, -2e-9 + 2 * math.pi, 2, 10.0)
    assert inside == pytest.approx(touch, abs=1e-3) and outside == math.inf
    (exactly,) = caster.cast((0.0, 0.0), tangent, 0.1, 1, 10.0)
    assert exactly == math.inf or exactly == pytest.approx(touch, abs=1e-3)  # rounding decides
    # A fan too fine to count its steps in integers still finds the disc.
    assert (caster.cast((0.0, 0.0), -1e-300, 1e-300, 3, 10.0) == 4.0).all()


def test_grazing_beams_agree_with_mujoco():
    scenario = scenario_of([cylinder([5.0, 5.0], 0.8), box([5.0, 8.0], [2.0, 1.0], 0.0)])
    caster, mujoco_rays = RayCaster(footprints(scenario)), MujocoRays(scenario)
    origin = (1.0, 5.0)
    tangent = math.asin(0.8 / 4.0)
    for offset in (-1e-6, 1e-6):  # just inside and just outside each tangent
        for first in (tangent + offset, -tangent + offset):
            assert_same_ranges(
                caster.cast(origin, first, 1e-3, 3, 9.0), mujoco_rays.cast(origin, first, 1e-3, 3, 9.0)
            )


def test_a_beam_along_a_boxs_edge_hits_its_corner():
    caster = RayCaster([shapes.Rect(center=(1.5, 0.5), half=(0.5, 0.5))])  # x in [1, 2], y in [0, 1]
    for y in (0.0, 1.0):  # along the bottom and the top edge
        (along,) = caster.cast((0.0, y), 0.0, 0.1, 1, 5.0)
        assert along == 1.0
    (beyond,) = caster.cast((0.0, 1.0 + 1e-12), 0.0, 0.1, 1, 5.0)
    assert beyond == math.inf
    (down,) = caster.cast((1.0, 3.0), -math.pi / 2, 0.1, 1, 5.0)  # along the left edge, from above
    assert down == pytest.approx(2.0, abs=1e-12)
    scenario = scenario_of([box([1.5, 0.5], [1.0, 1.0])], border=False)
    mujoco_rays = MujocoRays(scenario)
    for origin in ((0.0, 0.0), (0.0, 1.0)):
        assert_same_ranges(caster.cast(origin, 0.0, 0.1, 1, 5.0), mujoco_rays.cast(origin, 0.0, 0.1, 1, 5.0))


@pytest.mark.parametrize("first", [-math.pi, math.pi - 0.05, 3 * math.pi, -4 * math.pi + 0.02, 0.5])
def test_pieces_straddling_the_wrap_at_pi(first):
    # A disc and a box straddle the -x axis, where the angle wraps from +pi to -pi.
    scenario = scenario_of([cylinder([2.0, 5.0], 0.3), box([5.0, 2.5], [0.4, 0.6], 10.0)])
    caster, mujoco_rays = RayCaster(footprints(scenario)), MujocoRays(scenario)
    step = 2 * math.pi / 1000
    for origin in ((4.0, 5.0), (7.0, 2.5)):
        ours = caster.cast(origin, first, step, 1000, 5.0)
        assert_same_ranges(ours, mujoco_rays.cast(origin, first, step, 1000, 5.0))
        # The beam nearest the -x axis reads the piece's near side: 2 m away, less the disc's
        # radius or the box's half width turned by 10 degrees.
        k = round(((math.pi - first) % (2 * math.pi)) / step)
        near_side = 2.0 - (0.3 if origin == (4.0, 5.0) else 0.2 / math.cos(math.radians(10.0)))
        assert ours[k] == pytest.approx(near_side, abs=2e-3)


def test_a_full_turn_sees_every_side_once():
    centres = np.arange(8) * math.pi / 4
    caster = RayCaster([shapes.Disc(center=(math.cos(a), math.sin(a)), radius=0.1) for a in centres])
    angles = -math.pi + np.arange(360) * 2 * math.pi / 360
    ranges = caster.cast((0.0, 0.0), -math.pi, 2 * math.pi / 360, 360, 5.0)
    # Each disc at 1 m, seen off its centre by delta, is hit at cos(delta) - sqrt(r^2 - sin(delta)^2).
    off = np.angle(np.exp(1j * (angles[:, None] - centres[None, :])))
    reach = 0.1**2 - np.sin(off) ** 2
    hits = np.where((reach >= 0) & (np.cos(off) > 0), np.cos(off) - np.sqrt(np.abs(reach)), np.inf)
    np.testing.assert_allclose(ranges, hits.min(axis=1), rtol=0, atol=1e-12)
    # 11 beams on each disc, the one straddling +-180 degrees too; 8 runs of hits, 8 of misses.
    hit = np.isfinite(ranges)
    assert hit.sum() == 8 * 11 and hit[0] and hit[-1]
    assert np.sum(hit != np.roll(hit, 1)) == 16


def test_origins_near_pieces_agree_with_mujoco():
    obstacles = [
        box([4.0, 4.0], [1.0, 0.6], 25.0),
        cylinder([7.0, 6.0], 0.4),
        wall([2.0, 7.0], [5.0, 8.5], 0.1),
    ]
    scenario = scenario_of(obstacles)
    caster, mujoco_rays, scene = RayCaster(footprints(scenario)), MujocoRays(scenario), footprints(scenario)
    rng = np.random.default_rng(3)
    tried = 0
    for piece in scene.pieces[:3]:
        for gap in (1e-4, 1e-3, 1e-2):
            for angle in rng.uniform(-math.pi, math.pi, 6):
                # Walk out from the piece's centre along `angle` until `gap` from its boundary.
                direction = np.array([math.cos(angle), math.sin(angle)])
                lo, hi = 0.0, 3.0
                for _ in range(60):
                    mid = (lo + hi) / 2
                    d = shapes.Footprints([piece]).distance(np.array(piece.center) + mid * direction)[0]
                    lo, hi = (mid, hi) if d < gap else (lo, mid)
                origin = tuple(np.array(piece.center) + hi * direction)
                if scene.distance(np.array([origin]))[0] <= 0:
                    continue
                tried += 1
                step = 2 * math.pi / 720
                ours = caster.cast(origin, -math.pi, step, 720, 10.0)
                assert_same_ranges(ours, mujoco_rays.cast(origin, -math.pi, step, 720, 10.0))
                assert ours.min() <= 1.01 * gap
    assert tried > 40


def test_a_beam_starting_inside_or_on_a_piece_reads_zero():
    caster = RayCaster(
        [
            shapes.Rect(center=(0.0, 0.0), half=(1.0, 0.5), yaw=0.3),
            shapes.Rect(center=(0.0, 5.0), half=(1.0, 1.0)),
            shapes.Disc((5.0, 0.0), 1.0),
        ]
    )
    # Inside each piece; on the square's face and corner; on the disc's rim.
    for origin in ((0.2, 0.1), (0.5, 5.5), (5.5, 0.0), (1.0, 5.0), (-1.0, 4.0), (4.0, 0.0), (6.0, 0.0)):
        assert (caster.cast(origin, 0.0, 0.01, 600, 3.0) == 0.0).all()


def test_an_empty_world_reads_inf():
    assert np.isinf(RayCaster([]).cast((0.0, 0.0), 0.0, 0.01, 100, 30.0)).all()


@pytest.mark.parametrize(
    ("first", "step", "beams", "range_max"),
    [
        (0.0, 0.0, 10, 5.0),
        (0.0, 0.1, 0, 5.0),
        (0.0, 2 * math.pi / 10, 11, 5.0),
        (math.nan, 0.1, 10, 5.0),
        (0.0, 0.1, 10, 0.0),
    ],
)
def test_the_cast_refuses_a_fan_it_cannot_cast(first, step, beams, range_max):
    with pytest.raises(ValueError):
        RayCaster([]).cast((0.0, 0.0), first, step, beams, range_max)


def test_the_mount_height_lies_between_the_floor_and_the_obstacles_tops():
    assert 0.0 < MOUNT_HEIGHT_M < OBSTACLE_HEIGHT_M


def test_importing_the_package_does_not_import_numba():
    code = (
        "import sys, vplane_mj\n"
        "assert 'numba' not in sys.modules\n"
        "import vplane_mj.sim.laser\n"
        "assert 'numba' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


# -- The sensor ------------------------------------------------------------------------------------

WALL_AHEAD = [shapes.Rect(center=(3.0, 0.0), half=(0.05, 100.0))]
"""A wall across the x axis: its near face is 2.95 m ahead of a robot at the origin."""


def scanner(pieces=WALL_AHEAD, seed=0, **options):
    settings = {"fov_deg": 270.0, "beams": 720, "range_min": 0.1, "range_max": 30.0, "rate_hz": 50.0}
    settings.update(options)
    return LaserScanner(RayCaster(pieces), rng=np.random.default_rng(seed), **settings)


def test_beams_are_centred_on_the_heading_and_evenly_spaced():
    jackal = scanner()
    assert jackal.bearings[0] == pytest.approx(-math.radians(135))
    assert jackal.bearings[-1] == pytest.approx(math.radians(135))
    np.testing.assert_allclose(np.diff(jackal.bearings), jackal.angle_step, rtol=1e-12)
    burger = scanner(fov_deg=360.0, beams=360)
    assert burger.angle_step == pytest.approx(math.radians(1.0))
    np.testing.assert_allclose(burger.bearings, -burger.bearings[::-1], atol=1e-15)
    # All round with no beam repeated: the gap across +-180 degrees is one step too.
    assert burger.bearings[0] + 2 * math.pi - burger.bearings[-1] == pytest.approx(burger.angle_step)
    assert len(np.unique(np.round(np.mod(burger.bearings, 2 * math.pi), 9))) == 360


def test_a_reading_is_the_cast_from_the_robots_pose():
    disc = shapes.Disc(center=(1.0, 3.0), radius=0.25)
    laser = scanner([disc], fov_deg=180.0, beams=361)
    ranges = laser.read(1.0, 1.0, math.pi / 2)  # facing the disc, 2 m ahead
    assert ranges[180] == pytest.approx(1.75, abs=1e-12)
    expected = RayCaster([disc]).cast(
        (1.0, 1.0), math.pi / 2 + laser.bearings[0], laser.angle_step, 361, 30.0
    )
    np.testing.assert_array_equal(np.isnan(ranges), np.isinf(expected))
    np.testing.assert_array_equal(ranges[~np.isnan(ranges)], expected[np.isfinite(expected)])


def test_no_return_beyond_range_max_or_closer_than_range_min():
    bearings = scanner().bearings
    far = scanner(range_max=3.5).read(0.0, 0.0, 0.0)
    exact = 2.95 / np.cos(bearings)
    ahead = (exact > 0) & (exact <= 3.5)
    np.testing.assert_allclose(far[ahead], exact[ahead], rtol=0, atol=1e-12)
    assert np.isnan(far[~ahead]).all() and (~ahead).sum() > 300
    near = scanner(range_min=0.2).read(2.8, 0.0, 0.0)  # 0.15 m from the wall
    exact = 0.15 / np.cos(bearings)
    seen = (exact >= 0.2) & (exact <= 30.0)
    assert np.isnan(near[~seen]).all()
    assert not seen[np.abs(bearings) < 0.5].any()  # the wall straight ahead is too close
    np.testing.assert_allclose(near[seen], exact[seen], rtol=0, atol=1e-12)


def test_noise_is_gaussian_with_the_given_deviation():
    laser, truth = scanner(noise_std=0.05, fov_deg=90.0, beams=200), scanner(fov_deg=90.0, beams=200)
    exact = truth.read(0.0, 0.0, 0.0)
    errors = np.concatenate([laser.read(0.0, 0.0, 0.0) - exact for _ in range(200)])
    assert not np.isnan(errors).any()
    assert abs(errors.mean()) < 4 * 0.05 / math.sqrt(len(errors))
    assert errors.std() == pytest.approx(0.05, rel=0.03)


def test_range_rules_apply_to_the_noisy_range():
    # Returns 1 cm inside range_max: noise of 5 cm pushes about 42% of them beyond it.
    laser = scanner(noise_std=0.05, fov_deg=1.0, beams=2, range_max=2.96)
    lost = np.mean([np.isnan(laser.read(0.0, 0.0, 0.0)) for _ in range(2000)])
    assert lost == pytest.approx(0.42, abs=0.03)
    readings = np.concatenate([laser.read(0.0, 0.0, 0.0) for _ in range(200)])
    assert np.nanmax(readings) <= 2.96


def test_dropout_loses_returns_at_the_given_rate():
    laser = scanner(dropout=0.3)
    lost = np.array([np.isnan(laser.read(0.0, 0.0, 0.0)) for _ in range(100)])
    returns = np.isfinite(scanner().read(0.0, 0.0, 0.0))
    rate = lost[:, returns].mean()
    n = lost[:, returns].size
    assert abs(rate - 0.3) < 4 * math.sqrt(0.3 * 0.7 / n)
    assert lost[:, ~returns].all()  # a beam without a return stays without one


def test_the_same_seed_gives_the_same_scans():
    def scans(seed):
        laser = scanner(seed=seed, noise_std=0.02, dropout=0.2)
        return np.array([laser.read(0.1 * i, 0.0, 0.05 * i) for i in range(5)])

    np.testing.assert_array_equal(scans(4), scans(4))
    assert not np.array_equal(scans(4), scans(5), equal_nan=True)


@pytest.mark.parametrize(
    "options",
    [
        {"fov_deg": 0.0},
        {"fov_deg": 360.5},
        {"beams": 1},
        {"beams": 2049},
        {"beams": 10.5},
        {"range_min": 5.0, "range_max": 5.0},
        {"range_min": -0.1},
        {"rate_hz": 0.0},
        {"noise_std": -0.01},
        {"dropout": 1.5},
    ],
)
def test_the_sensor_refuses_impossible_settings(options):
    with pytest.raises(ValueError, match=next(iter(options)).split("_")[0]):
        scanner(**options)
