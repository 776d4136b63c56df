"""A run's MCAP log as a ROS 2 bag (docs/ros2.md): what `ros2 bag play` of Humble and Jazzy
replays into RViz 2, and PlotJuggler and Foxglove open.

The bag is a rosbag2 directory: `metadata.yaml` (version `BAG_VERSION`) and one MCAP file
(profile `ros2`, zstd chunks) of CDR messages whose `ros2msg` schemas carry the definitions
they depend on, as `ros2 bag record` stores them; written with rosbags. Every time is the
log's, simulated time from 0; frames as REP 105 names them: `map` (the log's `world`), `odom`
(the frame of the pose the planner used), `base_link` and the sensor's frame.

| topic | type | from the log |
|---|---|---|
| `/clock` | rosgraph_msgs/msg/Clock | every control tick (`/robot/pose`) |
| `/tf` | tf2_msgs/msg/TFMessage | every tick: `map` -> `odom`, `odom` -> `base_link` |
| `/tf_static` | tf2_msgs/msg/TFMessage | once: `base_link` -> `laser` or `sonar` (`/scan`'s pose) |
| `/scan` | sensor_msgs/msg/LaserScan | every tick (`/scan`), the sensor's frame |
| `/odom` | nav_msgs/msg/Odometry | the pose the planner used (`/robot/odometry`, else `/robot/pose`) |
| `/ground_truth` | nav_msgs/msg/Odometry | the true pose (`/robot/pose`), frame `map` |
| `/cmd_vel` | geometry_msgs/msg/Twist | every tick: the commanded speed and turn rate (`/metrics`) |
| `/goal_pose` | geometry_msgs/msg/PoseStamped | once: the scenario's goal, frame `map` |
| `/plan` | nav_msgs/msg/Path | at the start and when the planner's intermediate aim changes |
| `/markers/world` | visualization_msgs/msg/MarkerArray | once: arena, obstacles, goal, robot (`/world`) |
| `/markers/moving` | visualization_msgs/msg/MarkerArray | the moving obstacles (`/world/moving`) |
| `/markers/forces` | visualization_msgs/msg/MarkerArray | the force arrows (`/forces`) |
| `/markers/virtual` | visualization_msgs/msg/MarkerArray | virtual objective, planes (`/virtual`); `odom` |
| `/markers/path` | visualization_msgs/msg/MarkerArray | the path travelled (`/path`) |
| `/markers/tracks` | visualization_msgs/msg/MarkerArray | the planner's moving tracks (`/tracks`); `odom` |
| `/rosout` | rcl_interfaces/msg/Log | the events (`/events`), named `vplane_mj.<kind>` |
| `/run/summary` | std_msgs/msg/String | once, at the end: the run summary as JSON |

`map` -> `odom` is the log's `world` -> `odom` (the identity when the planner's pose is the
truth, and before the first), and `odom` -> `base_link` what puts `base_link` on the true pose:
the planner's pose, wherever the log has it. The Odometry twists are the poses' differences
from the tick before (m/s, rad/s in `base_link`; zero at the first), their covariances zero.
`/scan` ranges are the log's, from the robot's centre at the sensor's height (NaN where no
echo came back: the log does not tell "nothing within range" from "closer than range_min"),
a sonar ring as one scan as in the log. `/plan` runs from the planner's pose through what it
aims at, when anything, to the goal (frame `odom`): the virtual objective of an escape, the
waypoint past an obstacle's edge; the planners here plan no longer way. Each marker topic's
message holds its part of the scene whole, as the log's topics do, so that a viewer that keeps
a topic's latest message draws it right after a seek. `/tf_static`, `/markers/world` and
`/goal_pose` are offered transient-local (one message each), so a late subscriber gets them.
"""

from __future__ import annotations

import contextlib
import gc
import itertools
import json
import math
from collections.abc import Iterator
from functools import partial
from pathlib import Path
from typing import Any, Literal

import numpy as np
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

from vplane_mj.errors import VPlaneError, readable
from vplane_mj.files import write_directory_atomically
from vplane_mj.logs.reader import LogContents, LoggedEvent, LogMessage
from vplane_mj.logs.replay import load_log
from vplane_mj.logs.ros2_markers import SceneMarkers
from vplane_mj.logs.ros2_messages import (
    STORE,
    Clock,
    Headers,
    LaserScan,
    Log,
    NavPath,
    Odometry,
    PoseStamped,
    PoseWithCovariance,
    Quaternion,
    String,
    TFMessage,
    Twist,
    TwistWithCovariance,
    Vector3,
    planar_pose,
    serialize,
    stamp,
    transform,
    yaw_quaternion,
)
from vplane_mj.logs.scene import ODOM_FRAME, ROBOT_FRAME
from vplane_mj.logs.writer import METADATA_NAME, MOVING_TOPIC, TRACKS_TOPIC
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.scenario import Scenario

RVIZ_CONFIG = Path(__file__).with_name("vplane.rviz")
"""An RViz 2 configuration that shows the bag's topics (docs/ros2.md)."""
BAG_VERSION: Literal[8] = 8
"""The rosbag2 metadata version written: Jazzy's; Humble reads it too (the fields it knows)."""
ABOUT_KEYS = ("scenario", "planner", "seed", "robot_profile", "sensor_kind", "vplane_mj_version")
"""The log's metadata that the bag's `custom_data` repeats (as `vplane_mj.<key>`)."""
MAP_FRAME = "map"
SENSOR_FRAMES = {"laser": "laser", "sonar": "sonar"}
"""The sensor's frame, by the log's `sensor_kind`."""
_PLANNER_TOPICS = ("/virtual", TRACKS_TOPIC)
"""Log topics in the planner's frame (`odom`); the rest of the scene is in `map`."""
MARKER_TOPICS = {
    "/world": "/markers/world",
    MOVING_TOPIC: "/markers/moving",
    "/forces": "/markers/forces",
    "/virtual": "/markers/virtual",
    "/path": "/markers/path",
    TRACKS_TOPIC: "/markers/tracks",
}
"""The bag's marker topic of each scene topic of the log."""
READ_TOPICS = ("/robot/odometry", "/tf", "/scan", "/metrics", "/events", *MARKER_TOPICS)
"""The log's topics read for the bag, besides those `read_log` reads anyway."""
AIMS = {EventKind.ESCAPE_STARTED: "objective", EventKind.AVOIDANCE_STARTED: "waypoint"}
"""The events that give the planner an intermediate aim, and the point of their data it is."""
AIM_ENDS = (EventKind.ESCAPE_FINISHED, EventKind.ESCAPE_TIMED_OUT, EventKind.AVOIDANCE_FINISHED)
"""The events after which the planner aims at the goal again."""
LOG_LEVELS = {1: 10, 2: 20, 3: 30, 4: 40, 5: 50}
"""rcl_interfaces/msg/Log level of each `foxglove.Log` level (debug, info, warning, error, fatal)."""


def _qos(durability: QosDurability, depth: int) -> Qos:
    """A reliable, keep-last QoS profile as the bag's metadata offers it."""
    never = QosTime(sec=0, nsec=0)
    return Qos(
        history=QosHistory.KEEP_LAST,
        depth=depth,
        reliability=QosReliability.RELIABLE,
        durability=durability,
        deadline=never,
        lifespan=never,
        liveliness=QosLiveliness.AUTOMATIC,
        liveliness_lease_duration=never,
        avoid_ros_namespace_conventions=False,
    )


VOLATILE = _qos(QosDurability.VOLATILE, 10)
LATCHED = _qos(QosDurability.TRANSIENT_LOCAL, 1)
"""Transient-local: the publisher keeps its message for subscribers that come later (as
tf2's static broadcaster does)."""
TOPICS: dict[str, tuple[str, Qos]] = {
    "/clock": ("rosgraph_msgs/msg/Clock", VOLATILE),
    "/tf": ("tf2_msgs/msg/TFMessage", VOLATILE),
    "/tf_static": ("tf2_msgs/msg/TFMessage", LATCHED),
    "/scan": ("sensor_msgs/msg/LaserScan", VOLATILE),
    "/odom": ("nav_msgs/msg/Odometry", VOLATILE),
    "/ground_truth": ("nav_msgs/msg/Odometry", VOLATILE),
    "/cmd_vel": ("geometry_msgs/msg/Twist", VOLATILE),
    "/goal_pose": ("geometry_msgs/msg/PoseStamped", LATCHED),
    "/plan": ("nav_msgs/msg/Path", VOLATILE),
    **{
        topic: ("visualization_msgs/msg/MarkerArray", LATCHED if topic == "/markers/world" else VOLATILE)
        for topic in MARKER_TOPICS.values()
    },
    "/rosout": ("rcl_interfaces/msg/Log", VOLATILE),
    "/run/summary": ("std_msgs/msg/String", VOLATILE),
}
"""Every topic a bag may have, in the order it lists them: its type and offered QoS."""

_Message = tuple[int, str, Any]
"""A message of the bag: its time (ns), topic and content."""
_Pose = tuple[float, float, float]
"""x, y (m) and yaw (rad)."""


def export_ros2(log: Path, target: Path) -> Path:
    """Write the bag of the vplane-mj log `log` as the directory `target` (in place of a bag
    there) and return `target`. A VPlaneError names the file and the reason when `log` is not a
    whole vplane-mj log or `target` cannot be written; nothing is left behind then."""
    log, target = Path(log), Path(target)
    _check_target(target)
    with _cycles_uncollected():
        contents, scenario = load_log(log, READ_TOPICS)
        if not contents.complete:
            raise VPlaneError(
                f"{readable(log)}: truncated: the log ends before its MCAP footer (its run was killed, "
                "or the file was cut)"
            )
        messages = _Conversion(contents, scenario).messages()
        info = contents.metadata[METADATA_NAME]
        about = {f"vplane_mj.{key}": info[key] for key in ABOUT_KEYS if key in info}
        try:
            write_directory_atomically(target, partial(_write_bag, messages=messages, about=about))
        except OSError as exc:
            raise VPlaneError(f"{readable(target)}: cannot write the bag: {exc.strerror or exc}") from None
    return target


@contextlib.contextmanager
def _cycles_uncollected() -> Iterator[None]:
    """Python's cyclic garbage collector paused for the block: the export makes a few hundred
    thousand small objects and no cycles, and the collector, started every few hundred of them,
    would walk all the log's messages again each time (it tripled the time of the conversion)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _check_target(target: Path) -> None:
    """Refuse a target whose parent is missing, or that is there and not a bag (a directory
    with its metadata.yaml), which it would replace."""
    if not target.parent.is_dir():
        raise VPlaneError(f"{readable(target)}: no such directory: {readable(target.parent)}")
    if target.exists() and not (target.is_dir() and (target / "metadata.yaml").is_file()):
        raise VPlaneError(f"{readable(target)}: is there and is not a ROS 2 bag: not replaced")


def _write_bag(directory: Path, messages: list[_Message], about: dict[str, str]) -> None:
    """The bag of `messages` as `directory`: in time order, those of one time in their order;
    `about` its metadata's `custom_data`."""
    writer = Writer(directory, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    for key, value in about.items():
        writer.set_custom_data(key, value)
    present = {topic for _, topic, _ in messages}
    with writer:
        connections = {
            topic: writer.add_connection(topic, kind, typestore=STORE, offered_qos_profiles=[qos])
            for topic, (kind, qos) in TOPICS.items()
            if topic in present
        }
        for ns, topic, message in sorted(messages, key=lambda m: m[0]):
            writer.write(connections[topic], ns, serialize(message))


class _Conversion:
    """The bag's messages from one log: `contents` (with the messages of READ_TOPICS) and
    `scenario` as `load_log` read them."""

    def __init__(self, contents: LogContents, scenario: Scenario):
        self.contents = contents
        self.scenario = scenario
        self.times_ns = [int(ns) for ns in contents.times_ns]
        self.truth: list[_Pose] = [
            (float(x), float(y), float(yaw))
            for (x, y), yaw in zip(contents.positions, contents.yaws, strict=True)
        ]
        self.out: list[_Message] = []
        self.header = Headers()
        read: dict[str, list[LogMessage]] = {topic: [] for topic in READ_TOPICS}
        for message in contents.messages:
            read[message.topic].append(message)
        self.beliefs = {m.log_time_ns: _planar(m.message.pose) for m in read["/robot/odometry"]}
        self.drifts = {
            m.log_time_ns: _transform_pose(frame)
            for m in read["/tf"]
            for frame in m.message.transforms
            if frame.child_frame_id == ODOM_FRAME
        }
        self.scans, self.commands, self.logs = read["/scan"], read["/metrics"], read["/events"]
        self.scene = [m for m in contents.messages if m.topic in MARKER_TOPICS]

    def messages(self) -> list[_Message]:
        """Every message of the bag, in the order of their making (the static ones first)."""
        self._static()
        planner = self._planner_poses()
        self._ticks(planner)
        self._odometry("/odom", ODOM_FRAME, planner)
        self._odometry("/ground_truth", MAP_FRAME, list(zip(self.times_ns, self.truth, strict=True)))
        self._scans()
        self._commands()
        self._plan(planner)
        self._markers()
        self._events()
        summary = self.contents.summary
        if summary is not None:
            self.out.append((self.times_ns[-1], "/run/summary", String(data=json.dumps(summary))))
        return self.out

    def _static(self) -> None:
        """`/tf_static` (the sensor's frame, where the first scan was taken) and `/goal_pose`."""
        if self.scans:
            first = self.scans[0].message
            where = first.pose.position
            q = first.pose.orientation
            rotation = Quaternion(x=q.x, y=q.y, z=q.z, w=q.w)
            mount = transform(
                self.header(0, ROBOT_FRAME), self._sensor_frame(), where.x, where.y, where.z, rotation
            )
            self.out.append((0, "/tf_static", TFMessage(transforms=[mount])))
        gx, gy = self.scenario.robot.goal
        goal = PoseStamped(header=self.header(0, MAP_FRAME), pose=planar_pose(float(gx), float(gy), 0.0))
        self.out.append((0, "/goal_pose", goal))

    def _sensor_frame(self) -> str:
        return SENSOR_FRAMES[self.contents.metadata[METADATA_NAME]["sensor_kind"]]

    def _planner_poses(self) -> list[tuple[int, _Pose]]:
        """The pose the planner used at each tick that has one: the believed pose where the log
        has any, else the true pose."""
        if not self.beliefs:
            return list(zip(self.times_ns, self.truth, strict=True))
        return [(ns, self.beliefs[ns]) for ns in self.times_ns if ns in self.beliefs]

    def _ticks(self, planner: list[tuple[int, _Pose]]) -> None:
        """`/clock` and `/tf` at every tick."""
        drift: _Pose = (0.0, 0.0, 0.0)
        for ns, truth in zip(self.times_ns, self.truth, strict=True):
            drift = self.drifts.get(ns, drift)
            x, y, yaw = _relative(drift, truth)
            odom = transform(
                self.header(ns, MAP_FRAME), ODOM_FRAME, *drift[:2], 0.0, yaw_quaternion(drift[2])
            )
            base = transform(self.header(ns, ODOM_FRAME), ROBOT_FRAME, x, y, 0.0, yaw_quaternion(yaw))
            self.out.append((ns, "/clock", Clock(clock=self.header(ns, MAP_FRAME).stamp)))
            self.out.append((ns, "/tf", TFMessage(transforms=[odom, base])))

    def _odometry(self, topic: str, frame: str, poses: list[tuple[int, _Pose]]) -> None:
        """nav_msgs/msg/Odometry of `poses` in `frame`, the twist their differences."""
        none = np.zeros(36)
        for (ns, pose), (vx, vy, wz) in zip(poses, _twists(poses), strict=True):
            twist = Twist(linear=Vector3(x=vx, y=vy, z=0.0), angular=Vector3(x=0.0, y=0.0, z=wz))
            message = Odometry(
                header=self.header(ns, frame),
                child_frame_id=ROBOT_FRAME,
                pose=PoseWithCovariance(pose=planar_pose(*pose), covariance=none),
                twist=TwistWithCovariance(twist=twist, covariance=none),
            )
            self.out.append((ns, topic, message))

    def _scans(self) -> None:
        frame = self._sensor_frame()
        sensors = self.scenario.sensors
        range_min = sensors.range_min if sensors.kind == "laser" else 0.0
        no_intensities = np.empty(0, np.float32)
        for logged in self.scans:
            ns, message = logged.log_time_ns, logged.message
            ranges = np.array(message.ranges, dtype=np.float32)
            count = len(ranges)
            step = (message.end_angle - message.start_angle) / (count - 1) if count > 1 else 0.0
            self.out.append(
                (
                    ns,
                    "/scan",
                    LaserScan(
                        header=self.header(ns, frame),
                        angle_min=message.start_angle,
                        angle_max=message.end_angle,
                        angle_increment=step,
                        time_increment=0.0,
                        scan_time=1.0 / sensors.rate_hz,
                        range_min=range_min,
                        range_max=sensors.range_max,
                        ranges=ranges,
                        intensities=no_intensities,
                    ),
                )
            )

    def _commands(self) -> None:
        """`/cmd_vel`: the speed and turn rate commanded at each tick (zero where none)."""
        for logged in self.commands:
            ns, metrics = logged.log_time_ns, logged.message
            v, omega = metrics.get("command_v_mps", 0.0), metrics.get("command_omega_radps", 0.0)
            twist = Twist(linear=Vector3(x=v, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=omega))
            self.out.append((ns, "/cmd_vel", twist))

    def _plan(self, planner: list[tuple[int, _Pose]]) -> None:
        """`/plan` at the start and at every event that changes what the planner aims at."""
        if not planner:
            return
        times = np.array([ns for ns, _ in planner], dtype=np.int64)
        gx, gy = (float(v) for v in self.scenario.robot.goal)
        for ns, aim in [(planner[0][0], None), *_aims(self.contents.events)]:
            x, y, yaw = planner[max(int(np.searchsorted(times, ns, side="right")) - 1, 0)][1]
            ahead = [*([aim] if aim is not None else []), (gx, gy)]
            poses = [planar_pose(x, y, yaw), *(planar_pose(px, py, 0.0) for px, py in ahead)]
            header = self.header(ns, ODOM_FRAME)
            stamped = [PoseStamped(header=header, pose=pose) for pose in poses]
            self.out.append((ns, "/plan", NavPath(header=header, poses=stamped)))

    def _markers(self) -> None:
        converters = {
            topic: SceneMarkers(ODOM_FRAME if topic in _PLANNER_TOPICS else MAP_FRAME, self.header)
            for topic in MARKER_TOPICS
        }
        for logged in self.scene:
            ns, topic = logged.log_time_ns, logged.topic
            self.out.append((ns, MARKER_TOPICS[topic], converters[topic].markers(logged.message, ns)))

    def _events(self) -> None:
        """`/rosout`: each event's text, its kind as the logger's name."""
        for logged in self.logs:
            ns, log = logged.log_time_ns, logged.message
            message = Log(
                stamp=stamp(ns),
                level=LOG_LEVELS.get(log.level, Log.INFO),
                name=f"vplane_mj.{log.name}",
                msg=log.message,
                file="",
                function="",
                line=0,
            )
            self.out.append((ns, "/rosout", message))


def _aims(events: list[LoggedEvent]) -> list[tuple[int, tuple[float, float] | None]]:
    """When (ns) the planner's aim changed, and to what: a point, or None for the goal alone."""
    changes: list[tuple[int, tuple[float, float] | None]] = []
    for event in events:
        ns = round(event.time_s * 1e9)
        if event.kind in AIMS and AIMS[event.kind] in event.data:
            changes.append((ns, event.data[AIMS[event.kind]]))
        elif event.kind in AIM_ENDS:
            changes.append((ns, None))
    return changes


def _planar(pose: Any) -> _Pose:
    """x, y and yaw of a decoded `foxglove.Pose`."""
    q = pose.orientation
    return (pose.position.x, pose.position.y, 2 * math.atan2(q.z, q.w))


def _transform_pose(frame: Any) -> _Pose:
    """x, y and yaw of a decoded `foxglove.FrameTransform`."""
    q = frame.rotation
    return (frame.translation.x, frame.translation.y, 2 * math.atan2(q.z, q.w))


def _relative(frame: _Pose, pose: _Pose) -> _Pose:
    """`pose` (in the frame `frame` is in) in `frame`."""
    dx, dy = pose[0] - frame[0], pose[1] - frame[1]
    c, s = math.cos(frame[2]), math.sin(frame[2])
    return (c * dx + s * dy, -s * dx + c * dy, pose[2] - frame[2])


def _twists(poses: list[tuple[int, _Pose]]) -> list[tuple[float, float, float]]:
    """Forward and sideways speed (m/s) in the body frame and turn rate (rad/s) of each pose,
    from the pose before it (zero at the first)."""
    twists = [(0.0, 0.0, 0.0)] if poses else []
    for (t0, (x0, y0, yaw0)), (t1, (x1, y1, yaw1)) in itertools.pairwise(poses):
        dt = (t1 - t0) / 1e9
        c, s = math.cos(yaw1), math.sin(yaw1)
        dx, dy = (x1 - x0) / dt, (y1 - y0) / dt
        turn = math.remainder(yaw1 - yaw0, 2 * math.pi) / dt
        twists.append((c * dx + s * dy, -s * dx + c * dy, turn))
    return twists
