"""Facts about the robot model in models/robot.xml that the rest of the code relies on."""

from __future__ import annotations

import functools
import math

import mujoco
import numpy as np

from vplane_mj.resources import model_path

BASE_BODY = "base_link"
WHEEL_JOINTS = ("wheel_left", "wheel_right")
WHEEL_MOTORS = ("wheel_left", "wheel_right")
SONAR_MOUNT_HEIGHT_M = 0.07
"""Height of the sonar sites above base_link's origin: above the wheels (top at 0.04 m)."""
SONAR_MOUNT_RADIUS_M = 0.10
"""Distance of the sonar sites from base_link's vertical axis."""


@functools.cache
def robot_geometry() -> dict[str, float]:
    """Wheel radius and track (m), torque limit (N m) and footprint radius, read from robot.xml."""
    model = mujoco.MjModel.from_xml_path(str(model_path("robot.xml")))
    wheel = model.geom("wheel_left")
    left = model.body("wheel_left").pos
    right = model.body("wheel_right").pos
    return {
        "wheel_radius_m": float(wheel.size[0]),
        "track_m": float(abs(left[1] - right[1])),
        "torque_limit_nm": float(model.actuator("wheel_left").forcerange[1]),
        "radius_m": round(footprint_radius(model), 9),
    }


def robot_radius_m() -> float:
    """Radius (m) of a disc around base_link's centre that contains every robot geom."""
    return robot_geometry()["radius_m"]


def footprint_radius(model: mujoco.MjModel) -> float:
    """Largest horizontal distance from the root body's axis to any point of any geom.

    Computed in the robot's default pose from each geom's own shape: spheres by
    their radius, cylinders by their two rim circles, boxes by their corners.
    """
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    origin = data.xpos[model.body(BASE_BODY).id][:2]
    reach = 0.0
    ring = np.linspace(0.0, 2 * math.pi, 73)
    for g in range(model.ngeom):
        if model.geom_bodyid[g] == 0:
            continue
        pos, rot, size = data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3), model.geom_size[g]
        gtype = model.geom_type[g]
        if gtype == mujoco.mjtGeom.mjGEOM_SPHERE:
            reach = max(reach, float(np.hypot(*(pos[:2] - origin))) + size[0])
            continue
        if gtype == mujoco.mjtGeom.mjGEOM_CYLINDER:
            rim = np.column_stack((size[0] * np.cos(ring), size[0] * np.sin(ring)))
            local = np.vstack([np.column_stack((rim, np.full(len(rim), z))) for z in (-size[1], size[1])])
        else:
            signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            local = signs * size
        points = pos + local @ rot.T
        reach = max(reach, float(np.max(np.hypot(*(points[:, :2] - origin).T))))
    return reach
