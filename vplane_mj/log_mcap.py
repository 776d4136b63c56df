"""The MCAP log of one run (README "Replaying a run in Foxglove"), written with foxglove-sdk, and read back.

Writing: `McapLog` is an `Observer` of `run_scenario`. It owns a private
`foxglove.Context`, so several runs (threads, tests) never share channels, and an
MCAP writer with zstd chunks. Every timestamp, both the record's `log_time` and the
messages' own `timestamp` fields, is the integer nanosecond of *simulated* time,
`round(time_s * 1e9)`; `/world` is logged once at time 0.

| topic | schema | when |
|---|---|---|
| `/robot/pose` | `foxglove.PoseInFrame` | every control tick, frame `world`, z = 0 |
| `/tf` | `foxglove.FrameTransforms` | every tick, `world` -> `base_link` and `base_link_xy` |
| `/scan` | `foxglove.LaserScan` | every tick, frame `base_link`, NaN where no echo |
| `/world` | `foxglove.SceneUpdate` | once at time 0: arena, obstacles, border, start, goal, robot |
| `/forces` | `foxglove.SceneUpdate` | every tick: force arrows at the robot |
| `/virtual` | `foxglove.SceneUpdate` | at time 0 (empty), then when the objective or planes change |
| `/path` | `foxglove.SceneUpdate` | the path so far: first tick, about once per simulated second, close |
| `/events` | `foxglove.Log` | `run started: ...` at time 0, then one per event, name `vplane_mj` |
| `/metrics` | JSON (`vplane_mj.Metrics` JSON schema) | every tick (see below) |
| `/robot/odometry` | `foxglove.PoseInFrame` | believed pose, every tick, if `sensors.pose = "odometry"` |

Force arrows start at the robot's centre and point along the force (world frame);
their length is `ARROW_M_PER_UNIT` (0.5 m) per unit of force, clipped to
`ARROW_MAX_M` (1.5 m); an arrow whose force is (near) zero or not finite is deleted
until it comes back. Entity ids: `/forces` `attractive`, `repulsive`, `virtual`,
`total`; `/virtual` `objective`, `plane_0`, `plane_1`, ... (by position in the
planner's list); `/path` `path` (one line strip from the start to the robot, replaced
by every message, so that the latest message before any time, all a viewer keeps of a
scene topic after a seek, shows the whole path up to then; simplified to within
`PATH_TOLERANCE_M` of every logged pose, which keeps it a few hundred points long);
`/world` `arena`, `border`, `obstacle_<i>`, `start`, `goal` (frame `world`) and `robot`
(a disc of `robot_radius_m` with a heading arrow in frame `base_link`, frame-locked, so
it moves with `/tf`). Entities that vanish are removed with `SceneUpdate.deletions`.

`/metrics` uses only plain JSON schema types (`number`, `string`), as viewers require:
a number that is missing (`force_virtual` without a virtual force, `odometry_error_m`
without odometry) or not finite is omitted from the message instead of being null.

The file metadata: record `vplane_mj` (scenario name, resolved TOML text, seed,
planner and its parameters, package versions, time base, plus the caller's
`metadata` entries, which win over a same-named key) and, at close, record
`summary` whose key `json` holds the run summary as JSON text.

Crash safety: the writer is flushed (open chunk finished and written to disk) about
once per simulated second, so a process killed with SIGKILL loses at most about the
last second; `read_log` recovers every complete chunk of such a file (see there).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, BinaryIO

import foxglove
import mujoco
import numpy as np
from foxglove import channels as fc
from foxglove import messages as fm
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from mcap import records as mr
from mcap.exceptions import EndOfFile
from mcap.stream_reader import StreamReader
from mcap_protobuf.decoder import DecoderFactory

from vplane_mj import __version__, shapes
from vplane_mj.polyline import PathSimplifier
from vplane_mj.robot import SONAR_MOUNT_HEIGHT_M
from vplane_mj.scenario import Scenario
from vplane_mj.sim import Tick
from vplane_mj.world import OBSTACLE_HEIGHT_M

WORLD_FRAME = "world"
ROBOT_FRAME = "base_link"
FOLLOW_FRAME = "base_link_xy"
"""At base_link's position with the world's orientation: a camera following it never turns."""
LOGGER_NAME = "vplane_mj"
METADATA_NAME = "vplane_mj"
"""Name of the metadata record with the scenario, seed, planner and versions."""
START_EVENT = "run started"
"""The first `/events` message (time 0), from the log itself, so that the topic is never empty."""
SUMMARY_METADATA_NAME = "summary"
"""Name of the metadata record written at close; its key `json` holds the summary."""
METRICS_SCHEMA_NAME = "vplane_mj.Metrics"

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
FLUSH_PERIOD_S = 1.0
"""Simulated time between two writer flushes (and /path updates)."""
PATH_TOLERANCE_M = 0.01
"""The drawn path passes within this distance of every logged pose."""
PATH_ID = "path"
"""The one `/path` entity, replaced by every message."""

_FORCE_STYLE: dict[str, tuple[tuple[float, float, float, float], float]] = {
    # name: (RGBA colour, extra height (m) so that overlapping arrows stay visible)
    "attractive": ((0.15, 0.75, 0.25, 1.0), 0.00),
    "repulsive": ((0.90, 0.20, 0.15, 1.0), 0.01),
    "virtual": ((0.70, 0.25, 0.90, 1.0), 0.02),
    "total": ((0.15, 0.45, 1.00, 1.0), 0.03),
}
_COMPONENTS = ("attractive", "repulsive", "virtual")

METRICS_JSON_SCHEMA: dict[str, Any] = {
    "title": METRICS_SCHEMA_NAME,
    "type": "object",
    "properties": {
        "time_s": {"type": "number", "description": "simulated time (s)"},
        "speed_mps": {"type": "number", "description": "base speed (m/s)"},
        "distance_to_goal_m": {"type": "number", "description": "to the goal centre (m)"},
        "force_attractive": {"type": "number", "description": "magnitude"},
        "force_repulsive": {"type": "number", "description": "magnitude"},
        "force_virtual": {"type": "number", "description": "magnitude, omitted without one"},
        "force_total": {"type": "number", "description": "magnitude"},
        "mode": {"type": "string", "description": "planner mode"},
        "command_v_mps": {"type": "number", "description": "forward speed command (m/s)"},
        "command_omega_radps": {"type": "number", "description": "turn rate command (rad/s)"},
        "odometry_error_m": {"type": "number", "description": "believed to true position, odometry only"},
    },
    "required": ["time_s", "mode"],
}
"""Every value optional but `time_s` and `mode`: a missing or non-finite one is omitted."""

_WARNING_PREFIXES = ("collision", "gave up")

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
}


# --------------------------------------------------------------------------- small helpers


def time_ns(time_s: float) -> int:
    """Integer nanoseconds of simulated time, the log's one time base."""
    return round(time_s * 1e9)


def _stamp(ns: int) -> fm.Timestamp:
    sec, nsec = divmod(ns, 1_000_000_000)
    return fm.Timestamp(sec, nsec)


def _yaw_quaternion(yaw: float) -> fm.Quaternion:
    """Rotation by `yaw` about +z in Foxglove's order (x, y, z, w)."""
    return fm.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def _pose(x: float, y: float, z: float = 0.0, yaw: float = 0.0) -> fm.Pose:
    return fm.Pose(position=fm.Vector3(x=x, y=y, z=z), orientation=_yaw_quaternion(yaw))


def _colour(rgba: tuple[float, float, float, float]) -> fm.Color:
    return fm.Color(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])


def _magnitude(vector: np.ndarray | None) -> float | None:
    if vector is None:
        return None
    return math.hypot(float(vector[0]), float(vector[1]))


def _package_version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "unknown"


def _piece_primitives(
    piece: shapes.Piece, colour: fm.Color
) -> tuple[list[fm.CubePrimitive], list[fm.CylinderPrimitive]]:
    """One footprint piece as a vertical cube or cylinder standing on the floor."""
    h = OBSTACLE_HEIGHT_M
    if isinstance(piece, shapes.Disc):
        size = fm.Vector3(x=2 * piece.radius, y=2 * piece.radius, z=h)
        pose = _pose(piece.center[0], piece.center[1], h / 2)
        return [], [fm.CylinderPrimitive(pose=pose, size=size, bottom_scale=1.0, top_scale=1.0, color=colour)]
    size = fm.Vector3(x=2 * piece.half[0], y=2 * piece.half[1], z=h)
    pose = _pose(piece.center[0], piece.center[1], h / 2, piece.yaw)
    return [fm.CubePrimitive(pose=pose, size=size, color=colour)], []


def _pieces_entity(
    entity_id: str, pieces: tuple[shapes.Piece, ...], rgba, stamp: fm.Timestamp
) -> fm.SceneEntity:
    colour = _colour(rgba)
    cubes: list[fm.CubePrimitive] = []
    cylinders: list[fm.CylinderPrimitive] = []
    for piece in pieces:
        piece_cubes, piece_cylinders = _piece_primitives(piece, colour)
        cubes += piece_cubes
        cylinders += piece_cylinders
    return fm.SceneEntity(
        timestamp=stamp, frame_id=WORLD_FRAME, id=entity_id, cubes=cubes, cylinders=cylinders
    )


def _flat_disc(center, radius: float, rgba) -> fm.CylinderPrimitive:
    """A 1 cm thick disc lying on the floor (start and goal markers)."""
    return fm.CylinderPrimitive(
        pose=_pose(center[0], center[1], 0.005),
        size=fm.Vector3(x=2 * radius, y=2 * radius, z=0.01),
        bottom_scale=1.0,
        top_scale=1.0,
        color=_colour(rgba),
    )


def _deletion(stamp: fm.Timestamp, entity_id: str) -> fm.SceneEntityDeletion:
    return fm.SceneEntityDeletion(timestamp=stamp, type=fm.SceneEntityDeletionType.MatchingId, id=entity_id)


# --------------------------------------------------------------------------- the writer


class McapLog:
    """Observer writing one run to an MCAP file; see the module docstring for the topics.

    `sonar_bearings` (rad, robot frame, evenly spaced from 0) and `range_max` (m)
    describe the sonar ring for `/scan`; `robot_radius_m` sizes the start marker.
    The file is created (an existing file is replaced unless `allow_overwrite` is
    False). Call `close` at the end; it is idempotent, and ticks or events after it
    are ignored.
    """

    def __init__(
        self,
        path: Path,
        scenario: Scenario,
        robot_radius_m: float,
        sonar_bearings: np.ndarray,
        range_max: float,
        metadata: dict[str, str],
        *,
        allow_overwrite: bool = True,
    ):
        self.path = Path(path)
        self.scenario = scenario
        self.robot_radius_m = float(robot_radius_m)
        self.bearings = np.asarray(sonar_bearings, dtype=float)
        self.range_max = float(range_max)
        self._goal = np.asarray(scenario.robot.goal, dtype=float)
        self._closed = False

        self._context = foxglove.Context()
        options = MCAPWriteOptions(compression=MCAPCompression.Zstd, compression_threads=0)
        self._writer = foxglove.open_mcap(
            self.path, allow_overwrite=allow_overwrite, context=self._context, writer_options=options
        )
        ctx = self._context
        self._pose_ch = fc.PoseInFrameChannel("/robot/pose", context=ctx)
        self._tf_ch = fc.FrameTransformsChannel("/tf", context=ctx)
        self._scan_ch = fc.LaserScanChannel("/scan", context=ctx)
        self._world_ch = fc.SceneUpdateChannel("/world", context=ctx)
        self._forces_ch = fc.SceneUpdateChannel("/forces", context=ctx)
        self._virtual_ch = fc.SceneUpdateChannel("/virtual", context=ctx)
        self._path_ch = fc.SceneUpdateChannel("/path", context=ctx)
        self._events_ch = fc.LogChannel("/events", context=ctx)
        self._metrics_ch = foxglove.Channel("/metrics", schema=METRICS_JSON_SCHEMA, context=ctx)
        self._odometry_ch = None
        if scenario.sensors.pose == "odometry":
            self._odometry_ch = fc.PoseInFrameChannel("/robot/odometry", context=ctx)

        self._writer.write_metadata(METADATA_NAME, self._run_metadata(metadata))
        self._log_world()
        # An empty /virtual update at time 0 keeps the topic in every file, even without escapes.
        self._virtual_ch.log(fm.SceneUpdate(), log_time=0)
        self._log_event(
            0, f"{START_EVENT}: {scenario.name}, planner {scenario.planner}, seed {scenario.run.seed}"
        )

        start = np.asarray(scenario.robot.start, dtype=float)
        self._last_pose = (float(start[0]), float(start[1]), float(scenario.robot.start_yaw))
        self._last_ns = 0
        self._shown_forces: set[str] = set()
        self._virtual_state: tuple[tuple[float, ...] | None, tuple[tuple[float, ...], ...]] = (None, ())
        self._shown_planes = 0
        self._path = PathSimplifier(PATH_TOLERANCE_M)
        self._path_dirty = False
        self._next_flush_s = 0.0  # the first tick flushes, so /path starts with the run

    # -- metadata and the static world -------------------------------------------------------
    def _run_metadata(self, extra: dict[str, str]) -> dict[str, str]:
        s = self.scenario
        info = {
            "format": "1",
            "scenario": s.name,
            "scenario_source": s.source,
            "scenario_toml": s.to_toml(),
            "seed": str(s.run.seed),
            "planner": s.planner,
            "planner_params": json.dumps(dict(s.planner_params), sort_keys=True),
            "time_base": "simulated time, integer nanoseconds from the start of the run",
            "robot_radius_m": repr(self.robot_radius_m),
            "sonar_count": str(len(self.bearings)),
            "sonar_range_max_m": repr(self.range_max),
            "arrow_m_per_unit_force": repr(ARROW_M_PER_UNIT),
            "arrow_max_m": repr(ARROW_MAX_M),
            "vplane_mj_version": __version__,
            "mujoco_version": mujoco.__version__,
            "numpy_version": np.__version__,
            "foxglove_sdk_version": _package_version("foxglove-sdk"),
        }
        info.update({str(key): str(value) for key, value in extra.items()})
        return info

    def _log_world(self) -> None:
        stamp = _stamp(0)
        world = self.scenario.world
        w, h = world.size
        entities = [
            fm.SceneEntity(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                id="arena",
                cubes=[
                    fm.CubePrimitive(
                        pose=_pose(w / 2, h / 2, -0.005),
                        size=fm.Vector3(x=w, y=h, z=0.01),
                        color=_colour(_COLOURS["arena"]),
                    )
                ],
            )
        ]
        for index, obstacle in enumerate(world.obstacles):
            entities.append(
                _pieces_entity(f"obstacle_{index}", obstacle.footprint(), _COLOURS["obstacle"], stamp)
            )
        if world.border:
            entities.append(
                _pieces_entity("border", shapes.border_footprint(world.size), _COLOURS["border"], stamp)
            )
        robot = self.scenario.robot
        radius = max(self.robot_radius_m, 0.05)
        entities.append(
            fm.SceneEntity(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                id="start",
                cylinders=[_flat_disc(robot.start, radius, _COLOURS["start"])],
                arrows=[
                    fm.ArrowPrimitive(
                        pose=_pose(robot.start[0], robot.start[1], 0.02, robot.start_yaw),
                        shaft_length=radius,
                        shaft_diameter=0.02,
                        head_length=0.06,
                        head_diameter=0.06,
                        color=_colour(_COLOURS["start"]),
                    )
                ],
            )
        )
        tol = robot.goal_tolerance
        entities.append(
            fm.SceneEntity(
                timestamp=stamp,
                frame_id=WORLD_FRAME,
                id="goal",
                cylinders=[_flat_disc(robot.goal, tol, _COLOURS["goal"])],
            )
        )
        entities.append(self._robot_body(stamp))
        self._world_ch.log(fm.SceneUpdate(entities=entities), log_time=0)

    def _robot_body(self, stamp: fm.Timestamp) -> fm.SceneEntity:
        """The robot as a disc of `robot_radius_m` with a heading arrow, locked to base_link."""
        radius = self.robot_radius_m
        return fm.SceneEntity(
            timestamp=stamp,
            frame_id=ROBOT_FRAME,
            id="robot",
            frame_locked=True,
            cylinders=[
                fm.CylinderPrimitive(
                    pose=_pose(0.0, 0.0, ROBOT_BODY_HEIGHT_M / 2),
                    size=fm.Vector3(x=2 * radius, y=2 * radius, z=ROBOT_BODY_HEIGHT_M),
                    bottom_scale=1.0,
                    top_scale=1.0,
                    color=_colour(_COLOURS["robot"]),
                )
            ],
            arrows=[
                fm.ArrowPrimitive(
                    pose=_pose(0.0, 0.0, ROBOT_BODY_HEIGHT_M + 0.01),
                    shaft_length=0.7 * radius,
                    shaft_diameter=0.03,
                    head_length=0.3 * radius + 0.03,
                    head_diameter=0.08,
                    color=_colour(_COLOURS["heading"]),
                )
            ],
        )

    # -- the Observer protocol ---------------------------------------------------------------
    def on_tick(self, tick: Tick) -> None:
        if self._closed:
            return
        ns = time_ns(tick.time_s)
        self._last_ns = max(self._last_ns, ns)
        stamp = _stamp(ns)
        x, y, yaw = float(tick.position[0]), float(tick.position[1]), float(tick.yaw)
        if math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw):
            self._last_pose = (x, y, yaw)
        else:  # never log a non-finite pose: repeat the last good one
            x, y, yaw = self._last_pose
        self._log_pose(ns, stamp, x, y, yaw)
        self._log_belief(ns, stamp, tick.believed_pose)
        self._log_scan(ns, stamp, tick.ranges)
        self._log_forces(ns, stamp, x, y, tick)
        self._log_virtual(ns, stamp, tick)
        self._log_metrics(ns, tick)
        self._path.add(x, y)
        self._path_dirty = True
        if tick.time_s >= self._next_flush_s - 1e-9:
            self._log_path(ns)
            self._writer.flush()
            while self._next_flush_s <= tick.time_s + 1e-9:
                self._next_flush_s += FLUSH_PERIOD_S

    def on_event(self, time_s: float, text: str) -> None:
        if self._closed:
            return
        ns = time_ns(time_s)
        self._last_ns = max(self._last_ns, ns)
        self._log_event(ns, text)

    def _log_event(self, ns: int, text: str) -> None:
        level = fm.LogLevel.Warning if text.startswith(_WARNING_PREFIXES) else fm.LogLevel.Info
        self._events_ch.log(
            fm.Log(timestamp=_stamp(ns), level=level, message=text, name=LOGGER_NAME), log_time=ns
        )

    def close(self, summary: dict | None = None) -> None:
        """Log the final path, store `summary` (JSON) as metadata `summary`, close the file."""
        if self._closed:
            return
        self._closed = True
        try:
            if self._path_dirty:
                self._log_path(self._last_ns)
            if summary is not None:
                text = json.dumps(_json_safe(summary), allow_nan=False, default=str)
                self._writer.write_metadata(SUMMARY_METADATA_NAME, {"json": text})
        finally:
            self._writer.close()

    def __enter__(self) -> McapLog:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    # -- per-tick topics ---------------------------------------------------------------------
    def _log_pose(self, ns: int, stamp: fm.Timestamp, x: float, y: float, yaw: float) -> None:
        pose = _pose(x, y, 0.0, yaw)
        self._pose_ch.log(fm.PoseInFrame(timestamp=stamp, frame_id=WORLD_FRAME, pose=pose), log_time=ns)
        transforms = [
            fm.FrameTransform(
                timestamp=stamp,
                parent_frame_id=WORLD_FRAME,
                child_frame_id=child,
                translation=fm.Vector3(x=x, y=y, z=0.0),
                rotation=_yaw_quaternion(rotation),
            )
            for child, rotation in ((ROBOT_FRAME, yaw), (FOLLOW_FRAME, 0.0))
        ]
        self._tf_ch.log(fm.FrameTransforms(transforms=transforms), log_time=ns)

    def _log_belief(self, ns: int, stamp: fm.Timestamp, pose: tuple[float, float, float] | None) -> None:
        if self._odometry_ch is None or pose is None or not all(map(math.isfinite, pose)):
            return
        message = fm.PoseInFrame(
            timestamp=stamp, frame_id=WORLD_FRAME, pose=_pose(pose[0], pose[1], 0.0, pose[2])
        )
        self._odometry_ch.log(message, log_time=ns)

    def _log_scan(self, ns: int, stamp: fm.Timestamp, ranges: np.ndarray) -> None:
        values = np.asarray(ranges, dtype=float)
        values = np.where(np.isfinite(values) & (values >= 0), values, np.nan)  # no echo -> NaN
        n = len(self.bearings)
        scan = fm.LaserScan(
            timestamp=stamp,
            frame_id=ROBOT_FRAME,
            pose=_pose(0.0, 0.0, SONAR_MOUNT_HEIGHT_M),
            # Foxglove spaces the n readings by (end - start) / (n - 1).
            start_angle=float(self.bearings[0]) if n else 0.0,
            end_angle=float(self.bearings[-1]) if n else 0.0,
            ranges=values.tolist(),
        )
        self._scan_ch.log(scan, log_time=ns)

    def _log_forces(self, ns: int, stamp: fm.Timestamp, x: float, y: float, tick: Tick) -> None:
        vectors = {name: tick.decision.components.get(name) for name in _COMPONENTS}
        vectors["total"] = tick.decision.force
        entities = []
        shown = set()
        for name, vector in vectors.items():
            arrow = _force_arrow(x, y, vector, *_FORCE_STYLE[name])
            if arrow is None:
                continue
            shown.add(name)
            entities.append(fm.SceneEntity(timestamp=stamp, frame_id=WORLD_FRAME, id=name, arrows=[arrow]))
        deletions = [_deletion(stamp, name) for name in sorted(self._shown_forces - shown)]
        self._shown_forces = shown
        self._forces_ch.log(fm.SceneUpdate(deletions=deletions, entities=entities), log_time=ns)

    def _log_virtual(self, ns: int, stamp: fm.Timestamp, tick: Tick) -> None:
        objective = _finite_tuple(tick.decision.objective)
        planes = tuple(
            plane
            for plane in (_finite_tuple(np.concatenate([e1, e2])) for e1, e2 in tick.decision.planes)
            if plane is not None
        )
        state = (objective, planes)
        if state == self._virtual_state:
            return
        old_objective, _ = self._virtual_state
        self._virtual_state = state
        entities, deletions = [], []
        if objective is not None:
            entities.append(
                fm.SceneEntity(
                    timestamp=stamp,
                    frame_id=WORLD_FRAME,
                    id="objective",
                    spheres=[
                        fm.SpherePrimitive(
                            pose=_pose(objective[0], objective[1], 0.1),
                            size=fm.Vector3(x=0.2, y=0.2, z=0.2),
                            color=_colour(_COLOURS["objective"]),
                        )
                    ],
                    cylinders=[
                        fm.CylinderPrimitive(
                            pose=_pose(objective[0], objective[1], OBSTACLE_HEIGHT_M / 2),
                            size=fm.Vector3(x=0.03, y=0.03, z=OBSTACLE_HEIGHT_M),
                            bottom_scale=1.0,
                            top_scale=1.0,
                            color=_colour(_COLOURS["objective"]),
                        )
                    ],
                )
            )
        elif old_objective is not None:
            deletions.append(_deletion(stamp, "objective"))
        for index, plane in enumerate(planes):
            entities.append(_plane_entity(stamp, f"plane_{index}", plane))
        deletions += [_deletion(stamp, f"plane_{index}") for index in range(len(planes), self._shown_planes)]
        self._shown_planes = len(planes)
        self._virtual_ch.log(fm.SceneUpdate(deletions=deletions, entities=entities), log_time=ns)

    def _log_metrics(self, ns: int, tick: Tick) -> None:
        components = tick.decision.components
        distance = math.hypot(
            self._goal[0] - float(tick.position[0]), self._goal[1] - float(tick.position[1])
        )
        values = {
            "time_s": tick.time_s,
            "speed_mps": tick.speed,
            "distance_to_goal_m": distance,
            "force_attractive": _magnitude(components.get("attractive")),
            "force_repulsive": _magnitude(components.get("repulsive")),
            "force_virtual": _magnitude(components.get("virtual")),
            "force_total": _magnitude(tick.decision.force),
            "command_v_mps": tick.command[0],
            "command_omega_radps": tick.command[1],
        }
        if tick.believed_pose is not None:
            position = (float(tick.position[0]), float(tick.position[1]))
            values["odometry_error_m"] = math.dist(tick.believed_pose[:2], position)
        record: dict[str, float | str] = {
            key: float(value) for key, value in values.items() if value is not None and math.isfinite(value)
        }
        record["mode"] = tick.decision.mode
        self._metrics_ch.log(record, log_time=ns)

    # -- the path ----------------------------------------------------------------------------
    def _log_path(self, ns: int) -> None:
        """Log the path from the start to the newest pose as the one entity `path`.

        Each message replaces the previous one, so a viewer that keeps only the latest
        message of the topic (after a seek) still draws the whole path up to its time.
        """
        points = [fm.Point3(x=px, y=py) for px, py in self._path.polyline()]
        line = fm.LinePrimitive(
            type=fm.LinePrimitiveLineType.LineStrip,
            pose=_pose(0.0, 0.0, 0.01),
            thickness=0.03,
            scale_invariant=False,
            points=points,
            color=_colour(_COLOURS["path"]),
        )
        entity = fm.SceneEntity(timestamp=_stamp(ns), frame_id=WORLD_FRAME, id=PATH_ID, lines=[line])
        self._path_ch.log(fm.SceneUpdate(entities=[entity]), log_time=ns)
        self._path_dirty = False


def _finite_tuple(vector: np.ndarray | None) -> tuple[float, ...] | None:
    if vector is None:
        return None
    values = tuple(float(v) for v in np.ravel(vector))
    return values if all(math.isfinite(v) for v in values) else None


def _force_arrow(x: float, y: float, vector: np.ndarray | None, rgba, dz: float) -> fm.ArrowPrimitive | None:
    """The arrow of one force at (x, y), or None when it is absent, ~zero or not finite."""
    if vector is None:
        return None
    fx, fy = float(vector[0]), float(vector[1])
    magnitude = math.hypot(fx, fy)
    if not math.isfinite(magnitude) or magnitude < ARROW_MIN_FORCE:
        return None
    length = min(ARROW_M_PER_UNIT * magnitude, ARROW_MAX_M)
    head = min(0.1, 0.4 * length)
    return fm.ArrowPrimitive(
        pose=_pose(x, y, ARROW_HEIGHT_M + dz, math.atan2(fy, fx)),
        shaft_length=length - head,
        shaft_diameter=0.025,
        head_length=head,
        head_diameter=0.07,
        color=_colour(rgba),
    )


def _plane_entity(stamp: fm.Timestamp, entity_id: str, plane: tuple[float, ...]) -> fm.SceneEntity:
    """A virtual plane e1-e2 as a thin, tall, translucent wall plus its centre line."""
    x1, y1, x2, y2 = plane
    length = max(math.hypot(x2 - x1, y2 - y1), 0.01)
    colour = _colour(_COLOURS["plane"])
    return fm.SceneEntity(
        timestamp=stamp,
        frame_id=WORLD_FRAME,
        id=entity_id,
        cubes=[
            fm.CubePrimitive(
                pose=_pose((x1 + x2) / 2, (y1 + y2) / 2, OBSTACLE_HEIGHT_M / 2, math.atan2(y2 - y1, x2 - x1)),
                size=fm.Vector3(x=length, y=0.02, z=OBSTACLE_HEIGHT_M),
                color=colour,
            )
        ],
        lines=[
            fm.LinePrimitive(
                type=fm.LinePrimitiveLineType.LineStrip,
                pose=_pose(0.0, 0.0),
                thickness=0.03,
                points=[fm.Point3(x=x1, y=y1, z=0.02), fm.Point3(x=x2, y=y2, z=0.02)],
                color=_colour(_COLOURS["objective"]),
            )
        ],
    )


def _json_safe(value: object) -> object:
    """The summary as plain JSON values: numpy types unwrapped, NaN and inf as null."""
    if isinstance(value, dict):
        return {str(key): _json_safe(item) for key, item in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_json_safe(item) for item in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


# --------------------------------------------------------------------------- reading


_LEVEL_NAMES = {0: "UNKNOWN", 1: "DEBUG", 2: "INFO", 3: "WARNING", 4: "ERROR", 5: "FATAL"}


@dataclass(frozen=True)
class LogMessage:
    """One decoded message: its topic, schema name, log time (ns) and decoded content.

    Protobuf messages are decoded to their generated protobuf classes (fields as in
    the `foxglove.*` schemas), JSON messages to Python dicts.
    """

    topic: str
    schema: str
    log_time_ns: int
    message: Any


@dataclass
class LogContents:
    """What `read_log` gets back from a log file.

    `metadata`: metadata record name -> its key/value strings; `times_ns`, `positions`
    (N, 2) and `yaws` (N,): the `/robot/pose` messages; `modes`: planner mode per
    `/metrics` message; `events`: (time_s, level, text) of `/events`; `topics`: topic
    -> (schema name, message count) over every message read; `complete`: whether the
    file ended with its footer (False for a file whose writer was killed).
    """

    metadata: dict[str, dict[str, str]]
    times_ns: np.ndarray
    positions: np.ndarray
    yaws: np.ndarray
    modes: list[str]
    events: list[tuple[float, str, str]]
    topics: dict[str, tuple[str, int]]
    complete: bool = True
    message_encodings: dict[str, str] = field(default_factory=dict)

    @property
    def summary(self) -> dict | None:
        """The run summary stored at close, or None (e.g. the writer was killed)."""
        record = self.metadata.get(SUMMARY_METADATA_NAME)
        return None if record is None else json.loads(record["json"])


class _StrictStream:
    """A read-only stream that fails on a short read instead of returning fewer bytes.

    The mcap stream reader trusts each record's length prefix; on a cut-off file the
    last record's read comes back short, and this turns that into `EndOfFile`, so an
    incomplete record is never parsed.
    """

    def __init__(self, raw: BinaryIO):
        self._raw = raw

    def read(self, size: int = -1) -> bytes:
        data = self._raw.read(size)
        if size is not None and size >= 0 and len(data) < size:
            raise EndOfFile()
        return data


class _RecordScan:
    """Sequentially scan a (possibly truncated) MCAP file, tracking schemas, channels, metadata."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.metadata: dict[str, dict[str, str]] = {}
        self.complete = False

    def messages(self) -> Iterator[tuple[Any, Any, Any]]:
        """(schema, channel, message record) for every message in a complete record."""
        schemas: dict[int, Any] = {}
        channels: dict[int, Any] = {}
        with open(self.path, "rb") as raw:
            reader = StreamReader(_StrictStream(raw), validate_crcs=True)
            records = reader.records
            while True:
                try:
                    record = next(records)
                except StopIteration:
                    return
                except Exception:  # a cut-off (EndOfFile) or damaged tail: keep what came before
                    return
                if isinstance(record, mr.Message):
                    channel = channels.get(record.channel_id)
                    if channel is not None:
                        yield schemas.get(channel.schema_id), channel, record
                elif isinstance(record, mr.Schema):
                    schemas[record.id] = record
                elif isinstance(record, mr.Channel):
                    channels[record.id] = record
                elif isinstance(record, mr.Metadata):
                    self.metadata[record.name] = dict(record.metadata)
                elif isinstance(record, mr.Footer):
                    self.complete = True


class _Decoders:
    """Message decoders by (encoding, schema id): protobuf via mcap-protobuf-support, JSON."""

    def __init__(self) -> None:
        self._factory = DecoderFactory()
        self._cache: dict[tuple[str, int], Any] = {}

    def decode(self, schema: Any, channel: Any, data: bytes) -> Any:
        if channel.message_encoding == "json":
            return json.loads(data)
        key = (channel.message_encoding, channel.schema_id)
        decoder = self._cache.get(key)
        if decoder is None:
            decoder = self._factory.decoder_for(channel.message_encoding, schema)
            if decoder is None:
                raise ValueError(f"no decoder for {channel.message_encoding!r} on {channel.topic}")
            self._cache[key] = decoder
        return decoder(data)


def iter_messages(path: Path, topics: tuple[str, ...] | None = None) -> Iterator[LogMessage]:
    """Decoded messages of `topics` (all when None) in file order; tolerates a cut-off file."""
    decoders = _Decoders()
    for schema, channel, record in _RecordScan(path).messages():
        if topics is not None and channel.topic not in topics:
            continue
        yield LogMessage(
            topic=channel.topic,
            schema=schema.name if schema is not None else "",
            log_time_ns=record.log_time,
            message=decoders.decode(schema, channel, record.data),
        )


def read_log(path: Path) -> LogContents:
    """Read a log written by `McapLog`, also one whose writer was killed.

    The file is read front to back with the `mcap` package's `StreamReader` (never
    seeking to the summary section, which a killed writer never wrote), through a
    stream that treats a short read as the end of the file. Every complete record
    before the cut is kept: all chunks finished by a flush (about once per simulated
    second) and the metadata written at the start; reading stops quietly at the
    first incomplete or damaged record (chunk CRCs are checked). `complete` tells
    whether the footer was reached. Protobuf messages are decoded with
    `mcap_protobuf.decoder.DecoderFactory`, `/metrics` as JSON.
    """
    scan = _RecordScan(Path(path))
    decoders = _Decoders()
    counts: dict[str, list] = {}
    encodings: dict[str, str] = {}
    times: list[int] = []
    poses: list[tuple[float, float, float]] = []
    modes: list[str] = []
    events: list[tuple[float, str, str]] = []
    for schema, channel, record in scan.messages():
        topic = channel.topic
        entry = counts.setdefault(topic, [schema.name if schema is not None else "", 0])
        entry[1] += 1
        encodings[topic] = channel.message_encoding
        if topic == "/robot/pose":
            pose = decoders.decode(schema, channel, record.data).pose
            q = pose.orientation
            times.append(record.log_time)
            poses.append((pose.position.x, pose.position.y, 2 * math.atan2(q.z, q.w)))
        elif topic == "/metrics":
            modes.append(str(decoders.decode(schema, channel, record.data).get("mode", "")))
        elif topic == "/events":
            log = decoders.decode(schema, channel, record.data)
            events.append(
                (record.log_time / 1e9, _LEVEL_NAMES.get(int(log.level), str(log.level)), log.message)
            )
    pose_array = np.array(poses, dtype=float).reshape(-1, 3)
    return LogContents(
        metadata=scan.metadata,
        times_ns=np.array(times, dtype=np.int64),
        positions=pose_array[:, :2].copy(),
        yaws=pose_array[:, 2].copy(),
        modes=modes,
        events=events,
        topics={topic: (name, count) for topic, (name, count) in counts.items()},
        complete=scan.complete,
        message_encodings=encodings,
    )
