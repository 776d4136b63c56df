"""The compiled world: every shipped scenario builds, the robot fits its disc, the sonar reads truly."""

import math

import mujoco
import numpy as np
import pytest

from vplane_mj.files import data_dir
from vplane_mj.robots.facts import SONAR_MOUNT_RADIUS_M, robot_geometry
from vplane_mj.sim.sonar import SonarRays, SonarRing
from vplane_mj.sim.world import BUMP_SENSOR, ROBOT_PREFIX, SonarLayout, build_model, standalone_xml

RING_16 = np.full(16, SONAR_MOUNT_RADIUS_M)
"""Each sonar of the default ring reaches this far along its bearing (m)."""

SHIPPED = sorted(p.stem for p in data_dir("scenarios").glob("*.toml"))

WALL_AHEAD = """
format = 1
name = "wall_ahead"
[world]
size = [6.0, 4.0]
[[world.obstacles]]
kind = "wall"
from = [3.0, 0.5]
to = [3.0, 3.5]
thickness = 0.1
[robot]
start = [1.5, 2.0]
start_yaw_deg = 0.0
goal = [5.0, 2.0]
"""


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_scenario_compiles(shipped, name):
    scenario = shipped(name)
    model = build_model(scenario)
    rays = scenario.sensors.count * scenario.sensors.rays_per_sonar
    assert model.nsensor == rays + 1
    assert model.sensor(BUMP_SENSOR).type == mujoco.mjtSensor.mjSENS_CONTACT
    obstacle_geoms = [
        model.geom(g).name for g in range(model.ngeom) if model.geom(g).name.startswith("obstacle")
    ]
    assert len(obstacle_geoms) == sum(len(o.footprint()) for o in scenario.world.obstacles)


def test_the_world_without_rangefinders_keeps_everything_else(shipped):
    scenario = shipped("paper_h_escape", "robot.motor_gain=[0.8, 1.0]", "robot.wheel_friction=0.4")
    full, bare = build_model(scenario), build_model(scenario, rangefinders=False)
    assert bare.nsensor == 1 and bare.sensor(BUMP_SENSOR).type == mujoco.mjtSensor.mjSENS_CONTACT
    assert (full.nsite, full.ngeom, full.nbody, full.nu) == (bare.nsite, bare.ngeom, bare.nbody, bare.nu)
    for name in (
        "geom_size",
        "geom_pos",
        "geom_friction",
        "site_pos",
        "site_quat",
        "body_mass",
        "actuator_gear",
    ):
        np.testing.assert_array_equal(getattr(full, name), getattr(bare, name))


CLUTTER = """
format = 1
name = "clutter"
[world]
size = [6.0, 5.0]
[[world.obstacles]]
kind = "box"
center = [3.0, 1.2]
size = [0.6, 0.3]
yaw_deg = 30
[[world.obstacles]]
kind = "cylinder"
center = [2.0, 3.6]
radius = 0.3
[[world.obstacles]]
kind = "u"
center = [4.6, 3.0]
width = 1.4
depth = 1.0
yaw_deg = 200
[[world.obstacles]]
kind = "wall"
from = [1.0, 0.5]
to = [1.6, 2.0]
[robot]
start = [1.2, 2.6]
goal = [5.0, 1.0]
[sensors]
rays_per_sonar = 5
beam_deg = 30.0
range_max = 2.5
"""


def test_the_sonar_casts_exactly_what_the_rangefinders_read(scenario_from):
    # Two copies of the world driven alike: one with rangefinders evaluated at every step
    # (MuJoCo's sensor stage), one without, whose sonar casts its rays only when asked.
    scenario = scenario_from(CLUTTER)
    reference, stepped = build_model(scenario), build_model(scenario, rangefinders=False)
    ref_data, data = mujoco.MjData(reference), mujoco.MjData(stepped)
    sensors = scenario.sensors
    rays = sensors.count * sensors.rays_per_sonar
    first = reference.sensor_adr[reference.sensor(ROBOT_PREFIX + "sonar0_ray0").id]
    sonar = SonarRays(build_model(scenario), reference.sensor(ROBOT_PREFIX + "sonar0_ray0").id, rays, data)
    faults = {"noise_std": 0.03, "dropout": 0.1, "crosstalk": 0.05, "dead": (3,)}
    rings = [
        SonarRing(
            SonarLayout.from_spec(sensors).reach,
            sensors.rays_per_sonar,
            2.5,
            np.random.default_rng(5),
            **faults,
        )
        for _ in "ab"
    ]
    rng = np.random.default_rng(0)
    echoes = 0
    for step in range(3000):
        if step % 25 == 0:
            data.ctrl[:] = ref_data.ctrl[:] = rng.uniform(-0.3, 0.3, 2)
        mujoco.mj_step(reference, ref_data)
        mujoco.mj_step(stepped, data)
        if step % 7 == 0:
            expected = ref_data.sensordata[first : first + rays]
            cast = sonar.cast()
            np.testing.assert_array_equal(cast, expected)
            np.testing.assert_array_equal(rings[0].read(cast), rings[1].read(expected))
            echoes += int(((expected >= 0) & (expected < 2.5)).sum())
    assert echoes > 1000  # the rays did meet obstacles


def test_robot_fits_its_reported_disc():
    geometry = robot_geometry()
    assert geometry["radius_m"] == pytest.approx(0.11)
    assert geometry["radius_m"] <= 0.15
    assert geometry["track_m"] == pytest.approx(0.15)
    assert geometry["wheel_radius_m"] == pytest.approx(0.04)


def test_standalone_mjcf_loads_from_a_file(shipped, tmp_path):
    path = tmp_path / "world.xml"
    path.write_text(standalone_xml(shipped("paper_h_avoid")))
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.body(ROBOT_PREFIX + "base_link").id > 0


def test_sonar_ring_measures_a_wall_from_the_robot_centre(scenario_from):
    scenario = scenario_from(WALL_AHEAD)
    model = build_model(scenario)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    first = model.sensor_adr[model.sensor(ROBOT_PREFIX + "sonar0_ray0").id]
    rays = data.sensordata[first : first + 48]
    ring = SonarRing(RING_16, 3, 3.0, np.random.default_rng(0))
    ranges = ring.read(rays)
    # The wall's near face is at x = 2.95, 1.45 m ahead of the centre.
    assert ranges[0] == pytest.approx(1.45, abs=0.01)
    # Sonar 4 looks along +y at empty space up to the border 2 m away: within range 3 m.
    assert ranges[4] == pytest.approx(2.0, abs=0.01)
    # Sonar 8 looks back along -x: the west border is 1.5 m away.
    assert ranges[8] == pytest.approx(1.5, abs=0.01)


def test_sonar_reports_no_echo_as_nan_never_as_a_distance():
    ring = SonarRing(RING_16[:2], 3, 3.0, np.random.default_rng(0))
    ranges = ring.read(np.array([-1.0, 3.0, 3.0, 2.0, -1.0, 1.5]))
    assert math.isnan(ranges[0])
    assert ranges[1] == pytest.approx(1.5 + 0.10)  # shortest ray wins, measured from the centre


def test_sonar_noise_and_dropout_follow_the_seed():
    rays = np.full(48, 1.0)
    a = SonarRing(RING_16, 3, 3.0, np.random.default_rng(7), noise_std=0.05, dropout=0.3).read(rays)
    b = SonarRing(RING_16, 3, 3.0, np.random.default_rng(7), noise_std=0.05, dropout=0.3).read(rays)
    np.testing.assert_array_equal(a, b)
    assert np.isnan(a).any() and np.nanstd(a) > 0


def test_sonar_crosstalk_gives_short_echoes_and_dead_sonars_stay_silent():
    rays = np.tile([2.0, 2.0, 2.0, -1.0, -1.0, -1.0], 8)  # even sonars see a wall at 2 m, odd ones nothing
    ring = SonarRing(RING_16, 3, 3.0, np.random.default_rng(3), crosstalk=0.3, dead=(0, 5))
    scans = np.array([ring.read(rays) for _ in range(400)])
    assert np.isnan(scans[:, [0, 5]]).all()
    live = np.delete(scans, [0, 5], axis=1)
    true_range = np.where(np.arange(16) % 2 == 0, 2.1, np.nan)
    spurious = ~np.isclose(live, np.delete(true_range, [0, 5]), equal_nan=True)
    assert 0.25 < spurious.mean() < 0.35  # the crosstalk rate
    even = np.delete(np.arange(16), [0, 5]) % 2 == 0
    assert (live[:, even][spurious[:, even]] < 2.1).all()  # spurious echoes are shorter than the wall
    odd_echoes = live[:, ~even][spurious[:, ~even]]
    assert (odd_echoes >= 0.1).all() and (odd_echoes <= 3.1).all()  # within the transducer's range


def test_sonar_layout_spans_the_beam():
    class Spec:
        count, rays_per_sonar, beam_deg = 16, 3, 20.0

    layout = SonarLayout.from_spec(Spec)
    assert len(layout.bearings) == 16
    assert np.degrees(layout.ray_offsets) == pytest.approx([-10.0, 0.0, 10.0])
