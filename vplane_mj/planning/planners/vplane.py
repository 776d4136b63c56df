"""The paper's planner (`vplane`): APF, histogram avoidance, virtual new objective, virtual plane.

Algorithm 3 of the paper, as a state machine with three modes:
- `normal`: F = F_A(goal) + F_R(echoes) + F_P(planes) (eqs. 3, 5, 8-10);
- `avoiding` (Algorithm 1): a concave obstacle blocks the goal and no wide-enough valley
  leads to the goal, so the robot is attracted past the cup's nearer edge instead;
- `escaping` (Algorithm 2): after a local minimum the robot is attracted by the virtual
  new objective (eq. 7); on reaching it (`tempGoal` cleared) the target is re-activated
  and the virtual plane e1-e2 is added to the list L.

One departure from the paper: within `goal_fade_m` of the goal the echo repulsion fades
to zero with the square of the distance to the goal (after Ge and Cui's fix of "goal not
reachable with obstacles nearby", which the paper names but does not treat), so a goal
close to a wall can be reached: near the goal the attraction falls only linearly, so it
wins there over any bounded repulsion (a linear fade would balance it short of the goal).

The rules the paper leaves open: a plane is retired once the robot is nearer the goal
than any point of the plane, or when more than `max_planes` exist (the oldest goes); a
local minimum while escaping, or an escape that takes longer than `escape_timeout_s`,
starts a new escape from where the robot is; after `max_escapes` escapes the planner
gives up (outcome `stuck`).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.motion import fields
from vplane_mj.planning.motion.governor import Steering
from vplane_mj.planning.perception import histogram
from vplane_mj.planning.perception.localmap import angular_extremes
from vplane_mj.planning.planners.groups import DetectorParams, FieldParams, MotionParams, SonarMapParams
from vplane_mj.planning.planners.vplane_geometry import (
    VirtualPlane,
    make_plane,
    plane_force,
    virtual_objective,
)
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.events import Event, EventKind, point
from vplane_mj.planning.protocol.params import param
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.planning.protocol.vectors import dot, unit

CONCAVITY_CHECK_PERIOD_S = 0.2
"""How often (s) the map is examined for a concave obstacle ahead (cheap checks run every tick)."""

EDGE_OFFSETS_M = (0.05, 0.3, 0.6)
"""Distances beyond the robot's width at which a waypoint past a concave obstacle's edge is tried."""


@dataclass(frozen=True)
class VPlaneParams(MotionParams, SonarMapParams, DetectorParams, FieldParams):
    """The fields', the detector's, the sonar map's and the governor's parameters, and the
    escape's."""

    echo_memory: int = param(100, "", "sonar scans kept for the extreme points e1, e2", ge=1, integer=True)
    clearance_m: float = param(
        0.08, "m", "clearance added to the robot radius (gap width, VFH+ enlargement)", ge=0, le=1.0
    )
    min_gap_deg: float = param(10.0, "deg", "narrowest valley that counts as a passage", gt=0)
    concave_depth_m: float = param(
        0.3, "m", "depth behind the chord e1-e2 that makes an obstacle concave", gt=0
    )
    lookahead_m: float = param(2.0, "m", "how far ahead toward the goal obstacles are examined", gt=0)
    goal_fade_m: float = param(
        0.6, "m", "echo repulsion fades (quadratically) to zero within this distance of the goal", ge=0
    )
    vno_gain: float = param(0.5, "1/m", "gamma of eq. 7, attraction of the virtual new objective", gt=0)
    vno_tolerance_m: float = param(
        0.15, "m", "distance at which the virtual objective counts as reached", gt=0
    )
    escape_margin_m: float = param(0.3, "m", "objective lies at least radius + this outside the trap", ge=0)
    escape_timeout_s: float = param(25.0, "s", "an escape that takes longer starts over", gt=0)
    max_escapes: int = param(4, "", "escapes tried before giving up", ge=1, integer=True)
    plane_gain: float = param(0.05, "m", "eta of eqs. 8-10, virtual plane repulsion gain", gt=0)
    plane_influence_m: float = param(0.6, "m", "r of eq. 8, the virtual plane's radius of influence", gt=0)
    plane_step_m: float = param(0.05, "m", "spacing of the points p_i on the plane (eqs. 9-10)", ge=0.005)
    plane_margin_m: float = param(0.3, "m", "the corridor extends this far past the plane's ends", ge=0)
    slide_gain: float = param(1.0, "", "tangential force along the plane, relative to its normal force", ge=0)
    max_planes: int = param(4, "", "virtual planes kept at most (list L)", ge=1, integer=True)


def escape_started(e1: np.ndarray, e2: np.ndarray, objective: np.ndarray) -> Event:
    """The event of an escape that starts toward `objective`, from the trap's extreme points."""
    return Event(
        EventKind.ESCAPE_STARTED,
        f"escape started: e1=({e1[0]:.2f}, {e1[1]:.2f}) e2=({e2[0]:.2f}, {e2[1]:.2f}) "
        f"objective=({objective[0]:.2f}, {objective[1]:.2f})",
        {"e1": point(e1), "e2": point(e2), "objective": point(objective)},
    )


def plane_created(plane: VirtualPlane) -> Event:
    """The event of an escape finished with a new virtual plane."""
    return Event(
        EventKind.ESCAPE_FINISHED,
        "objective reached: virtual plane created, target re-activated",
        {"e1": point(plane.e1), "e2": point(plane.e2)},
    )


class VPlanePlanner(Planner):
    """Algorithm 3 with its flags: `temp_goal` (escaping) and the list L of virtual planes."""

    name = "vplane"
    summary = "APF with histogram avoidance, virtual new objective and virtual plane (the paper)"
    governs_itself = True
    citation = (
        "A Novel Approach to Local Minima Problem in Robot Path Planning Using Artificial "
        "Potential Field (virtual plane method)"
    )
    Params = VPlaneParams
    params: VPlaneParams

    def __init__(self, params: VPlaneParams, robot: RobotBody | float):
        super().__init__(params, robot)
        p = params
        self.detector = p.detector()
        self.map = p.local_map()
        self.n_sectors = p.sector_count()
        self.planes: list[VirtualPlane] = []
        self.temp_goal: np.ndarray | None = None  # the virtual new objective while escaping
        self.pending_plane: VirtualPlane | None = None
        self.escape_started_s = 0.0
        self.escapes_tried = 0
        self.avoid_waypoint: np.ndarray | None = None
        self.next_concavity_check_s = 0.0
        self.echoes: deque[np.ndarray] = deque(maxlen=max(1, round(p.echo_memory)))
        self.governor = p.governor(self.robot)

    # -- the loop -------------------------------------------------------------------------
    def step(self, obs: Observation) -> Decision:
        p = self.params
        self.map.update(obs.position, obs.yaw, obs.bearings, obs.static_ranges(), obs.beam_width)
        self.map.forget(obs.tracks, obs.time_s)
        self.echoes.append(obs.static_echo_points())
        decision = Decision(force=np.zeros(2), mode="normal")
        if self.planes:
            self._retire_planes(obs, decision)

        near_goal = obs.distance_to_goal() <= obs.goal_tolerance
        state = self.detector.update(obs.time_s, obs.position, near_goal)
        if state.new:
            decision.local_minimum = True
            decision.events.append(Event(EventKind.LOCAL_MINIMUM, "local minimum detected"))
            if not self._start_escape(obs, decision):
                return decision
        elif self.temp_goal is not None and obs.time_s - self.escape_started_s > p.escape_timeout_s:
            decision.events.append(Event(EventKind.ESCAPE_TIMED_OUT, "escape timed out"))
            if not self._start_escape(obs, decision):
                return decision

        if self.temp_goal is not None and np.hypot(*(obs.position - self.temp_goal)) <= p.vno_tolerance_m:
            self._finish_escape(obs, decision)

        components = p.firas_components(obs)
        if p.goal_fade_m > 0:  # goals near obstacles stay reachable (GNRON)
            components["repulsive"] *= min(1.0, obs.distance_to_goal() / p.goal_fade_m) ** 2
        if self.temp_goal is not None:
            decision.mode = "escaping"
            components["attractive"] = -2.0 * p.vno_gain * (obs.position - self.temp_goal)  # eq. 7
        else:
            self._update_avoidance(obs, decision)
            if self.avoid_waypoint is not None:
                decision.mode = "avoiding"
                components["attractive"] = fields.attractive_force(
                    obs.position, self.avoid_waypoint, p.attract_gain, p.attract_radius
                )
        components["virtual"] = self._planes_force(obs.position)
        decision.components = components
        steering = self._governed(sum(components.values(), np.zeros(2)), obs)
        decision.force, decision.command = steering.force, steering.command
        decision.objective = self.temp_goal
        decision.planes = [(plane.e1, plane.e2) for plane in self.planes]
        return decision

    def _governed(self, force: np.ndarray, obs: Observation) -> Steering:
        """The command for the force (motion/governor.py) among the echoes and the mapped
        cells around it, which remember what the sensor sees between its beams or behind."""
        if self.governor.idle:
            return Steering(force)
        cells, _ = self.map.cells(self.params.map_threshold, obs.position, self.governor.reach_m)
        return self.governor.steer(force, obs, np.vstack((obs.static_echo_points(), cells)))

    # -- Algorithm 2: escaping ---------------------------------------------------------------
    def _start_escape(self, obs: Observation, decision: Decision) -> bool:
        """Place a virtual new objective; False (and gave_up) when escapes are exhausted."""
        self.avoid_waypoint = None
        if self.escapes_tried >= self.params.max_escapes:
            decision.gave_up = True
            decision.events.append(Event(EventKind.GAVE_UP, f"gave up after {self.escapes_tried} escapes"))
            return False
        trap = self._trap_cluster(obs.position, obs.goal)
        if trap is None:
            decision.events.append(
                Event(EventKind.GAVE_UP, "local minimum without mapped obstacles: no escape possible")
            )
            decision.gave_up = True
            return False
        i1, i2, _ = angular_extremes(obs.position, trap)
        e1, e2 = trap[i1], trap[i2]
        plane = make_plane(e1, e2, trap, obs.position, obs.goal, extend=self._link_m())
        # The robot stands and turns at the objective: its circumscribed radius.
        clearance = self.radius + self.params.escape_margin_m
        self.temp_goal = virtual_objective(obs.position, e1, e2, obs.goal, plane, clearance)
        self.pending_plane = plane
        self.escape_started_s = obs.time_s
        self.escapes_tried += 1
        self.detector.reset()
        decision.events.append(escape_started(e1, e2, self.temp_goal))
        return True

    def _finish_escape(self, obs: Observation, decision: Decision) -> None:
        """Objective reached (the robot as `obs` shows it): re-activate the target and add the
        virtual plane to L."""
        plane, self.temp_goal, self.pending_plane = self.pending_plane, None, None
        assert plane is not None, "an escape places its plane together with its objective"
        self.planes.append(plane)
        if len(self.planes) > self.params.max_planes:
            self.planes.pop(0)
            decision.events.append(Event(EventKind.PLANE_RETIRED, "oldest virtual plane retired"))
        self.detector.reset()
        decision.escape_completed = True
        decision.events.append(plane_created(self.planes[-1]))

    def _trap_cluster(self, position: np.ndarray, goal: np.ndarray) -> np.ndarray | None:
        """Echo points of the obstacle that traps the robot: the cluster nearest toward the goal.

        The map's clusters say which echoes belong together; the extreme points are then
        taken from the echoes themselves (the sonar's acoustic axis), not from the map's
        beam-wide arcs, so the plane spans the trap's true mouth.
        """
        cells, labels, grid_labels = self.map.clusters(self.params.map_threshold, self._link_m())
        if len(cells) == 0:
            return None
        rel = cells - position
        toward_goal = dot(rel, unit(goal - position))
        distance = np.hypot(rel[:, 0], rel[:, 1])
        ahead = toward_goal > 0.5 * distance  # within 60 degrees of the goal direction
        pool = np.flatnonzero(ahead) if ahead.any() else np.arange(len(cells))
        trap_label = labels[pool[np.argmin(distance[pool])]]
        echoes = np.vstack(self.echoes)
        trap = echoes[self.map.lookup(grid_labels, echoes) == trap_label]
        return trap if len(trap) >= 2 else cells[labels == trap_label]

    def _link_m(self) -> float:
        """Obstacle cells closer than this leave no gap for the robot: one cluster. The robot
        passes a gap aligned with it, so its width counts (the diameter of a round robot)."""
        return 2 * self.robot.half_width_m + self.params.clearance_m

    # -- the virtual planes -------------------------------------------------------------------
    def _planes_force(self, position: np.ndarray) -> np.ndarray:
        p = self.params
        total = np.zeros(2)
        for plane in self.planes:
            if plane.in_corridor(position, p.plane_influence_m, p.plane_margin_m):
                total += plane_force(
                    position,
                    plane,
                    p.plane_gain,
                    p.plane_influence_m,
                    p.plane_step_m,
                    p.slide_gain,
                )
        return total

    def _retire_planes(self, obs: Observation, decision: Decision) -> None:
        """Drop the planes the robot has left behind on its way to the goal."""
        to_goal = obs.distance_to_goal()
        kept = []
        for plane in self.planes:
            nearest_to_goal = min(np.hypot(*(plane.e1 - obs.goal)), np.hypot(*(plane.e2 - obs.goal)))
            if to_goal < nearest_to_goal - self.radius:
                decision.events.append(
                    Event(EventKind.PLANE_RETIRED, "virtual plane retired: the trap is behind")
                )
            else:
                kept.append(plane)
        self.planes = kept

    # -- Algorithm 1: histogram avoidance -------------------------------------------------------
    def _update_avoidance(self, obs: Observation, decision: Decision) -> None:
        """Enter, keep or leave the avoiding mode (steering past a concave obstacle's edge)."""
        p = self.params
        # A valley is a direction the robot drives along, aligned with it: cells enlarged by
        # its half width (VFH+'s robot radius for a round robot). Only cells within the
        # histogram's window count: those of the square around the robot.
        h, count = histogram.map_histogram(
            self.map,
            p.map_threshold,
            obs.position,
            self.n_sectors,
            p.window_m,
            self.robot.half_width_m + p.clearance_m,
        )
        if count == 0 and not self.map.any_cells(p.map_threshold):
            self.avoid_waypoint = None
            return
        goal_bearing = math.atan2(obs.goal[1] - obs.position[1], obs.goal[0] - obs.position[0])
        blocked = h > p.histogram_threshold
        goal_free = not blocked[histogram.sector_of(goal_bearing, self.n_sectors)]
        if goal_free:
            if self.avoid_waypoint is not None:
                decision.events.append(
                    Event(EventKind.AVOIDANCE_FINISHED, "avoidance finished: the way to the goal is free")
                )
            self.avoid_waypoint = None
            return
        if self.avoid_waypoint is not None:
            if np.hypot(*(obs.position - self.avoid_waypoint)) < 2 * self.radius:
                self.avoid_waypoint = None
                decision.events.append(Event(EventKind.AVOIDANCE_FINISHED, "avoidance finished: edge passed"))
            return
        if obs.time_s < self.next_concavity_check_s:
            return
        self.next_concavity_check_s = obs.time_s + CONCAVITY_CHECK_PERIOD_S
        waypoint = self._concave_edge_waypoint(obs)
        if waypoint is not None and self._passage_is_wide(blocked, waypoint - obs.position):
            self.avoid_waypoint = waypoint
            decision.events.append(
                Event(
                    EventKind.AVOIDANCE_STARTED,
                    f"concave obstacle ahead: passing its edge via ({waypoint[0]:.2f}, {waypoint[1]:.2f})",
                    {"waypoint": point(waypoint)},
                )
            )

    def _passage_is_wide(self, blocked: np.ndarray, direction: np.ndarray) -> bool:
        """Algorithm 1 step 5: a valley of at least `min_gap_deg` opens next to `direction`.

        The waypoint just past an edge is seen along the edge itself, so the valley may
        begin up to `min_gap_deg` beside its bearing.
        """
        p = self.params
        min_sectors = max(1, math.ceil(p.min_gap_deg / p.sector_deg))
        _, distance = histogram.nearest_wide_valley(
            histogram.find_valleys(blocked),
            math.atan2(direction[1], direction[0]),
            self.n_sectors,
            min_sectors,
        )
        return distance <= min_sectors

    def _concave_edge_waypoint(self, obs: Observation) -> np.ndarray | None:
        """A point just past the nearer edge of a concave obstacle ahead, or None."""
        p = self.params
        cells, labels, _ = self.map.clusters(p.map_threshold, self._link_m())
        heading = unit(obs.goal - obs.position)
        rel = cells - obs.position
        forward = dot(rel, heading)
        lateral = np.abs(dot(rel, np.array([-heading[1], heading[0]])))
        reach = min(p.lookahead_m, obs.distance_to_goal())
        ahead = (forward > 0) & (forward < reach) & (lateral < self.robot.half_width_m + p.clearance_m)
        if not ahead.any():
            return None
        nearest = np.flatnonzero(ahead)[np.argmin(forward[ahead])]
        cluster = cells[labels == labels[nearest]]
        i1, i2, span = angular_extremes(obs.position, cluster)
        if span >= math.pi:  # it surrounds the robot: that is a trap, not an obstacle ahead
            return None
        e1, e2 = cluster[i1], cluster[i2]
        chord = unit(e2 - e1)
        away = np.array([-chord[1], chord[0]])
        if dot(e1 - obs.position, away) < 0:
            away = -away
        depth = float(np.max(dot(cluster - e1, away)))
        if depth < p.concave_depth_m:
            return None
        via = [np.hypot(*(e - obs.position)) + np.hypot(*(obs.goal - e)) for e in (e1, e2)]
        edge = e1 if via[0] <= via[1] else e2
        # Beside the edge as seen from the robot, on the side away from the obstacle's middle,
        # so the straight way there passes the edge at that distance.
        sight = unit(edge - obs.position)
        outward = np.array([-sight[1], sight[0]])
        if dot(outward, edge - (e1 + e2) / 2) < 0:
            outward = -outward
        # Just past the edge; farther out when the straight way there grazes the obstacle.
        for offset in EDGE_OFFSETS_M:
            waypoint = edge + outward * (self._link_m() + offset)
            if self._reachable(obs.position, waypoint, cells):
                return waypoint
        return None

    def _reachable(self, start: np.ndarray, end: np.ndarray, cells: np.ndarray) -> bool:
        """No known obstacle cell within the robot's half width plus clearance of the segment
        (the robot drives along it, aligned with it)."""
        span = end - start
        t = np.clip(dot(cells - start, span) / max(float(dot(span, span)), 1e-12), 0.0, 1.0)
        nearest = start + t[:, None] * span
        return bool(
            np.min(np.hypot(*(cells - nearest).T)) > self.robot.half_width_m + self.params.clearance_m
        )
