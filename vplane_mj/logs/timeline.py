"""A run's moving parts at every control tick, from its MCAP log alone (what a video shows)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vplane_mj.logs.reader import LogContents, LoggedEvent, iter_messages

FORCE_NAMES = ("attractive", "repulsive", "virtual", "total")
"""The `/forces` entities, drawn in this order."""


@dataclass(frozen=True)
class Timeline:
    """Everything that moves, at the log's control ticks.

    `times_s` (N,) simulated seconds; `poses` (N, 3) x, y (m) and yaw (rad); `modes` the
    planner mode per tick; `echoes[k]` (M, 2) the sonar echoes of tick k in the world
    frame (m); `forces[k]` force name -> (x, y, dx, dy), the arrow as drawn in the log
    (m, 0.5 m per unit of force, at most 1.5 m); `objectives[k]` the virtual objective
    (x, y) or None; `planes[k]` the virtual planes ((x1, y1), (x2, y2)); `events` the logged
    events in order; `obstacles` (N, count, 2) where the moving obstacles stood (m), in the
    order of the scenario's `world.moving`, None in a world without any.
    """

    times_s: np.ndarray
    poses: np.ndarray
    modes: list[str]
    echoes: list[np.ndarray]
    forces: list[dict[str, tuple[float, float, float, float]]]
    objectives: list[tuple[float, float] | None]
    planes: list[list[tuple[tuple[float, float], tuple[float, float]]]]
    events: list[LoggedEvent]
    obstacles: np.ndarray | None = None

    def index_at(self, time_s: float) -> int:
        """The last tick at or before `time_s` (the first tick before the run starts)."""
        return max(int(np.searchsorted(self.times_s, time_s, side="right")) - 1, 0)


def timeline_from_log(path: Path, contents: LogContents) -> Timeline:
    """Read the per-tick topics of a log; `contents` is its `read_log`."""
    times_ns = contents.times_ns
    poses = np.column_stack([contents.positions, contents.yaws])
    echoes = _echoes(path, times_ns, poses)
    forces = _per_tick(path, "/forces", times_ns, _arrows, {})
    virtual = _virtual_states(path, times_ns)
    modes = contents.modes if len(contents.modes) == len(times_ns) else ["normal"] * len(times_ns)
    return Timeline(
        times_s=times_ns / 1e9,
        poses=poses,
        modes=modes,
        echoes=echoes,
        forces=forces,
        objectives=[objective for objective, _ in virtual],
        planes=[planes for _, planes in virtual],
        events=contents.events,
        obstacles=contents.obstacles_at_poses(),
    )


def _echoes(path: Path, times_ns: np.ndarray, poses: np.ndarray) -> list[np.ndarray]:
    """Each tick's sonar echoes in the world frame; ranges are measured from the robot's centre."""
    by_time: dict[int, np.ndarray] = {}
    for scan in iter_messages(path, ("/scan",)):
        message = scan.message
        ranges = np.array(message.ranges, dtype=float)
        count = len(ranges)
        step = (message.end_angle - message.start_angle) / (count - 1) if count > 1 else 0.0
        bearings = message.start_angle + step * np.arange(count)
        seen = np.isfinite(ranges)
        by_time[scan.log_time_ns] = np.column_stack([ranges[seen], bearings[seen]])
    echoes = []
    for ns, (x, y, yaw) in zip(times_ns, poses, strict=True):
        polar = by_time.get(int(ns), np.empty((0, 2)))
        angle = yaw + polar[:, 1]
        echoes.append(np.column_stack([x + polar[:, 0] * np.cos(angle), y + polar[:, 0] * np.sin(angle)]))
    return echoes


def _arrows(message, state: dict) -> dict:
    """The force arrows after one `/forces` update (each update holds every arrow shown)."""
    arrows = {}
    for entity in message.entities:
        arrow = entity.arrows[0]
        q = arrow.pose.orientation
        yaw = 2 * math.atan2(q.z, q.w)
        length = arrow.shaft_length + arrow.head_length
        arrows[entity.id] = (
            arrow.pose.position.x,
            arrow.pose.position.y,
            length * math.cos(yaw),
            length * math.sin(yaw),
        )
    return arrows


def _virtual_states(path: Path, times_ns: np.ndarray) -> list[tuple]:
    """(objective, planes) at each tick, from the `/virtual` updates (entities and deletions)."""
    entities: dict[str, Any] = {}  # foxglove.SceneEntity messages by id

    def apply(message, state):
        for deletion in message.deletions:
            entities.pop(deletion.id, None)
        for entity in message.entities:
            entities[entity.id] = entity
        objective = entities.get("objective")
        centre = None
        if objective is not None:
            position = objective.spheres[0].pose.position
            centre = (position.x, position.y)
        planes = []
        for name in sorted(key for key in entities if key.startswith("plane_")):
            a, b = entities[name].lines[0].points[:2]
            planes.append(((a.x, a.y), (b.x, b.y)))
        return centre, planes

    return _per_tick(path, "/virtual", times_ns, apply, (None, []))


def _per_tick(path: Path, topic: str, times_ns: np.ndarray, update, initial) -> list:
    """The state a topic's updates built up by each tick: `update(message, state) -> state`."""
    states, state = [], initial
    messages = iter(iter_messages(path, (topic,)))
    pending = next(messages, None)
    for ns in times_ns:
        while pending is not None and pending.log_time_ns <= ns:
            state = update(pending.message, state)
            pending = next(messages, None)
        states.append(state)
    return states
