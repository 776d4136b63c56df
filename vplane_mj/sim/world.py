"""Build the MuJoCo world of a scenario with MjSpec: arena, border, obstacles, robot, sonar.

The robot is its profile's model (`vplane_mj.robots.profiles`, models/*.xml). Element names are
predictable: obstacle geoms are `obstacle<i>_<part>` (parts per kind in PART_NAMES, i the
obstacle's index in the file) and border walls `border_<side>`, all in the static body
`obstacles`, but for a moving obstacle's geom `obstacle<i>_body`, alone in a mocap body
`moving<i>` that the run sets at every physics step (`vplane_mj.sim.moving`); sonar ray sites are
`robot/sonar<k>_ray<j>`, in order, so their poses are contiguous, and so are the readings of
the rangefinders of the same names. The cameras are `top` (above the arena) and `robot/chase`
(behind the robot); the site `goal` marks the goal (a disc of the goal tolerance on the floor,
seen by cameras only: sites neither collide nor stop rays). A laser is not a MuJoCo sensor:
`vplane_mj.sim.laser` casts it in 2D against the same pieces the obstacles are built from.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from vplane_mj.files import model_path
from vplane_mj.geometry import shapes
from vplane_mj.robots.facts import BASE_BODY, SONAR_MOUNT_RADIUS_M, WHEEL_JOINTS, WHEEL_MOTORS, robot_facts
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario import RobotSpec, Scenario, SensorSpec

OBSTACLE_HEIGHT_M = 0.5
ROBOT_PREFIX = "robot/"
IMU_SITE, IMU_GYRO, IMU_ACCELEROMETER = "imu", "imu_gyro", "imu_accelerometer"
OBSTACLES_BODY = "obstacles"
"""The static body that holds every obstacle and border geom."""
BUMP_SENSOR = "bump"
"""Contact sensor: number of contacts between the robot's subtree and the obstacles body; in a
world with moving obstacles, between the robot's subtree and anything, BUMP_FLOOR's among
them."""
BUMP_FLOOR = "bump_floor"
"""Contact sensor of a world with moving obstacles: the robot's contacts with the floor."""
FLOOR_GEOM = "floor"
"""The arena's floor plane (models/arena.xml)."""
MOVING_PREFIX = "moving"
"""A moving obstacle's mocap body is `moving<i>`, i its index in the file."""
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
TOP_CAMERA = "top"
"""The orthographic camera above the arena that frames it whole (the renders' camera)."""
CHASE_CAMERA = "chase"
"""The camera that follows the robot (named `robot/chase` in the world)."""
CHASE_BACK_M, CHASE_UP_M, CHASE_PITCH_DEG = 1.2, 0.9, 35.0
SONAR_SITE_SIZE_M = 0.004
SONAR_SITE_RGBA = (0.1, 0.7, 0.2, 0.6)
GOAL_SITE = "goal"
GOAL_SITE_RGBA = (0.95, 0.75, 0.0, 1.0)
GOAL_SITE_HALF_HEIGHT_M = 0.002
CAMERA_MARGIN_M = 2 * shapes.BORDER_THICKNESS_M + 0.1
"""What the top camera shows around the arena on each axis (m): the border and a little floor."""


@dataclass(frozen=True)
class SonarLayout:
    """Geometry of the sonars: each one's bearing (rad, robot frame) and mount (x, y in m,
    base_link), their height above base_link's origin (m), and the rays' offsets (rad) about a
    sonar's bearing. `reach` is each mount's distance (m) along its own bearing: a range
    measured from the sonar plus its reach is measured from the robot's centre, along the
    bearing (exact on the ring, whose mounts lie on their bearings; for mounts off their
    bearing, the echo is placed on the bearing through the centre, off by the mount's
    distance from that line)."""

    bearings: np.ndarray
    mounts: np.ndarray
    reach: np.ndarray
    height_m: float
    ray_offsets: np.ndarray

    @classmethod
    def from_spec(cls, spec: SensorSpec, profile: str = "default") -> SonarLayout:
        """The profile's sonars at their places, or the evenly spaced ring of `spec.count` on a
        circle of SONAR_MOUNT_RADIUS_M."""
        robot = robot_profile(profile)
        if robot.sonar_mounts is None:
            bearings = np.arange(spec.count) * (2 * math.pi / spec.count)
            mounts = np.array(
                [(SONAR_MOUNT_RADIUS_M * math.cos(b), SONAR_MOUNT_RADIUS_M * math.sin(b)) for b in bearings]
            )
            reach = np.full(spec.count, SONAR_MOUNT_RADIUS_M)
        else:
            mounts = np.array([(x, y) for x, y, _ in robot.sonar_mounts])
            bearings = np.radians([heading for _, _, heading in robot.sonar_mounts])
            reach = mounts[:, 0] * np.cos(bearings) + mounts[:, 1] * np.sin(bearings)
        if spec.rays_per_sonar == 1:
            offsets = np.zeros(1)
        else:
            half = math.radians(spec.beam_deg) / 2
            offsets = np.linspace(-half, half, spec.rays_per_sonar)
        return cls(bearings, mounts, reach, robot.sensor_height_m, offsets)


def build_spec(scenario: Scenario, rangefinders: bool = True) -> mujoco.MjSpec:
    """The scenario's whole world as an MjSpec (not yet compiled).

    With `rangefinders`, every sonar ray site carries a MuJoCo rangefinder (the exported
    world). The run loop builds the world without them: MuJoCo would cast every ray at
    every physics step, while the sonar pings only at its rate (`vplane_mj.sim.sonar`).
    """
    arena = mujoco.MjSpec.from_file(str(model_path("arena.xml")))
    arena.option.timestep = scenario.run.physics_dt_s
    _size_camera(arena, scenario.world.size)
    _add_goal_marker(arena, scenario.robot)
    statics = arena.worldbody.add_body(name=OBSTACLES_BODY)
    if scenario.world.border:
        for side, rect in zip(BORDER_SIDES, shapes.border_footprint(scenario.world.size), strict=True):
            _add_piece(statics, f"border_{side}", rect, "border")
    world = scenario.world
    for index, obstacle in zip(world.static_indices(), world.obstacles, strict=True):
        parts = PART_NAMES[type(obstacle)]
        for part, piece in zip(parts, obstacle.footprint(), strict=True):
            _add_piece(statics, f"obstacle{index}_{part}", piece, "obstacle")
    for moving in world.moving:
        x, y = moving.shape.center  # where it stands at the run's start; its geom about the body's origin
        (piece,) = dataclasses.replace(moving.shape, center=(0.0, 0.0)).footprint()
        body = arena.worldbody.add_body(name=f"{MOVING_PREFIX}{moving.index}", mocap=True, pos=[x, y, 0.0])
        _add_piece(body, f"obstacle{moving.index}_body", piece, "obstacle")
    # Counts robot-obstacle contacts inside MuJoCo, so the run loop reads one number per check.
    # Moving obstacles are bodies of their own: the robot's contacts with anything, less those
    # with the floor, count them all in two sensors (a sensor per obstacle cost a tenth of a
    # physics step among DynaBARN's 20-odd cylinders).
    body, geom = mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_GEOM
    touched = (
        [(BUMP_SENSOR, None, ""), (BUMP_FLOOR, geom, FLOOR_GEOM)]
        if world.moving
        else [(BUMP_SENSOR, body, OBSTACLES_BODY)]
    )
    for name, reftype, refname in touched:
        sensor = arena.add_sensor(
            name=name,
            type=mujoco.mjtSensor.mjSENS_CONTACT,
            objtype=mujoco.mjtObj.mjOBJ_XBODY,  # the subtree of base_link
            objname=ROBOT_PREFIX + BASE_BODY,
            intprm=[1, 0, 1],  # data "found" (all the matching contacts), no reduction, one contact
        )
        if reftype is not None:  # else: contacts with anything
            sensor.reftype, sensor.refname = reftype, refname

    robot = mujoco.MjSpec.from_file(str(model_path(robot_profile(scenario.robot.profile).model_file)))
    if scenario.sensors.kind == "sonar":
        layout = SonarLayout.from_spec(scenario.sensors, scenario.robot.profile)
        _add_sonar_ring(robot, layout, scenario.sensors, rangefinders)
    _apply_actuation_faults(robot, scenario.robot)
    if scenario.sensors.pose == "ekf":
        _add_imu(robot)
    x, y = scenario.robot.start
    yaw = scenario.robot.start_yaw
    mount = arena.worldbody.add_body(
        name=ROBOT_PREFIX, pos=[x, y, 0.0], quat=[math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
    )
    mount.add_freejoint(name=ROBOT_PREFIX)
    _add_chase_camera(robot)
    arena.attach(robot, prefix=ROBOT_PREFIX, frame=mount.add_frame())
    return arena


def build_model(scenario: Scenario, rangefinders: bool = True) -> mujoco.MjModel:
    """The compiled MuJoCo model of a scenario (see `build_spec` for `rangefinders`)."""
    return build_spec(scenario, rangefinders).compile()


def standalone_xml(scenario: Scenario) -> str:
    """One self-contained MJCF document of the world, rangefinders included (assets are
    built-in textures only; numbers at MuJoCo's XML precision of 6 significant digits)."""
    return build_spec(scenario).to_xml()


def _add_chase_camera(robot: mujoco.MjSpec) -> None:
    """A camera that follows the robot from behind and above, looking ahead and down
    (`robot/chase`): CHASE_BACK_M behind base_link, CHASE_UP_M above it, pitched CHASE_PITCH_DEG
    below the horizon. A camera looks along its -z, its image's x and y being its own."""
    pitch = math.radians(CHASE_PITCH_DEG)
    right = [0.0, -1.0, 0.0]  # the image's x: the robot's right
    up = [math.sin(pitch), 0.0, math.cos(pitch)]  # the image's y: up, leaning ahead
    camera = robot.body(BASE_BODY).add_camera(
        name=CHASE_CAMERA, mode=mujoco.mjtCamLight.mjCAMLIGHT_FIXED, pos=[-CHASE_BACK_M, 0.0, CHASE_UP_M]
    )
    camera.fovy = 60.0
    camera.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
    camera.alt.xyaxes = right + up


def top_view_extent(size: tuple[float, float]) -> tuple[float, float]:
    """The width and height (m) of the floor the top camera frames: the arena of `size` (m)
    with CAMERA_MARGIN_M around it."""
    return size[0] + CAMERA_MARGIN_M, size[1] + CAMERA_MARGIN_M


def _size_camera(arena: mujoco.MjSpec, size: tuple[float, float]) -> None:
    """Centre the orthographic top camera on the arena and fit the arena plus its border."""
    width, height = top_view_extent(size)
    camera = arena.camera(TOP_CAMERA)
    camera.pos = [size[0] / 2, size[1] / 2, 20.0]
    camera.fovy = height  # orthographic: the vertical extent in metres
    scale = RENDER_PIXELS / max(width, height)
    arena.visual.global_.offwidth = max(64, round(width * scale))
    arena.visual.global_.offheight = max(64, round(height * scale))


def _add_goal_marker(arena: mujoco.MjSpec, robot: RobotSpec) -> None:
    """The site GOAL_SITE: a flat disc of the goal tolerance's radius lying on the floor at the goal."""
    site = arena.worldbody.add_site(
        name=GOAL_SITE,
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        pos=[*robot.goal, GOAL_SITE_HALF_HEIGHT_M],
        rgba=list(GOAL_SITE_RGBA),
    )
    site.size = [robot.goal_tolerance, GOAL_SITE_HALF_HEIGHT_M, 0.0]


def _add_piece(body: mujoco.MjsBody, name: str, piece: shapes.Piece, material: str) -> None:
    """One footprint piece as a vertical geom standing on the floor."""
    half_z = OBSTACLE_HEIGHT_M / 2
    if isinstance(piece, shapes.Disc):
        body.add_geom(
            name=name,
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=[piece.radius, half_z, 0.0],
            pos=[*piece.center, half_z],
            material=material,
        )
        return
    geom = body.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[*piece.half, half_z],
        pos=[*piece.center, half_z],
        material=material,
    )
    geom.alt.type = mujoco.mjtOrientation.mjORIENTATION_EULER
    geom.alt.euler = [0.0, 0.0, piece.yaw]


def _add_imu(robot: mujoco.MjSpec) -> None:
    """A gyro and an accelerometer at the robot model's `imu` site (the maker's mounting),
    `IMU_GYRO` and `IMU_ACCELEROMETER` after the robot's prefix: what `sensors.pose = "ekf"`
    fuses (only then: an accelerometer makes MuJoCo compute accelerations at every step)."""
    for name, kind in (
        (IMU_GYRO, mujoco.mjtSensor.mjSENS_GYRO),
        (IMU_ACCELEROMETER, mujoco.mjtSensor.mjSENS_ACCELEROMETER),
    ):
        robot.add_sensor(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=IMU_SITE)


def _add_sonar_ring(robot: mujoco.MjSpec, layout: SonarLayout, spec: SensorSpec, rangefinders: bool) -> None:
    """Sonar k emulates a beam of `beam_deg` with `rays_per_sonar` rays.

    All rays of one sonar start at the same site position, its mount; each ray is a
    site whose +z axis points along the ray. With `rangefinders`, each site carries a
    rangefinder cut off at the range limit, with the sonar's period as its interval.
    """
    base = robot.body(BASE_BODY)
    for k, bearing in enumerate(layout.bearings):
        pos = [float(layout.mounts[k, 0]), float(layout.mounts[k, 1]), layout.height_m]
        for j, offset in enumerate(layout.ray_offsets):
            angle = bearing + offset
            name = f"sonar{k}_ray{j}"
            site = base.add_site(name=name, pos=pos, rgba=list(SONAR_SITE_RGBA))
            site.size[0] = SONAR_SITE_SIZE_M
            site.alt.type = mujoco.mjtOrientation.mjORIENTATION_ZAXIS
            site.alt.zaxis = [math.cos(angle), math.sin(angle), 0.0]
            if rangefinders:
                robot.add_sensor(
                    name=name,
                    type=mujoco.mjtSensor.mjSENS_RANGEFINDER,
                    objtype=mujoco.mjtObj.mjOBJ_SITE,
                    objname=name,
                    cutoff=spec.range_max,
                    interval=[1.0 / spec.rate_hz, 0.0],
                    intprm=[1, 0, 0],  # data "dist"
                )


def _apply_actuation_faults(robot: mujoco.MjSpec, spec: RobotSpec) -> None:
    """Wheel slip and motor faults as model properties, so an exported world keeps them.

    The wheels' sliding friction becomes `wheel_friction` (the wheel geoms take priority
    over the floor in the contact, so theirs is the friction used). A motor with gain g
    and bias b becomes an affine actuator of gear g: torque = g * clamp(ctrl + b / g),
    i.e. g times the commanded torque plus b, saturating at g times the torque limit.
    """
    for geom in robot.geoms:
        if geom.classname.name == "wheel":
            geom.friction[0] = spec.wheel_friction
    limit = robot_facts(spec.profile).torque_limit_nm
    for motor_name, joint, gain, bias in zip(
        WHEEL_MOTORS, WHEEL_JOINTS, spec.motor_gain, spec.motor_bias_nm, strict=True
    ):
        if gain == 1.0 and bias == 0.0:
            continue
        robot.delete(robot.actuator(motor_name))
        robot.add_actuator(
            name=motor_name,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            target=joint,
            gear=[gain, 0.0, 0.0, 0.0, 0.0, 0.0],
            ctrlrange=[-limit, limit],
            forcerange=[-limit, limit],
            biastype=mujoco.mjtBias.mjBIAS_AFFINE,
            biasprm=[bias / gain] + [0.0] * 9,
        )
