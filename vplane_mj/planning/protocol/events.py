"""What happens during a run, as data: an event's kind, its human-readable text and its numbers.

Planners report their decisions as events (a local minimum, an escape, a plane created or
retired, ...); the run loop adds its own (a collision, the goal reached, the time limit, an
error). The log stores each with its kind and data, so a run's summary can be recomputed
from the log without reading the text (`vplane_mj.logs.replay`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np


class EventKind(StrEnum):
    """Every kind of event; the value is what the log stores."""

    RUN_STARTED = "run_started"
    """The run loop began; the text names the scenario, planner and seed."""
    LOCAL_MINIMUM = "local_minimum"
    """The local-minimum detector fired (counted in the summary's `local_minima`)."""
    ESCAPE_STARTED = "escape_started"
    """A virtual new objective was placed; data: `objective` (x, y) and `e1`, `e2` when known."""
    ESCAPE_TIMED_OUT = "escape_timed_out"
    """The virtual objective was not reached in time; the planner tries another escape."""
    ESCAPE_FINISHED = "escape_finished"
    """The virtual objective was reached and the target re-activated (counted in `escapes`)."""
    PLANE_CREATED = "plane_created"
    """A virtual plane was added; data: `e1`, `e2`."""
    PLANE_REFUSED = "plane_refused"
    """A virtual plane was considered and not created (the text says why)."""
    PLANE_RETIRED = "plane_retired"
    """A virtual plane was removed (the oldest, or one the text says is no longer needed)."""
    AVOIDANCE_STARTED = "avoidance_started"
    """Histogram avoidance steers past an obstacle's edge; data: `waypoint`."""
    AVOIDANCE_FINISHED = "avoidance_finished"
    """The edge was passed or the way to the goal is free: avoidance ends."""
    FOLLOWING_STARTED = "following_started"
    """A fallback that follows a way (the map's, or a wall's) took over."""
    WAY_CHANGED = "way_changed"
    """The way being followed was found blocked, held up, lost or found again."""
    HELD_UP = "held_up"
    """Following a way, the robot was held up; data: `point`."""
    WALL_LEFT = "wall_left"
    """A wall follower left the wall, back on its line to the goal; data: `point`."""
    VIRTUAL_OBSTACLE_PLACED = "virtual_obstacle_placed"
    """A virtual obstacle was placed; data: `point` (`vobs` reports its own as `local_minimum`)."""
    VIRTUAL_OBSTACLES_CLEARED = "virtual_obstacles_cleared"
    """Virtual obstacles expired and were removed (the text says how many)."""
    BLOCKED = "blocked"
    """No admissible motion: the planner brakes."""
    UNBLOCKED = "unblocked"
    """An admissible motion again after `blocked`."""
    GAVE_UP = "gave_up"
    """The planner gave up: the run ends as `stuck`."""
    COLLISION = "collision"
    """A new contact episode between the robot and an obstacle; data: `point`."""
    GOAL_REACHED = "goal_reached"
    """The robot's centre came within the goal tolerance: the run ends as `reached`."""
    TIME_LIMIT = "time_limit"
    """The simulated time limit passed: the run ends as `timeout`."""
    BELIEVED_ARRIVED = "believed_arrived"
    """Odometry has held the robot at a goal it has not reached: the run ends as `stuck`."""
    ERROR = "error"
    """A MuJoCo warning, a non-finite state or force: the run ends as `error`."""


EVENT_POINTS = ("point", "e1", "e2", "objective", "waypoint")
"""The names an event's data may use, each a point (x, y) in metres (world frame)."""


@dataclass(frozen=True)
class Event:
    """One event: its kind, a short text for people, and its named points.

    Attributes:
        kind: What happened.
        text: A short sentence for people (the log's and the console's).
        data: Its named points, each (x, y) in m, world frame; the names are `EVENT_POINTS`
            (`point`, `e1`, `e2`, `objective`, `waypoint`).

    Raises:
        ValueError: `data` names a point not among `EVENT_POINTS`.
    """

    kind: EventKind
    text: str
    data: dict[str, tuple[float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = set(self.data) - set(EVENT_POINTS)
        if unknown:
            raise ValueError(f"event data names {sorted(unknown)}: not among {EVENT_POINTS}")

    def __str__(self) -> str:
        return self.text


def point(xy: Sequence[float] | np.ndarray) -> tuple[float, float]:
    """A point for an event's data.

    Args:
        xy: A plane point (m): a pair of numbers or an array of two.

    Returns:
        (x, y) as plain floats, rounded to the millimetre.
    """
    return (round(float(xy[0]), 3), round(float(xy[1]), 3))
