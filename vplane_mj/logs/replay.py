"""A run recomputed from its MCAP log alone: the scenario, the summary and the render's track.

The outcome and the counts come from the kinds of the logged events (`/run/events`), the
path and clearance from the poses, and where the moving obstacles stood from `/world/moving`
(the places the run itself saw at each tick, not recomputed from their motions): no event
text is parsed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from vplane_mj.errors import VPlaneError
from vplane_mj.geometry import shapes
from vplane_mj.geometry.motion import Moving
from vplane_mj.logs.reader import LogContents, iter_messages, read_log
from vplane_mj.logs.writer import METADATA_NAME
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import Scenario, parse_scenario
from vplane_mj.sim.loop import Track
from vplane_mj.sim.metrics import robot_clearance
from vplane_mj.sim.summary import Outcome

ENDINGS: dict[EventKind, Outcome] = {
    EventKind.GOAL_REACHED: Outcome.REACHED,
    EventKind.TIME_LIMIT: Outcome.TIMEOUT,
    EventKind.GAVE_UP: Outcome.STUCK,
    EventKind.BELIEVED_ARRIVED: Outcome.STUCK,
    EventKind.ERROR: Outcome.ERROR,
}
"""The event that ends a run, by kind, and the outcome it means (the run's last such event)."""
INTERRUPTED = "interrupted"
"""The recomputed outcome of a log that holds no ending (the run was stopped or killed)."""
COMPARED_KEYS = (
    "outcome",
    "reached",
    "success",
    "time_to_goal_s",
    "sim_time_s",
    "path_length_m",
    "collisions",
    "min_clearance_m",
    "min_clearance_moving_m",
    "local_minima",
    "escapes",
    "message",
)
"""The summary keys that a log reproduces."""


def load_log(path: Path, keep: tuple[str, ...] = ()) -> tuple[LogContents, Scenario]:
    """The log's contents (with the decoded messages of the topics `keep`, as `read_log` reads
    them) and the scenario stored in its metadata; VPlaneError if unreadable."""
    if not path.is_file():
        raise VPlaneError(f"{path}: no such log file")
    try:
        contents = read_log(path, keep)
    except Exception as exc:
        raise VPlaneError(f"{path}: not a readable vplane-mj MCAP log ({exc})") from exc
    info = contents.metadata.get(METADATA_NAME)
    if info is None or "scenario_toml" not in info:
        raise VPlaneError(f"{path}: no vplane-mj metadata (was it written by vplane-mj run?)")
    if len(contents.times_ns) == 0:
        raise VPlaneError(f"{path}: the log holds no robot pose")
    if not contents.events:
        raise VPlaneError(f"{path}: no /run/events (written by an older vplane-mj?)")
    return contents, parse_scenario(info["scenario_toml"], f"{path} (metadata)", recorded=True)


def summarize(contents: LogContents, scenario: Scenario) -> dict:
    """The run summary recomputed from the poses and events of a log.

    Path length and clearance come from the poses at the control rate (20 Hz), the
    run's own summary from the 100 Hz motor rate, so they agree to about a millimetre (a few
    near moving obstacles, which move between ticks too).
    """
    info = contents.metadata[METADATA_NAME]
    radius = float(info["robot_radius_m"])
    events = contents.events
    endings = [event for event in events if event.kind in ENDINGS]
    ending = endings[-1] if endings else None
    outcome = INTERRUPTED if ending is None else str(ENDINGS[ending.kind])
    collisions = sum(event.kind is EventKind.COLLISION for event in events)
    steps = np.diff(contents.positions, axis=0)
    clearance, moving = pose_clearance(scenario, contents, radius)
    reached = outcome == Outcome.REACHED
    return {
        "scenario": scenario.name,
        "planner": scenario.planner,
        "seed": scenario.run.seed,
        "outcome": outcome,
        "reached": reached,
        "success": reached and collisions == 0,
        "time_to_goal_s": ending.time_s if reached and ending is not None else None,
        "sim_time_s": contents.times_ns[-1] / 1e9,
        "path_length_m": float(np.sum(np.hypot(steps[:, 0], steps[:, 1]))),
        "collisions": collisions,
        "min_clearance_m": None if math.isinf(clearance) else clearance,
        "min_clearance_moving_m": moving,
        "local_minima": sum(event.kind is EventKind.LOCAL_MINIMUM for event in events),
        "escapes": sum(event.kind is EventKind.ESCAPE_FINISHED for event in events),
        "message": "" if ending is None or outcome in (Outcome.REACHED, Outcome.TIMEOUT) else ending.text,
        "events": [f"{event.time_s:8.2f} s  {event.text}" for event in events],
    }


def pose_clearance(scenario: Scenario, contents: LogContents, radius_m: float) -> tuple[float, float | None]:
    """The robot's smallest clearance (m) over the logged poses, measured as the run measures it
    (`robot_clearance`; inf without obstacles), and that to the moving obstacles alone where
    they stood at those poses (None without any)."""
    body = robot_body(scenario.robot.profile, scenario.sensors.kind)
    clearance = robot_clearance(scenario, body, radius_m)
    poses = np.column_stack((contents.positions, contents.yaws))
    clearance.add(poses)
    clearance.flush()
    places = contents.obstacles_at_poses()
    if not scenario.world.moving or places is None:
        return clearance.robot_minimum, None
    gaps = obstacle_distances(scenario.world.moving, poses, places, None if body.disc else body.footprint)
    moving = float(gaps.min()) - (radius_m if body.disc else 0.0)
    return min(clearance.robot_minimum, moving), moving


def obstacle_distances(
    moving: Sequence[Moving], poses: np.ndarray, places: np.ndarray, outline: np.ndarray | None = None
) -> np.ndarray:
    """Signed distance (m; N, count) from each pose (N, 3: x, y, yaw; or N, 2 points) to each
    moving obstacle standing where `places` (N, count, 2; m) says: from the point, or with
    `outline` (the robot's footprint in its frame, m) from the outline, as the run measures it
    (`shapes.moving_distances`)."""
    columns = []
    for k, obstacle in enumerate(moving):
        (piece,) = obstacle.shape.footprint()
        discs, rects = np.empty((0, 3)), np.empty((0, 6))
        if isinstance(piece, shapes.Disc):
            discs = np.array([[0.0, 0.0, piece.radius]])
        else:
            rects = np.array([[0.0, 0.0, *piece.half, math.cos(piece.yaw), math.sin(piece.yaw)]])
        columns.append(shapes.moving_distances(discs, rects, places[:, k : k + 1], poses, outline))
    return np.column_stack(columns)


def disagreements(recomputed: dict, stored: dict, tolerance_m: float = 0.01) -> list[str]:
    """Keys where the recomputed summary and the run's stored summary differ."""
    differing = []
    for key in COMPARED_KEYS:
        a, b = recomputed.get(key), stored.get(key)
        if isinstance(a, float) and isinstance(b, float):
            limit = tolerance_m + 0.002 * abs(b) if key.endswith("_m") else 1e-6
            if abs(a - b) > limit:
                differing.append(f"{key}: log {a:.4f}, run {b:.4f}")
        elif a != b:
            differing.append(f"{key}: log {a}, run {b}")
    return differing


def track_from_log(path: Path, contents: LogContents) -> Track:
    """What a render shows, from the log: path, modes, final pose, virtual objects, collisions,
    and where the moving obstacles stood at each pose (from `/world/moving`)."""
    objectives = [
        e.data["objective"]
        for e in contents.events
        if e.kind is EventKind.ESCAPE_STARTED and "objective" in e.data  # a planner may place none
    ]
    collisions = [e.data["point"] for e in contents.events if e.kind is EventKind.COLLISION]
    planes = []
    for update in iter_messages(path, ("/virtual",)):
        for entity in update.message.entities:
            if entity.id.startswith("plane_") and entity.lines:
                a, b = entity.lines[0].points[:2]
                plane = ((a.x, a.y), (b.x, b.y))
                if plane not in planes:
                    planes.append(plane)
    modes = (
        contents.modes
        if len(contents.modes) == len(contents.positions)
        else ["normal"] * len(contents.positions)
    )
    final = (float(contents.positions[-1, 0]), float(contents.positions[-1, 1]), float(contents.yaws[-1]))
    return Track(
        contents.positions, modes, final, collisions, objectives, planes, contents.obstacles_at_poses()
    )
