"""ROS 2 messages as the bag of a run holds them: the message types of ROS 2 Humble (rosbags'
typestore, which also serializes them as CDR) and the small parts every message is made of.

Times are integer nanoseconds of simulated time, lengths metres, angles radians.
"""

from __future__ import annotations

import math
from typing import Any

from rosbags.typesys import Stores, get_typestore

STORE = get_typestore(Stores.ROS2_HUMBLE)
"""The message definitions of ROS 2 Humble, which Jazzy's equal for every type the bag uses."""
_TYPES = STORE.types

Time: Any = _TYPES["builtin_interfaces/msg/Time"]
Duration: Any = _TYPES["builtin_interfaces/msg/Duration"]
Header: Any = _TYPES["std_msgs/msg/Header"]
ColorRGBA: Any = _TYPES["std_msgs/msg/ColorRGBA"]
String: Any = _TYPES["std_msgs/msg/String"]
Vector3: Any = _TYPES["geometry_msgs/msg/Vector3"]
Point: Any = _TYPES["geometry_msgs/msg/Point"]
Quaternion: Any = _TYPES["geometry_msgs/msg/Quaternion"]
Pose: Any = _TYPES["geometry_msgs/msg/Pose"]
PoseStamped: Any = _TYPES["geometry_msgs/msg/PoseStamped"]
PoseWithCovariance: Any = _TYPES["geometry_msgs/msg/PoseWithCovariance"]
Transform: Any = _TYPES["geometry_msgs/msg/Transform"]
TransformStamped: Any = _TYPES["geometry_msgs/msg/TransformStamped"]
Twist: Any = _TYPES["geometry_msgs/msg/Twist"]
TwistWithCovariance: Any = _TYPES["geometry_msgs/msg/TwistWithCovariance"]
Clock: Any = _TYPES["rosgraph_msgs/msg/Clock"]
TFMessage: Any = _TYPES["tf2_msgs/msg/TFMessage"]
LaserScan: Any = _TYPES["sensor_msgs/msg/LaserScan"]
CompressedImage: Any = _TYPES["sensor_msgs/msg/CompressedImage"]
Odometry: Any = _TYPES["nav_msgs/msg/Odometry"]
NavPath: Any = _TYPES["nav_msgs/msg/Path"]
"""nav_msgs/msg/Path (named apart from pathlib's)."""
Marker: Any = _TYPES["visualization_msgs/msg/Marker"]
MarkerArray: Any = _TYPES["visualization_msgs/msg/MarkerArray"]
MeshFile: Any = _TYPES["visualization_msgs/msg/MeshFile"]
Log: Any = _TYPES["rcl_interfaces/msg/Log"]

IDENTITY = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
"""No rotation. The bag's messages share such parts: none is changed once made."""


def serialize(message: Any) -> memoryview:
    """`message` as CDR (little-endian), as a ROS 2 publisher sends it."""
    return STORE.serialize_cdr(message, message.__msgtype__)


def stamp(ns: int) -> Any:
    """The Time of `ns` nanoseconds."""
    sec, nanosec = divmod(ns, 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


def yaw_quaternion(yaw: float) -> Any:
    """The rotation by `yaw` about +z."""
    return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def planar_pose(x: float, y: float, yaw: float) -> Any:
    """A Pose on the floor (z = 0), heading `yaw`."""
    return Pose(position=Point(x=x, y=y, z=0.0), orientation=yaw_quaternion(yaw))


def transform(header: Any, child: str, x: float, y: float, z: float, rotation: Any) -> Any:
    """A TransformStamped from the frame of `header` to `child`."""
    translation = Vector3(x=x, y=y, z=z)
    return TransformStamped(
        header=header, child_frame_id=child, transform=Transform(translation=translation, rotation=rotation)
    )


class Headers:
    """One Header for each time and frame: the messages of a tick share theirs."""

    def __init__(self) -> None:
        self._made: dict[tuple[int, str], Any] = {}
        self._stamps: dict[int, Any] = {}

    def __call__(self, ns: int, frame: str) -> Any:
        made = self._made.get((ns, frame))
        if made is None:
            when = self._stamps.get(ns)
            if when is None:
                when = self._stamps[ns] = stamp(ns)
            made = self._made[ns, frame] = Header(stamp=when, frame_id=frame)
        return made
