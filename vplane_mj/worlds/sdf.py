"""A Gazebo world file (SDF) read into the footprints of its static, upright cylinders and boxes.

What `vplane-mj import barn` needs from BARN's worlds, read strictly: every `<model>` of the
`<world>` must be static, and every collision geometry must be a `<cylinder>` or a `<box>`
standing upright (roll and pitch 0); a horizontal `<plane>` (the ground) is skipped. A model's
pose is the one the world's `<state>` block gives for it, where it gives one (the pose Gazebo
uses), else the model's own `<pose>`; it is composed with the link's and the collision's poses.
Anything else (a mesh, a sphere, a non-static model, an `<include>` anywhere, a `<model>` inside
another element than `<world>`, a pose relative to another frame, a malformed file or number, a
number out of its range) is a WorldFileError naming the file and the element, as an XPath below
`<world>`, e.g. `model[@name='m']/link[@name='link']/collision[@name='c']/geometry`.

Numbers are read as SDF writes them, in plain decimal or scientific notation (not Python's
`float`, which also takes `0.0_75`, `nan` or `infinity`); each must lie within +-NUMBER_LIMIT,
positions within +-POSITION_LIMIT_M and sizes in (0, SIZE_LIMIT_M]. Angles are wrapped to
[-pi, pi]. Names in messages are cut to a readable length (`vplane_mj.errors.shown`), and an
XPath longer than XPATH_STEPS steps.

The file, at most MAX_WORLD_BYTES, is parsed with xml.etree.ElementTree: it never fetches
external entities or DTDs, and its expat (2.4.1 or later) refuses the exponential entity
expansion of a "billion laughs" file. `ElementReader` is what the DynaBARN importer shares.
"""

from __future__ import annotations

import collections
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from vplane_mj.errors import WorldFileError, cut, shown
from vplane_mj.scenario.keys import MAX_OBSTACLE_M

MAX_WORLD_BYTES = 16 * 1024 * 1024
"""The largest world file read (bytes); BARN's are about 0.5 MB, DynaBARN's 20 to 40 kB."""
NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
"""A number as SDF writes one: decimal or scientific notation, ASCII digits only (unambiguous,
so that matching takes time linear in the token's length)."""
NUMBER_LIMIT = 1e4
"""The largest magnitude of any number read (angles in rad, positions in m, unitless values)."""
POSITION_LIMIT_M = MAX_OBSTACLE_M
"""The largest magnitude of a pose's x, y or z (m): a scenario's obstacle coordinates' bound."""
SIZE_LIMIT_M = MAX_OBSTACLE_M
"""The largest radius or box side (m): a scenario's obstacle sizes' bound."""
_TILT_TOLERANCE_RAD = 1e-6
"""Largest roll or pitch (rad) of a pose that still counts as upright."""
_UNSUPPORTED_WORLD_CHILDREN = frozenset({"include", "actor", "population", "road", "frame", "joint"})
"""Children of `<world>` that may hold or move obstacles this reader cannot take."""
XPATH_STEPS = 8
"""The most steps of an XPath a message shows: the first and the last half, the rest elided."""
_NESTED_REFUSED = frozenset({"include", "model"})
"""Elements refused below `<world>`'s own children (`<state>`'s models aside): they would hold
obstacles where no reader looks."""


@dataclass(frozen=True)
class WorldShape:
    """One collision shape in Gazebo's world frame: `kind` "cylinder" (with `radius`) or "box"
    (with `size`, x and y), its centre (m) and yaw (rad), and the element it came from."""

    kind: str
    x: float
    y: float
    yaw: float
    element: str
    radius: float = 0.0
    size: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class _Pose:
    """A planar pose (m, rad)."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def then(self, inner: _Pose) -> _Pose:
        """This pose composed with `inner`, a pose given in this pose's frame."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        x, y = self.x + c * inner.x - s * inner.y, self.y + s * inner.x + c * inner.y
        return _Pose(x, y, math.remainder(self.yaw + inner.yaw, math.tau))


def step(node: ET.Element) -> str:
    """One step of an XPath: the element's tag, with its name (quoted) when it has one, both cut."""
    name = node.get("name")
    return cut(node.tag) if name is None else f"{cut(node.tag)}[@name={shown(name)}]"


def xpath(world: ET.Element, target: ET.Element) -> str:
    """The XPath of `target` below `world`, each step named as `step` names it, the middle steps
    of a path longer than XPATH_STEPS elided."""
    parents = {child: parent for parent in world.iter() for child in parent}
    nodes = [target]
    while parents[nodes[-1]] is not world:
        nodes.append(parents[nodes[-1]])
    nodes.reverse()
    half = XPATH_STEPS // 2
    if len(nodes) <= XPATH_STEPS:
        return "/".join(map(step, nodes))
    elided = f"...({len(nodes) - XPATH_STEPS} steps)..."
    return "/".join([*map(step, nodes[:half]), elided, *map(step, nodes[-half:])])


def nested_element(world: ET.Element) -> ET.Element | None:
    """The first `<include>` or `<model>` below `<world>`'s own children (a `<model>` of the
    `<state>` block aside), or None."""
    pending = collections.deque((child, True) for child in world)
    while pending:
        node, on_top = pending.popleft()
        for child in node:
            state_model = on_top and node.tag == "state" and child.tag == "model"
            if child.tag in _NESTED_REFUSED and not state_model:
                return child
            pending.append((child, False))
    return None


class ElementReader:
    """Reads one file's elements; every error names `source` and the element."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, element: str, reason: str) -> WorldFileError:
        return WorldFileError(self.source, element, reason)

    def file_bytes(self, path: Path) -> bytes:
        """The file's bytes, at most MAX_WORLD_BYTES."""
        try:
            with path.open("rb") as file:
                data = file.read(MAX_WORLD_BYTES + 1)
        except OSError as exc:
            raise self.fail("", f"cannot read the file: {exc.strerror or exc}") from None
        if len(data) > MAX_WORLD_BYTES:
            raise self.fail("", f"is larger than {MAX_WORLD_BYTES} bytes: not a world of BARN or DynaBARN")
        return data

    def parse(self, data: bytes) -> ET.Element:
        """The root element of an XML document."""
        try:
            return ET.fromstring(data)
        except ET.ParseError as exc:
            raise self.fail("", f"not well-formed XML: {exc}") from None

    def refuse_nested(self, world: ET.Element) -> None:
        """No `<include>` or `<model>` may stand below `<world>`'s own children."""
        nested = nested_element(world)
        if nested is not None:
            raise self.fail(xpath(world, nested), f"<{nested.tag}> is not supported inside another element")

    def numbers(self, node: ET.Element, where: str, count: int, meaning: str) -> list[float]:
        """The `count` numbers of an element's text, each within +-NUMBER_LIMIT."""
        text = (node.text or "").strip()
        tokens = text.split()
        if len(tokens) == count and all(NUMBER.fullmatch(token) for token in tokens):
            values = [float(token) for token in tokens]
            if all(abs(value) <= NUMBER_LIMIT for value in values):
                return values
        numbers = "a number" if count == 1 else f"{count} numbers"
        reason = (
            f"must be {numbers} ({meaning}) in decimal or scientific notation, each within "
            f"+-{NUMBER_LIMIT:g}, got {shown(text)}"
        )
        raise self.fail(where, reason)

    def positive(self, parent: ET.Element, tag: str, where: str, count: int, meaning: str) -> list[float]:
        """The `count` sizes (m) of the required child `tag`, each in (0, SIZE_LIMIT_M]."""
        node = parent.find(tag)
        if node is None:
            raise self.fail(where, f"has no <{tag}>")
        values = self.numbers(node, f"{where}/{tag}", count, meaning)
        if not all(0 < value <= SIZE_LIMIT_M for value in values):
            text = (node.text or "").strip()
            reason = f"must be greater than 0 and at most {SIZE_LIMIT_M:g} m, got {shown(text)}"
            raise self.fail(f"{where}/{tag}", reason)
        return values

    def pose_numbers(self, node: ET.Element, where: str) -> list[float]:
        """A `<pose>`'s x, y, z (m, each within +-POSITION_LIMIT_M) and roll, pitch, yaw (rad,
        wrapped to [-pi, pi])."""
        values = self.numbers(node, where, 6, "x y z roll pitch yaw")
        if max(abs(value) for value in values[:3]) > POSITION_LIMIT_M:
            x, y, z = values[:3]
            reason = f"x, y and z must lie within +-{POSITION_LIMIT_M:g} m, got {x:g}, {y:g}, {z:g}"
            raise self.fail(where, reason)
        return values[:3] + [math.remainder(angle, math.tau) for angle in values[3:]]


class _Reader(ElementReader):
    """Reads one BARN world file's shapes."""

    def pose(self, owner: ET.Element, where: str) -> _Pose:
        """The planar pose of `owner`'s `<pose>` child (none: the identity); it must be upright
        and relative to its parent's frame."""
        node = owner.find("pose")
        if node is None:
            return _Pose()
        where = f"{where}/pose"
        frame = node.get("relative_to") or node.get("frame")
        if frame:
            reason = f"is relative to the frame {shown(frame)}: only poses in the parent's frame"
            raise self.fail(where, reason)
        x, y, _, roll, pitch, yaw = self.pose_numbers(node, where)
        if max(abs(roll), abs(pitch)) > _TILT_TOLERANCE_RAD:
            raise self.fail(where, f"is tilted (roll {roll:g}, pitch {pitch:g} rad): only upright shapes")
        return _Pose(x, y, yaw)

    def static(self, model: ET.Element, where: str) -> None:
        """The model must be `<static>`."""
        node = model.find("static")
        text = "" if node is None else (node.text or "").strip().lower()
        if text not in ("1", "true"):
            if text not in ("", "0", "false"):
                raise self.fail(f"{where}/static", f"must be true, false, 1 or 0, got {shown(text)}")
            raise self.fail(where, "is not static: only static models can be imported")

    def state_poses(self, world: ET.Element) -> dict[str, _Pose]:
        """The model poses the `<state>` block gives, by model name (unscaled models only)."""
        poses: dict[str, _Pose] = {}
        for state in world.findall("state"):
            for model in state.findall("model"):
                where = f"state/model[@name={shown(model.get('name', ''))}]"
                scale = model.find("scale")
                if scale is not None and self.numbers(scale, f"{where}/scale", 3, "x y z") != [1, 1, 1]:
                    raise self.fail(f"{where}/scale", "scaled models are not supported")
                if model.find("pose") is not None:
                    poses[model.get("name", "")] = self.pose(model, where)
        return poses

    def geometry(self, collision: ET.Element, where: str, pose: _Pose) -> WorldShape | None:
        """The shape of one collision (None for a horizontal plane, the ground)."""
        node = collision.find("geometry")
        where = f"{where}/geometry"
        shapes = [] if node is None else list(node)
        if len(shapes) != 1:
            raise self.fail(where, f"must hold exactly one shape, got {len(shapes)}")
        shape = shapes[0]
        where_shape = f"{where}/{cut(shape.tag)}"
        if shape.tag == "cylinder":
            (radius,) = self.positive(shape, "radius", where_shape, 1, "metres")
            return WorldShape("cylinder", pose.x, pose.y, pose.yaw, where_shape, radius=radius)
        if shape.tag == "box":
            sx, sy, _ = self.positive(shape, "size", where_shape, 3, "x y z, metres")
            return WorldShape("box", pose.x, pose.y, pose.yaw, where_shape, size=(sx, sy))
        if shape.tag == "plane":
            normal = shape.find("normal")
            if normal is None or self.numbers(normal, f"{where_shape}/normal", 3, "x y z")[:2] == [0, 0]:
                return None
            raise self.fail(f"{where_shape}/normal", "a plane that is not horizontal is not supported")
        raise self.fail(where_shape, f"<{cut(shape.tag)}> is not supported: only <cylinder> and <box>")

    def model(self, model: ET.Element, state_pose: _Pose | None) -> list[WorldShape]:
        """The shapes of one static model's collisions."""
        if not model.get("name"):
            raise self.fail("model", "has no name")
        where = step(model)
        self.static(model, where)
        model_pose = state_pose if state_pose is not None else self.pose(model, where)
        shapes = []
        for link in model.findall("link"):
            where_link = f"{where}/link[@name={shown(link.get('name', ''))}]"
            link_pose = model_pose.then(self.pose(link, where_link))
            for collision in link.findall("collision"):
                where_collision = f"{where_link}/collision[@name={shown(collision.get('name', ''))}]"
                pose = link_pose.then(self.pose(collision, where_collision))
                shape = self.geometry(collision, where_collision, pose)
                if shape is not None:
                    shapes.append(shape)
        return shapes

    def world(self, root: ET.Element) -> list[WorldShape]:
        """Every shape of the file's one world."""
        if root.tag != "sdf":
            raise self.fail(cut(root.tag), "the root element must be <sdf>")
        worlds = root.findall("world")
        if len(worlds) != 1:
            raise self.fail("sdf", f"must hold exactly one <world>, got {len(worlds)}")
        world = worlds[0]
        for child in world:
            if child.tag in _UNSUPPORTED_WORLD_CHILDREN:
                raise self.fail(child.tag, f"<{child.tag}> is not supported: only <model> elements")
        self.refuse_nested(world)
        poses = self.state_poses(world)
        shapes = []
        for model in world.findall("model"):
            shapes.extend(self.model(model, poses.get(model.get("name", ""))))
        return shapes


def read_world_shapes(path: Path, source: str | None = None) -> list[WorldShape]:
    """The collision shapes of the static models of a Gazebo world file, in Gazebo's world frame.

    `source` names the file in errors (default: the path)."""
    reader = _Reader(source or str(path))
    return reader.world(reader.parse(reader.file_bytes(path)))
