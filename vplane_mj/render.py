"""Offscreen (OSMesa by default) top-down PNG of a run: arena, obstacles, start, goal and the path."""

from __future__ import annotations

import itertools
from pathlib import Path

import matplotlib.image
import mujoco
import numpy as np

from vplane_mj.sim import RunResult
from vplane_mj.world import build_model

PATH_RGBA = (0.85, 0.1, 0.1, 1.0)
START_RGBA = (0.1, 0.6, 0.1, 1.0)
GOAL_RGBA = (0.95, 0.75, 0.0, 1.0)
COLLISION_RGBA = (0.6, 0.0, 0.6, 1.0)
MAX_PATH_SEGMENTS = 3000
MARKER_HEIGHT_M = 0.6
"""Markers and the path are drawn above the obstacles (0.5 m) so nothing hides them."""


def render_top_view(scenario, result: RunResult) -> np.ndarray:
    """RGB image (H, W, 3) of the whole arena from the orthographic top camera."""
    model = build_model(scenario)
    data = mujoco.MjData(model)
    data.qpos[:] = result.final_qpos
    mujoco.mj_forward(model, data)
    height, width = model.vis.global_.offheight, model.vis.global_.offwidth
    with mujoco.Renderer(model, height=height, width=width, max_geom=MAX_PATH_SEGMENTS + 500) as renderer:
        options = mujoco.MjvOption()
        options.flags[mujoco.mjtVisFlag.mjVIS_RANGEFINDER] = False
        renderer.update_scene(data, camera="top", scene_option=options)
        scene = renderer.scene
        _add_disc(scene, scenario.robot.start, 0.12, START_RGBA)
        _add_disc(scene, scenario.robot.goal, scenario.robot.goal_tolerance, GOAL_RGBA)
        for point in result.collision_points:
            _add_disc(scene, point, 0.06, COLLISION_RGBA)
        _add_polyline(scene, result.positions, PATH_RGBA)
        return renderer.render()


def write_png(image: np.ndarray, path: Path) -> None:
    """Save an RGB image as PNG."""
    matplotlib.image.imsave(path, image, format="png")


def _add_disc(scene: mujoco.MjvScene, center, radius: float, rgba) -> None:
    if scene.ngeom >= scene.maxgeom:
        return
    mujoco.mjv_initGeom(
        scene.geoms[scene.ngeom],
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=np.array([radius, 0.005, 0.0]),
        pos=np.array([center[0], center[1], MARKER_HEIGHT_M]),
        mat=np.eye(3).flatten(),
        rgba=np.array(rgba, dtype=np.float32),
    )
    scene.ngeom += 1


def _add_polyline(scene: mujoco.MjvScene, points: np.ndarray, rgba) -> None:
    """Line geoms through `points` (N, 2), decimated to at most MAX_PATH_SEGMENTS segments."""
    if len(points) < 2:
        return
    stride = max(1, int(np.ceil((len(points) - 1) / MAX_PATH_SEGMENTS)))
    kept = np.vstack([points[::stride], points[-1:]])
    z = MARKER_HEIGHT_M + 0.01
    for a, b in itertools.pairwise(kept):
        if scene.ngeom >= scene.maxgeom:
            return
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(
            geom,
            type=mujoco.mjtGeom.mjGEOM_LINE,
            size=np.zeros(3),
            pos=np.zeros(3),
            mat=np.eye(3).flatten(),
            rgba=np.array(rgba, dtype=np.float32),
        )
        mujoco.mjv_connector(
            geom, mujoco.mjtGeom.mjGEOM_LINE, 4.0, np.array([a[0], a[1], z]), np.array([b[0], b[1], z])
        )
        scene.ngeom += 1
