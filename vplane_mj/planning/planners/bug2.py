"""Bug2 (`bug2`): go along the start-goal line, follow an obstacle's boundary until back on it.

Lumelsky and Stepanov's Bug2, following walls on the range scan (sonar or laser). The
m-line runs from the position at the first tick to the goal. In mode "go_to_goal" the robot
drives along it; when an echo lies within `hit_distance_m` ahead (within +-30 degrees of
the goal direction) it records the hit point and switches to "following", keeping the wall
on one side at `wall_distance_m`. It leaves the wall when it is back on the m-line closer
to the goal than the hit point and the way to the goal is clear. It gives up when it comes
back to the hit point after a loop around the obstacle (the goal is unreachable) or after
`max_follow_s` of following. The governor (motion/governor.py) drives the force on the robot's body.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.planners.groups import MotionParams
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.events import Event, EventKind, point
from vplane_mj.planning.protocol.params import param
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.planning.protocol.vectors import unit, wrap_angle

AHEAD_HALF_ANGLE = math.radians(30.0)
"""Echoes within this angle of the goal direction count as ahead (hit and leave tests)."""
LEAVE_MARGIN_M = 0.1
"""A leave point must be at least this much closer to the goal than the hit point."""
SILENT_FREE_M = 3.0
"""A beam without an echo counts as free this far (m), or as the scan's farthest echo if farther."""


@dataclass(frozen=True)
class Bug2Params(MotionParams):
    """Bug2's hit and leave tests, wall following and the m-line, and the governor's margins."""

    hit_distance_m: float = param(0.45, "m", "an echo this close ahead (+-30 deg of the goal) is a hit", gt=0)
    wall_distance_m: float = param(0.4, "m", "distance kept from the followed wall (from the centre)", gt=0)
    wall_gain: float = param(2.0, "1/m", "proportional correction toward the desired wall distance", ge=0)
    follow_speed: float = param(0.7, "", "force magnitude while following (speed 0.5 m/s per unit)", gt=0)
    lost_wall_m: float = param(1.2, "m", "no echo on the wall side within this: turn toward the wall", gt=0)
    mline_tolerance_m: float = param(0.1, "m", "distance from the m-line that counts as on it", gt=0)
    mline_gain: float = param(1.0, "1/m", "lateral correction back onto the m-line per metre off it", ge=0)
    slow_radius_m: float = param(1.0, "m", "the force shrinks within this distance of the goal", gt=0)
    follow_side: int = param(
        1,
        "",
        "1: turn left (wall on the right); -1: turn right; 0: choose by the echoes",
        ge=-1,
        le=1,
        integer=True,
    )
    loop_radius_m: float = param(0.3, "m", "back within this of the hit point after a loop: give up", gt=0)
    max_follow_s: float = param(120.0, "s", "give up after following one obstacle this long", gt=0)


def _rotate(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


class Bug2Planner(Planner):
    """Bug2: modes "go_to_goal" and "following"; gives up on a closed loop or a timeout."""

    name = "bug2"
    summary = "Bug2: along the start-goal line, sonar wall following around obstacles"
    governs_itself = True
    citation = (
        "V. Lumelsky and A. Stepanov, Path-planning strategies for a point mobile automaton "
        "moving amidst unknown obstacles of arbitrary shape, Algorithmica 2, 1987"
    )
    Params = Bug2Params
    params: Bug2Params

    def __init__(self, params: Bug2Params, robot: RobotBody | float):
        super().__init__(params, robot)
        self.mode = "go_to_goal"
        self.mline: tuple[np.ndarray, np.ndarray] | None = None
        self.hit_point: np.ndarray | None = None
        self.hit_distance = math.inf
        self.follow_start_s = 0.0
        self.side = 1  # +1: wall on the right (turned left); -1: wall on the left
        self.left_hit_area = False
        self.gave_up = False
        self.governor = params.governor(self.robot)

    # ------------------------------------------------------------------ geometry

    def _mline_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """The m-line's start and goal (m), fixed at the first tick (RuntimeError before it)."""
        if self.mline is None:
            raise RuntimeError("bug2 has no m-line before its first step")
        return self.mline

    def mline_offset(self, position: np.ndarray) -> float:
        """Signed distance (m) of `position` from the m-line (positive on its left)."""
        start, goal = self._mline_ends()
        direction = unit(goal - start)
        rel = position - start
        return float(direction[0] * rel[1] - direction[1] * rel[0])

    def _ahead_range(self, obs: Observation) -> float:
        """Shortest echo within +-30 degrees of the goal direction (inf when none)."""
        goal_angle = math.atan2(*(obs.goal - obs.position)[::-1])
        relative = np.abs(wrap_angle(obs.yaw + obs.bearings - goal_angle))
        ahead = (relative <= AHEAD_HALF_ANGLE + obs.beam_width / 2) & np.isfinite(obs.ranges)
        return float(obs.ranges[ahead].min()) if ahead.any() else math.inf

    # ------------------------------------------------------------------ modes

    def _go_to_goal(self, obs: Observation) -> dict[str, np.ndarray]:
        to_goal = obs.goal - obs.position
        distance = float(np.hypot(*to_goal))
        scale = max(0.3, min(1.0, distance / self.params.slow_radius_m))
        attract = unit(to_goal) * scale
        start, goal = self._mline_ends()
        normal = _rotate(unit(goal - start), math.pi / 2)
        offset = self.mline_offset(obs.position)
        correction = -normal * float(np.clip(self.params.mline_gain * offset, -0.5, 0.5))
        return {"goal": attract, "mline": correction}

    def _choose_side(self, obs: Observation) -> int:
        fixed = round(self.params.follow_side)
        if fixed != 0:
            return 1 if fixed > 0 else -1
        # Turn toward the side with more free space: compare the mean free range left and right
        # (a side the sensor does not see counts as no free space).
        echoes = np.isfinite(obs.ranges)
        farthest = max(SILENT_FREE_M, float(obs.ranges[echoes].max())) if echoes.any() else SILENT_FREE_M
        free = np.where(echoes, obs.ranges, farthest)
        rel = wrap_angle(obs.bearings)
        sides = ((rel > 0.1) & (rel < math.pi / 2 + 0.1), (rel < -0.1) & (rel > -math.pi / 2 - 0.1))
        left, right = (float(free[side].mean()) if side.any() else 0.0 for side in sides)
        return 1 if left >= right else -1

    def _follow(self, obs: Observation) -> dict[str, np.ndarray]:
        """Steer along the wall on side `self.side` at `wall_distance_m`."""
        p = self.params
        heading = np.array([math.cos(obs.yaw), math.sin(obs.yaw)])
        rel = wrap_angle(obs.bearings)
        # The wall side (right for side=+1) and the front; the other side is ignored so that a
        # wall across a narrow passage does not capture the follower.
        usable = (-self.side * rel > -math.radians(50.0)) & (-self.side * rel < math.radians(160.0))
        usable &= np.isfinite(obs.ranges)
        if not usable.any() or float(obs.ranges[usable].min()) > p.lost_wall_m:
            # Lost the wall: curve toward its side to find it again.
            turn = _rotate(heading, -self.side * math.radians(60.0))
            return {"search": turn * p.follow_speed}
        ranges = obs.ranges[usable]
        angles = obs.yaw + obs.bearings[usable]
        nearest = float(np.min(ranges))
        # The wall's direction: echoes within a few cm of the nearest, weighted toward the nearest.
        close = ranges <= nearest + 0.1
        weights = 1.0 / (ranges[close] - nearest + 0.02)
        toward = np.array([np.sum(weights * np.cos(angles[close])), np.sum(weights * np.sin(angles[close]))])
        away = -unit(toward)  # the wall's normal at the robot, pointing away from it
        tangent = _rotate(away, -self.side * math.pi / 2)
        error = nearest - p.wall_distance_m
        correction = float(np.clip(p.wall_gain * error, -1.0, 1.0))
        steer = unit(tangent - correction * away)
        return {"tangent": steer * p.follow_speed}

    # ------------------------------------------------------------------ the tick

    def step(self, obs: Observation) -> Decision:
        p = self.params
        position = np.asarray(obs.position, float)
        if self.mline is None:
            self.mline = (position.copy(), np.asarray(obs.goal, float).copy())
        events: list[Event] = []
        if self.gave_up:
            return Decision(force=np.zeros(2), mode="gave_up", gave_up=True)

        distance = obs.distance_to_goal()
        ahead = self._ahead_range(obs)
        if self.mode == "go_to_goal" and ahead < p.hit_distance_m and distance > obs.goal_tolerance:
            self.mode = "following"
            self.hit_point = position.copy()
            self.hit_distance = distance
            self.follow_start_s = obs.time_s
            self.left_hit_area = False
            self.side = self._choose_side(obs)
            turn = "left" if self.side > 0 else "right"
            events.append(
                Event(
                    EventKind.FOLLOWING_STARTED,
                    f"hit at ({position[0]:.2f}, {position[1]:.2f}): following, turning {turn}",
                    {"point": point(position)},
                )
            )
        elif self.mode == "following":
            from_hit = float(np.hypot(*(position - self.hit_point)))
            if from_hit > 2.0 * p.loop_radius_m:
                self.left_hit_area = True
            on_mline = abs(self.mline_offset(position)) <= p.mline_tolerance_m
            closer = distance <= self.hit_distance - LEAVE_MARGIN_M
            clear = ahead > p.hit_distance_m + 0.15
            if on_mline and closer and clear:
                self.mode = "go_to_goal"
                events.append(
                    Event(
                        EventKind.WALL_LEFT,
                        f"leave at ({position[0]:.2f}, {position[1]:.2f}): back on the m-line",
                        {"point": point(position)},
                    )
                )
            elif self.left_hit_area and from_hit <= p.loop_radius_m:
                self.gave_up = True
                events.append(
                    Event(
                        EventKind.GAVE_UP,
                        "gave up: back at the hit point after a loop, the goal is unreachable",
                    )
                )
            elif obs.time_s - self.follow_start_s >= p.max_follow_s:
                self.gave_up = True
                events.append(
                    Event(
                        EventKind.GAVE_UP, f"gave up: following for {obs.time_s - self.follow_start_s:.1f} s"
                    )
                )

        if self.gave_up:
            return Decision(force=np.zeros(2), mode="gave_up", events=events, gave_up=True)
        components = self._go_to_goal(obs) if self.mode == "go_to_goal" else self._follow(obs)
        force = np.sum(list(components.values()), axis=0)
        steering = self.governor.steer(force, obs, obs.static_echo_points())
        return Decision(
            force=steering.force,
            mode=self.mode,
            components=components,
            events=events,
            command=steering.command,
        )
