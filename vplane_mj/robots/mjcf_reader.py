"""An MJCF file read with xml.etree, without MuJoCo: bodies and geoms posed, attributes resolved.

Only the subset of MJCF that models/robot.xml uses is understood: nested default classes,
`class` and `childclass`, positions, `quat` and `euler` orientations (with the compiler's
`angle` unit, `eulerseq` xyz), and sphere, cylinder and box geoms. Anything else that would
move or shape a geom is refused with a ValueError rather than misread. Poses are those of
the model as loaded (every joint at its reference), in metres, in the world frame.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vplane_mj.planning.protocol.matrices import product

MAIN_CLASS = "main"
"""The default class that the top-level `<default>` defines and every class inherits from."""
GEOM_TYPES = ("sphere", "cylinder", "box")
UNSUPPORTED_ORIENTATIONS = ("axisangle", "xyaxes", "zaxis", "fromto")
UNSUPPORTED_ELEMENTS = ("frame", "include", "replicate", "attach")


@dataclass(frozen=True)
class PosedGeom:
    """A geom in the world frame: its name and body's name, type and size (MJCF's), position, rotation."""

    name: str
    body: str
    type: str
    size: tuple[float, ...]
    pos: np.ndarray
    rot: np.ndarray


class MjcfReader:
    """One MJCF file: attribute values as MuJoCo resolves them, and the pose of every body and geom."""

    def __init__(self, path: Path):
        self.path = path
        self.root = ET.parse(path).getroot()
        for tag in UNSUPPORTED_ELEMENTS:
            if self.root.find(f".//{tag}") is not None:
                raise ValueError(f"{path}: <{tag}> is not supported by this reader")
        # class -> (its <default> element, its parent class or None)
        self._defaults: dict[str, tuple[ET.Element, str | None]] = {}
        for top in self.root.findall("default"):
            self._collect_defaults(top, None)
        compiler = self.root.find("compiler")
        self._radians = compiler is not None and compiler.get("angle", "degree") == "radian"
        if compiler is not None and compiler.get("eulerseq", "xyz") != "xyz":
            raise ValueError(f"{path}: compiler eulerseq other than xyz is not supported by this reader")

    def _collect_defaults(self, element: ET.Element, parent: str | None) -> None:
        name = element.get("class", MAIN_CLASS)
        self._defaults[name] = (element, parent)
        for child in element.findall("default"):
            self._collect_defaults(child, name)

    def attribute(self, element: ET.Element, name: str, cls: str = MAIN_CLASS) -> str | None:
        """The element's attribute `name`: its own, else from its class and that class's ancestors."""
        if name in element.attrib:
            return element.attrib[name]
        current: str | None = element.get("class", cls)
        while current is not None:
            if current not in self._defaults:
                raise ValueError(f"{self.path}: unknown default class {current!r}")
            default, current = self._defaults[current]
            setting = default.find(element.tag)
            if setting is not None and name in setting.attrib:
                return setting.attrib[name]
        return None

    def numbers(self, element: ET.Element, name: str, cls: str = MAIN_CLASS) -> tuple[float, ...] | None:
        """The attribute `name` as numbers, or None when neither the element nor its class sets it."""
        text = self.attribute(element, name, cls)
        return None if text is None else tuple(float(item) for item in text.split())

    def named(self, tag: str, name: str) -> ET.Element:
        """The element `<tag name="name">`."""
        found = self.root.find(f".//{tag}[@name='{name}']")
        if found is None:
            raise ValueError(f"{self.path}: no <{tag} name={name!r}>")
        return found

    def body_poses(self) -> Iterator[tuple[ET.Element, str, np.ndarray, np.ndarray]]:
        """Every body below the world: (element, its class for children, world position, rotation)."""
        worldbody = self.root.find("worldbody")
        if worldbody is None:
            return
        stack = [(body, MAIN_CLASS, np.zeros(3), np.eye(3)) for body in worldbody.findall("body")]
        while stack:
            body, inherited, parent_pos, parent_rot = stack.pop()
            cls = body.get("childclass", inherited)
            local_pos, local_rot = self._frame(body, inherited)
            pos, rot = parent_pos + product(parent_rot, local_pos), product(parent_rot, local_rot)
            yield body, cls, pos, rot
            stack.extend((child, cls, pos, rot) for child in body.findall("body"))

    def body_position(self, name: str) -> np.ndarray:
        """The world position (m) of the body `name`."""
        for body, _, pos, _ in self.body_poses():
            if body.get("name") == name:
                return pos
        raise ValueError(f"{self.path}: no <body name={name!r}>")

    def geoms(self) -> list[PosedGeom]:
        """Every geom of every body below the world (the world's own geoms are not the model's)."""
        posed = []
        for body, cls, body_pos, body_rot in self.body_poses():
            for geom in body.findall("geom"):
                kind = self.attribute(geom, "type", cls) or "sphere"
                if kind not in GEOM_TYPES:
                    raise ValueError(f"{self.path}: geom type {kind!r} is not supported by this reader")
                size = self.numbers(geom, "size", cls) or ()
                local_pos, local_rot = self._frame(geom, cls)
                pos, rot = body_pos + product(body_rot, local_pos), product(body_rot, local_rot)
                posed.append(PosedGeom(geom.get("name", ""), body.get("name", ""), kind, size, pos, rot))
        return posed

    def _frame(self, element: ET.Element, cls: str) -> tuple[np.ndarray, np.ndarray]:
        """The element's position and rotation in its parent's frame."""
        for name in UNSUPPORTED_ORIENTATIONS:
            if self.attribute(element, name, cls) is not None:
                raise ValueError(f"{self.path}: {name} is not supported by this reader")
        pos = np.array(self.numbers(element, "pos", cls) or (0.0, 0.0, 0.0))
        quat = self.numbers(element, "quat", cls)
        euler = self.numbers(element, "euler", cls)
        if quat is not None:
            return pos, quat_to_matrix(quat)
        if euler is not None:
            angles = euler if self._radians else tuple(math.radians(angle) for angle in euler)
            return pos, euler_xyz_to_matrix(angles)
        return pos, np.eye(3)


def quat_to_matrix(quat: tuple[float, ...]) -> np.ndarray:
    """The rotation matrix of a quaternion (w, x, y, z), normalised first as MuJoCo does."""
    w, x, y, z = np.asarray(quat, float) / math.hypot(*quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def euler_xyz_to_matrix(angles: tuple[float, ...]) -> np.ndarray:
    """Rotations (rad) about x, then the new y, then the newer z (MJCF's default eulerseq xyz)."""
    a, b, c = angles
    rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    return product(product(rx, ry), rz)
