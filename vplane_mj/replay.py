"""A run recomputed from its MCAP log alone: the scenario, the summary and the render's track."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from vplane_mj import shapes
from vplane_mj.errors import VPlaneError
from vplane_mj.log_mcap import METADATA_NAME, LogContents, iter_messages, read_log
from vplane_mj.render import Track
from vplane_mj.scenario import Scenario, parse_scenario

_POINT = r"\(([-0-9.]+), ([-0-9.]+)\)"
_OUTCOME_EVENTS = (
    ("goal reached", "reached"),
    ("gave up", "stuck"),
    ("time limit reached", "timeout"),
    ("the simulation diverged", "error"),
)
COMPARED_KEYS = (
    "outcome",
    "reached",
    "success",
    "time_to_goal_s",
    "sim_time_s",
    "path_length_m",
    "collisions",
    "min_clearance_m",
    "local_minima",
    "escapes",
)
"""The summary keys that a log reproduces."""


def load_log(path: Path) -> tuple[LogContents, Scenario]:
    """The log's contents and the scenario stored in its metadata; VPlaneError if unreadable."""
    if not path.is_file():
        raise VPlaneError(f"{path}: no such log file")
    try:
        contents = read_log(path)
    except Exception as exc:
        raise VPlaneError(f"{path}: not a readable vplane-mj MCAP log ({exc})") from exc
    info = contents.metadata.get(METADATA_NAME)
    if info is None or "scenario_toml" not in info:
        raise VPlaneError(f"{path}: no vplane-mj metadata (was it written by vplane-mj run?)")
    if len(contents.times_ns) == 0:
        raise VPlaneError(f"{path}: the log holds no robot pose")
    return contents, parse_scenario(info["scenario_toml"], f"{path} (metadata)")


def summarize(contents: LogContents, scenario: Scenario) -> dict:
    """The run summary recomputed from the poses and events of a log.

    Path length and clearance come from the poses at the control rate (20 Hz), the
    run's own summary from the 100 Hz motor rate, so they agree to about a millimetre.
    """
    info = contents.metadata[METADATA_NAME]
    radius = float(info["robot_radius_m"])
    texts = [(time_s, text) for time_s, _, text in contents.events]
    outcome = next(
        (label for prefix, label in _OUTCOME_EVENTS for _, text in texts if text.startswith(prefix)),
        "timeout" if contents.complete else "interrupted",
    )
    reached_at = [t for t, text in texts if text.startswith("goal reached")]
    collisions = sum(text.startswith("collision at") for _, text in texts)
    steps = np.diff(contents.positions, axis=0)
    footprints = shapes.scene_footprints(
        scenario.world.obstacles, scenario.world.size if scenario.world.border else None
    )
    clearance = float(footprints.distance(contents.positions).min()) if len(footprints) else math.inf
    return {
        "scenario": scenario.name,
        "planner": scenario.planner,
        "seed": scenario.run.seed,
        "outcome": outcome,
        "reached": outcome == "reached",
        "success": outcome == "reached" and collisions == 0,
        "time_to_goal_s": reached_at[0] if reached_at else None,
        "sim_time_s": contents.times_ns[-1] / 1e9,
        "path_length_m": float(np.sum(np.hypot(steps[:, 0], steps[:, 1]))),
        "collisions": collisions,
        "min_clearance_m": None if math.isinf(clearance) else clearance - radius,
        "local_minima": sum(text.startswith("local minimum detected") for _, text in texts),
        "escapes": sum(text.startswith("objective reached") for _, text in texts),
        "events": [f"{t:8.2f} s  {text}" for t, text in texts],
    }


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
    """What a render shows, from the log: path, modes, final pose, virtual objects, collisions."""
    objectives, planes, collisions = [], [], []
    for _, _, text in contents.events:
        if text.startswith("escape started"):
            points = [(float(x), float(y)) for x, y in re.findall(_POINT, text)]
            if len(points) == 3:  # e1, e2, objective
                objectives.append(points[2])
        elif text.startswith("collision at"):
            collisions.extend((float(x), float(y)) for x, y in re.findall(_POINT, text))
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
    return Track(contents.positions, modes, final, collisions, objectives, planes)
