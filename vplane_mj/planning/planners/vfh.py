"""VFH+ steering toward the goal (`vfh`), after Borenstein and Koren, and Ulrich and Borenstein.

The sonar certainty grid (localmap.py) gives a polar histogram with obstacle cells
enlarged by the robot's half width (its radius when round) plus a clearance (histogram.py):
the free valleys are the directions the robot fits through, driving along them aligned;
cells beyond the goal do not count. Candidates are the
goal direction when it lies in a valley, the middle of narrow valleys and, in wide
valleys, the directions half a wide valley in from each border. The cost
5 |c - goal| + 2 |c - heading| + 2 |c - previous| picks one (VFH+'s weights). The force
is a unit vector that way, shortened within 1 m of the goal. With no valley the robot
stops; the local-minimum detector then makes it give up after `patience_s` (`stuck`).
The governor (motion/governor.py) then drives the force on the robot's body: its commands keep the
footprint off the obstacles over the motion they start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.motion.governor import Steering
from vplane_mj.planning.perception import histogram
from vplane_mj.planning.perception.minima import report_trap
from vplane_mj.planning.planners.groups import MinimumParams, MotionParams, SonarMapParams
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.params import param
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.planning.protocol.vectors import wrap_angle

GOAL_WEIGHT, HEADING_WEIGHT, PREVIOUS_WEIGHT = 5.0, 2.0, 2.0
"""VFH+ cost weights (Ulrich and Borenstein, 1998)."""


@dataclass(frozen=True)
class VfhParams(MotionParams, SonarMapParams, MinimumParams):
    """The detector's and the patience's parameters, the sonar map's, the governor's and VFH+'s
    own."""

    clearance_m: float = param(0.1, "m", "clearance added to the robot's half width (enlargement)", ge=0)
    wide_valley_deg: float = param(80.0, "deg", "valleys at least this wide are wide (s_max)", gt=0)


def _angle_between(a: float, b: float) -> float:
    return abs(wrap_angle(a - b))


class VfhPlanner(Planner):
    """Steers along the cheapest free direction of the polar histogram."""

    name = "vfh"
    summary = "VFH+ polar-histogram steering toward the goal, from the sonar grid"
    governs_itself = True
    citation = (
        "J. Borenstein, Y. Koren, The vector field histogram, IEEE TRA 7(3), 1991; "
        "I. Ulrich, J. Borenstein, VFH+, ICRA 1998"
    )
    Params = VfhParams
    params: VfhParams

    def __init__(self, params: VfhParams, robot: RobotBody | float):
        super().__init__(params, robot)
        self.detector = params.detector()
        self.map = params.local_map()
        self.n_sectors = params.sector_count()
        self.previous: float | None = None
        self.governor = params.governor(self.robot)

    def step(self, obs: Observation) -> Decision:
        p = self.params
        self.map.update(obs.position, obs.yaw, obs.bearings, obs.static_ranges(), obs.beam_width)
        self.map.forget(obs.tracks, obs.time_s)
        enlarge = self.robot.half_width_m + p.clearance_m
        window = min(p.window_m, obs.distance_to_goal() + enlarge)  # nothing beyond the goal blocks it
        h, _ = histogram.map_histogram(
            self.map, p.map_threshold, obs.position, self.n_sectors, window, enlarge
        )
        to_goal = obs.goal - obs.position
        goal_bearing = math.atan2(to_goal[1], to_goal[0])
        direction = self._choose(histogram.find_valleys(h > p.histogram_threshold), goal_bearing, obs.yaw)
        decision = Decision(force=np.zeros(2), mode="normal")
        force = np.zeros(2)
        if direction is None:
            decision.mode = "blocked"
        else:
            self.previous = direction
            force = min(1.0, obs.distance_to_goal()) * np.array([math.cos(direction), math.sin(direction)])
        steering = self._governed(force, obs)
        decision.force, decision.command = steering.force, steering.command
        decision.components = {"steering": decision.force}
        report_trap(self.detector, obs, decision, p.patience_s)
        return decision

    def _governed(self, force: np.ndarray, obs: Observation) -> Steering:
        """The command for the force (motion/governor.py) among the echoes and the mapped cells near it."""
        if self.governor.idle:
            return Steering(force)
        cells, _ = self.map.cells(self.params.map_threshold, obs.position, self.governor.reach_m)
        return self.governor.steer(force, obs, np.vstack((obs.static_echo_points(), cells)))

    def _choose(self, valleys: list[histogram.Valley], goal: float, heading: float) -> float | None:
        """The VFH+ candidate direction of least cost, or None when every sector is blocked."""
        sector = 2 * math.pi / self.n_sectors
        wide = max(1, round(math.radians(self.params.wide_valley_deg) / sector))
        goal_sector = histogram.sector_of(goal, self.n_sectors)
        candidates = []
        for valley in valleys:
            if valley.count >= self.n_sectors:
                candidates.append(goal)
                continue
            if (goal_sector - valley.first) % self.n_sectors < valley.count:
                candidates.append(goal)
            if valley.count >= wide:
                candidates.append((valley.first + wide / 2) * sector)
                candidates.append((valley.first + valley.count - wide / 2) * sector)
            else:
                candidates.append((valley.first + valley.count / 2) * sector)
        if not candidates:
            return None
        previous = heading if self.previous is None else self.previous

        def cost(c: float) -> float:
            return (
                GOAL_WEIGHT * _angle_between(c, goal)
                + HEADING_WEIGHT * _angle_between(c, heading)
                + PREVIOUS_WEIGHT * _angle_between(c, previous)
            )

        return min(candidates, key=cost)
