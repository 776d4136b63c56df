"""Flat shapes for MuJoCo's top camera: discs, line segments and triangles lying at a height
above the floor, added to a scene as its own geoms. A higher shape hides a lower one."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from vplane_mj.viz.palette import RGBA

DISC_HALF_HEIGHT_M = 0.0005
"""Half the height of a disc's cylinder: flat, under the next shape up."""

Point = tuple[float, float] | np.ndarray
"""A point (x, y) on the floor (m)."""


@dataclass(frozen=True)
class Disc:
    """A filled disc: centre (x, y) and radius (m), colour, height (m)."""

    center: Point
    radius_m: float
    rgba: RGBA
    z_m: float


@dataclass(frozen=True)
class Segment:
    """A line from a to b (x, y; m), `width_px` pixels wide, at height `z_m` (m)."""

    a: Point
    b: Point
    rgba: RGBA
    width_px: float
    z_m: float


@dataclass(frozen=True)
class Triangle:
    """A filled triangle of three corners (3, 2; m) at height `z_m` (m)."""

    corners: np.ndarray
    rgba: RGBA
    z_m: float


Shape = Disc | Segment | Triangle


def add_shapes(scene: mujoco.MjvScene, shapes: list[Shape]) -> None:
    """Add each shape to `scene` as a geom (the scene must have room for them)."""
    if scene.ngeom + len(shapes) > scene.maxgeom:
        raise ValueError(f"the scene holds {scene.maxgeom} geoms: no room for {len(shapes)} more")
    for shape in shapes:
        geom = scene.geoms[scene.ngeom]
        if isinstance(shape, Disc):
            _init(geom, mujoco.mjtGeom.mjGEOM_CYLINDER, (shape.radius_m, DISC_HALF_HEIGHT_M, 0.0), shape)
            geom.pos[:] = (*shape.center, shape.z_m)
        elif isinstance(shape, Segment):
            _init(geom, mujoco.mjtGeom.mjGEOM_LINE, (0.0, 0.0, 0.0), shape)
            a, b = np.array([*shape.a, shape.z_m]), np.array([*shape.b, shape.z_m])
            mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_LINE, shape.width_px, a, b)
        else:
            _init(geom, mujoco.mjtGeom.mjGEOM_TRIANGLE, (1.0, 1.0, 1.0), shape)
            first, second, third = np.column_stack((shape.corners, np.full(3, shape.z_m)))
            # MuJoCo's triangle has the corners (0, 0), (size[0], 0) and (0, size[1]) of its
            # frame: a frame whose x and y axes are the edges from the first corner (not a
            # rotation) makes it any triangle.
            geom.pos[:] = first
            geom.mat[:] = np.column_stack((second - first, third - first, (0.0, 0.0, 1.0)))
        scene.ngeom += 1


def _init(geom, kind: mujoco.mjtGeom, size: tuple[float, float, float], shape: Shape) -> None:
    mujoco.mjv_initGeom(
        geom,
        type=kind,
        size=np.array(size),
        pos=np.zeros(3),
        mat=np.eye(3).flatten(),
        rgba=np.array(shape.rgba, dtype=np.float32),
    )
