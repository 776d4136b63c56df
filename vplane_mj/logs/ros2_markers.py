"""The scene of a run's log as ROS 2 markers: each `foxglove.SceneUpdate` of one topic as a
visualization_msgs/msg/MarkerArray that makes an RViz 2 MarkerArray display show what a
Foxglove 3D panel shows.

A scene entity becomes one marker per primitive: namespace the entity's id, id the primitive's
place among the entity's (cubes, cylinders, spheres, arrows, lines, triangles, texts, in that
order). An entity replaced by one with fewer primitives, or deleted, has its other markers
deleted (DELETE); a deletion of every entity is a DELETEALL. Frames keep their names but
`world`, which becomes the frame the caller names. Arrows are drawn from their two end points,
so that their heads are as long as the log's; texts `TEXT_HEIGHT_M` tall.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from vplane_mj.logs.ros2_messages import (
    IDENTITY,
    ColorRGBA,
    CompressedImage,
    Duration,
    Headers,
    Marker,
    MarkerArray,
    MeshFile,
    Point,
    Pose,
    Quaternion,
    Vector3,
)
from vplane_mj.logs.scene import WORLD_FRAME

TEXT_HEIGHT_M = 0.2
"""The height of a text marker (m): the log's labels are sized in screen pixels, which markers
cannot be."""
_LINE_LOOP, _LINE_LIST = 1, 2
"""`foxglove.LinePrimitive` types (0 is a strip)."""
_DELETE_ALL = 1
"""`foxglove.SceneEntityDeletion` type that deletes every entity (0 deletes one by its id)."""
_ORIGIN = Pose(position=Point(x=0.0, y=0.0, z=0.0), orientation=IDENTITY)
_UNIT = Vector3(x=1.0, y=1.0, z=1.0)
_FOREVER = Duration(sec=0, nanosec=0)
_UNUSED = {  # the fields of a Marker that no marker here uses
    "colors": [],
    "texture_resource": "",
    "texture": CompressedImage(header=Headers()(0, ""), format="", data=np.empty(0, np.uint8)),
    "uv_coordinates": [],
    "mesh_resource": "",
    "mesh_file": MeshFile(filename="", data=np.empty(0, np.uint8)),
    "mesh_use_embedded_materials": False,
}


class SceneMarkers:
    """Turns the SceneUpdates of one topic, in their order, into MarkerArrays; the log's frame
    `world` becomes `world_frame`, and the headers come from `headers`."""

    def __init__(self, world_frame: str, headers: Headers):
        self.world_frame = world_frame
        self._headers = headers
        self._shown: dict[str, tuple[str, int]] = {}  # entity id -> its frame and marker count
        self._colours: dict[tuple[float, float, float, float], Any] = {}

    def markers(self, update: Any, ns: int) -> Any:
        """The MarkerArray of the decoded SceneUpdate `update`, logged at `ns`."""
        markers = []
        for deletion in update.deletions:
            if deletion.type == _DELETE_ALL:
                markers.append(self._deletion(ns, self.world_frame, "", 0, Marker.DELETEALL))
                self._shown.clear()
            elif deletion.id in self._shown:
                frame, count = self._shown.pop(deletion.id)
                markers += [self._deletion(ns, frame, deletion.id, k, Marker.DELETE) for k in range(count)]
        for entity in update.entities:
            drawn = list(self._entity(entity))
            frame = self._frame(entity.frame_id)
            _, before = self._shown.get(entity.id, (frame, 0))
            markers += drawn
            markers += [
                self._deletion(ns, frame, entity.id, k, Marker.DELETE) for k in range(len(drawn), before)
            ]
            self._shown[entity.id] = (frame, len(drawn))
        return MarkerArray(markers=markers)

    def _frame(self, frame_id: str) -> str:
        return self.world_frame if frame_id == WORLD_FRAME else frame_id

    def _entity(self, entity: Any) -> Iterator[Any]:
        """One marker per primitive of the decoded SceneEntity."""
        when = entity.timestamp.seconds * 1_000_000_000 + entity.timestamp.nanos
        lifetime = entity.lifetime
        common = {
            "header": self._headers(when, self._frame(entity.frame_id)),
            "ns": entity.id,
            "lifetime": Duration(sec=lifetime.seconds, nanosec=lifetime.nanos)
            if lifetime.seconds or lifetime.nanos
            else _FOREVER,
            "frame_locked": entity.frame_locked,
        }
        shapes = (
            (entity.cubes, Marker.CUBE),
            (entity.cylinders, Marker.CYLINDER),
            (entity.spheres, Marker.SPHERE),
        )
        index = 0
        for primitives, kind in shapes:
            for shape in primitives:
                yield self._new(common, index, kind, _pose(shape.pose), _vector(shape.size), shape.color)
                index += 1
        for arrow in entity.arrows:
            yield self._arrow(common, index, arrow)
            index += 1
        for line in entity.lines:
            yield self._line(common, index, line)
            index += 1
        for triangles in entity.triangles:
            points = [Point(x=p.x, y=p.y, z=p.z) for p in triangles.points]
            yield self._new(
                common, index, Marker.TRIANGLE_LIST, _pose(triangles.pose), _UNIT, triangles.color, points
            )
            index += 1
        for text in entity.texts:
            scale = Vector3(x=1.0, y=1.0, z=TEXT_HEIGHT_M)
            yield self._new(
                common, index, Marker.TEXT_VIEW_FACING, _pose(text.pose), scale, text.color, text=text.text
            )
            index += 1

    def _arrow(self, common: dict, index: int, arrow: Any) -> Any:
        """An arrow from its tail (the primitive's position) along its pose's x axis: scale x
        the shaft's diameter, y the head's, z the head's length."""
        length = arrow.shaft_length + arrow.head_length
        scale = Vector3(x=arrow.shaft_diameter, y=arrow.head_diameter, z=arrow.head_length)
        ends = [Point(x=0.0, y=0.0, z=0.0), Point(x=length, y=0.0, z=0.0)]
        return self._new(common, index, Marker.ARROW, _pose(arrow.pose), scale, arrow.color, ends)

    def _line(self, common: dict, index: int, line: Any) -> Any:
        """A line strip (a loop closed by its first point again) or a line list, `thickness` wide."""
        points = [Point(x=p.x, y=p.y, z=p.z) for p in line.points]
        if line.type == _LINE_LOOP and points:
            points.append(points[0])
        kind = Marker.LINE_LIST if line.type == _LINE_LIST else Marker.LINE_STRIP
        scale = Vector3(x=line.thickness, y=0.0, z=0.0)
        return self._new(common, index, kind, _pose(line.pose), scale, line.color, points)

    def _new(
        self,
        common: dict,
        index: int,
        kind: int,
        pose: Any,
        scale: Any,
        rgba: Any,
        points: list | None = None,
        text: str = "",
    ) -> Any:
        return Marker(
            **common,
            id=index,
            type=kind,
            action=Marker.ADD,
            pose=pose,
            scale=scale,
            color=self._colour(rgba),
            points=points or [],
            text=text,
            **_UNUSED,
        )

    def _colour(self, rgba: Any) -> Any:
        """The ColorRGBA of a decoded `foxglove.Color`, one object for each colour."""
        key = (rgba.r, rgba.g, rgba.b, rgba.a)
        made = self._colours.get(key)
        if made is None:
            made = self._colours[key] = ColorRGBA(r=rgba.r, g=rgba.g, b=rgba.b, a=rgba.a)
        return made

    def _deletion(self, ns: int, frame: str, name: str, index: int, action: int) -> Any:
        return Marker(
            header=self._headers(ns, frame),
            ns=name,
            id=index,
            type=Marker.CUBE,
            action=action,
            pose=_ORIGIN,
            scale=_UNIT,
            color=ColorRGBA(r=0.0, g=0.0, b=0.0, a=0.0),
            lifetime=_FOREVER,
            frame_locked=False,
            points=[],
            text="",
            **_UNUSED,
        )


def _pose(pose: Any) -> Any:
    """A decoded `foxglove.Pose` as a Pose."""
    p, q = pose.position, pose.orientation
    return Pose(position=Point(x=p.x, y=p.y, z=p.z), orientation=Quaternion(x=q.x, y=q.y, z=q.z, w=q.w))


def _vector(v: Any) -> Any:
    return Vector3(x=v.x, y=v.y, z=v.z)
