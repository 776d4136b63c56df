"""The MCAP log of one run (docs/interface.md section 4, docs/foxglove.md),
written with foxglove-sdk (the scene drawn by `log_scene`, read back by `log_read`).

Writing: `McapLog` is an `Observer` of `run_scenario`. It owns a private
`foxglove.Context`, so several runs (threads, tests) never share channels, and an
MCAP writer with zstd chunks. Every timestamp, both the record's `log_time` and the
messages' own `timestamp` fields, is the integer nanosecond of *simulated* time,
`round(time_s * 1e9)`; `/world` is logged once at time 0.

| topic | schema | when |
|---|---|---|
| `/robot/pose` | `foxglove.PoseInFrame` | every control tick, frame `world`, z = 0 |
| `/tf` | `foxglove.FrameTransforms` | every tick, `world` -> `base_link`, `base_link_xy` (`odom`: below) |
| `/scan` | `foxglove.LaserScan` | every tick, frame `base_link`, NaN where no echo (see below) |
| `/world` | `foxglove.SceneUpdate` | once at time 0: arena, static obstacles, border, start, goal, robot |
| `/world/moving` | `foxglove.SceneUpdate` | every tick, at least every 0.1 s, if any obstacle moves |
| `/forces` | `foxglove.SceneUpdate` | every tick: force arrows at the robot |
| `/virtual` | `foxglove.SceneUpdate` | at time 0 (empty), then when the objective or planes change |
| `/path` | `foxglove.SceneUpdate` | the path so far: first tick, about once per simulated second, close |
| `/events` | `foxglove.Log` | one per event (`run started: ...` at time 0), name = its kind |
| `/run/events` | JSON (`vplane_mj.Event` JSON schema) | the same events as data: kind, text, points |
| `/metrics` | JSON (`vplane_mj.Metrics` JSON schema) | every tick (see below) |
| `/robot/odometry` | `foxglove.PoseInFrame` | believed pose, every tick, unless `sensors.pose = "truth"` |
| `/tracks` | `foxglove.SceneUpdate` | ticks with moving tracks, from the first (and when the last vanish) |

An arrow whose force is (near) zero or not finite is deleted until it comes back.
Entity ids: `/forces` `attractive`, `repulsive`, `virtual`,
`total`; `/virtual` `objective`, `plane_0`, `plane_1`, ... (by position in the
planner's list); `/path` `path` (one line strip from the start to the robot, replaced
by every message, so that the latest message before any time, all a viewer keeps of a
scene topic after a seek, shows the whole path up to then; simplified to within
`PATH_TOLERANCE_M` of every logged pose, which keeps it a few hundred points long, and
never longer than `PATH_MAX_VERTICES`: beyond, its older part is drawn coarser);
`/world` `arena`, `border`, `obstacle_<i>` (i the obstacle's index in the scenario file),
`start`, `goal` (frame `world`) and `robot`
(a round robot as a disc of `robot_radius_m`, another as its footprint polygon, with a
heading arrow, in frame `base_link`, frame-locked, so it moves with `/tf`); `/world/moving`
`obstacle_<i>` for each moving obstacle (never in `/world`), every message all of them where
they stood at its time: the tick's `Tick.obstacles`, and where ticks are further apart than
`MOVING_PERIOD_S`, their motions' places between them; `/tracks` `track_<id>`, the planner's
moving tracks as it estimates them (in its own frame, the world's unless its pose comes
from odometry). Entities that vanish are removed with `SceneUpdate.deletions`. Unless
`sensors.pose = "truth"`, `/tf` also carries `world` -> `odom` at every tick (a message of its
own): the frame of the pose estimate, placed so that the believed pose in it is the true pose.

`/scan` holds the sensor's ranges from the robot's centre at the sensor's height, rounded to
RANGE_STEP_M (a step that compresses: a 720-beam laser costs about 2 MB a minute at 20 Hz,
three times less than at full precision): a laser's beams or a sonar ring as they are;
sonars at uneven bearings (the pioneer3dx) on a scan of one-degree steps, each reading at its
bearing's degree (the nearer of two that share one), NaN elsewhere.

`/metrics` and `/run/events` use only plain JSON schema types (`number`, `string`, arrays
of numbers), as viewers require: a value that is missing (`force_virtual` without a
virtual force, `odometry_error_m` without odometry, an event's points) or not finite is
omitted from the message instead of being null. `/run/events` has the kind
(`vplane_mj.planning.protocol.events.EventKind`), the text and the event's named points (`point`,
`e1`, `e2`, `objective`, `waypoint`, each [x, y] in m), from which `vplane-mj summary`
recomputes a run's outcome and counts.

The file metadata: record `vplane_mj` (scenario name, resolved TOML text, seed,
planner and its parameters, package versions, time base, plus the caller's
`metadata` entries, which win over a same-named key) and, at close, record
`summary` whose key `json` holds the run summary as JSON text.

A tick's messages are written with the rest of its simulated second, just before the flush
(events first write the ticks before them, so the file keeps the run's order).

Crash safety: the writer is flushed (open chunk finished and written to disk) about
once per simulated second, so a process killed with SIGKILL loses at most about the
last second; `vplane_mj.logs.reader.read_log` recovers every complete chunk of such a file.

Size: the `/path` messages are held back and written every `PATH_CHUNK_PERIOD_S` in a chunk of
their own (log times earlier than the chunks before it, which MCAP readers sort by), where
compression stores their common part once. Written with the rest, every message would cost
the whole path, and the log would grow as the square of the run's length. A killed run loses
at most the last `PATH_CHUNK_PERIOD_S` of `/path` (its poses only the last second).
"""

from __future__ import annotations

import json
import math
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

import foxglove
import mujoco
import numpy as np
from foxglove import channels as fc
from foxglove import messages as fm
from foxglove.mcap import MCAPCompression, MCAPWriteOptions

from vplane_mj.geometry.polyline import PathSimplifier
from vplane_mj.logs import scene
from vplane_mj.logs.scene import (
    ARROW_M_PER_UNIT,
    ARROW_MAX_M,
    FOLLOW_FRAME,
    FORCE_COLOURS,
    FORCE_STYLE,
    ODOM_FRAME,
    ROBOT_FRAME,
    WORLD_FRAME,
    TrackMark,
)
from vplane_mj.planning.protocol.events import EVENT_POINTS, Event, EventKind
from vplane_mj.planning.protocol.types import Decision
from vplane_mj.robots.facts import robot_body
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.scenario import Scenario
from vplane_mj.sim.loop import Tick
from vplane_mj.version import __version__

METADATA_NAME = "vplane_mj"
"""Name of the metadata record with the scenario, seed, planner and versions."""
SUMMARY_METADATA_NAME = "summary"
"""Name of the metadata record written at close; its key `json` holds the summary."""
EVENTS_DATA_TOPIC = "/run/events"
FLUSH_PERIOD_S = 1.0
"""Simulated time between two writer flushes (and /path updates)."""
PATH_CHUNK_PERIOD_S = 30.0
"""Simulated time between two writes of the `/path` messages held back, in a chunk of their own."""
PATH_MAX_VERTICES = 5000
"""The most vertices of a `/path` message: beyond, its older part is drawn coarser."""
RANGE_STEP_M = 1.0 / 1024
"""`/scan` ranges are rounded to this step (m), finer than any sensor's noise: a binary fraction
leaves the low bytes of each number zero, which the chunks' compression then removes."""
PATH_TOLERANCE_M = 0.01
"""The drawn path passes within this distance of every logged pose."""
MOVING_TOPIC = "/world/moving"
TRACKS_TOPIC = "/tracks"
MOVING_PERIOD_S = 0.1
"""Longest simulated time between two `/world/moving` messages."""

METRICS_JSON_SCHEMA: dict[str, Any] = {
    "title": "vplane_mj.Metrics",
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
        "odometry_error_m": {"type": "number", "description": "believed to true position, not with truth"},
    },
    "required": ["time_s", "mode"],
}
"""Every value optional but `time_s` and `mode`: a missing or non-finite one is omitted."""
_METRIC_KEYS = (
    "time_s",
    "speed_mps",
    "distance_to_goal_m",
    "force_attractive",
    "force_repulsive",
    "force_virtual",
    "force_total",
    "command_v_mps",
    "command_omega_radps",
    "odometry_error_m",
)
"""The numbers of /metrics, in the order of its messages (then `mode`)."""

EVENTS_JSON_SCHEMA: dict[str, Any] = {
    "title": "vplane_mj.Event",
    "type": "object",
    "properties": {
        "kind": {
            "type": "string",
            "description": "the event's kind (vplane_mj.planning.EventKind)",
        },
        "text": {"type": "string", "description": "what happened, for people"},
        **{
            name: {"type": "array", "items": {"type": "number"}, "description": "[x, y] (m), if any"}
            for name in EVENT_POINTS
        },
    },
    "required": ["kind", "text"],
}
"""An event as data; its points are present only when the event has them."""
_FORCE_ARROWS = tuple((name, FORCE_COLOURS[name], dz) for name, (_, dz) in FORCE_STYLE.items())
"""Each force arrow's name, colour and extra height, in the order they are drawn."""
_Forces = tuple[tuple[float, float] | None, ...]
"""A tick's force vectors (N) in `_FORCE_ARROWS`' order, None where the planner gives none."""
_METRIC_FORCES = tuple(
    list(FORCE_STYLE).index(name) for name in ("attractive", "repulsive", "virtual", "total")
)
"""Where /metrics' force magnitudes are among `_FORCE_ARROWS`."""
WARNING_EVENTS = {EventKind.COLLISION, EventKind.GAVE_UP, EventKind.ERROR, EventKind.BELIEVED_ARRIVED}
"""Events logged at the Warning level."""
_Pending = tuple[Tick, _Forces, tuple[TrackMark, ...]]
"""A tick kept until its simulated second is written, with its forces and tracks as they came."""


class McapLog:
    """Observer writing one run to an MCAP file; see the module docstring for the topics.

    `bearings` (rad, robot frame) are the sensor's; the robot's body and the sensor's
    range and height are the scenario's profile's. The file is created (an existing file is
    replaced unless `allow_overwrite` is False). Call `close` at the end; it is idempotent,
    and ticks or events after it are ignored.
    """

    def __init__(
        self,
        path: Path,
        scenario: Scenario,
        bearings: np.ndarray,
        metadata: dict[str, str],
        *,
        allow_overwrite: bool = True,
    ):
        self.path = Path(path)
        self.scenario = scenario
        self.body = robot_body(scenario.robot.profile, scenario.sensors.kind)
        self.robot_radius_m = self.body.radius_m
        self.bearings = np.asarray(bearings, dtype=float)
        self.range_max = scenario.sensors.range_max
        self._goal = (float(scenario.robot.goal[0]), float(scenario.robot.goal[1]))
        self._closed = False

        self._context = foxglove.Context()
        # Chunks end at the flushes alone, so that one chunk holds all the /path messages held back.
        options = MCAPWriteOptions(compression=MCAPCompression.Zstd, compression_threads=0, chunk_size=None)
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
        self._event_data_ch = foxglove.Channel(EVENTS_DATA_TOPIC, schema=EVENTS_JSON_SCHEMA, context=ctx)
        self._metrics_ch = foxglove.Channel("/metrics", schema=METRICS_JSON_SCHEMA, context=ctx)
        self._odometry_ch = None
        if scenario.sensors.pose in ("odometry", "ekf"):
            self._odometry_ch = fc.PoseInFrameChannel("/robot/odometry", context=ctx)
        self._moving = scenario.world.moving
        self._moving_ch = fc.SceneUpdateChannel(MOVING_TOPIC, context=ctx) if self._moving else None
        self._moving_last_s: float | None = None  # the time of the last /world/moving message
        self._tracks_ch: fc.SceneUpdateChannel | None = None  # made at the first tick with tracks
        self._shown_tracks: list[str] = []

        self._writer.write_metadata(METADATA_NAME, self._run_metadata(metadata))
        self._world_ch.log(fm.SceneUpdate(entities=scene.world_entities(scenario, self.body)), log_time=0)
        # An empty /virtual update at time 0 keeps the topic in every file, even without escapes.
        self._virtual_ch.log(fm.SceneUpdate(), log_time=0)

        start = np.asarray(scenario.robot.start, dtype=float)
        self._last_pose = (float(start[0]), float(start[1]), float(scenario.robot.start_yaw))
        self._last_ns = 0
        self._shown_forces: list[str] = []  # in FORCE_STYLE's order
        self._virtual_state: tuple[tuple[float, ...] | None, tuple[tuple[float, ...], ...]] = (None, ())
        self._shown_planes = 0
        self._virtual_shown: tuple[np.ndarray | None, list[tuple[np.ndarray, np.ndarray]]] = (None, [])
        self._path = PathSimplifier(PATH_TOLERANCE_M, max_vertices=PATH_MAX_VERTICES)
        self._held_paths: list[tuple[fm.SceneUpdate, int]] = []  # /path messages not yet written
        self._next_path_chunk_s = PATH_CHUNK_PERIOD_S
        self._scan_pose = scene.pose(0.0, 0.0, robot_profile(scenario.robot.profile).sensor_height_m)
        self._scan_slots, self._scan_angles = scan_slots(self.bearings)
        self._path_dirty = False
        self._modes: dict[str, str] = {}  # mode -> its JSON string
        self._next_flush_s = 0.0  # the first tick flushes, so /path starts with the run
        self._pending: list[_Pending] = []

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
            "robot_profile": s.robot.profile,
            "footprint_m": json.dumps(self.body.footprint.tolist()),
            "sensor_kind": s.sensors.kind,
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

    # -- the Observer protocol ---------------------------------------------------------------
    def on_tick(self, tick: Tick) -> None:
        """Keep the tick; its messages are written with the others of the same simulated second,
        before the flush (one tight loop runs faster than the same work between physics steps)."""
        if self._closed:
            return
        self._pending.append((tick, _force_vectors(tick.decision), scene.track_marks(tick.tracks)))
        if tick.time_s >= self._next_flush_s - 1e-9:
            self._write_pending()
            self._log_path(self._last_ns)
            self._writer.flush()
            while self._next_flush_s <= tick.time_s + 1e-9:
                self._next_flush_s += FLUSH_PERIOD_S
            if tick.time_s >= self._next_path_chunk_s - 1e-9:
                self._write_held_paths()
                while self._next_path_chunk_s <= tick.time_s + 1e-9:
                    self._next_path_chunk_s += PATH_CHUNK_PERIOD_S

    def on_event(self, time_s: float, event: Event) -> None:
        if self._closed:
            return
        self._write_pending()  # the ticks before the event first: the file keeps their order
        ns = time_ns(time_s)
        self._last_ns = max(self._last_ns, ns)
        level = fm.LogLevel.Warning if event.kind in WARNING_EVENTS else fm.LogLevel.Info
        self._events_ch.log(
            fm.Log(timestamp=scene.stamp(ns), level=level, message=event.text, name=str(event.kind)),
            log_time=ns,
        )
        record: dict[str, object] = {"kind": str(event.kind), "text": event.text}
        record.update({name: [float(v) for v in xy] for name, xy in event.data.items()})
        self._event_data_ch.log(record, log_time=ns)

    def close(self, summary: dict | None = None) -> None:
        """Log the final path, store `summary` (JSON) as metadata `summary`, close the file."""
        if self._closed:
            return
        self._closed = True
        try:
            self._write_pending()
            if self._path_dirty:
                self._log_path(self._last_ns)
            self._write_held_paths()
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
    def _write_pending(self) -> None:
        """Write the messages of the ticks kept since the last call, in their order."""
        pending, self._pending = self._pending, []
        for tick, forces, tracks in pending:
            self._write_tick(tick, forces, tracks)

    def _write_tick(self, tick: Tick, forces: _Forces, tracks: tuple[TrackMark, ...]) -> None:
        ns = time_ns(tick.time_s)
        self._last_ns = max(self._last_ns, ns)
        stamp = scene.stamp(ns)
        x, y, yaw = float(tick.position[0]), float(tick.position[1]), float(tick.yaw)
        if math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw):
            self._last_pose = (x, y, yaw)
        else:  # never log a non-finite pose: repeat the last good one
            x, y, yaw = self._last_pose
        self._log_pose(ns, stamp, x, y, yaw)
        self._log_belief(ns, stamp, tick.believed_pose, (x, y, yaw))
        self._log_scan(ns, stamp, tick.ranges)
        self._log_forces(ns, stamp, x, y, forces)
        self._log_virtual(ns, stamp, tick)
        self._log_metrics(ns, tick, forces)
        self._log_moving(tick.time_s, tick.obstacles)
        self._log_tracks(ns, stamp, tracks)
        self._path.add(x, y)
        self._path_dirty = True

    def _log_pose(self, ns: int, stamp: fm.Timestamp, x: float, y: float, yaw: float) -> None:
        turn = fm.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))  # scene.yaw_quaternion
        where = fm.Vector3(x=x, y=y, z=0.0)
        here = fm.Pose(position=where, orientation=turn)
        self._pose_ch.log(fm.PoseInFrame(timestamp=stamp, frame_id=WORLD_FRAME, pose=here), log_time=ns)
        robot = fm.FrameTransform(
            timestamp=stamp,
            parent_frame_id=WORLD_FRAME,
            child_frame_id=ROBOT_FRAME,
            translation=where,
            rotation=turn,
        )
        follow = fm.FrameTransform(
            timestamp=stamp,
            parent_frame_id=WORLD_FRAME,
            child_frame_id=FOLLOW_FRAME,
            translation=where,
            rotation=scene.IDENTITY,
        )
        self._tf_ch.log(fm.FrameTransforms(transforms=[robot, follow]), log_time=ns)

    def _log_belief(
        self,
        ns: int,
        stamp: fm.Timestamp,
        belief: tuple[float, float, float] | None,
        truth: tuple[float, float, float],
    ) -> None:
        """The believed pose on `/robot/odometry` (frame `world`), and on `/tf` the transform
        `world` -> `odom` that puts the belief, a pose in the estimate's frame `odom`, on the true
        pose `truth` (x, y m, yaw rad): yaw - believed yaw, and the shift that follows."""
        if self._odometry_ch is None or belief is None or not all(map(math.isfinite, belief)):
            return
        message = fm.PoseInFrame(
            timestamp=stamp, frame_id=WORLD_FRAME, pose=scene.pose(belief[0], belief[1], 0.0, belief[2])
        )
        self._odometry_ch.log(message, log_time=ns)
        turn = truth[2] - belief[2]
        c, s = math.cos(turn), math.sin(turn)
        shift = (truth[0] - (c * belief[0] - s * belief[1]), truth[1] - (s * belief[0] + c * belief[1]))
        drift = fm.FrameTransform(
            timestamp=stamp,
            parent_frame_id=WORLD_FRAME,
            child_frame_id=ODOM_FRAME,
            translation=fm.Vector3(x=shift[0], y=shift[1], z=0.0),
            rotation=fm.Quaternion(x=0.0, y=0.0, z=math.sin(turn / 2), w=math.cos(turn / 2)),
        )
        self._tf_ch.log(fm.FrameTransforms(transforms=[drift]), log_time=ns)

    def _log_scan(self, ns: int, stamp: fm.Timestamp, ranges: np.ndarray) -> None:
        if self._scan_slots is not None:
            ranges = on_slots(ranges, self._scan_slots)
        ranges = np.rint(ranges * (1.0 / RANGE_STEP_M)) * RANGE_STEP_M  # a step of 2^-10: exact
        scan = fm.LaserScan(
            timestamp=stamp,
            frame_id=ROBOT_FRAME,
            pose=self._scan_pose,
            start_angle=self._scan_angles[0],
            end_angle=self._scan_angles[1],
            ranges=np.where((ranges >= 0.0) & (ranges < math.inf), ranges, math.nan).tolist(),  # no echo: NaN
        )
        self._scan_ch.log(scan, log_time=ns)

    def _log_forces(self, ns: int, stamp: fm.Timestamp, x: float, y: float, forces: _Forces) -> None:
        entities = []
        shown = []
        for (name, colour, dz), vector in zip(_FORCE_ARROWS, forces, strict=True):
            if vector is None:
                continue
            arrow = scene.force_arrow(x, y, vector[0], vector[1], colour, dz)
            if arrow is None:
                continue
            shown.append(name)
            entities.append(fm.SceneEntity(timestamp=stamp, frame_id=WORLD_FRAME, id=name, arrows=[arrow]))
        deletions = [scene.deletion(stamp, name) for name in self._shown_forces if name not in shown]
        self._shown_forces = shown
        self._forces_ch.log(fm.SceneUpdate(deletions=deletions, entities=entities), log_time=ns)

    def _log_virtual(self, ns: int, stamp: fm.Timestamp, tick: Tick) -> None:
        decision = tick.decision
        last_objective, last_planes = self._virtual_shown
        if (
            decision.objective is last_objective
            and len(decision.planes) == len(last_planes)
            and all(a is c and b is d for (a, b), (c, d) in zip(decision.planes, last_planes, strict=True))
        ):
            return  # the very objects of the last tick (held here): a planner keeps them while they stand
        self._virtual_shown = (decision.objective, list(decision.planes))
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
            entities.append(scene.objective_entity(stamp, objective))
        elif old_objective is not None:
            deletions.append(scene.deletion(stamp, "objective"))
        for index, plane in enumerate(planes):
            entities.append(scene.plane_entity(stamp, f"plane_{index}", plane))
        stale = range(len(planes), self._shown_planes)
        deletions += [scene.deletion(stamp, f"plane_{index}") for index in stale]
        self._shown_planes = len(planes)
        self._virtual_ch.log(fm.SceneUpdate(deletions=deletions, entities=entities), log_time=ns)

    def _log_metrics(self, ns: int, tick: Tick, forces: _Forces) -> None:
        x, y = float(tick.position[0]), float(tick.position[1])
        attractive, repulsive, virtual, total = (_length(forces[k]) for k in _METRIC_FORCES)
        values = (
            tick.time_s,
            tick.speed,
            math.hypot(self._goal[0] - x, self._goal[1] - y),
            attractive,
            repulsive,
            virtual,
            total,
            tick.command[0],
            tick.command[1],
            None if tick.believed_pose is None else math.dist(tick.believed_pose[:2], (x, y)),
        )
        # JSON text as json.dumps writes it (a float's repr); a missing or non-finite value is left out.
        fields = [
            f'"{key}": {float(value)!r}'
            for key, value in zip(_METRIC_KEYS, values, strict=True)
            if value is not None and math.isfinite(value)
        ]
        mode = self._modes.get(tick.decision.mode)
        if mode is None:
            mode = self._modes[tick.decision.mode] = json.dumps(tick.decision.mode)
        fields.append(f'"mode": {mode}')
        self._metrics_ch.log(("{" + ", ".join(fields) + "}").encode(), log_time=ns)

    def _log_moving(self, time_s: float, places: np.ndarray | None) -> None:
        """The moving obstacles where the tick saw them (`places`, count x 2; m), after where their
        motions put them between this tick and the last, evenly, when those are further apart
        than MOVING_PERIOD_S."""
        if self._moving_ch is None or places is None:
            return
        last = self._moving_last_s
        if last is not None and time_s - last > MOVING_PERIOD_S + 1e-9:
            parts = math.ceil((time_s - last) / MOVING_PERIOD_S - 1e-9)
            for between in last + (time_s - last) * np.arange(1, parts) / parts:
                self._log_places(float(between), np.array([m.motion.position(between) for m in self._moving]))
        self._log_places(time_s, places)
        self._moving_last_s = time_s

    def _log_places(self, time_s: float, places: np.ndarray) -> None:
        """One `/world/moving` message: every moving obstacle at `places` (count x 2; m)."""
        assert self._moving_ch is not None
        ns = time_ns(time_s)
        entities = scene.moving_entities(scene.stamp(ns), self._moving, places)
        self._moving_ch.log(fm.SceneUpdate(entities=entities), log_time=ns)

    def _log_tracks(self, ns: int, stamp: fm.Timestamp, tracks: tuple[TrackMark, ...]) -> None:
        """Every track of the tick, replacing the last tick's; those no longer tracked deleted."""
        if not tracks and not self._shown_tracks:
            return
        if self._tracks_ch is None:
            self._tracks_ch = fc.SceneUpdateChannel(TRACKS_TOPIC, context=self._context)
        shown = [mark.entity_id for mark in tracks]
        deletions = [scene.deletion(stamp, name) for name in self._shown_tracks if name not in shown]
        self._shown_tracks = shown
        entities = [scene.track_entity(stamp, mark) for mark in tracks]
        self._tracks_ch.log(fm.SceneUpdate(deletions=deletions, entities=entities), log_time=ns)

    # -- the path ----------------------------------------------------------------------------
    def _log_path(self, ns: int) -> None:
        """Hold back a message of the path from the start to the newest pose as the one entity
        `path` (written by `_write_held_paths`).

        Each message replaces the previous one, so a viewer that keeps only the latest
        message of the topic (after a seek) still draws the whole path up to its time.
        """
        entity = scene.path_entity(scene.stamp(ns), self._path.polyline())
        self._held_paths.append((fm.SceneUpdate(entities=[entity]), ns))
        self._path_dirty = False

    def _write_held_paths(self) -> None:
        """Write the `/path` messages held back as one chunk: each repeats the one before it and
        adds a few vertices, which the chunk's compression stores once, so that the log grows
        with the path's length, not with its square."""
        for update, ns in self._held_paths:
            self._path_ch.log(update, log_time=ns)
        self._held_paths.clear()
        self._writer.flush()


SCAN_SLOT_RAD = math.radians(1.0)
"""The step of the scan that shows sonars at uneven bearings."""


def scan_slots(bearings: np.ndarray) -> tuple[np.ndarray | None, tuple[float, float]]:
    """How `/scan` shows readings at these bearings (rad): evenly spaced ones as they are (None),
    others on one-degree slots from -180 degrees (each reading's slot); and the scan's first and
    last angles (rad). Foxglove spaces n readings by (end - start) / (n - 1)."""
    n = len(bearings)
    if n < 2:
        return None, (float(bearings[0]) if n else 0.0,) * 2
    steps = np.diff(bearings)
    if np.allclose(steps, steps[0], rtol=0.0, atol=1e-9):
        return None, (float(bearings[0]), float(bearings[-1]))
    slots = np.rint((np.mod(bearings + math.pi, 2 * math.pi)) / SCAN_SLOT_RAD).astype(int) % 360
    return slots, (-math.pi, math.pi - SCAN_SLOT_RAD)


def on_slots(ranges: np.ndarray, slots: np.ndarray) -> np.ndarray:
    """The readings on a scan of one-degree slots: NaN where no reading falls, the nearest
    where two do."""
    scan = np.full(360, np.inf)
    np.minimum.at(scan, slots, np.where(np.isnan(ranges), np.inf, ranges))
    return scan


def time_ns(time_s: float) -> int:
    """Integer nanoseconds of simulated time, the log's one time base."""
    return round(time_s * 1e9)


def _force_vectors(decision: Decision) -> _Forces:
    """The decision's forces in `_FORCE_ARROWS`' order, as numbers (None: not given): taken when
    the tick arrives, whatever a planner later does with its arrays."""
    components = decision.components
    return tuple(
        _numbers(decision.force if name == "total" else components.get(name)) for name, _, _ in _FORCE_ARROWS
    )


def _length(vector: tuple[float, float] | None) -> float | None:
    return None if vector is None else math.hypot(vector[0], vector[1])


def _numbers(vector: np.ndarray | None) -> tuple[float, float] | None:
    return None if vector is None else (float(vector[0]), float(vector[1]))


def _package_version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "unknown"


def _finite_tuple(vector: np.ndarray | None) -> tuple[float, ...] | None:
    if vector is None:
        return None
    values = tuple(float(v) for v in np.ravel(vector))
    return values if all(math.isfinite(v) for v in values) else None


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
