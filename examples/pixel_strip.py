"""Pixel observations of one episode, saved as a strip: dm_control's pixel wrapper on the dm_env
environment, driven by a planner.

1. `VPlaneNavDmEnv` runs the scenario; `dm_control.suite.wrappers.pixels.Wrapper` adds the view
   of its top camera to every observation (`pixels`), and a second one the view of the chase
   camera behind the robot (`chase`), each an H x W x 3 uint8 image of the current state.
2. `PlannerPolicy` drives the episode with a planner (a built-in one, or your own as
   `file.py:Class`), as `vplane-mj run` would.
3. The strip: `--frames` observations evenly spaced over the episode, first and last included,
   the top camera's row above the chase camera's, written as one PNG (the pixels as observed).

    python examples/pixel_strip.py                      # paper_c_escape, vplane; logs/pixel_strip/
    python examples/pixel_strip.py paper_h_escape --planner bug2 --frames 6 --size 96
    python examples/pixel_strip.py --planner examples/random_walk_planner.py:RandomWalkPlanner
"""

from __future__ import annotations

import argparse
import sys
from argparse import RawDescriptionHelpFormatter
from pathlib import Path

import numpy as np

import vplane_mj  # before dm_control: it picks OSMesa for rendering unless MUJOCO_GL is set
from vplane_mj.envs import PlannerPolicy, VPlaneNavDmEnv
from vplane_mj.planning.protocol.registry import load_planner

# isort: split
from dm_control.suite.wrappers import pixels
from matplotlib import image

GAP_PX = 4
"""White space between the pictures of the strip (px)."""


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=RawDescriptionHelpFormatter)
    parser.add_argument("scenario", nargs="?", default="paper_c_escape", help="a scenario file or name")
    parser.add_argument("--planner", default="vplane", help="a planner's name, or file.py:Class")
    parser.add_argument("--seed", type=int, default=0, help="the episode's seed (run.seed)")
    parser.add_argument("--frames", type=int, default=8, help="pictures per camera in the strip (>= 2)")
    parser.add_argument("--size", type=int, default=160, help="height of each picture (px); width 4/3 of it")
    parser.add_argument("--out", type=Path, default=Path("logs/pixel_strip"), help="output directory")
    args = parser.parse_args()
    if args.frames < 2 or not 16 <= args.size <= 600:
        raise vplane_mj.VPlaneError("--frames must be at least 2 and --size within [16, 600] px")
    return args


def episode_views(env: VPlaneNavDmEnv, policy: PlannerPolicy, height: int) -> tuple[list, list[float]]:
    """Every TimeStep of one episode, each observation with `pixels` (top) and `chase` images,
    and the simulated time of each (s)."""
    size = {"height": height, "width": height * 4 // 3}
    top = pixels.Wrapper(env, pixels_only=False, render_kwargs={**size, "camera_id": "top"})
    both = pixels.Wrapper(
        top, pixels_only=False, render_kwargs={**size, "camera_id": "robot/chase"}, observation_key="chase"
    )
    steps, times = [both.reset()], [env.info["time_s"]]
    while not steps[-1].last():
        steps.append(both.step(policy(steps[-1])))
        times.append(env.info["time_s"])
    return steps, times


def strip(rows: list[list[np.ndarray]]) -> np.ndarray:
    """The pictures of each row side by side, the rows one above the other, GAP_PX apart (white)."""
    height, width, _ = rows[0][0].shape
    columns = len(rows[0])
    canvas = np.full(
        (len(rows) * (height + GAP_PX) - GAP_PX, columns * (width + GAP_PX) - GAP_PX, 3), 255, np.uint8
    )
    for r, row in enumerate(rows):
        for c, picture in enumerate(row):
            top, left = r * (height + GAP_PX), c * (width + GAP_PX)
            canvas[top : top + height, left : left + width] = picture
    return canvas


def main() -> None:
    args = parse_args()
    planner = load_planner(args.planner) if ":" in args.planner else args.planner
    # Velocity actions carry any planner's decision, a force or a commanded speed and turn rate.
    env = VPlaneNavDmEnv(args.scenario, action="velocity", seed=args.seed)
    try:
        steps, times = episode_views(env, PlannerPolicy(env, planner), args.size)
        summary = env.info["summary"]
    finally:
        env.close()  # frees the Physics and its rendering contexts
    chosen = np.linspace(0, len(steps) - 1, args.frames).round().astype(int)
    shown = ", ".join(f"{times[i]:.1f}" for i in chosen)
    print(
        f"{summary['scenario']} [{args.planner}, seed {summary['seed']}]: {summary['outcome']} after "
        f"{summary['sim_time_s']:.2f} s simulated, {len(steps)} observations; the strip shows t = {shown} s"
    )
    rows = [[steps[i].observation[key] for i in chosen] for key in ("pixels", "chase")]
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / f"{summary['scenario']}-pixels.png"
    image.imsave(path, strip(rows))
    print(f"wrote {path}")


if __name__ == "__main__":
    try:
        main()
    except vplane_mj.VPlaneError as exc:  # bad input: the message names the key and the reason
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
