"""Build the MuJoCo world of a scenario with dm_control.mjcf: arena, border, obstacles, robot, sonar.

Element names are predictable: obstacle geoms are `obstacle<i>_<part>` (parts per kind
in PART_NAMES) and border walls `border_<side>`, all in the static body `obstacles`;
sonar rays are `robot/sonar<k>_ray<j>`, in order, so their readings are contiguous.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from dm_control import mjcf

from vplane_mj import shapes
from vplane_mj.resources import model_path
from vplane_mj.robot import (
    BASE_BODY,
    SONAR_MOUNT_HEIGHT_M,
    SONAR_MOUNT_RADIUS_M,
    WHEEL_JOINTS,
    WHEEL_MOTORS,
    robot_geometry,
)
from vplane_mj.scenario import RobotSpec, Scenario, SensorSpec

OBSTACLE_HEIGHT_M = 0.5
ROBOT_PREFIX = "robot/"
OBSTACLES_BODY = "obstacles"
"""The static body that holds every obstacle and border geom."""
BUMP_SENSOR = "bump"
"""Contact sensor: number of contacts between the robot's subtree and the obstacles body."""
PART_NAMES: dict[type, tuple[str, ...]] = {
    shapes.Box: ("body",),
    shapes.Wall: ("wall",),
    shapes.Cylinder: ("body",),
    shapes.Cup: ("back", "arm_left", "arm_right"),
    shapes.HShape: ("post_left", "post_right", "crossbar"),
}
BORDER_SIDES = ("west", "east", "south", "north")
RENDER_PIXELS = 800
"""Longest side (px) of the offscreen buffer that the top camera renders into."""


@dataclass(frozen=True)
class SonarLayout:
    """Geometry of the sonar ring: one bearing (rad, robot frame) per sonar; rays per sonar."""

    bearings: np.ndarray
    ray_offsets: np.ndarray

    @classmethod
    def from_spec(cls, spec: SensorSpec) -> SonarLayout:
        bearings = np.arange(spec.count) * (2 * math.pi / spec.count)
        if spec.rays_per_sonar == 1:
            offsets = np.zeros(1)
        else:
            half = math.radians(spec.beam_deg) / 2
            offsets = np.linspace(-half, half, spec.rays_per_sonar)
        return cls(bearings=bearings, ray_offsets=offsets)


def build_mjcf(scenario: Scenario) -> mjcf.RootElement:
    """The scenario's whole world as an mjcf tree (not yet compiled)."""
    arena = mjcf.from_path(str(model_path("arena.xml")))
    arena.option.timestep = scenario.run.physics_dt_s
    _size_camera(arena, scenario.world.size)
    statics = arena.worldbody.add("body", name=OBSTACLES_BODY)
    if scenario.world.border:
        for side, rect in zip(BORDER_SIDES, shapes.border_footprint(scenario.world.size), strict=True):
            _add_piece(statics, f"border_{side}", rect, "border")
    for index, obstacle in enumerate(scenario.world.obstacles):
        parts = PART_NAMES[type(obstacle)]
        for part, piece in zip(parts, obstacle.footprint(), strict=True):
            _add_piece(statics, f"obstacle{index}_{part}", piece, "obstacle")

    robot = mjcf.from_path(str(model_path("robot.xml")))
    robot.model = ROBOT_PREFIX.rstrip("/")
    _add_sonar_ring(robot, scenario.sensors)
    _apply_actuation_faults(robot, scenario.robot)
    frame = arena.attach(robot)
    frame.add("freejoint")
    x, y = scenario.robot.start
    frame.pos = (x, y, 0.0)
    yaw = scenario.robot.start_yaw
    frame.quat = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    # Counts robot-obstacle contacts inside MuJoCo, so the run loop reads one number per check.
    arena.sensor.add(
        "contact",
        name=BUMP_SENSOR,
        subtree1=ROBOT_PREFIX + BASE_BODY,
        body2=OBSTACLES_BODY,
        data="found",
        reduce="mindist",
    )
    return arena


def compile_model(root: mjcf.RootElement) -> mujoco.MjModel:
    """Compile an mjcf tree with MuJoCo directly (dm_control's Physics does not support MuJoCo 4)."""
    return mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())


def build_model(scenario: Scenario) -> mujoco.MjModel:
    """The compiled MuJoCo model of a scenario."""
    return compile_model(build_mjcf(scenario))


def standalone_xml(scenario: Scenario) -> str:
    """One self-contained MJCF document of the world (assets are built-in textures only)."""
    return build_mjcf(scenario).to_xml_string()


def _size_camera(arena: mjcf.RootElement, size: tuple[float, float]) -> None:
    """Centre the orthographic top camera on the arena and fit the arena plus its border."""
    w, h = size
    margin = 2 * shapes.BORDER_THICKNESS_M + 0.1
    camera = arena.find("camera", "top")
    camera.pos = (w / 2, h / 2, 20.0)
    camera.fovy = h + margin  # orthographic: the vertical extent in metres
    scale = RENDER_PIXELS / max(w + margin, h + margin)
    buffer = getattr(arena.visual, "global")  # `global` is a Python keyword
    buffer.offwidth = max(64, round((w + margin) * scale))
    buffer.offheight = max(64, round((h + margin) * scale))


def _add_piece(body: mjcf.Element, name: str, piece: shapes.Piece, material: str) -> None:
    """One footprint piece as a vertical geom standing on the floor."""
    half_z = OBSTACLE_HEIGHT_M / 2
    if isinstance(piece, shapes.Disc):
        body.add(
            "geom",
            name=name,
            type="cylinder",
            size=(piece.radius, half_z),
            pos=(*piece.center, half_z),
            material=material,
        )
        return
    body.add(
        "geom",
        name=name,
        type="box",
        size=(*piece.half, half_z),
        pos=(*piece.center, half_z),
        euler=(0.0, 0.0, piece.yaw),
        material=material,
    )


def _add_sonar_ring(robot: mjcf.RootElement, spec: SensorSpec) -> None:
    """Sonar k emulates a beam of `beam_deg` with `rays_per_sonar` rangefinder rays.

    All rays of one sonar start at the same site position on the ring; each ray is a
    site whose +z axis points along the ray. Rangefinders update every 1/rate_hz s.
    """
    layout = SonarLayout.from_spec(spec)
    base = robot.find("body", BASE_BODY)
    for k, bearing in enumerate(layout.bearings):
        pos = (
            SONAR_MOUNT_RADIUS_M * math.cos(bearing),
            SONAR_MOUNT_RADIUS_M * math.sin(bearing),
            SONAR_MOUNT_HEIGHT_M,
        )
        for j, offset in enumerate(layout.ray_offsets):
            angle = bearing + offset
            name = f"sonar{k}_ray{j}"
            base.add(
                "site",
                name=name,
                pos=pos,
                size=(0.004,),
                rgba=(0.1, 0.7, 0.2, 0.6),
                zaxis=(math.cos(angle), math.sin(angle), 0.0),
            )
            robot.sensor.add(
                "rangefinder",
                name=name,
                site=name,
                cutoff=spec.range_max,
                interval=(1.0 / spec.rate_hz, 0.0),
            )


def _apply_actuation_faults(robot: mjcf.RootElement, spec: RobotSpec) -> None:
    """Wheel slip and motor faults as model properties, so an exported world keeps them.

    The wheels' sliding friction becomes `wheel_friction` (the wheel geoms take priority
    over the floor in the contact, so theirs is the friction used). A motor with gain g
    and bias b becomes an affine actuator of gear g: torque = g * clamp(ctrl + b / g),
    i.e. g times the commanded torque plus b, saturating at g times the torque limit.
    """
    wheel = robot.find("default", "wheel").geom
    wheel.friction = (spec.wheel_friction, *wheel.friction[1:])
    limit = robot_geometry()["torque_limit_nm"]
    for motor_name, joint, gain, bias in zip(
        WHEEL_MOTORS, WHEEL_JOINTS, spec.motor_gain, spec.motor_bias_nm, strict=True
    ):
        if gain == 1.0 and bias == 0.0:
            continue
        robot.find("actuator", motor_name).remove()
        robot.actuator.add(
            "general",
            name=motor_name,
            joint=joint,
            gear=(gain,),
            ctrlrange=(-limit, limit),
            forcerange=(-limit, limit),
            biastype="affine",
            biasprm=(bias / gain, 0.0, 0.0),
        )
