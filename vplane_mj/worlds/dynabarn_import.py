"""`vplane-mj import dynabarn`: DynaBARN's Gazebo worlds as scenarios of its layout.

A DynaBARN world file (`world_N.world`) holds a `<model>` per obstacle: a cylinder with a
`<plugin filename='easylibobs_N.so'>` that moves it (`vplane_mj.worlds.dynabarn_plugins` reads
the plugin's keyframes from its machine code). Each becomes a moving cylinder of
`vplane_mj.worlds.dynabarn_layout`: its radius from its `<collision>`, its keyframes moved to the
arena's frame by `dynabarn_layout.to_arena`. The model's own `<pose>` is not used: Gazebo sets
the model's world pose to the animation's at every step. A plugin is looked up in the folder
given (`plugins`), else in `plugins/` beside the world file, else beside it.

The world's three walls (`back_wall`, `top_wall`, `bottom_wall`: static boxes) are left out,
since the layout is an open plane without walls, as the BARN challenge runs DynaBARN. Its two
`<include>`s of `model://ground_plane` and `model://sun` are allowed; any other include, an
include or a model inside another element, an actor, a world plugin, any other model (one
without a plugin that is not a wall, a moving one that is not one cylinder) is a WorldFileError
naming the file and the element, as an XPath below `<world>`. Other children of `<world>`
(physics, scene, lights) place no obstacle and are ignored. Numbers and their ranges, names in
messages and the file's size are checked as `vplane_mj.worlds.sdf` checks BARN's worlds, and
world numbers and scenario names must be distinct as in `vplane_mj.worlds.barn_import`.

DynaBARN's world files are not well-formed XML as they stand: its walls carry `<pose frame=>`,
an attribute without a quoted value, which Gazebo's lenient TinyXML reads as an empty one. That
exact text is read as `<pose frame=''>` before parsing; anything else malformed is refused. (The
walls' stray backslash is character data, which XML allows.) The file is parsed with
xml.etree.ElementTree, which never fetches external entities or DTDs, and whose expat (2.4.1 or
later) refuses the exponential entity expansion of a "billion laughs" file.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from vplane_mj.errors import ScenarioError, WorldFileError, cut, readable, shown
from vplane_mj.scenario import parse_document
from vplane_mj.worlds.barn_import import world_files, world_number
from vplane_mj.worlds.dynabarn_layout import DIFFICULTIES, layout_document, moving_cylinder, to_arena
from vplane_mj.worlds.dynabarn_plugins import PluginAnimation, read_plugin
from vplane_mj.worlds.families import Case
from vplane_mj.worlds.sdf import ElementReader, step

WALLS = ("back_wall", "top_wall", "bottom_wall")
"""DynaBARN's static walls, left out of the scenario."""
INCLUDES = ("model://ground_plane", "model://sun")
"""The only `<include>`s allowed."""
PLUGIN_FILE = re.compile(r"easylibobs_[0-9]+\.so")
"""A DynaBARN plugin's file name."""
WORLDS_PER_DIFFICULTY = 20
"""DynaBARN's worlds 0-19 are easy, 20-39 medium, 40-59 hard."""
GAZEBO_EMPTY_FRAME = (b"<pose frame=>", b"<pose frame=''>")
"""DynaBARN's one malformation, and how it is read (as Gazebo's TinyXML does)."""
_REFUSED_WORLD_CHILDREN = frozenset({"actor", "population", "road", "frame", "joint", "plugin"})
"""Children of `<world>` that may hold or move obstacles this reader cannot take."""


@dataclass(frozen=True)
class MovingModel:
    """One model of a world that a plugin moves: its name, the element (XPath below `<world>`),
    its plugin's file name and its cylinder's radius (m)."""

    name: str
    element: str
    plugin: str
    radius: float


@dataclass(frozen=True)
class ImportedDynaWorld:
    """One converted world: the scenario, its moving cylinders' count, their mean speed between
    keyframes (m/s), DynaBARN's difficulty third ("easy", "medium", "hard"; None for a file
    numbered outside 0-59) and the static models (walls) left out."""

    case: Case
    cylinders: int
    mean_speed_mps: float
    difficulty: str | None
    static_left_out: int


class _Reader(ElementReader):
    """Reads one DynaBARN world file's models."""

    def centred(self, owner: ET.Element, where: str) -> None:
        """`owner`'s `<pose>`, if any, must not move the cylinder off its model's origin nor tilt it."""
        node = owner.find("pose")
        if node is None:
            return
        x, y, _, roll, pitch, _ = self.pose_numbers(node, f"{where}/pose")
        if node.get("relative_to") or node.get("frame") or any((x, y, roll, pitch)):
            reason = "moves or tilts the cylinder off its model's origin, which the animation places"
            raise self.fail(f"{where}/pose", reason)

    def radius(self, model: ET.Element, where: str) -> float:
        """The radius (m) of a moving model's one cylinder collision."""
        links = model.findall("link")
        collisions = [collision for link in links for collision in link.findall("collision")]
        if len(links) != 1 or len(collisions) != 1:
            reason = f"must have one link with one collision, got {len(links)} and {len(collisions)}"
            raise self.fail(where, reason)
        link_where = f"{where}/link[@name={shown(links[0].get('name', ''))}]"
        where = f"{link_where}/collision[@name={shown(collisions[0].get('name', ''))}]"
        self.centred(links[0], link_where)
        self.centred(collisions[0], where)
        geometry = collisions[0].find("geometry")
        shapes = [] if geometry is None else list(geometry)
        if len(shapes) != 1 or shapes[0].tag != "cylinder":
            got = ", ".join(f"<{cut(shape.tag)}>" for shape in shapes[:3]) or "nothing"
            got += f" and {len(shapes) - 3} more" if len(shapes) > 3 else ""
            raise self.fail(f"{where}/geometry", f"must be one <cylinder> (a moving model), got {got}")
        (radius,) = self.positive(shapes[0], "radius", f"{where}/geometry/cylinder", 1, "metres")
        return radius

    def wall(self, model: ET.Element, where: str) -> None:
        """One of DynaBARN's walls: static, its collisions boxes."""
        static = model.find("static")
        if static is None or (static.text or "").strip().lower() not in ("1", "true"):
            raise self.fail(where, "is not static: DynaBARN's walls are")
        for link in model.findall("link"):
            for collision in link.findall("collision"):
                geometry = collision.find("geometry")
                if geometry is None or [shape.tag for shape in geometry] != ["box"]:
                    raise self.fail(where, "has a collision that is not a <box>: DynaBARN's walls are boxes")

    def model(self, model: ET.Element) -> MovingModel | None:
        """A moving model, or None for one of the walls."""
        name = model.get("name")
        if not name:
            raise self.fail("model", "has no name")
        where = step(model)
        plugins = model.findall("plugin")
        if not plugins:
            if name not in WALLS:
                reason = f"has no plugin and is not one of DynaBARN's walls ({', '.join(WALLS)})"
                raise self.fail(where, reason)
            self.wall(model, where)
            return None
        if len(plugins) != 1:
            raise self.fail(where, f"must have one <plugin>, got {len(plugins)}")
        filename = plugins[0].get("filename", "")
        if not PLUGIN_FILE.fullmatch(filename):
            reason = f"filename must name a DynaBARN plugin easylibobs_N.so, got {shown(filename)}"
            raise self.fail(f"{where}/plugin", reason)
        return MovingModel(name, where, filename, self.radius(model, where))

    def include(self, node: ET.Element) -> None:
        uri = node.find("uri")
        text = "" if uri is None else (uri.text or "").strip()
        if text not in INCLUDES:
            raise self.fail("include/uri", f"{shown(text)} is not supported: only {' and '.join(INCLUDES)}")

    def world(self, root: ET.Element) -> tuple[list[MovingModel], int]:
        """The world's moving models and the number of walls left out."""
        if root.tag != "sdf":
            raise self.fail(root.tag, "the root element must be <sdf>")
        worlds = root.findall("world")
        if len(worlds) != 1:
            raise self.fail("sdf", f"must hold exactly one <world>, got {len(worlds)}")
        self.refuse_nested(worlds[0])
        moving: list[MovingModel] = []
        names: set[str] = set()
        walls = 0
        for child in worlds[0]:
            if child.tag in _REFUSED_WORLD_CHILDREN:
                raise self.fail(child.tag, f"<{child.tag}> is not supported in a DynaBARN world")
            if child.tag == "include":
                self.include(child)
            elif child.tag == "model":
                found = self.model(child)
                name = child.get("name", "")
                if name in names:
                    raise self.fail(step(child), "a second model of this name")
                names.add(name)
                if found is None:
                    walls += 1
                else:
                    moving.append(found)
        if not moving:
            raise self.fail("world", "holds no moving cylinder: not a DynaBARN world")
        return moving, walls


def read_world_models(path: Path, source: str | None = None) -> tuple[list[MovingModel], int]:
    """A DynaBARN world file's moving models and the number of its walls (left out).

    `source` names the file in errors (default: the path)."""
    reader = _Reader(source or str(path))
    return reader.world(reader.parse(reader.file_bytes(path).replace(*GAZEBO_EMPTY_FRAME)))


def plugin_path(world: Path, model: MovingModel, plugins: Path | None) -> Path:
    """Where a model's plugin is: in `plugins` when given, else in `plugins/` beside the world
    file, else beside it."""
    places = [plugins] if plugins is not None else [world.parent / "plugins", world.parent]
    for place in places:
        if (place / model.plugin).is_file():
            return place / model.plugin
    reason = f"its plugin {model.plugin} is in none of: {', '.join(readable(str(place)) for place in places)}"
    raise WorldFileError(str(world), f"{model.element}/plugin", reason)


def scenario_name(path: Path) -> str:
    """`dynabarn_` and the file's stem in the scenario name's alphabet: world_7.world -> dynabarn_world_7."""
    return "dynabarn_" + re.sub(r"[^a-z0-9_]", "_", path.stem.lower())


def difficulty(path: Path) -> str | None:
    """DynaBARN's difficulty third of world_N.world (N in 0-59), else None."""
    number = world_number(path)
    thirds = len(DIFFICULTIES) * WORLDS_PER_DIFFICULTY
    return DIFFICULTIES[number // WORLDS_PER_DIFFICULTY] if number is not None and number < thirds else None


def mean_speed(animations: list[PluginAnimation]) -> float:
    """The mean of the speeds (m/s) between consecutive keyframes, over every animation."""
    speeds = [
        math.hypot(x1 - x0, y1 - y0) / (t1 - t0)
        for animation in animations
        for (t0, x0, y0), (t1, x1, y1) in zip(animation.keyframes, animation.keyframes[1:], strict=False)
    ]
    return sum(speeds) / len(speeds)


def import_world(
    path: Path, plugins: Path | None = None, read: dict[Path, PluginAnimation] | None = None
) -> ImportedDynaWorld:
    """One DynaBARN world file as a scenario of the layout (a WorldFileError if it cannot be
    converted); `read` keeps the plugins read so far, by path."""
    source = str(path)
    read = {} if read is None else read
    models, walls = read_world_models(path, source)
    animations = []
    for model in models:
        plugin = plugin_path(path, model, plugins)
        if plugin not in read:
            read[plugin] = read_plugin(plugin)
        animations.append(read[plugin])
    obstacles = [
        moving_cylinder([[t, *to_arena(x, y)] for t, x, y in animation.keyframes], model.radius)
        for model, animation in zip(models, animations, strict=True)
    ]
    name = scenario_name(path)
    third = difficulty(path)
    description = (
        f"DynaBARN world {readable(path.name)} (Gazebo), {len(models)} cylinders moved by their plugins"
    )
    if third is not None:
        description += f"; DynaBARN's {third} third"
    document = layout_document(name, description, obstacles)
    try:
        parse_document(document, source)
    except ScenarioError as exc:
        raise WorldFileError(source, "", f"does not make a valid scenario: {exc.key}: {exc.reason}") from None
    return ImportedDynaWorld(Case(name, document), len(models), mean_speed(animations), third, walls)


def import_worlds(paths: list[Path], plugins: Path | None = None) -> list[ImportedDynaWorld]:
    """Every world `paths` name (files, or directories of world_N.world files), converted, or
    the first error: nothing is written here. `plugins`: the folder of the plugins, if not
    beside the worlds."""
    files = world_files(paths, scenario_name)
    read: dict[Path, PluginAnimation] = {}
    return [import_world(path, plugins, read) for path in files]


def report_line(world: ImportedDynaWorld) -> str:
    """One line on a converted world: its moving cylinders, their mean speed, its difficulty and
    the walls left out."""
    third = "" if world.difficulty is None else f", DynaBARN's {world.difficulty} third"
    return (
        f"{world.case.name}: {world.cylinders} moving cylinders, mean speed {world.mean_speed_mps:.2f} m/s "
        f"between keyframes{third}; {world.static_left_out} static models left out (walls)"
    )
