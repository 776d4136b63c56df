"""dm_control on the dm_env environment (docs/environments.md): its Physics over the model and data
the run steps, the cameras and goal marker of every world, pixel observations from dm_control's
wrapper (the robot where it is; the same episodes with and without the wrapper), action scaling,
and the fit of dm_control's size table to MuJoCo 4.0 made only when an environment needs it."""

import subprocess
import sys

import dm_env
import mujoco
import numpy as np
import pytest
from dm_control import mujoco as dm_mujoco
from dm_control.suite.wrappers import action_scale, pixels

from vplane_mj.envs import VPlaneNavDmEnv
from vplane_mj.envs.physics import OFFSCREEN_PX
from vplane_mj.envs.task import family_case
from vplane_mj.files import data_dir
from vplane_mj.robots.facts import BASE_BODY
from vplane_mj.scenario import load_scenario, parse_scenario
from vplane_mj.sim.world import (
    BORDER_SIDES,
    CHASE_BACK_M,
    CHASE_CAMERA,
    CHASE_UP_M,
    GOAL_SITE,
    ROBOT_PREFIX,
    TOP_CAMERA,
    build_model,
)

CHASE_NAME = ROBOT_PREFIX + CHASE_CAMERA
"""The chase camera's name in the world."""
BASE_LINK = ROBOT_PREFIX + BASE_BODY


def is_robot_colour(pixel: np.ndarray) -> bool:
    """The default robot's orange (rgba 0.85 0.45 0.15), lit: not the grey floor and walls, the
    blue obstacles or the yellow goal marker (whose green is close to its red)."""
    red, green, blue = (float(channel) for channel in pixel)
    return red > 150 and 0.4 < green / red < 0.75 and blue < 0.5 * red


def robot_seen_at(image: np.ndarray, pixel: tuple[int, int]) -> bool:
    """Some pixel of the 3 x 3 around `pixel` has the robot's colour (an edge pixel may be blended)."""
    row, column = pixel
    return any(
        is_robot_colour(colour) for colour in image[row - 1 : row + 2, column - 1 : column + 2].reshape(-1, 3)
    )


def top_pixel(physics, point, height: int, width: int) -> tuple[int, int]:
    """Row and column where the top camera's latest image (height x width) shows the world point
    (x, y in m): orthographic, centred on the camera, `cam_fovy` metres high."""
    camera = physics.model.name2id(TOP_CAMERA, "camera")
    centre = physics.data.cam_xpos[camera]
    metres_per_px = physics.model.cam_fovy[camera] / height
    return (
        int(height / 2 - (point[1] - centre[1]) / metres_per_px),
        int(width / 2 + (point[0] - centre[0]) / metres_per_px),
    )


def chase_pixel(physics, point, height: int, width: int) -> tuple[int, int]:
    """Row and column where the chase camera shows the world point (x, y, z in m): dm_control's
    camera matrix (a perspective camera)."""
    xs, ys, s = dm_mujoco.Camera(physics, height, width, camera_id=CHASE_NAME).matrix @ [*point, 1.0]
    return int(ys / s), int(xs / s)


def test_physics_is_dm_controls_over_the_model_and_data_the_run_steps():
    env = VPlaneNavDmEnv("single_box", action="velocity", overrides=["run.time_limit_s=1"])
    ready = env.physics  # made before the first episode, so that it can be rendered at once
    assert isinstance(ready, dm_mujoco.Physics) and ready.data.time == 0.0
    env.reset()
    run = env.task.run
    assert env.physics is ready and ready.model.ptr is run.model and ready.data.ptr is run.data
    for _ in range(5):
        time_step = env.step(np.array([0.4, 1.0]))
    assert ready.data.time == pytest.approx(env.info["time_s"]) and ready.data.time == pytest.approx(0.25)
    assert np.array_equal(ready.named.data.xpos[BASE_LINK][:2], run.position)
    while not time_step.last():
        time_step = env.step(np.array([0.4, 1.0]))
    assert env.physics is ready  # the episode that has just ended
    env.reset()
    assert env.physics is not ready and env.physics.data.ptr is env.task.run.data
    env.close()
    assert env.task.run is None and env.physics.data.time == 0.0  # the next episode's, new
    env.close()


@pytest.mark.slow  # a process of its own
def test_the_size_table_is_fitted_when_the_first_physics_is_made_and_not_on_import():
    script = """
import sys
import mujoco
import vplane_mj
assert "dm_control" not in sys.modules, "import vplane_mj loaded dm_control"
from vplane_mj.envs import VPlaneNavDmEnv
env = VPlaneNavDmEnv("single_box")
from dm_control.mujoco.wrapper.mjbindings import sizes
model = mujoco.MjModel.from_xml_string("<mujoco/>")
def unknown():
    return [name for name in sizes.array_sizes["mjmodel"] if not hasattr(model, name)]
print("before", len(unknown()))
env.physics.render(32, 32, camera_id="top")
print("after", len(unknown()))
env.close()
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    # dm_control 1.0.50 names 7 mjModel fields that MuJoCo 4.0 removed; once a dm_control that
    # knows MuJoCo 4.0 lists none, vplane_mj.envs.physics need not fit its table any more.
    assert done.stdout.split() == ["before", "7", "after", "0"]
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr  # closed cleanly


WORLDS = [load_scenario(path.stem) for path in sorted(data_dir("scenarios").glob("*.toml"))]
WORLDS += [parse_scenario(family_case(family, 0).toml(), family) for family in ("traps", "corridors", "barn")]


@pytest.mark.parametrize("scenario", WORLDS, ids=[scenario.name for scenario in WORLDS])
def test_every_world_has_the_top_and_chase_cameras_and_the_goal_marker(scenario):
    model = build_model(scenario, rangefinders=False)
    top, chase = model.camera(TOP_CAMERA), model.camera(CHASE_NAME)
    assert top.bodyid[0] == 0 and model.cam_projection[top.id] == mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC
    assert np.allclose(top.pos[:2], np.array(scenario.world.size) / 2)
    assert (
        chase.bodyid[0] == model.body(BASE_LINK).id and chase.mode[0] == mujoco.mjtCamLight.mjCAMLIGHT_FIXED
    )
    assert np.allclose(chase.pos, [-CHASE_BACK_M, 0.0, CHASE_UP_M])
    goal = model.site(GOAL_SITE)
    assert goal.bodyid[0] == 0 and np.allclose(goal.pos[:2], scenario.robot.goal)
    assert goal.size[0] == pytest.approx(scenario.robot.goal_tolerance)


@pytest.mark.parametrize("name", ["single_box", "barn"])
@pytest.mark.parametrize(("height", "width"), [(64, 128), (128, 64), (96, 96)])
def test_the_top_camera_frames_the_whole_arena_at_any_aspect(name, height, width):
    scenario = parse_scenario(family_case("barn", 0).toml(), "barn") if name == "barn" else name
    with VPlaneNavDmEnv(scenario) as env:
        physics, size = env.physics, env.task.episode_scenario(0).world.size
        # dm_control's own render shows the camera as the world defines it, fitted to the arena's
        # aspect: it crops a 6 x 4 m arena in a square or tall image.
        plain = dm_mujoco.Physics.render(physics, height, width, camera_id=TOP_CAMERA, segmentation=True)
        labels = physics.render(height, width, camera_id=TOP_CAMERA, segmentation=True)
        metres_per_px = physics.model.cam_fovy[physics.model.name2id(TOP_CAMERA, "camera")] / height
        walls = {side: physics.model.name2id(f"border_{side}", "geom") for side in BORDER_SIDES}

    def span(side: str, image: np.ndarray) -> tuple[int, int]:
        """How many rows and columns of `image` show the border wall `side`."""
        shown = (image[..., 0] == walls[side]) & (image[..., 1] == mujoco.mjtObj.mjOBJ_GEOM)
        return int(shown.any(axis=1).sum()), int(shown.any(axis=0).sum())

    arena_w, arena_h = (metres / metres_per_px for metres in size)
    spans = {side: span(side, labels) for side in BORDER_SIDES}
    assert min(spans["west"][0], spans["east"][0]) >= 0.95 * arena_h  # the whole height
    assert min(spans["south"][1], spans["north"][1]) >= 0.95 * arena_w  # the whole width
    if name == "single_box" and height >= width:
        assert span("west", plain) == span("east", plain) == (0, 0)


def test_the_offscreen_buffer_holds_renders_up_to_its_size_in_every_world():
    env = VPlaneNavDmEnv(parse_scenario(family_case("barn", 0).toml(), "barn"))  # 4.2 x 10.5 m: narrow
    frame = env.physics.render(OFFSCREEN_PX, OFFSCREEN_PX, camera_id=CHASE_NAME)
    assert frame.shape == (OFFSCREEN_PX, OFFSCREEN_PX, 3) and frame.dtype == np.uint8
    env.close()


def wrapped(env, height=48, width=64):
    """The environment with the top camera's `pixels` and the chase camera's `chase` observations."""
    top = pixels.Wrapper(
        env, pixels_only=False, render_kwargs={"height": height, "width": width, "camera_id": TOP_CAMERA}
    )
    size = {"height": height, "width": width}
    return pixels.Wrapper(
        top, pixels_only=False, render_kwargs={**size, "camera_id": CHASE_NAME}, observation_key="chase"
    )


def test_pixel_observations_are_the_cameras_views_of_the_robot_where_it_is():
    env = VPlaneNavDmEnv("paper_c_escape", action="velocity", overrides=["run.time_limit_s=5"])
    height, width = 120, 160  # the top camera: 9 cm a pixel, the robot 22 cm across
    views = wrapped(env, height, width)
    spec = views.observation_spec()
    assert sorted(spec) == ["chase", "echo", "goal", "pixels", "ranges", "velocity"]
    assert spec["pixels"].shape == spec["chase"].shape == (height, width, 3)
    assert spec["pixels"].dtype == np.uint8
    time_step, start = views.reset(), env.physics.named.data.xpos[BASE_LINK].copy()
    for tick in range(100):
        if tick % 20 == 0:
            physics, observation = env.physics, time_step.observation
            robot = physics.named.data.xpos[BASE_LINK].copy()
            top = observation["pixels"]
            assert np.array_equal(top, physics.render(height, width, camera_id=TOP_CAMERA))
            assert robot_seen_at(top, top_pixel(physics, robot, height, width)), tick
            assert robot_seen_at(observation["chase"], chase_pixel(physics, robot, height, width)), tick
        time_step = views.step(np.array([0.5, 0.8]))  # an arc out of the trap's mouth
    assert time_step.last() and np.hypot(*(robot - start)[:2]) > 0.8  # the robot moved
    assert not robot_seen_at(top, top_pixel(physics, start, height, width))  # and left its start
    env.close()


def episode_steps(env, actions):
    steps = [env.reset()]
    steps += [env.step(action) for action in actions]
    return steps


def test_the_same_seed_gives_the_same_observations_with_and_without_the_wrapper():
    options = {
        "family": "clutter",
        "seed": 3,
        "overrides": ["run.time_limit_s=1.5", "sensors.noise_std=0.02"],
    }
    actions = np.random.default_rng(1).uniform(-1.0, 1.0, (45, 2))  # across an episode's end
    plain = episode_steps(VPlaneNavDmEnv(**options), actions)
    first_env, again_env = VPlaneNavDmEnv(**options), VPlaneNavDmEnv(**options)
    first = episode_steps(wrapped(first_env), actions)
    again = episode_steps(wrapped(again_env), actions)
    assert [step.step_type for step in plain].count(dm_env.StepType.FIRST) == 2
    for bare, seen, seen_again in zip(plain, first, again, strict=True):
        assert (bare.step_type, bare.reward, bare.discount) == (seen.step_type, seen.reward, seen.discount)
        assert all(np.array_equal(bare.observation[key], seen.observation[key]) for key in bare.observation)
        assert np.array_equal(seen.observation["pixels"], seen_again.observation["pixels"])
        assert np.array_equal(seen.observation["chase"], seen_again.observation["chase"])
    assert not np.array_equal(first[0].observation["pixels"], first[-1].observation["pixels"])
    first_env.close()
    again_env.close()


def test_dm_controls_action_scaling_maps_its_box_onto_the_velocity_bounds():
    options = {"action": "velocity", "overrides": ["run.time_limit_s=2"]}
    env = VPlaneNavDmEnv("single_box", **options)
    scaled = action_scale.Wrapper(VPlaneNavDmEnv("single_box", **options), -np.ones(2), np.ones(2))
    assert np.array_equal(scaled.action_spec().minimum, [-1.0, -1.0])
    plain = episode_steps(env, [np.array([0.5, -1.25])] * 20)  # (v, omega) within [0.5, 2.5]
    same = episode_steps(scaled, [np.array([1.0, -0.5])] * 20)
    for a, b in zip(plain, same, strict=True):
        assert all(np.array_equal(a.observation[key], b.observation[key]) for key in a.observation)


def test_velocity_actions_are_bounded_by_the_robots_own_limits():
    jackal = VPlaneNavDmEnv("single_box", action="velocity", overrides=["robot.profile=jackal"])
    assert np.array_equal(jackal.action_spec().maximum, [2.0, 4.0])
