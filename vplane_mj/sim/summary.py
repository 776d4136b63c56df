"""A run's outcome and summary (docs/interface.md section 3), one frozen type shared by the run
loop, the command line, sweeps, the log and replays."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

SUMMARY_FORMAT = 1
TIMING_KEYS = ("wall_time_s", "kernel_load_s", "planner_cpu_ms_mean", "planner_cpu_ms_max")
"""Summary keys measured on the wall clock: the only ones that differ between identical runs."""


class Outcome(StrEnum):
    """How a run ended: the four outcomes of the summary (a `str`, so JSON writes its value)."""

    REACHED = "reached"
    """The robot's centre came within the goal tolerance."""
    TIMEOUT = "timeout"
    """The simulated time limit passed first."""
    STUCK = "stuck"
    """The planner gave up, or odometry held the robot at a goal it had not reached."""
    ERROR = "error"
    """The simulation or the planner failed (a MuJoCo warning, a non-finite state or force, an
    exception raised by the planner's code)."""


@dataclass(frozen=True)
class RunSummary:
    """The `.json` summary of one run; field for field the keys of docs/interface.md section 3
    and docs/outputs.md's table, in the order they are written."""

    scenario: str
    planner: str
    seed: int
    outcome: Outcome
    reached: bool = False
    success: bool = False
    time_to_goal_s: float | None = None
    sim_time_s: float = 0.0
    steps: int = 0
    physics_dt_s: float | None = None
    control_hz: float | None = None
    wall_time_s: float = 0.0
    kernel_load_s: float = 0.0
    path_length_m: float = 0.0
    collisions: int = 0
    min_clearance_m: float | None = None
    mean_clearance_m: float | None = None
    moving_obstacles: int = 0
    min_clearance_moving_m: float | None = None
    smoothness_rad_per_m: float | None = None
    oscillation_per_m: float | None = None
    planner_cpu_ms_mean: float | None = None
    planner_cpu_ms_max: float | None = None
    local_minima: int = 0
    escapes: int = 0
    robot_radius_m: float | None = None
    robot_profile: str = "default"
    footprint_m: list[list[float]] = field(default_factory=list)
    top_speed_mps: float | None = None
    sensor_kind: str = "sonar"
    reference_length_m: float | None = None
    optimal_length_m: float | None = None
    path_ratio: float | None = None
    score: float | None = None
    score_path_m: float | None = None
    score_path_source: str | None = None
    final_distance_to_goal_m: float | None = None
    odometry_error_m: float | None = None
    odometry_error_max_m: float | None = None
    trajectory_sha256: str = ""
    message: str = ""
    traceback: str = ""
    """The planner's traceback when its code raised (outcome `error`, `message` names the
    exception and where); empty otherwise."""
    planner_params: dict[str, float] = field(default_factory=dict)
    governor: str = "none"
    """What drove the planner's forces on the robot's body: `own` (the planner drives its
    body itself, as the built-in planners do), `run` (the run's governor) or `none`."""
    version: str = ""
    format: int = SUMMARY_FORMAT

    def to_dict(self) -> dict[str, Any]:
        """The summary as JSON-ready values, `format` first as in the file."""
        values = {item.name: getattr(self, item.name) for item in dataclasses.fields(self)}
        values["outcome"] = str(self.outcome)
        values["planner_params"] = dict(self.planner_params)
        return {"format": values.pop("format"), **values}

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> RunSummary:
        """The summary from its JSON form (a `.json` file, a sweep's row); other keys are ignored."""
        names = {item.name for item in dataclasses.fields(cls)}
        known = {key: value for key, value in values.items() if key in names}
        known["outcome"] = Outcome(known["outcome"])
        return cls(**known)

    def without_timing(self) -> dict[str, Any]:
        """The summary as a dict without the wall-clock keys: equal for identical runs."""
        return without_timing(self.to_dict())


def without_timing(summary: Mapping[str, Any]) -> dict[str, Any]:
    """A summary's (or a bench row's) keys but the wall-clock ones: equal for identical runs."""
    return {key: value for key, value in summary.items() if key not in TIMING_KEYS}
