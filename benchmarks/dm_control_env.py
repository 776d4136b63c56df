"""What dm_control costs and saves in the dm_env environment (docs/environments.md).

1. A step of `VPlaneNavDmEnv` on a scenario, plain and through dm_control's pixel wrapper with
   each camera at two image sizes: medians over `--steps` steps (velocity actions on an arc).
2. A `reset`: the dm_env environment's (its world built and wrapped in dm_control's Physics)
   against the shared task's begin without a Physics (the Gymnasium environment's).
3. Building and compiling a world: with MuJoCo's MjSpec (`vplane_mj.sim.world.build_model`, what
   a run does) and with `dm_control.mjcf` (the arena and robot files parsed, the obstacles, the
   border and the sonar sites added, the robot attached, the XML compiled; without the bump
   sensor, camera sizing, goal marker and motor faults, which favours mjcf).

The tables are written to `OUT/dm_control_env.md` (steps), `dm_control_env_reset.md` and
`dm_control_env_build.md`, with their `.csv` and `.json` (the command and the date).

    python benchmarks/dm_control_env.py [SCENARIO] [--steps 200] [--repeat 20] [--out logs/dm_control_env]
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from vplane_mj.bench import options  # vplane_mj before dm_control: OSMesa unless MUJOCO_GL is set
from vplane_mj.bench.tables import formatted, markdown_table, write_table
from vplane_mj.envs import VPlaneNavDmEnv
from vplane_mj.envs.task import NavigationTask
from vplane_mj.files import model_path, prepare_out_dir
from vplane_mj.geometry import shapes
from vplane_mj.robots.facts import BASE_BODY
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario import Scenario, load_scenario
from vplane_mj.sim.world import BORDER_SIDES, OBSTACLE_HEIGHT_M, SonarLayout, build_model

# isort: split
from dm_control import mjcf
from dm_control.suite.wrappers import pixels

SIZES = ((84, 84), (240, 320))
"""(height, width) of the pixel observations timed (px)."""


def median_ms(action: Callable[[], object], repeat: int) -> float:
    """Median wall time (ms) of `repeat` calls of `action`, after one untimed call."""
    action()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        action()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def step_table(scenario: str, steps: int) -> list[dict]:
    """A step's median wall time (ms), plain and with each camera's pixels at each size."""
    table = []
    with VPlaneNavDmEnv(scenario, action="velocity") as env:
        views = [("no pixels", env)]
        for camera in ("top", "robot/chase"):
            for height, width in SIZES:
                view = pixels.Wrapper(
                    env, render_kwargs={"height": height, "width": width, "camera_id": camera}
                )
                views.append((f"pixels {camera} {height} x {width}", view))
        arc = np.array([0.3, 0.4])
        for name, view in views:
            view.reset()
            table.append({"environment": name, "step ms": median_ms(lambda view=view: view.step(arc), steps)})
    return table


def reset_table(scenario: str, repeat: int) -> list[dict]:
    """A reset with dm_control's Physics against the task's begin without one (ms)."""
    with VPlaneNavDmEnv(scenario) as env:
        with_physics = median_ms(env.reset, repeat)
    task = NavigationTask(scenario)
    without = median_ms(lambda: task.begin(task.episode_scenario(0)), repeat)
    return [
        {"reset": "dm_env, with a Physics", "ms": with_physics},
        {"reset": "the task's begin, without", "ms": without},
    ]


def mjcf_model(scenario: Scenario) -> mujoco.MjModel:
    """The scenario's world built with dm_control.mjcf and compiled (see the module docstring)."""
    arena = mjcf.from_path(str(model_path("arena.xml")))
    arena.option.timestep = scenario.run.physics_dt_s
    statics = arena.worldbody.add("body", name="obstacles")
    half_z = OBSTACLE_HEIGHT_M / 2
    pieces = []
    if scenario.world.border:
        border = shapes.border_footprint(scenario.world.size)
        pieces += [
            (f"border_{side}", piece, "border") for side, piece in zip(BORDER_SIDES, border, strict=True)
        ]
    for index, obstacle in enumerate(scenario.world.obstacles):
        pieces += [
            (f"obstacle{index}_{k}", piece, "obstacle") for k, piece in enumerate(obstacle.footprint())
        ]
    for name, piece, material in pieces:
        if isinstance(piece, shapes.Disc):
            shape = {"type": "cylinder", "size": [piece.radius, half_z], "pos": [*piece.center, half_z]}
        else:
            shape = {"type": "box", "size": [*piece.half, half_z], "pos": [*piece.center, half_z]}
            shape["euler"] = [0.0, 0.0, piece.yaw]
        statics.add("geom", name=name, material=material, **shape)
    robot = mjcf.from_path(str(model_path(robot_profile(scenario.robot.profile).model_file)))
    base = robot.find("body", BASE_BODY)
    layout = SonarLayout.from_spec(scenario.sensors, scenario.robot.profile)
    for k, bearing in enumerate(layout.bearings):
        for j, offset in enumerate(layout.ray_offsets):
            ray = [math.cos(bearing + offset), math.sin(bearing + offset), 0.0]
            mount = [*layout.mounts[k], layout.height_m]
            base.add("site", name=f"sonar{k}_ray{j}", pos=mount, zaxis=ray, size=[0.004])
    frame = arena.attach(robot)
    frame.pos = [*scenario.robot.start, 0.0]
    frame.add("freejoint")
    return mujoco.MjModel.from_xml_string(arena.to_xml_string(), arena.get_assets())


def build_table(scenario: str, repeat: int) -> list[dict]:
    """Building and compiling the world with MjSpec and with dm_control.mjcf (ms)."""
    world = load_scenario(scenario)
    spec_ms = median_ms(lambda: build_model(world, rangefinders=False), repeat)
    mjcf_ms = median_ms(lambda: mjcf_model(world), repeat)
    title = f"building the {scenario} world"
    return [{title: "MjSpec", "ms": spec_ms}, {title: "dm_control.mjcf", "ms": mjcf_ms}]


def publish(out: Path, stem: str, table: list[dict], digits: int) -> list[Path]:
    """`table` printed and written as `stem` into `out`, its times with `digits` decimals."""
    columns = list(table[0])
    text = markdown_table(table, columns, formatted({columns[1]: f".{digits}f"}))
    print(f"\n{text}")
    return write_table(out, stem, table, columns, text)


@options.refusing
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", type=options.scenario, default="paper_c_escape")
    parser.add_argument("--steps", type=options.whole(1), default=200, help="steps timed per variant")
    parser.add_argument("--repeat", type=options.whole(1), default=20, help="resets and builds timed")
    parser.add_argument("--out", type=Path, default=Path("logs/dm_control_env"))
    args = parser.parse_args(argv)
    out = prepare_out_dir(args.out)
    written = publish(out, "dm_control_env", step_table(args.scenario, args.steps), 2)
    written += publish(out, "dm_control_env_reset", reset_table(args.scenario, args.repeat), 1)
    written += publish(out, "dm_control_env_build", build_table(args.scenario, args.repeat), 1)
    print("\n" + "\n".join(f"wrote {path}" for path in written))
    return 0


if __name__ == "__main__":
    sys.exit(main())
