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
    and docs/outputs.md's table, in the order they are written (`format` first).

    Attributes:
        scenario: The scenario's name.
        planner: The planner's name.
        seed: The run's seed.
        outcome: How the run ended.
        reached: The robot's centre came within the goal tolerance.
        success: Reached with no collision.
        time_to_goal_s: Simulated time to the goal (s); None when not reached.
        sim_time_s: Simulated time of the run (s).
        steps: Physics steps.
        physics_dt_s: The physics step (s).
        control_hz: The planner's rate (Hz).
        wall_time_s: Wall-clock time of the simulation loop (s).
        kernel_load_s: Wall-clock time spent before the loop loading compiled kernels (s).
        path_length_m: Length travelled by the robot's centre (m).
        collisions: Separate contact episodes between the robot and any obstacle or wall.
        min_clearance_m: Least distance from the footprint to any obstacle or border (m;
            negative: they overlapped).
        mean_clearance_m: Mean of that distance over the run (m).
        moving_obstacles: How many obstacles move.
        min_clearance_moving_m: Least clearance to the moving obstacles alone (m); None
            without any.
        smoothness_rad_per_m: Total absolute heading change per metre travelled (rad/m).
        oscillation_per_m: Reversals of the turning direction per metre travelled (1/m).
        planner_cpu_ms_mean: The planner's mean wall-clock time per control tick (ms).
        planner_cpu_ms_max: Its largest (ms).
        local_minima: Local-minimum detections.
        escapes: Completed escapes.
        robot_radius_m: Radius of the disc about base_link that holds every robot geom (m).
        robot_profile: The robot profile's name.
        footprint_m: The footprint polygon in base_link, [[x, y], ...] (m).
        top_speed_mps: The profile's top speed (m/s).
        sensor_kind: "sonar" or "laser".
        reference_length_m: The reference shortest path from start to goal (m); None when
            no path exists.
        optimal_length_m: The reference path to the goal tolerance (m).
        path_ratio: `path_length_m` over `optimal_length_m`; None when not reached.
        score: The BARN score, between 0.125 and 0.5 for a success, 0 otherwise; None
            without a reference path.
        score_path_m: The path length the score's optimal time was taken from (m).
        score_path_source: Whence: "world" (the scenario's `score_path_m`) or "reference".
        final_distance_to_goal_m: Distance from the robot's centre to the goal at the end (m).
        odometry_error_m: Distance between the believed and the true position at the end
            (m); None on the true pose.
        odometry_error_max_m: Its largest over the run (m).
        trajectory_sha256: SHA-256 of the positions at every control tick and the final pose.
        message: Why the run ended `error` or `stuck`; else empty.
        traceback: The planner's traceback when its code raised; else empty.
        planner_params: The resolved planner parameters, by name.
        governor: What drove the planner's forces on the robot's body: `own` (the planner
            drives its body itself, as the built-in planners do), `run` (the run's governor)
            or `none`.
        version: The package version that ran it.
        format: The summary format, 1.
    """

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
    planner_params: dict[str, float] = field(default_factory=dict)
    governor: str = "none"
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
