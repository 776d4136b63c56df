"""Moving obstacles: the keyframed motion (Gazebo's PoseAnimation), the scenario's `motion`
table and its validation, the mocap bodies placed at every physics step, collisions with an
obstacle that moved, the clearance to moving obstacles, and the sensors seeing them where
they are (the laser's cast equal to MuJoCo's ray at random times)."""

import math

import mujoco
import numpy as np
import pytest

from vplane_mj.errors import ScenarioError
from vplane_mj.geometry import shapes
from vplane_mj.geometry.motion import Motion, MotionTable, catmull_rom_tangents
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.laser import MOUNT_HEIGHT_M, RayCaster
from vplane_mj.sim.loop import Run
from vplane_mj.sim.moving import MovingObstacles
from vplane_mj.sim.world import build_model

SAMPLE = ((0.0, -8.67, -10.0), (1.59, -7.78, -9.33), (5.56, -5.56, -7.67), (9.52, -3.33, -6.0))
"""The first keyframes of DynaBARN world 0's first obstacle (Gazebo frame)."""


def scenario_text(
    obstacles: str, robot: str = "start = [1.0, 3.0]\ngoal = [9.0, 3.0]", extra: str = ""
) -> str:
    return f"""
format = 1
name = "moving"
[world]
size = [10.0, 6.0]
{obstacles}
[robot]
{robot}
{extra}
"""


CROSSING = """
[[world.obstacles]]
kind = "cylinder"
radius = 0.4
[world.obstacles.motion]
keyframes = [[0.0, 5.0, 0.5], [4.0, 5.0, 5.5]]
interpolation = "linear"
phase_s = 1.0
"""


# -- the motion --------------------------------------------------------------------------------
def test_a_spline_passes_through_its_keyframes_and_between_them_follows_the_hermite_curve():
    motion = Motion(SAMPLE, loop=False)
    for t, x, y in SAMPLE:
        np.testing.assert_allclose(motion.position(t), (x, y), atol=1e-12)
    points = np.array(SAMPLE)[:, 1:]
    tangents = catmull_rom_tangents(points)
    # Inside: half the chord between the neighbours (tension 0); at the open ends half the end chord.
    np.testing.assert_allclose(tangents[1], (points[2] - points[0]) / 2)
    np.testing.assert_allclose(tangents[0], (points[1] - points[0]) / 2)
    np.testing.assert_allclose(tangents[-1], (points[-1] - points[-2]) / 2)
    # Half way through the second segment (time fraction 0.5): the Hermite basis 1/2, 1/2, 1/8, -1/8.
    t = (SAMPLE[1][0] + SAMPLE[2][0]) / 2
    expected = 0.5 * points[1] + 0.5 * points[2] + 0.125 * tangents[1] - 0.125 * tangents[2]
    np.testing.assert_allclose(motion.position(t), expected, atol=1e-12)


def test_a_closed_spline_wraps_its_end_tangents():
    square = ((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (2.0, 1.0, 1.0), (3.0, 0.0, 1.0), (4.0, 0.0, 0.0))
    tangents = catmull_rom_tangents(np.array(square)[:, 1:])
    np.testing.assert_allclose(tangents[0], (np.array([1.0, 0.0]) - np.array([0.0, 1.0])) / 2)
    np.testing.assert_allclose(tangents[-1], tangents[0])


def test_a_looping_motion_jumps_back_to_its_first_keyframe_and_a_held_one_stays_at_its_last():
    looping, held = Motion(SAMPLE), Motion(SAMPLE, loop=False)
    duration = SAMPLE[-1][0]
    np.testing.assert_allclose(looping.position(duration), SAMPLE[0][1:])
    np.testing.assert_allclose(looping.position(duration + 1.0), looping.position(1.0))
    np.testing.assert_allclose(held.position(duration + 50.0), SAMPLE[-1][1:])
    phased = Motion(SAMPLE, phase_s=2.5)
    np.testing.assert_allclose(phased.position(1.0), looping.position(3.5))


def test_linear_interpolation_and_velocities():
    motion = Motion(((0.0, 0.0, 0.0), (2.0, 4.0, 0.0), (4.0, 4.0, 2.0)), interpolation="linear")
    np.testing.assert_allclose(motion.position(1.0), (2.0, 0.0))
    np.testing.assert_allclose(motion.velocity(3.0), (0.0, 1.0))
    spline = Motion(SAMPLE)
    times = np.linspace(0.3, 9.3, 400)
    step = 1e-6
    numeric = (spline.position(times + step) - spline.position(times - step)) / (2 * step)
    np.testing.assert_allclose(spline.velocity(times), numeric, atol=1e-6)


def test_the_compiled_table_equals_each_motion():
    rng = np.random.default_rng(5)
    motions = []
    for k in range(12):
        times = np.concatenate(([0.0], np.cumsum(rng.uniform(0.2, 4.0, rng.integers(1, 12)))))
        points = rng.uniform(-10, 10, (len(times), 2))
        if k % 4 == 3:
            points[-1] = points[0]  # closed
        motions.append(
            Motion(
                tuple(map(tuple, np.column_stack((times, points)))),
                loop=bool(k % 3),
                interpolation="linear" if k % 5 == 0 else "spline",
                phase_s=float(rng.uniform(0, 20)),
            )
        )
    table = MotionTable(motions)
    for time_s in np.concatenate(([0.0], rng.uniform(0, 200, 50))):
        expected = np.array([m.position(time_s) for m in motions])
        np.testing.assert_allclose(table.positions(time_s), expected, rtol=0, atol=1e-12)


def test_a_motion_refuses_what_a_scenario_refuses():
    for frames in (
        ((0.0, 0, 0),),
        ((0.0, 0, 0), (0.0, 1, 1)),
        ((1.0, 0, 0), (2.0, 1, 1)),
        ((0.0, 0, 0), (1.0, math.nan, 1)),
    ):
        with pytest.raises(ValueError):
            Motion(frames)


# -- the scenario ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("edit", "key", "reason"),
    [
        (("[4.0, 5.0, 5.5]", "[0.0, 5.0, 5.5]"), "motion.keyframes[1]", "times must strictly increase"),
        (("[[0.0, 5.0, 0.5], [4.0, 5.0, 5.5]]", "[[0.0, 5.0, 0.5]]"), "motion.keyframes", "2 to"),
        (("[4.0, 5.0, 5.5]", "[4.0, inf, 5.5]"), "motion.keyframes[1]", "x must be finite"),
        (("[0.0, 5.0, 0.5]", "[0.5, 5.0, 0.5]"), "motion.keyframes[0]", "first keyframe's time must be 0"),
        (("radius = 0.4", "radius = 0.4\ncenter = [5, 3]"), "center", "a moving obstacle has no center"),
        (('kind = "cylinder"', 'kind = "wall"'), "motion", "only a cylinder or a box can move"),
        (("phase_s = 1.0", 'phase_s = "later"'), "motion.phase_s", "'random'"),
        (("phase_s = 1.0", "phase_s = -1.0"), "motion.phase_s", "at least 0"),
        (('interpolation = "linear"', 'interpolation = "cubic"'), "motion.interpolation", "must be one of"),
        (("phase_s = 1.0", "phase_s = 1.0\nspeed = 2"), "motion.speed", "unknown key"),
    ],
)
def test_a_bad_motion_is_refused_naming_the_key(edit, key, reason):
    text = scenario_text(CROSSING.replace(*edit))
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text, "x.toml")
    message = str(caught.value)
    assert f"x.toml: world.obstacles[0].{key}" in message and reason in message, message


def test_a_start_or_goal_inside_a_moving_obstacle_at_the_runs_start_is_refused():
    # At phase 1.0 of the linear motion from y = 0.5 to 5.5 over 4 s the cylinder stands at (5, 1.75).
    robot = "start = [5.0, 1.75]\ngoal = [9.0, 3.0]"
    with pytest.raises(ScenarioError, match=r"robot.start: lies inside moving obstacle world.obstacles\[0\]"):
        parse_scenario(scenario_text(CROSSING, robot), "x.toml")
    # The same place at another phase is free.
    parse_scenario(scenario_text(CROSSING.replace("phase_s = 1.0", "phase_s = 3.0"), robot), "x.toml")


def test_a_random_phase_is_drawn_from_the_seed_within_the_motions_length():
    text = scenario_text(CROSSING.replace("phase_s = 1.0", 'phase_s = "random"'))
    phases = {
        seed: parse_scenario(text, "x.toml", [f"run.seed={seed}"]).world.moving[0].motion.phase_s
        for seed in range(20)
    }
    assert all(0.0 <= phase < 4.0 for phase in phases.values())
    assert len(set(phases.values())) == 20
    again = parse_scenario(text, "x.toml", ["run.seed=7"]).world.moving[0].motion.phase_s
    assert again == phases[7]
    # The file keeps "random": the same scenario saved and read with another seed draws again.
    assert parse_scenario(text, "x.toml").raw["world"]["obstacles"][0]["motion"]["phase_s"] == "random"


def test_static_obstacles_keep_their_file_index_beside_moving_ones():
    obstacles = CROSSING + '[[world.obstacles]]\nkind = "box"\ncenter = [8.0, 1.0]\nsize = [0.5, 0.5]\n'
    scenario = parse_scenario(scenario_text(obstacles), "x.toml")
    assert scenario.world.static_indices() == (1,)
    model = build_model(scenario, rangefinders=False)
    assert model.geom("obstacle1_body").bodyid == model.body("obstacles").id
    assert model.body(int(model.geom("obstacle0_body").bodyid[0])).mocapid[0] == 0


# -- the physics -------------------------------------------------------------------------------
def test_mocap_bodies_follow_their_motion_at_every_physics_step():
    scenario = parse_scenario(scenario_text(CROSSING), "x.toml")
    run = Run(scenario)
    motion = scenario.world.moving[0].motion
    for _ in range(7):
        run.step()
        # The last physics step of the tick began at data.time - dt, with the obstacle set there.
        time_s = run.data.time - run.model.opt.timestep
        np.testing.assert_allclose(run.obstacles()[0], motion.position(time_s), atol=1e-12)
        geom = run.data.geom_xpos[run.model.geom("obstacle0_body").id]
        np.testing.assert_allclose(geom[:2], motion.position(time_s), atol=1e-12)


def test_an_obstacle_that_runs_into_a_robot_standing_still_is_a_collision():
    # A wall-long box sweeps west across the start within a second, faster than the robot can
    # drive off toward its goal 2.5 m north.
    obstacles = """
[[world.obstacles]]
kind = "box"
size = [0.3, 5.0]
[world.obstacles.motion]
keyframes = [[0.0, 4.0, 3.0], [1.0, 0.5, 3.0]]
loop = false
interpolation = "linear"
"""
    robot = "start = [1.5, 3.0]\ngoal = [1.5, 5.5]\nstart_yaw_deg = 90"
    scenario = parse_scenario(scenario_text(obstacles, robot), "x.toml")
    result = Run(scenario).run()
    summary = result.summary
    assert summary.collisions >= 1
    assert summary.moving_obstacles == 1
    assert summary.min_clearance_moving_m < 0
    assert summary.min_clearance_m == summary.min_clearance_moving_m


def test_the_contact_of_any_of_several_moving_obstacles_is_a_collision_and_the_floor_is_not():
    # Two sensors count the robot's contacts with anything and with the floor: the third of
    # three cylinders (the first two far off) running into the robot is a collision; a robot
    # on the floor with nothing near touches nothing.
    far = "".join(
        f"""
[[world.obstacles]]
kind = "cylinder"
radius = 0.3
[world.obstacles.motion]
keyframes = [[0.0, {x}, 5.5], [4.0, {x}, 5.0]]
"""
        for x in (8.0, 9.0)
    )
    onto = """
[[world.obstacles]]
kind = "cylinder"
radius = 0.4
[world.obstacles.motion]
keyframes = [[0.0, 4.0, 3.0], [1.0, 1.5, 3.0]]
loop = false
interpolation = "linear"
"""
    robot = "start = [1.5, 3.0]\ngoal = [1.5, 5.5]\nstart_yaw_deg = 90"
    hit = Run(parse_scenario(scenario_text(far + onto, robot), "x.toml"))
    assert sum(hit.model.sensor_type == mujoco.mjtSensor.mjSENS_CONTACT) == 2
    assert hit.run().summary.collisions >= 1
    clear = Run(parse_scenario(scenario_text(far, robot, "[run]\ntime_limit_s = 3"), "x.toml")).run()
    assert clear.summary.collisions == 0 and clear.summary.min_clearance_moving_m > 0


def test_clearance_to_moving_obstacles_is_measured_where_they_stood():
    discs = np.array([[0.0, 0.0, 0.5]])
    rects = np.array([[0.0, 0.0, 0.5, 0.25, 1.0, 0.0]])
    places = np.array([[[2.0, 0.0], [0.0, 3.0]], [[1.0, 0.0], [0.0, -3.0]]])
    poses = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, math.pi / 2]])
    centre = shapes.moving_distances(discs, rects, places, poses)
    np.testing.assert_allclose(centre, [1.5, 0.5])
    square = np.array([[0.2, 0.2], [-0.2, 0.2], [-0.2, -0.2], [0.2, -0.2]])
    outline = shapes.moving_distances(discs, rects, places, poses, square)
    np.testing.assert_allclose(outline, [1.3, 0.3])
    only_rects = shapes.moving_distances(np.empty((0, 3)), rects, places[:, 1:], poses, square)
    np.testing.assert_allclose(only_rects, [3.0 - 0.25 - 0.2, 3.0 - 0.25 - 0.2])


def test_the_outline_is_measured_only_against_discs_that_can_be_nearest_and_nothing_is_lost():
    # The outline's clearance to many discs equals its least gap to every one of them, each
    # measured (an off-centre outline whose origin lies outside it, overlaps included).
    rng = np.random.default_rng(7)
    count, d = 300, 19
    discs = np.column_stack((np.zeros((d, 2)), rng.uniform(0.2, 0.6, d)))
    places = rng.uniform(-3, 3, (count, d, 2))
    poses = np.column_stack((rng.uniform(-3, 3, (count, 2)), rng.uniform(-math.pi, math.pi, count)))
    outline = np.array([[0.6, 0.1], [0.2, 0.3], [0.1, -0.2], [0.5, -0.3]])
    found = shapes.moving_distances(discs, np.empty((0, 6)), places, poses, outline)
    each = np.array(
        [
            [shapes._polygon_distance(outline, shapes._to_body(places[i, k : k + 1], poses[i : i + 1]))[0]
             - discs[k, 2] for k in range(d)]
            for i in range(count)
        ]
    )  # fmt: skip
    np.testing.assert_array_equal(found, each.min(axis=1))
    assert (found < 0).any() and (found > 0.5).any()


# -- the sensors -------------------------------------------------------------------------------
def random_moving_world(rng: np.random.Generator) -> str:
    """Moving cylinders and boxes on random looping paths, some static boxes."""
    items = []
    for _ in range(int(rng.integers(3, 9))):
        times = np.concatenate(([0.0], np.cumsum(rng.uniform(0.5, 3.0, int(rng.integers(1, 6))))))
        frames = ", ".join(
            f"[{t:.3f}, {x:.3f}, {y:.3f}]"
            for t, (x, y) in zip(times, rng.uniform(1, 9, (len(times), 2)), strict=True)
        )
        if rng.random() < 0.6:
            shape = f'kind = "cylinder"\nradius = {rng.uniform(0.1, 0.7):.3f}'
        else:
            sx, sy, yaw = rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0), rng.uniform(-180, 180)
            shape = f'kind = "box"\nsize = [{sx:.3f}, {sy:.3f}]\nyaw_deg = {yaw:.1f}'
        motion = f'[world.obstacles.motion]\nkeyframes = [{frames}]\nphase_s = "random"\n'
        items.append(f"[[world.obstacles]]\n{shape}\n{motion}")
    for _ in range(int(rng.integers(0, 4))):
        x, y = rng.uniform(1, 9, 2)
        items.append(f'[[world.obstacles]]\nkind = "box"\ncenter = [{x:.3f}, {y:.3f}]\nsize = [0.4, 0.4]\n')
    return "\n".join(items)


@pytest.mark.parametrize("seed", range(8))
def test_the_laser_sees_moving_obstacles_where_mujocos_ray_does(seed):
    rng = np.random.default_rng(seed)
    text = scenario_text(
        random_moving_world(rng), "start = [0.3, 0.3]\ngoal = [9.7, 5.7]", f"[run]\nseed = {seed}"
    )
    scenario = parse_scenario(text.replace("[10.0, 6.0]", "[10.0, 10.0]").replace("5.7]", "9.7]"), "x.toml")
    model = build_model(scenario, rangefinders=False)
    data = mujoco.MjData(model)
    moving = MovingObstacles(model, data, scenario.world)
    world = scenario.world
    caster = RayCaster(shapes.scene_footprints(world.obstacles, world.size))
    obstacle_bodies = [model.body("obstacles").id] + [model.body(f"moving{m.index}").id for m in world.moving]
    model.geom_group[~np.isin(model.geom_bodyid, obstacle_bodies)] = 5
    groups = np.array([1, 1, 1, 1, 1, 0], dtype=np.uint8)
    beams, step = 720, math.radians(270) / 719
    checked = 0
    for time_s in rng.uniform(0, 60, 6):
        moving.place(float(time_s))
        mujoco.mj_kinematics(model, data)
        for origin in rng.uniform(0.2, 9.8, (6, 2)):
            ours = caster.cast(tuple(origin), float(rng.uniform(-4, 4)), step, beams, 15.0, moving.pieces())
            if not np.any(ours > 0):
                continue  # the origin lies inside an obstacle: both casters read 0 or leave it
            first = float(rng.uniform(-4, 4))
            ours = caster.cast(tuple(origin), first, step, beams, 15.0, moving.pieces())
            angles = first + step * np.arange(beams)
            vec = np.column_stack((np.cos(angles), np.sin(angles), np.zeros(beams)))
            geom, dist = np.zeros(beams, np.int32), np.zeros(beams)
            point = np.array([origin[0], origin[1], MOUNT_HEIGHT_M])
            mujoco.mj_multiRay(
                model, data, point, vec.ravel(), groups, 1, -1, geom, dist, None, beams, np.inf
            )
            theirs = np.where((dist < 0) | (dist > 15.0), np.inf, dist)
            np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-3)
            checked += int(np.isfinite(ours).sum())
    assert checked > 1000


def test_the_sonar_hears_a_moving_obstacle_where_it_stands():
    # A cylinder parked 1 m ahead of the robot at the run's start (a motion that stays put there
    # for 10 s, then leaves): the front sonar echoes it at first, not once it has gone.
    obstacles = """
[[world.obstacles]]
kind = "cylinder"
radius = 0.3
[world.obstacles.motion]
keyframes = [[0.0, 3.0, 3.0], [10.0, 3.0, 3.0], [11.0, 3.0, 5.5]]
loop = false
interpolation = "linear"
"""
    robot = "start = [1.7, 3.0]\ngoal = [1.7, 0.5]\nstart_yaw_deg = 0"
    scenario = parse_scenario(scenario_text(obstacles, robot), "x.toml")
    run = Run(scenario)
    first = run.observe()
    assert first is not None
    front = int(np.argmin(np.abs(first.bearings)))
    assert first.ranges[front] == pytest.approx(3.0 - 0.3 - 1.7, abs=0.05)
    run.moving.place(12.0)
    mujoco.mj_kinematics(run.model, run.data)
    assert np.isnan(run.sensor.read(1.7, 3.0, 0.0)[front])
