"""dm_control's `Physics` over the model and data an episode's run steps: one simulation, which the
run advances and dm_control reads, renders and names (`physics.named.data.xpos["robot/base_link"]`).

dm_control 1.0.50 predates MuJoCo 4.0: the table behind its named indexing
(`dm_control.mujoco.wrapper.mjbindings.sizes.array_sizes`) lists fields of mjModel and mjData that
MuJoCo 4.0 removed (the flex vertices' edges, metric and Jacobian), and making a Physics fails on
them. `_forget_removed_fields` takes exactly those out of the table, once, when the first
environment's Physics is made (never on `import vplane_mj`): the one place the package touches
dm_control's internals.
"""

from __future__ import annotations

import functools
from typing import Any

import mujoco
from dm_control import mujoco as dm_mujoco
from dm_control.mujoco.wrapper import MjData
from dm_control.mujoco.wrapper.mjbindings import sizes

from vplane_mj.scenario import Scenario
from vplane_mj.sim.world import RENDER_PIXELS, TOP_CAMERA, build_model, top_view_extent

OFFSCREEN_PX = RENDER_PIXELS
"""Every episode's model renders offscreen up to this many pixels (px) in width and in height."""


class NavigationPhysics(dm_mujoco.Physics):
    """dm_control's Physics of a navigation world whose top camera frames the arena at any aspect.

    MuJoCo's orthographic camera keeps its vertical extent and widens or narrows its view with
    the image's aspect; `render` sets the extent so that the arena and its border fit whole in
    the image asked for (wider than the arena: floor left and right; narrower: above and below).
    `arena_view_m` is the width and height (m) of floor to frame (None: the camera as it is).
    """

    arena_view_m: tuple[float, float] | None = None

    def render(self, height: int = 240, width: int = 320, camera_id: int | str = -1, **options: Any) -> Any:
        """dm_control's `Physics.render` (the same arguments), the top camera fitted first."""
        camera = self.model.name2id(camera_id, "camera") if isinstance(camera_id, str) else camera_id
        if self.arena_view_m is not None and camera == self.model.name2id(TOP_CAMERA, "camera"):
            view_width, view_height = self.arena_view_m
            self.model.cam_fovy[camera] = max(view_height, view_width * height / width)
        return super().render(height, width, camera_id, **options)


def episode_physics(scenario: Scenario) -> NavigationPhysics:
    """A fresh Physics of the scenario's world as a run steps it (`world.build_model` without
    rangefinders), its kinematics computed, able to render up to OFFSCREEN_PX on each side.
    Hand `physics.model.ptr` and `physics.data.ptr` to `vplane_mj.sim.loop.Run`; call `free()`
    when done with it (its rendering contexts)."""
    _forget_removed_fields()
    model = build_model(scenario, rangefinders=False)
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, OFFSCREEN_PX)
    model.vis.global_.offheight = max(model.vis.global_.offheight, OFFSCREEN_PX)
    physics = NavigationPhysics(MjData(mujoco.MjData(model)))
    physics.arena_view_m = top_view_extent(scenario.world.size)
    return physics


@functools.cache
def _forget_removed_fields() -> None:
    """Drop from dm_control's size table the fields this MuJoCo's mjModel and mjData lack (once)."""
    probe = mujoco.MjModel.from_xml_string("<mujoco/>")
    for struct, instance in (("mjmodel", probe), ("mjdata", mujoco.MjData(probe))):
        table = sizes.array_sizes[struct]
        for name in [name for name in table if not hasattr(instance, name)]:
            del table[name]
