"""What a planner sees each control tick and what it answers."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from vplane_mj.planning.protocol.events import Event

if TYPE_CHECKING:
    from vplane_mj.planning.perception.tracker import Track


@dataclass(frozen=True)
class Observation:
    """The planner's whole view of the world: its pose, its goal and its range scan.

    The bearings are any sensor's: an evenly spaced sonar ring, uneven sonar arrays (several
    beams may share a bearing), or a laser's scan over its field of view, in any order. A
    sensor slower than the control rate hands one scan to several ticks, each with the pose
    of its own tick: a planner that maps should fold a scan once, at the pose of the tick it
    came with.

    Attributes:
        time_s: Simulated time of the tick (s).
        position: The position the planner believes in, [x, y] (m, world frame).
        yaw: Its heading (rad, counter-clockwise from +x).
        goal: The goal [x, y] (m, world frame).
        goal_tolerance: How close to the goal counts as reaching it (m).
        bearings: Each beam's bearing (rad, robot frame, counter-clockwise from the heading).
        ranges: Each beam's range from the robot's centre (m); NaN: no echo.
        beam_width: Each beam's width (rad), the same for all: an echo lies somewhere within
            it (a laser's is its angle step).
        velocity: Speed along the heading (m/s, negative when reversing) and turn rate
            (rad/s), as the wheel encoders measure them.
        tracks: The obstacles the run's tracker follows from the scans and the pose alone
            (each one's estimated disc and velocity, in the frame of `position`).
        moving_echoes: (beams,) which echoes are of tracks that move; None: none is known to.
        scan_time_s: When the sensor took `ranges` (s); None: at `time_s`.
    """

    time_s: float
    position: np.ndarray
    yaw: float
    goal: np.ndarray
    goal_tolerance: float
    bearings: np.ndarray
    ranges: np.ndarray
    beam_width: float
    velocity: tuple[float, float] = (0.0, 0.0)
    tracks: tuple[Track, ...] = ()
    moving_echoes: np.ndarray | None = None
    scan_time_s: float | None = None

    def static_ranges(self) -> np.ndarray:
        """`ranges` without the echoes of moving tracks (NaN there): what a map of the obstacles
        that stand still takes in. The ranges themselves when no echo is of a moving track."""
        ranges = self.__dict__.get("_static_ranges")
        if ranges is None:
            ranges = self.ranges
            if self.moving_echoes is not None and self.moving_echoes.any():
                ranges = np.where(self.moving_echoes, np.nan, self.ranges)
                ranges.flags.writeable = False
            self.__dict__["_static_ranges"] = ranges
        return ranges

    def echo_points(self) -> np.ndarray:
        """World-frame points (N, 2) of the echoes, each on its beam's axis; no-echo readings are dropped.

        Computed once per observation and shared by every caller, so it is read-only.
        """
        return self._points("_echo_points", self.ranges)

    def static_echo_points(self) -> np.ndarray:
        """`echo_points` of `static_ranges`: the echoes of what is not known to move (read-only)."""
        if self.static_ranges() is self.ranges:
            return self.echo_points()
        return self._points("_static_echo_points", self.static_ranges())

    def _points(self, key: str, ranges: np.ndarray) -> np.ndarray:
        """The world-frame points of `ranges`' echoes, cached under `key`."""
        points = self.__dict__.get(key)
        if points is None:
            from vplane_mj.kernels.maps import points as compiled  # numba: loaded by the first call

            points = compiled.echo_points(
                np.asarray(self.position, float),
                float(self.yaw),
                np.asarray(self.bearings, float),
                np.asarray(ranges, float),
            )
            points.flags.writeable = False
            self.__dict__[key] = points  # a frozen dataclass: cache outside its fields
        return points

    def distance_to_goal(self) -> float:
        """Distance (m) from the position to the goal."""
        distance = self.__dict__.get("_distance_to_goal")
        if distance is None:
            distance = float(np.hypot(self.goal[0] - self.position[0], self.goal[1] - self.position[1]))
            self.__dict__["_distance_to_goal"] = distance
        return distance


@dataclass
class Decision:
    """A planner's answer: the total force (world frame) to follow, and what it is doing.

    Args:
        force: The force to follow, [fx, fy] (world frame); the heading controller turns the
            robot towards it.
        mode: What the planner is doing (a short word: the log's and the plots' mode).
        components: The parts of the force by name (attractive, repulsive, ...), for the log.
        events: What happened this tick (kind, text and points).
        local_minimum: A local minimum was detected this tick.
        escape_completed: An escape finished this tick.
        gave_up: The planner gives up: the run ends as stuck.
        objective: The virtual new objective while one exists, [x, y] (m, world frame).
        planes: The virtual planes in force, each as its two end points (m, world frame).
        command: The body speed (m/s, negative to reverse) and turn rate (rad/s) to drive,
            within the robot's limits, instead of what the heading controller makes of the
            force (which is then only shown): for a planner that plans in velocities, or must
            back off.
    """

    force: np.ndarray
    mode: str
    components: dict[str, np.ndarray] = field(default_factory=dict)
    events: list[Event] = field(default_factory=list)
    local_minimum: bool = False
    escape_completed: bool = False
    gave_up: bool = False
    objective: np.ndarray | None = None
    planes: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    command: tuple[float, float] | None = None
