"""How a run is drawn in a viewer's 3D panel: the Foxglove scene entities of its log.

Every entity is in frame `world` (the robot's body in `base_link`, frame-locked so it moves
with `/tf`). Force arrows start at the robot's centre and point along the force; their
length is `ARROW_M_PER_UNIT` per unit of force, clipped to `ARROW_MAX_M`. Virtual planes are
thin translucent walls with their centre line; the virtual objective a sphere on a post;
the path one line strip. Moving obstacles look like the static ones, wherever they stand; the
planner's moving tracks are translucent cylinders of their radius with their velocity as an
arrow and their id as a label.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Sequence
from typing import NamedTuple, Protocol

import numpy as np
from foxglove import messages as fm

from vplane_mj.geometry import shapes
from vplane_mj.geometry.motion import Moving
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.scenario import Scenario
from vplane_mj.sim.world import OBSTACLE_HEIGHT_M

WORLD_FRAME = "world"
ROBOT_FRAME = "base_link"
FOLLOW_FRAME = "base_link_xy"
ODOM_FRAME = "odom"
"""At base_link's position with the world's orientation: a camera following it never turns."""
ARROW_M_PER_UNIT = 0.5
"""Force arrow length (m) per unit of force magnitude."""
ARROW_MAX_M = 1.5
"""Longest force arrow (m); stronger forces are drawn at this length."""
ARROW_MIN_FORCE = 1e-4
"""Forces weaker than this are not drawn (their arrow is deleted)."""
ROBOT_BODY_HEIGHT_M = 0.12
"""Height (m) of the robot's disc in `/world`."""
ARROW_HEIGHT_M = 0.3
"""Height (m) above the floor at which the force arrows are drawn."""
PATH_ID = "path"
"""The one `/path` entity, replaced by every message."""

FORCE_STYLE: dict[str, tuple[tuple[float, float, float, float], float]] = {
    # name: (RGBA colour, extra height (m) so that overlapping arrows stay visible)
    "attractive": ((0.15, 0.75, 0.25, 1.0), 0.00),
    "repulsive": ((0.90, 0.20, 0.15, 1.0), 0.01),
    "virtual": ((0.70, 0.25, 0.90, 1.0), 0.02),
    "total": ((0.15, 0.45, 1.00, 1.0), 0.03),
}
"""The force arrows drawn, by the name of the planner's force component (and the total)."""

_COLOURS = {
    "arena": (0.92, 0.92, 0.92, 1.0),
    "obstacle": (0.45, 0.45, 0.50, 1.0),
    "border": (0.30, 0.30, 0.33, 1.0),
    "start": (0.15, 0.75, 0.25, 1.0),
    "goal": (1.00, 0.75, 0.10, 0.6),
    "objective": (0.70, 0.25, 0.90, 1.0),
    "plane": (0.70, 0.25, 0.90, 0.45),
    "path": (0.10, 0.35, 0.95, 1.0),
    "robot": (0.20, 0.24, 0.32, 0.9),
    "heading": (1.00, 1.00, 1.00, 1.0),
    "outline": (1.00, 0.55, 0.10, 1.0),
    "track": (0.90, 0.15, 0.55, 1.0),
}
TRACK_FILL_ALPHA = 0.35
"""Opacity of a track's cylinder (its arrow and label are opaque)."""
TRACK_ARROW_S = 1.0
"""A moving track's velocity arrow reaches where it would be after this long (s)."""


IDENTITY = fm.Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
"""No rotation (x, y, z, w)."""


def stamp(ns: int) -> fm.Timestamp:
    """A message timestamp from integer nanoseconds of simulated time."""
    sec, nsec = divmod(ns, 1_000_000_000)
    return fm.Timestamp(sec, nsec)


def yaw_quaternion(yaw: float) -> fm.Quaternion:
    """Rotation by `yaw` about +z in Foxglove's order (x, y, z, w)."""
    return fm.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def pose(x: float, y: float, z: float = 0.0, yaw: float = 0.0) -> fm.Pose:
    return fm.Pose(position=fm.Vector3(x=x, y=y, z=z), orientation=yaw_quaternion(yaw))


def deletion(when: fm.Timestamp, entity_id: str) -> fm.SceneEntityDeletion:
    return fm.SceneEntityDeletion(timestamp=when, type=fm.SceneEntityDeletionType.MatchingId, id=entity_id)


def _colour(rgba: tuple[float, float, float, float]) -> fm.Color:
    return fm.Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])


def world_entities(scenario: Scenario, body: RobotBody) -> list[fm.SceneEntity]:
    """The static scene at time 0: arena, obstacles, border, start, goal and the robot's body."""
    robot_radius_m = body.radius_m
    when = stamp(0)
    world = scenario.world
    w, h = world.size
    entities = [
        fm.SceneEntity(
            timestamp=when,
            frame_id=WORLD_FRAME,
            id="arena",
            cubes=[
                fm.CubePrimitive(
                    pose=pose(w / 2, h / 2, -0.005),
                    size=fm.Vector3(x=w, y=h, z=0.01),
                    color=_colour(_COLOURS["arena"]),
                )
            ],
        )
    ]
    for index, obstacle in zip(world.static_indices(), world.obstacles, strict=True):
        entities.append(_pieces_entity(f"obstacle_{index}", obstacle.footprint(), _COLOURS["obstacle"], when))
    if world.border:
        entities.append(
            _pieces_entity("border", shapes.border_footprint(world.size), _COLOURS["border"], when)
        )
    robot = scenario.robot
    radius = max(robot_radius_m, 0.05)
    entities.append(
        fm.SceneEntity(
            timestamp=when,
            frame_id=WORLD_FRAME,
            id="start",
            cylinders=[_flat_disc(robot.start, radius, _COLOURS["start"])],
            arrows=[
                fm.ArrowPrimitive(
                    pose=pose(robot.start[0], robot.start[1], 0.02, robot.start_yaw),
                    shaft_length=radius,
                    shaft_diameter=0.02,
                    head_length=0.06,
                    head_diameter=0.06,
                    color=_colour(_COLOURS["start"]),
                )
            ],
        )
    )
    entities.append(
        fm.SceneEntity(
            timestamp=when,
            frame_id=WORLD_FRAME,
            id="goal",
            cylinders=[_flat_disc(robot.goal, robot.goal_tolerance, _COLOURS["goal"])],
        )
    )
    entities.append(_robot_body(when, body))
    return entities


def _robot_body(when: fm.Timestamp, body: RobotBody) -> fm.SceneEntity:
    """The robot locked to base_link: a round robot as a disc of its radius, another as its
    footprint polygon (filled, and outlined at the floor); with a heading arrow."""
    radius = body.radius_m
    cylinders, triangles, lines = [], [], []
    if body.disc:
        cylinders.append(
            fm.CylinderPrimitive(
                pose=pose(0.0, 0.0, ROBOT_BODY_HEIGHT_M / 2),
                size=fm.Vector3(x=2 * radius, y=2 * radius, z=ROBOT_BODY_HEIGHT_M),
                bottom_scale=1.0,
                top_scale=1.0,
                color=_colour(_COLOURS["robot"]),
            )
        )
    else:
        triangles.append(_polygon_fill(body.footprint, ROBOT_BODY_HEIGHT_M, _COLOURS["robot"]))
        lines.append(_polygon_outline(body.footprint, 0.01, _COLOURS["outline"]))
    return fm.SceneEntity(
        timestamp=when,
        frame_id=ROBOT_FRAME,
        id="robot",
        frame_locked=True,
        cylinders=cylinders,
        triangles=triangles,
        lines=lines,
        arrows=[
            fm.ArrowPrimitive(
                pose=pose(0.0, 0.0, ROBOT_BODY_HEIGHT_M + 0.01),
                shaft_length=0.7 * body.front_m,
                shaft_diameter=0.03,
                head_length=0.3 * body.front_m + 0.03,
                head_diameter=0.08,
                color=_colour(_COLOURS["heading"]),
            )
        ],
    )


def _polygon_fill(polygon: np.ndarray, z: float, rgba) -> fm.TriangleListPrimitive:
    """A convex polygon (k, 2) as a fan of triangles at height z (m)."""
    corners = [fm.Point3(x=float(x), y=float(y), z=z) for x, y in polygon]
    points = [p for i in range(1, len(corners) - 1) for p in (corners[0], corners[i], corners[i + 1])]
    return fm.TriangleListPrimitive(pose=pose(0.0, 0.0), points=points, color=_colour(rgba))


def _polygon_outline(polygon: np.ndarray, z: float, rgba) -> fm.LinePrimitive:
    """A polygon (k, 2) as a closed line at height z (m)."""
    return fm.LinePrimitive(
        type=fm.LinePrimitiveLineType.LineLoop,
        pose=pose(0.0, 0.0),
        thickness=0.02,
        scale_invariant=False,
        points=[fm.Point3(x=float(x), y=float(y), z=z) for x, y in polygon],
        color=_colour(rgba),
    )


def _piece_primitives(
    piece: shapes.Piece, colour: fm.Color
) -> tuple[list[fm.CubePrimitive], list[fm.CylinderPrimitive]]:
    """One footprint piece as a vertical cube or cylinder standing on the floor."""
    h = OBSTACLE_HEIGHT_M
    if isinstance(piece, shapes.Disc):
        size = fm.Vector3(x=2 * piece.radius, y=2 * piece.radius, z=h)
        at = pose(piece.center[0], piece.center[1], h / 2)
        return [], [fm.CylinderPrimitive(pose=at, size=size, bottom_scale=1.0, top_scale=1.0, color=colour)]
    size = fm.Vector3(x=2 * piece.half[0], y=2 * piece.half[1], z=h)
    at = pose(piece.center[0], piece.center[1], h / 2, piece.yaw)
    return [fm.CubePrimitive(pose=at, size=size, color=colour)], []


def _pieces_entity(
    entity_id: str, pieces: tuple[shapes.Piece, ...], rgba, when: fm.Timestamp
) -> fm.SceneEntity:
    colour = _colour(rgba)
    cubes: list[fm.CubePrimitive] = []
    cylinders: list[fm.CylinderPrimitive] = []
    for piece in pieces:
        piece_cubes, piece_cylinders = _piece_primitives(piece, colour)
        cubes += piece_cubes
        cylinders += piece_cylinders
    return fm.SceneEntity(
        timestamp=when, frame_id=WORLD_FRAME, id=entity_id, cubes=cubes, cylinders=cylinders
    )


def _flat_disc(center, radius: float, rgba) -> fm.CylinderPrimitive:
    """A 1 cm thick disc lying on the floor (start and goal markers)."""
    return fm.CylinderPrimitive(
        pose=pose(center[0], center[1], 0.005),
        size=fm.Vector3(x=2 * radius, y=2 * radius, z=0.01),
        bottom_scale=1.0,
        top_scale=1.0,
        color=_colour(rgba),
    )


FORCE_COLOURS: dict[str, fm.Color] = {name: _colour(rgba) for name, (rgba, _) in FORCE_STYLE.items()}
"""The colour of each force arrow, made once (a message keeps a copy of what it is given)."""


def force_arrow(
    x: float, y: float, fx: float, fy: float, colour: fm.Color, dz: float
) -> fm.ArrowPrimitive | None:
    """The arrow of the force (fx, fy) at (x, y), or None when it is ~zero or not finite."""
    magnitude = math.hypot(fx, fy)
    if not math.isfinite(magnitude) or magnitude < ARROW_MIN_FORCE:
        return None
    length = min(ARROW_M_PER_UNIT * magnitude, ARROW_MAX_M)
    head = min(0.1, 0.4 * length)
    return fm.ArrowPrimitive(
        pose=pose(x, y, ARROW_HEIGHT_M + dz, math.atan2(fy, fx)),
        shaft_length=length - head,
        shaft_diameter=0.025,
        head_length=head,
        head_diameter=0.07,
        color=colour,
    )


def objective_entity(when: fm.Timestamp, objective: tuple[float, ...]) -> fm.SceneEntity:
    """The virtual new objective: a sphere on a post as tall as the obstacles."""
    colour = _colour(_COLOURS["objective"])
    return fm.SceneEntity(
        timestamp=when,
        frame_id=WORLD_FRAME,
        id="objective",
        spheres=[
            fm.SpherePrimitive(
                pose=pose(objective[0], objective[1], 0.1), size=fm.Vector3(x=0.2, y=0.2, z=0.2), color=colour
            )
        ],
        cylinders=[
            fm.CylinderPrimitive(
                pose=pose(objective[0], objective[1], OBSTACLE_HEIGHT_M / 2),
                size=fm.Vector3(x=0.03, y=0.03, z=OBSTACLE_HEIGHT_M),
                bottom_scale=1.0,
                top_scale=1.0,
                color=colour,
            )
        ],
    )


def plane_entity(when: fm.Timestamp, entity_id: str, plane: tuple[float, ...]) -> fm.SceneEntity:
    """A virtual plane e1-e2 as a thin, tall, translucent wall plus its centre line."""
    x1, y1, x2, y2 = plane
    length = max(math.hypot(x2 - x1, y2 - y1), 0.01)
    return fm.SceneEntity(
        timestamp=when,
        frame_id=WORLD_FRAME,
        id=entity_id,
        cubes=[
            fm.CubePrimitive(
                pose=pose((x1 + x2) / 2, (y1 + y2) / 2, OBSTACLE_HEIGHT_M / 2, math.atan2(y2 - y1, x2 - x1)),
                size=fm.Vector3(x=length, y=0.02, z=OBSTACLE_HEIGHT_M),
                color=_colour(_COLOURS["plane"]),
            )
        ],
        lines=[
            fm.LinePrimitive(
                type=fm.LinePrimitiveLineType.LineStrip,
                pose=pose(0.0, 0.0),
                thickness=0.03,
                points=[fm.Point3(x=x1, y=y1, z=0.02), fm.Point3(x=x2, y=y2, z=0.02)],
                color=_colour(_COLOURS["objective"]),
            )
        ],
    )


def path_entity(when: fm.Timestamp, points: list[tuple[float, float]]) -> fm.SceneEntity:
    """The path from the start to the robot as the one line strip `PATH_ID`."""
    line = fm.LinePrimitive(
        type=fm.LinePrimitiveLineType.LineStrip,
        pose=pose(0.0, 0.0, 0.01),
        thickness=0.03,
        scale_invariant=False,
        points=[fm.Point3(x=px, y=py) for px, py in points],
        color=_colour(_COLOURS["path"]),
    )
    return fm.SceneEntity(timestamp=when, frame_id=WORLD_FRAME, id=PATH_ID, lines=[line])


def moving_entities(when: fm.Timestamp, moving: Sequence[Moving], places: np.ndarray) -> list[fm.SceneEntity]:
    """The moving obstacles standing at `places` (count, 2; m, in `moving`'s order), drawn as the
    static ones, each the entity `obstacle_<i>` of its index i in the file."""
    return [
        _pieces_entity(
            f"obstacle_{obstacle.index}",
            dataclasses.replace(obstacle.shape, center=(float(x), float(y))).footprint(),
            _COLOURS["obstacle"],
            when,
        )
        for obstacle, (x, y) in zip(moving, places, strict=True)
    ]


class TrackedObstacle(Protocol):
    """What the log reads of an obstacle the planner's tracker follows (`Tick.tracks`)."""

    @property
    def track_id(self) -> int: ...

    @property
    def position(self) -> np.ndarray: ...

    @property
    def velocity(self) -> np.ndarray: ...

    @property
    def radius_m(self) -> float: ...

    @property
    def moving(self) -> bool: ...


class TrackMark(NamedTuple):
    """A moving track as drawn: its id, centre (m), velocity (m/s) and radius (m)."""

    track_id: int
    x: float
    y: float
    vx: float
    vy: float
    radius_m: float

    @property
    def entity_id(self) -> str:
        return f"track_{self.track_id}"


def track_marks(tracks: Iterable[TrackedObstacle]) -> tuple[TrackMark, ...]:
    """The moving tracks, those the planners act on, as numbers taken when the tick comes (a
    tracker may reuse its objects); one without a finite centre and radius is left out. Tracks
    that stand (a BARN world's dozens of posts) are not drawn: they would double its log."""
    marks = []
    for track in tracks:
        if not track.moving:
            continue
        x, y = (float(v) for v in track.position[:2])
        vx, vy = (float(v) for v in track.velocity[:2])
        radius = float(track.radius_m)
        if math.isfinite(x) and math.isfinite(y) and math.isfinite(radius):
            marks.append(TrackMark(int(track.track_id), x, y, vx, vy, max(radius, 0.0)))
    return tuple(marks)


def track_entity(when: fm.Timestamp, mark: TrackMark) -> fm.SceneEntity:
    """A track: a translucent cylinder of its radius, a little taller than the obstacles (seen from
    above, a tinted disc around the obstacle it follows), its id as a label above it and an arrow
    from its centre to where it will be in TRACK_ARROW_S. No outline: a polygon per track at
    every tick would be most of a log."""
    rgba = _COLOURS["track"]
    colour = _colour(rgba)
    height = OBSTACLE_HEIGHT_M + 0.05
    return fm.SceneEntity(
        timestamp=when,
        frame_id=WORLD_FRAME,
        id=mark.entity_id,
        cylinders=[
            fm.CylinderPrimitive(
                pose=pose(mark.x, mark.y, height / 2),
                size=fm.Vector3(x=2 * mark.radius_m, y=2 * mark.radius_m, z=height),
                bottom_scale=1.0,
                top_scale=1.0,
                color=_colour((*rgba[:3], TRACK_FILL_ALPHA)),
            )
        ],
        arrows=[arrow] if (arrow := _velocity_arrow(mark, colour)) is not None else [],
        texts=[
            fm.TextPrimitive(
                pose=pose(mark.x, mark.y, OBSTACLE_HEIGHT_M + 0.1),
                billboard=True,
                font_size=14.0,
                scale_invariant=True,
                color=colour,
                text=str(mark.track_id),
            )
        ],
    )


def _velocity_arrow(mark: TrackMark, colour: fm.Color) -> fm.ArrowPrimitive | None:
    """The arrow from a track's centre to where its velocity takes it in TRACK_ARROW_S; None when
    that is (nearly) nowhere or not finite."""
    length = math.hypot(mark.vx, mark.vy) * TRACK_ARROW_S
    if not math.isfinite(length) or length < 0.01:
        return None
    head = min(0.1, 0.4 * length)
    return fm.ArrowPrimitive(
        pose=pose(mark.x, mark.y, 0.05, math.atan2(mark.vy, mark.vx)),
        shaft_length=length - head,
        shaft_diameter=0.025,
        head_length=head,
        head_diameter=0.07,
        color=colour,
    )
