"""The robots a scenario can choose (`[robot] profile = "NAME"`), as data: no MuJoCo here.

A profile names the robot's MJCF model and gives its published numbers: outline, mass,
wheels, top speed and turn rate, accelerations, its controller's gains and its real sensor
(the default `[sensors]` table, key for key as a scenario file writes it). Every number
has a source in `sources`; a number the makers do not publish is marked there "chosen:"
with the reason. docs/robots.md tabulates them; tests/test_profiles.py checks them against
the models and drives each model to its top speed and turn rate.

Frames and units: base_link (x forward, y left), metres, seconds, radians except the
sensor table's and the sonar mounts' degrees (as in a scenario file).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from vplane_mj.errors import VPlaneError, did_you_mean, shown
from vplane_mj.planning.protocol.body import DriveLimits, HeadingGains

DRIVES = ("differential", "skid_steer")
Point = tuple[float, float]


@dataclass(frozen=True)
class ControllerGains:
    """Gains of the controller (units in the field comments); the speed and turn rate it commands
    are bounded by the profile's `limits`. The defaults are the default robot's, its heading
    gains those of `HeadingGains`."""

    speed_gain: float = HeadingGains.speed_gain  # k_v: (m/s) per unit of force
    turn_gain: float = HeadingGains.turn_gain  # k_w: (rad/s) per rad of heading error
    max_wheel_speed: float = 15.0  # rad/s (0.6 m/s at the rim of a 0.04 m wheel)
    wheel_kp: float = 0.06  # N m per rad/s of wheel speed error
    wheel_ki: float = 0.6  # N m per rad of accumulated wheel speed error
    motor_rate_hz: float = 100.0  # how often the wheel PI loop runs


@dataclass(frozen=True)
class RobotProfile:
    """One robot: its model, published numbers, controller and sensor (see the module doc).

    `footprint_m` is the outline seen from above, a convex polygon counter-clockwise in
    base_link (None: the model's disc, the default robot). `track_scale` multiplies the
    wheel separation in the heading controller's wheel targets: a skid-steer robot turns
    slower than its geometric track predicts (1.0 for a differential drive).
    `wheel_friction` is the tyres' sliding friction the model was measured with.
    `sonar_mounts` are (x m, y m, heading deg) per sonar (None: the evenly spaced ring);
    `sensor_height_m` is the sonar's or laser's height above base_link's origin, which is
    on the driven wheels' axle. With `ramped`, the drive ramps its speed and turn commands at
    the limits' accelerations, which the model's motors deliver with margin, without wheel
    spin-out; without (the default robot, whose runs stay exactly as they were), the commands
    step and the limits are what the motors deliver from standing.
    `odometry_track_scale` multiplies the wheel separation in the robot's own wheel odometry (a
    skid-steer controller's `wheel_separation_multiplier`); `gyro_noise_radps` (rad/s, white)
    and `gyro_drift_radps` (rad/s per root second, the bias's random walk) are its IMU's gyro
    at the model's `imu` site (`sensors.pose = "ekf"`). `planner_settings` are parameters a
    planner runs with on this robot unless a scenario sets them: how the robot's own navigation
    stack configures its counterpart (a ROS robot's DWA follows its global planner's path).
    """

    name: str
    title: str
    model_file: str
    mass_kg: float
    wheel_radius_m: float
    track_m: float
    footprint_m: tuple[Point, ...] | None
    drive: str
    track_scale: float
    wheel_friction: float
    limits: DriveLimits
    ramped: bool
    gains: ControllerGains
    sensors: Mapping[str, str | int | float]
    sonar_mounts: tuple[tuple[float, float, float], ...] | None
    sensor_height_m: float
    sources: Mapping[str, str]
    odometry_track_scale: float = 1.0
    gyro_noise_radps: float = 0.005
    gyro_drift_radps: float = 0.005
    planner_settings: Mapping[str, Mapping[str, float]] = field(default_factory=lambda: MappingProxyType({}))

    def footprint_radius_m(self) -> float | None:
        """Radius (m) of the smallest disc about base_link's origin holding the outline."""
        if self.footprint_m is None:
            return None
        return max(math.hypot(x, y) for x, y in self.footprint_m)


def _frozen(mapping: dict) -> Mapping:
    return MappingProxyType(mapping)


def _mirrored(front_to_rear_left: list[Point]) -> tuple[Point, ...]:
    """A polygon symmetric about the x axis, CCW, from its left half listed front to rear;
    points on the axis are not repeated."""
    right = [(x, -y) for x, y in reversed(front_to_rear_left) if y != 0.0]
    return tuple(front_to_rear_left) + tuple(right)


DEFAULT = RobotProfile(
    name="default",
    title="vplane-mj differential-drive disc robot",
    model_file="robot.xml",
    mass_kg=2.34,
    wheel_radius_m=0.04,
    track_m=0.15,
    footprint_m=None,
    drive="differential",
    track_scale=1.0,
    wheel_friction=1.0,
    limits=DriveLimits(),
    ramped=False,
    gains=ControllerGains(),
    sensors=_frozen(
        {
            "kind": "sonar",
            "count": 16,
            "rays_per_sonar": 3,
            "beam_deg": 20.0,
            "range_max": 3.0,
            "rate_hz": 20.0,
        }
    ),
    sonar_mounts=None,
    sensor_height_m=0.07,
    sources=_frozen(
        {
            "model": "models/robot.xml",
            "limits": "chosen: the top speed and turn rate the controller always held the robot to",
            "accelerations": "measured: what the 0.3 N m motors deliver from standing, the commands "
            "stepped as today (tests/test_profiles.py): 4.0 m/s^2 straight (10-90 % of the top "
            "speed; 4.6 at the start); turning, 16.5 rad/s^2 from 10 to 90 % of the top turn rate and "
            "37 at the start, of which the dynamic window has always assumed 30",
            "gains": "chosen: ControllerGains' defaults, the controller's gains as they always were",
            "sensors": "chosen: the sonar ring the robot always had; the [sensors] defaults read it",
            "sensor height": "chosen: the sonar ring sits above the wheels (their top at 0.04 m)",
            "imu": "chosen: at the chassis' centre, the Jackal's gyro noise and drift",
            "odometry": "measured: the model turns as if its wheels stood 3% wider apart than they "
            "do (turning in place 1.032 at half the top turn rate and 1.034 at the top, as "
            "tests/test_profiles.py measures; 1.022 in an arc at half the top speed), so its wheel "
            "odometry is calibrated to 1.03 times the separation, as a real robot's is",
        }
    ),
    odometry_track_scale=1.03,
)

JACKAL = RobotProfile(
    name="jackal",
    title="Clearpath Jackal",
    model_file="jackal.xml",
    mass_kg=17.0,
    wheel_radius_m=0.098,
    track_m=0.37559,
    footprint_m=((0.254, 0.215), (-0.254, 0.215), (-0.254, -0.215), (0.254, -0.215)),
    drive="skid_steer",
    track_scale=1.9,
    wheel_friction=0.5,
    limits=DriveLimits(
        max_speed_mps=2.0,
        max_turn_rate_radps=4.0,
        max_accel_mps2=2.0,
        max_turn_accel_radps2=4.0,
        turn_lag_s=0.06,
        turning_brake_mps2=0.8,
    ),
    ramped=True,
    gains=ControllerGains(
        speed_gain=2.0,
        turn_gain=3.0,
        max_wheel_speed=24.5,
        wheel_kp=2.0,
        wheel_ki=20.0,
        motor_rate_hz=100.0,
    ),
    sensors=_frozen(
        {
            "kind": "laser",
            "fov_deg": 270.0,
            "beams": 720,
            "range_min": 0.1,
            "range_max": 30.0,
            "rate_hz": 50.0,
        }
    ),
    sonar_mounts=None,
    sensor_height_m=0.199,
    odometry_track_scale=1.5,
    planner_settings=_frozen({"dwa": _frozen({"follow_way": 1, "clearance_weight": 0.05})}),
    sources=_frozen(
        {
            "outline, mass, top speed": "Clearpath Robotics, Jackal UGV datasheet: 508 x 430 x 250 mm, "
            "17 kg, 2.0 m/s",
            "wheels, chassis, inertia": "jackal_description/urdf/jackal.urdf.xacro "
            "(https://github.com/jackal/jackal): wheel radius 0.098 m, width 0.04 m, separation "
            "0.37559 m, wheel base 0.262 m, chassis box 0.42 x 0.31 x 0.184 m, wheel 0.477 kg",
            "top turn rate": "jackal_control/config/control.yaml (https://github.com/jackal/jackal): "
            "angular max_velocity 4.0 rad/s (linear 2.0 m/s)",
            "dwa settings": "BARN challenge stack (jackal_helper move_base): DWA follows navfn's global "
            "path; here `follow_way` 1 and `clearance_weight` 0.05, chosen on generated protocol "
            "worlds (docs/barn.md)",
            "navigation footprint": "BARN challenge stack (jackal_helper move_base): "
            "[[-0.21, -0.165], [-0.21, 0.165], [0.21, 0.165], [0.21, -0.165]], padding 0.1 m",
            "laser": "jackal_description/urdf/accessories/hokuyo_ust10.urdf.xacro: Hokuyo UST-10LX as "
            "simulated in BARN, 720 samples over +-2.35619 rad, 0.1-30 m, 50 Hz",
            "sensor height": "jackal.urdf.xacro and hokuyo_ust10.urdf.xacro: front mount 0.184 m above "
            "base_link (0.0655 m above the floor), focal point 0.0474 m above the mount: 0.297 m above "
            "the floor, 0.199 m above the axle; the real laser sits 0.12 m ahead of the centre",
            "wheel friction": "jackal_description/urdf/jackal.urdf.xacro: Gazebo tyre mu1 = mu2 = 0.5",
            "odometry": "jackal_control/config/control.yaml: the controller's odometry multiplies the "
            "wheel separation by wheel_separation_multiplier 1.5",
            "imu": "jackal_description/urdf/jackal.urdf.xacro and jackal.gazebo: imu_link at base_link's "
            "origin; Gazebo's IMU plugin with 0.005 rad/s of rate noise and 0.005 of bias drift",
            "track scale": "measured (tests/test_profiles.py): turning in place at 4 rad/s on tyres of "
            "friction 0.5 the model yaws at the geometric rate of a 1.9 times wider track "
            "(Clearpath's controller multiplies the separation by 1.5, "
            "jackal_control/config/control.yaml)",
            "accelerations": "chosen: top speed and top turn rate in 1 s (control.yaml's limits of "
            "20 m/s^2 and 25 rad/s^2 do not bind); the 4 N m per side motors deliver 3.9 m/s^2 "
            "straight without spin-out, and turn in place at 4 rad/s against the tyres' skid; "
            "ramped at 6 rad/s^2 the model turns up at only 4.6 rad/s^2 (the limit must hold "
            "within 15 %), so 4 rad/s^2 stays",
            "turn lag": "measured (tests/test_profiles.py): stopped from turning in place at 2 and "
            "4 rad/s, the model turns 0.06-0.08 s x its turn rate beyond its ramp's "
            "omega^2 / 2 alpha (the tyres slip before they turn it; 0.01 s and less for the "
            "differential drives)",
            "gains": "chosen: speed_gain = top speed per unit force and turn_gain 3.0, as the default "
            "robot; wheel PI of the default's bandwidth (kp over the side's inertia about 24 /s, "
            "ki = 10 kp); max_wheel_speed 1.2 x the faster wheel speed of the top speed and the top "
            "turn rate, as the default's 15 rad/s",
        }
    ),
)

# Stage's pioneer.inc top plate (block 6) and the wheels' top-view corners (+-0.0975 m, +-0.189 m):
# their convex hull, left half from the front tip to the rear tip.
_PIONEER_LEFT: list[Point] = [
    (0.174, 0.0),
    (0.166, 0.056),
    (0.145, 0.107),
    (0.0975, 0.189),
    (0.064, 0.19),
    (-0.074, 0.19),
    (-0.0975, 0.189),
    (-0.2, 0.155),
    (-0.236, 0.107),
    (-0.256, 0.056),
    (-0.264, 0.0),
]
# ARIA params/p3dx.p SonarUnit lines: x mm, y mm, heading deg (0-7 the front array, 8-15 the rear).
_PIONEER_SONARS_MM = (
    (69, 136, 90),
    (114, 119, 50),
    (148, 78, 30),
    (166, 27, 10),
    (166, -27, -10),
    (148, -78, -30),
    (114, -119, -50),
    (69, -136, -90),
    (-157, -136, -90),
    (-203, -119, -130),
    (-237, -78, -150),
    (-255, -27, -170),
    (-255, 27, 170),
    (-237, 78, 150),
    (-203, 119, 130),
    (-157, 136, 90),
)

PIONEER_3DX = RobotProfile(
    name="pioneer3dx",
    title="Adept MobileRobots Pioneer 3-DX",
    model_file="pioneer3dx.xml",
    mass_kg=9.0,
    wheel_radius_m=0.0975,
    track_m=0.33,
    footprint_m=_mirrored(_PIONEER_LEFT),
    drive="differential",
    track_scale=1.0,
    wheel_friction=1.0,
    limits=DriveLimits(
        max_speed_mps=1.2,
        max_turn_rate_radps=5.236,
        max_accel_mps2=1.2,
        max_turn_accel_radps2=5.236,
        turning_brake_mps2=1.0,
    ),
    ramped=True,
    gains=ControllerGains(
        speed_gain=1.2,
        turn_gain=3.0,
        max_wheel_speed=14.8,
        wheel_kp=1.1,
        wheel_ki=11.0,
        motor_rate_hz=100.0,
    ),
    sensors=_frozen(
        {
            "kind": "sonar",
            "count": 16,
            "rays_per_sonar": 3,
            "beam_deg": 30.0,
            "range_max": 5.0,
            "rate_hz": 10.0,
        }
    ),
    sonar_mounts=tuple((x / 1000, y / 1000, float(heading)) for x, y, heading in _PIONEER_SONARS_MM),
    sensor_height_m=0.114,
    sources=_frozen(
        {
            "mass, top speed, top turn rate, wheels": "Adept MobileRobots, Pioneer 3-DX datasheet: "
            "9 kg, 1.2 m/s, 300 deg/s, 19.5 cm wheels",
            "outline": "Stage worlds/pioneer.inc (https://github.com/rtv/Stage), top plate after the "
            "Webots 5.3 manual; with the wheels, the convex hull, 0.438 x 0.38 m",
            "wheel radius, separation, sonar height": "Webots Pioneer3dx.proto "
            "(https://github.com/cyberbotics/webots): wheel radius 0.0975 m, hinges at y = +-0.165 m, "
            "wheel assembly 0.048 m wide, sonars 0.114 m above the axle",
            "sonar mounts": "ARIA params/p3dx.p (https://github.com/reedhedges/AriaCoda): SonarUnit "
            "0-15, front array +-90, +-50, +-30, +-10 deg, rear array mirrored",
            "sonar beam and range": "Stage worlds/pioneer.inc p3dx sonar: view 0.1-5.0 m, 30 deg",
            "sonar rate": "chosen: 10 Hz for the whole ring (the firing cycle is not in the sources checked)",
            "imu": "chosen: the optional gyro at the body's centre, the Jackal's noise and drift",
            "caster": "p2os_urdf/defs/pioneer3dx_body.xacro (https://github.com/allenh1/p2os): swivel "
            "wheel r = 0.0375 m at x = -0.211 m; wheel mass 0.5 kg",
            "inertia": "chosen: 8 kg body as a uniform 0.44 x 0.38 x 0.18 m box centred 0.045 m behind "
            "the axle (not published)",
            "accelerations": "chosen: top speed and top turn rate in 1 s; the 0.85 N m motors deliver "
            "1.7 m/s^2 without spin-out",
            "gains": "chosen as the Jackal's: speed_gain = top speed, turn_gain 3.0, wheel PI of the "
            "default's bandwidth, max_wheel_speed 1.2 x the faster wheel speed of the top speed and "
            "the top turn rate",
        }
    ),
)

TURTLEBOT3_BURGER = RobotProfile(
    name="turtlebot3_burger",
    title="ROBOTIS TurtleBot3 Burger",
    model_file="turtlebot3_burger.xml",
    mass_kg=1.0,
    wheel_radius_m=0.033,
    track_m=0.16,
    footprint_m=(
        (0.037, -0.069),
        (0.037, 0.069),
        (0.033, 0.089),
        (-0.033, 0.089),
        (-0.101, 0.069),
        (-0.101, -0.069),
        (-0.033, -0.089),
        (0.033, -0.089),
    ),
    drive="differential",
    track_scale=1.0,
    wheel_friction=1.0,
    limits=DriveLimits(
        max_speed_mps=0.22, max_turn_rate_radps=2.84, max_accel_mps2=2.0, max_turn_accel_radps2=3.2
    ),
    ramped=True,
    gains=ControllerGains(
        speed_gain=0.22,
        turn_gain=3.0,
        max_wheel_speed=8.3,
        wheel_kp=0.016,
        wheel_ki=0.16,
        motor_rate_hz=100.0,
    ),
    sensors=_frozen(
        {"kind": "laser", "fov_deg": 360.0, "beams": 360, "range_min": 0.12, "range_max": 3.5, "rate_hz": 5.0}
    ),
    sonar_mounts=None,
    sensor_height_m=0.149,
    planner_settings=_frozen({"dwa": _frozen({"follow_way": 1, "clearance_weight": 0.05})}),
    sources=_frozen(
        {
            "size, mass, top speed, top turn rate": "ROBOTIS e-Manual, TurtleBot3 Specifications "
            "(https://emanual.robotis.com/docs/en/platform/turtlebot3/specifications/): "
            "138 x 178 x 192 mm, 1 kg, 0.22 m/s, 2.84 rad/s",
            "wheels, plates, caster, inertia": "turtlebot3_description/urdf/turtlebot3_burger.urdf "
            "(https://github.com/ROBOTIS-GIT/turtlebot3): wheels r = 0.033 m, 0.018 m wide at "
            "y = +-0.08 m, plate stack centred 0.032 m behind the axle, caster at x = -0.081 m",
            "laser": "turtlebot3_description/urdf/turtlebot3_burger.gazebo.xacro: LDS-01, 360 samples "
            "over 360 deg, 0.12-3.5 m, 5 Hz",
            "sensor height": "turtlebot3_burger.urdf: scan 0.172 m above base_link, 0.182 m above the "
            "floor, 0.149 m above the axle; the real scanner sits 0.032 m behind it",
            "imu": "turtlebot3_burger.urdf: imu_link 0.032 m behind and 0.068 m above base_link "
            "(0.045 m above the axle); noise and drift chosen as the Jackal's",
            "navigation footprint": "turtlebot3_navigation/param/costmap_common_params_burger.yaml: "
            "[[-0.105, -0.105], [-0.105, 0.105], [0.041, 0.105], [0.041, -0.105]]",
            "dwa settings": "turtlebot3_navigation (move_base): DWA follows the global planner's path; "
            "here as the Jackal's",
            "turn acceleration": "turtlebot3_navigation/param/dwa_local_planner_params_burger.yaml: "
            "acc_lim_theta 3.2 rad/s^2",
            "acceleration": "chosen: 2.0 m/s^2, what the 0.05 N m motors deliver on rolling tyres; "
            "the navigation stack's acc_lim_x of 2.5 m/s^2 (same file) spins the model's tyres, which "
            "carry 60 % of the weight (the rear caster the rest)",
            "centre of mass": "chosen: the centre of the plate stack (the description puts it at "
            "base_link on the floor)",
            "gains": "chosen as the Jackal's: speed_gain = top speed, turn_gain 3.0, wheel PI of the "
            "default's bandwidth, max_wheel_speed 1.2 x the faster wheel speed of the top speed and "
            "the top turn rate",
        }
    ),
)

PROFILES: dict[str, RobotProfile] = {
    profile.name: profile for profile in (DEFAULT, JACKAL, PIONEER_3DX, TURTLEBOT3_BURGER)
}


class ProfileError(VPlaneError):
    """A robot profile name that names no profile."""


def robot_profile(name: str) -> RobotProfile:
    """The profile `name`: how every module looks a profile up by name. A ProfileError lists
    the profiles and the closest name otherwise."""
    if name not in PROFILES:
        hint = did_you_mean(name, PROFILES)
        raise ProfileError(f"unknown robot profile {shown(name)}; known: {', '.join(PROFILES)}{hint}")
    return PROFILES[name]
