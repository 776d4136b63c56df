"""Facts about each robot profile's MJCF model that the rest of the code relies on, and the
robot as its planner sees it.

The facts are read from the XML itself (`vplane_mj.robots.mjcf_reader`), not from a compiled model,
so validating a scenario or listing the planners never loads MuJoCo; tests/test_robot.py
checks them against the model MuJoCo compiles from the same file. Every model follows the
conventions below (base_link, the driven wheels' joints and motors).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vplane_mj.files import model_path
from vplane_mj.planning.protocol.body import HeadingGains, RobotBody
from vplane_mj.planning.protocol.matrices import product
from vplane_mj.robots.mjcf_reader import MjcfReader, PosedGeom
from vplane_mj.robots.profiles import robot_profile

BASE_BODY = "base_link"
WHEEL_JOINTS = ("wheel_left", "wheel_right")
WHEEL_MOTORS = ("wheel_left", "wheel_right")
SONAR_MOUNT_RADIUS_M = 0.10
"""Distance of the sonar sites from base_link's vertical axis."""
RIM_SAMPLES = 73
"""Points per rim circle of a cylinder when measuring the footprint (every 5 degrees)."""


@dataclass(frozen=True)
class RobotFacts:
    """Wheel radius and track (m), each motor's torque limit (N m), footprint radius (m).

    `radius_m` is the radius of the disc around base_link's centre that contains every
    geom, rounded to 1e-9 m (the summary's `robot_radius_m`).
    """

    wheel_radius_m: float
    track_m: float
    torque_limit_nm: float
    radius_m: float


def read_robot_facts(path: Path) -> RobotFacts:
    """The facts of the robot model in the MJCF file `path` (with the wheels and motors above)."""
    reader = MjcfReader(path)
    geoms = reader.geoms()
    wheel = next((geom for geom in geoms if geom.name == WHEEL_JOINTS[0]), None)
    forcerange = reader.numbers(reader.named("motor", WHEEL_MOTORS[0]), "forcerange")
    if wheel is None or forcerange is None:
        raise ValueError(f"{path}: no geom {WHEEL_JOINTS[0]!r} or no forcerange of motor {WHEEL_MOTORS[0]!r}")
    left, right = (
        reader.numbers(reader.named("body", name), "pos") or (0.0, 0.0, 0.0) for name in WHEEL_JOINTS
    )
    return RobotFacts(
        wheel_radius_m=float(wheel.size[0]),
        track_m=float(abs(left[1] - right[1])),
        torque_limit_nm=float(forcerange[1]),
        radius_m=round(footprint_radius(geoms, reader.body_position(BASE_BODY)[:2]), 9),
    )


def footprint_radius(geoms: list[PosedGeom], origin: np.ndarray) -> float:
    """Largest horizontal distance (m) from `origin` (x, y) to any point of any geom.

    Spheres count by their radius, cylinders by their two rim circles, boxes by their corners.
    """
    reach = 0.0
    ring = np.linspace(0.0, 2 * math.pi, RIM_SAMPLES)
    for geom in geoms:
        if geom.type == "sphere":
            reach = max(reach, float(np.hypot(*(geom.pos[:2] - origin))) + geom.size[0])
            continue
        if geom.type == "cylinder":
            radius, half = geom.size[0], geom.size[1]
            rim = np.column_stack((radius * np.cos(ring), radius * np.sin(ring)))
            local = np.vstack([np.column_stack((rim, np.full(len(rim), z))) for z in (-half, half)])
        else:
            signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            local = signs * np.asarray(geom.size[:3])
        points = geom.pos + product(local, geom.rot.T)
        reach = max(reach, float(np.max(np.hypot(*(points[:, :2] - origin).T))))
    return reach


@functools.cache
def robot_facts(profile: str = "default") -> RobotFacts:
    """The facts of a profile's model (models/robot.xml for the default robot)."""
    return read_robot_facts(model_path(robot_profile(profile).model_file))


def robot_geometry(profile: str = "default") -> dict[str, float]:
    """A profile's facts by name: wheel_radius_m, track_m, torque_limit_nm, radius_m."""
    return dataclasses.asdict(robot_facts(profile))


def robot_radius_m(profile: str = "default") -> float:
    """Radius (m) of a disc around base_link's centre that contains every geom of the profile's robot."""
    return robot_facts(profile).radius_m


@functools.cache
def robot_body(profile: str = "default", sensor_kind: str | None = None) -> RobotBody:
    """The robot as its planner sees it (`vplane_mj.planning.RobotBody`): the profile's outline
    (the model's disc for a round robot), limits, heading gains and sensor kind (default: the
    profile's own)."""
    chosen = robot_profile(profile)
    details = {
        "limits": chosen.limits,
        "gains": HeadingGains(chosen.gains.speed_gain, chosen.gains.turn_gain),
        "sensor_kind": sensor_kind or str(chosen.sensors["kind"]),
        "profile": profile,
    }
    if chosen.footprint_m is None:
        return RobotBody.round(robot_radius_m(profile), **details)
    return RobotBody.polygon(chosen.footprint_m, **details)
