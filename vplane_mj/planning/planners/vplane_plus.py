"""The paper's method made robust in clutter (`vplane_plus`).

The structure of Algorithm 3 stays: F = F_A + F_R + F_P in `normal` mode (eqs. 3, 5, 8-10),
histogram avoidance of concave obstacles (Algorithm 1, `avoiding`), and on a local minimum a
virtual new objective on the bisector of the trap's extreme points (Algorithm 2, `escaping`)
followed by a virtual plane e1-e2 that keeps the robot out of the trap. What the paper leaves
open is decided with what the sonar map remembers (`gridsearch`: the map's obstacle cells
inflated by the robot's half width, as a robot drives along a way aligned with it, the
unknown counted as free):

- the trap is one obstacle: the connected obstacle cells nearest toward the goal, where cells
  separated by a gap the robot fits through belong to different obstacles; e1 and e2 are its
  angular ends, and a plane whose segment passes another obstacle (so it would span a gap
  between two) is not created;
- the virtual new objective must lie on a cell the map says is free and reachable from the
  robot, outside the trap; the paper's point on the bisector is kept when it is, else the
  nearest such cell is taken; the robot goes there along the map's shortest way (`escaping`);
- a plane that cuts the only known way to the goal is retired;
- after `fallback_after` escapes, the robot follows the map's shortest way to the goal
  (`following`), replanned as the map grows: with a map that remembers, this finds the goal
  whenever the sonar can show a way (a complete fallback); the planner gives up only when the
  map holds no way to the goal at all for `no_way_patience_s`. A dense scan (a laser: scan.py)
  maps the obstacles it sees as they are from the first scan, so with one the robot follows
  the map's way from the start;
- the governor (motion/governor.py) drives a robot that is not a small disc for the force: its
  commands keep the footprint off the echoes and the mapped cells over the motion they start
  (the drive's ramp and the coast of a turn included), and back the robot off where it is shut
  in. On a way of the map such a robot is not repelled by the echoes: the way keeps it off the
  mapped obstacles and the governor off everything else, and the repulsion would only turn
  it off the way where it passes close to an obstacle.

Every decision is an event (`/events`), and objectives and planes appear in `/virtual`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from vplane_mj.planning.motion import fields, gridsearch
from vplane_mj.planning.motion.governor import Steering
from vplane_mj.planning.perception import scan
from vplane_mj.planning.perception.localmap import LocalMap, angular_extremes, mask_cells
from vplane_mj.planning.planners.vplane import VPlaneParams, VPlanePlanner, escape_started, plane_created
from vplane_mj.planning.planners.vplane_geometry import VirtualPlane, make_plane, virtual_objective
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.events import Event, EventKind, point
from vplane_mj.planning.protocol.params import param, with_default
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.planning.protocol.vectors import dot, unit, wrap_angle

CLOSE_ECHO_MARGIN_M = 0.1
"""An echo this close beyond the robot's disc (m) repels in full, even against the way."""
SCAN_MOVE_M, SCAN_TURN_RAD = 0.02, math.radians(3.0)
"""A scan is folded into the map only after the robot has moved or turned this much since the last."""
KEEP_WAY_RATIO = 1.25
"""A new way replaces the one being followed only when that one costs this much more."""
STALL_RADIUS_M = 0.3
"""Passing within this distance (m) of where the way was held up costs as much as a doubtful cell."""
BLOCK_LOOKAHEAD_M = 0.6
"""The way this far ahead (m) is checked against the map every tick; if blocked, it is replanned."""
SILENT_FREE_M = 1.0
"""A sonar that hears no echo shows its first metre free, for the choice of objectives only."""
OBJECTIVE_ROOM_M = 0.05
"""A virtual objective lies at least this much beyond the robot's disc from every mapped obstacle."""
BEND_HORIZON_M = 3.0
"""The way this far ahead (m) bounds the speed by the turns it asks for (motion/governor.py)."""
TRAP_REACH_M = 2.5
"""Obstacle cells farther than this from the robot are not part of the trap it is in."""
AIM_AHEAD_M = 8.0
"""Among moving tracks, the governor makes for the point of the way this far (m) along it:
farther than the robot gets within the evasion's horizon, so that no motion overshoots it."""
OFF_WAY_M = 0.5
"""A robot this far (m) from the way it follows (pushed off it evading a moving track) searches
its way again, at most every OFF_WAY_PERIOD_S."""
OFF_WAY_PERIOD_S = 0.25
NO_WAY = np.empty((0, 2))
NO_WAY.flags.writeable = False
"""An empty way (K = 0 waypoints): ways are (K, 2) arrays of waypoints (m), never written."""
NO_SIGHT = (np.empty((0, 0)), 0.0, 0.0, 1.0)
"""No window to look through (`kernels.way.next_waypoint`, as `Window.packed`): every waypoint
is in sight."""


def plane_refused(e1: np.ndarray, e2: np.ndarray, why: str) -> Event:
    """The event of a virtual plane e1-e2 not created, and why."""
    return Event(
        EventKind.PLANE_REFUSED,
        f"no virtual plane: e1=({e1[0]:.2f}, {e1[1]:.2f}) e2=({e2[0]:.2f}, {e2[1]:.2f}) {why}",
        {"e1": point(e1), "e2": point(e2)},
    )


@dataclass(frozen=True)
class VPlanePlusParams(VPlaneParams):
    """vplane's parameters (a finer, larger map), and those of the map's ways."""

    map_cell_m: float = with_default(VPlaneParams, "map_cell_m", 0.05)
    map_size_m: float = with_default(VPlaneParams, "map_size_m", 16.0)
    map_hit: int = param(1, "", "certainty an echo adds to each cell of its arc", ge=1, le=15, integer=True)
    map_miss: int = param(
        2, "", "certainty a reading removes from the cells it shows free", ge=0, le=15, integer=True
    )
    path_clearance_m: float = param(
        0.01, "m", "the map's ways never pass closer than the robot's half width plus this", ge=0, le=1.0
    )
    inflation_m: float = param(0.3, "m", "beyond that, the map's ways pay for passing closer than this", gt=0)
    inflation_weight: float = param(
        4.0, "", "extra step cost right at the clearance (costmap inflation)", ge=0
    )
    map_hit_range_m: float = param(
        1.5, "m", "echoes farther than this only clear the map, unless their arc is a cell wide at most", gt=0
    )
    map_sure: int = param(
        10, "", "certainty at which an obstacle cell is sure (lower: doubtful)", ge=1, integer=True
    )
    doubt_cost: float = param(20.0, "", "extra step cost of passing a doubtful obstacle cell", ge=0)
    waypoint_m: float = param(1.0, "m", "how far along the map's way the robot is attracted", gt=0)
    replan_period_s: float = param(0.5, "s", "the map's way is searched again this often", gt=0)
    search_margin_m: float = param(
        2.5, "m", "the search covers the robot and the goal plus this margin", gt=0
    )
    follow_influence_m: float = param(
        0.35, "m", "f0 of the echo repulsion while following the map's way", gt=0
    )
    guard_m: float = param(0.25, "m", "f0 of the repulsion of the nearest mapped obstacle cell", gt=0)
    fallback_after: int = param(
        2, "", "escapes before the map's way is followed to the goal", ge=0, integer=True
    )
    no_way_patience_s: float = param(
        8.0, "s", "give up after the map has held no way to the goal this long", gt=0
    )


class VPlanePlusPlanner(VPlanePlanner):
    """The paper's state machine plus the map's ways (see the module docstring)."""

    name = "vplane_plus"
    summary = (
        "the paper's method with map-checked extreme points, objectives and planes, and a "
        "map-way fallback (clutter)"
    )
    citation = (
        "A Novel Approach to Local Minima Problem in Robot Path Planning Using Artificial "
        "Potential Field (virtual plane method), extended for clutter"
    )
    Params = VPlanePlusParams
    params: VPlanePlusParams

    def __init__(self, params: VPlanePlusParams, robot: RobotBody | float):
        super().__init__(params, robot)
        p = params
        self.map = LocalMap(
            p.map_cell_m,
            p.map_size_m,
            hit=round(p.map_hit),
            miss=round(p.map_miss),
            # A laser's beams are narrow: its echoes place obstacles as far as it reaches.
            hit_range_m=p.map_hit_range_m if self.robot.sensor_kind != "laser" else math.inf,
            track_seen=True,
            silent_free_m=SILENT_FREE_M,
        )
        self.escape_way = NO_WAY  # waypoints (K, 2; m) to the virtual objective
        self.following = False
        self.follow_way = NO_WAY
        self.next_replan_s = 0.0
        self.no_way_since: float | None = None
        self.sight: gridsearch.Window | None = None  # the window of the latest way, for sight lines
        self.stalls: list[np.ndarray] = []  # where following the way was held up (m)
        self.last_scan_pose: tuple[float, float, float] | None = None
        self.last_scan_s: float | None = None  # when the sensor took the last scan seen (s)

    # -- the loop -------------------------------------------------------------------------
    def step(self, obs: Observation) -> Decision:
        p = self.params
        if self._new_scan(obs) and self._moved_since_last_scan(obs):
            self.map.update(obs.position, obs.yaw, obs.bearings, obs.static_ranges(), obs.beam_width)
            self.map.sweep(obs.position, self.robot.inner_radius_m)  # under the robot at any heading
        self.map.forget(obs.tracks, obs.time_s)
        decision = Decision(force=np.zeros(2), mode="normal")
        if not self.following and self.last_scan_pose is not None and scan.is_dense(obs):
            self._start_following(obs, decision, "a dense scan maps the way from the start")
        self._retire_planes(obs, decision)

        near_goal = obs.distance_to_goal() <= obs.goal_tolerance
        state = self.detector.update(obs.time_s, obs.position, near_goal)
        if state.new:
            decision.local_minimum = True
            decision.events.append(Event(EventKind.LOCAL_MINIMUM, "local minimum detected"))
            if self.following:
                # Held up on the way: the map missed something there. Charge for passing that
                # place again, and look for a way at once.
                stuck_at, self.follow_way = self._next_waypoint(obs.position, self.follow_way, obs.goal)
                self.stalls.append(stuck_at)
                decision.events.append(
                    Event(
                        EventKind.HELD_UP,
                        f"held up on the way near ({stuck_at[0]:.2f}, {stuck_at[1]:.2f})",
                        {"point": point(stuck_at)},
                    )
                )
                self.next_replan_s = obs.time_s
                self.detector.reset()
            else:
                self._start_escape(obs, decision)
        elif self.temp_goal is not None and obs.time_s - self.escape_started_s > p.escape_timeout_s:
            decision.events.append(Event(EventKind.ESCAPE_TIMED_OUT, "escape timed out"))
            self._start_escape(obs, decision)

        if self.temp_goal is not None and np.hypot(*(obs.position - self.temp_goal)) <= p.vno_tolerance_m:
            self._finish_escape(obs, decision)

        components: dict[str, np.ndarray] = {}
        if self.temp_goal is not None:
            decision.mode = "escaping"
            if self._way_is_blocked(obs.position, self.escape_way):
                window = self._window(obs.position, self.temp_goal, self.planes, margin=p.search_margin_m)
                self.escape_way = _or_no_way(self._way(window, obs.position, self.temp_goal))
            target, self.escape_way = self._next_waypoint(obs.position, self.escape_way, self.temp_goal)
            pull = 2.0 * p.vno_gain * float(np.hypot(*(obs.position - self.temp_goal)))  # eq. 7
            self._along_the_way(obs, components, target, pull, len(self.escape_way) > 0)
        elif self.following:
            decision.mode = "following"
            target = self._follow_target(obs, decision)
            if decision.gave_up:
                return decision
            goal_pull = fields.attractive_force(obs.position, obs.goal, p.attract_gain, p.attract_radius)
            on_a_way = len(self.follow_way) > 0
            self._along_the_way(obs, components, target, float(np.hypot(*goal_pull)), on_a_way)
        else:
            components.update(self._firas(obs))
            self._update_avoidance(obs, decision)
            if self.avoid_waypoint is not None:
                decision.mode = "avoiding"
                components["attractive"] = fields.attractive_force(
                    obs.position, self.avoid_waypoint, p.attract_gain, p.attract_radius
                )
        # While following the map's way the planes act as walls of the search instead: their
        # force would push the robot off a way that skirts a plane's end.
        components["virtual"] = np.zeros(2) if self.following else self._planes_force(obs.position)
        components["map"] = self._nearest_cell_force(obs.position)
        decision.components = components
        steering = self._governed(sum(components.values(), np.zeros(2)), obs)
        decision.force, decision.command = steering.force, steering.command
        decision.objective = self.temp_goal
        decision.planes = [(plane.e1, plane.e2) for plane in self.planes]
        return decision

    def _new_scan(self, obs: Observation) -> bool:
        """Whether the tick brings a scan not seen before: a sensor slower than the control rate
        hands one scan to several ticks, and folded again at a later pose it would show the
        obstacles displaced (erasing walls the robot has driven away from)."""
        taken = obs.time_s if obs.scan_time_s is None else obs.scan_time_s
        if taken == self.last_scan_s:
            return False
        self.last_scan_s = taken
        return True

    def _moved_since_last_scan(self, obs: Observation) -> bool:
        """Whether the robot has moved or turned enough since the last scan folded into the map:
        scans from one pose repeat the same phantoms of a wide beam, and are no new evidence."""
        last = self.last_scan_pose
        if last is not None:
            turned = abs(wrap_angle(obs.yaw - last[2]))
            if math.hypot(obs.position[0] - last[0], obs.position[1] - last[1]) < SCAN_MOVE_M and (
                turned < SCAN_TURN_RAD
            ):
                return False
        self.last_scan_pose = (float(obs.position[0]), float(obs.position[1]), obs.yaw)
        return True

    def _along_the_way(
        self,
        obs: Observation,
        components: dict[str, np.ndarray],
        waypoint: np.ndarray,
        pull: float,
        on_a_way: bool,
    ) -> None:
        """Forces while the robot heads for `waypoint`: the attraction of the way's end
        (magnitude `pull`) turned toward it, and, `on_a_way` of the map, the repulsion of the
        echoes within `follow_influence_m` without its part against the way. The way keeps the
        robot off the mapped obstacles, and the nearest mapped cell still repels at close range
        (`_nearest_cell_force`); the echoes' part against the way would stop the robot at
        every narrow gap, since an echo is placed on its sonar's axis, up to half a beam away
        from the obstacle that returned it. Echoes closer than the robot radius plus
        CLOSE_ECHO_MARGIN_M, and without a way (the map shows none) all echoes, repel in full,
        as in normal mode. A governed robot on a way is not repelled (module docstring)."""
        p = self.params
        heading = unit(waypoint - obs.position)
        if not on_a_way:
            components.update(self._firas(obs))
            components["attractive"] = pull * heading
            return
        components["attractive"] = pull * heading
        if not self.governor.idle:
            components["repulsive"] = np.zeros(2)
            return
        echoes = obs.echo_points()
        close = np.hypot(*(echoes - obs.position).T) < self.radius + CLOSE_ECHO_MARGIN_M
        fade = self._goal_fade(obs)
        gain, influence = p.repulse_gain, p.follow_influence_m
        farther = fade * fields.repulsive_force(obs.position, echoes[~close], gain, influence)
        near = fade * fields.repulsive_force(obs.position, echoes[close], gain, influence)
        components["repulsive"] = near + farther - min(float(dot(farther, heading)), 0.0) * heading

    def _firas(self, obs: Observation) -> dict[str, np.ndarray]:
        """Eq. 6's two terms at the robot (`FieldParams.firas_components`), the repulsion faded
        within `goal_fade_m` of the goal, so that goals near obstacles stay reachable (GNRON).
        Made only where they act: on the map's way both are replaced (`_along_the_way`)."""
        components = self.params.firas_components(obs)
        if self.params.goal_fade_m > 0:
            components["repulsive"] *= self._goal_fade(obs)
        return components

    def _goal_fade(self, obs: Observation) -> float:
        """How much of the echoes' repulsion acts: (distance to the goal / `goal_fade_m`)^2 within
        `goal_fade_m` of the goal, else (and without a fade) 1."""
        p = self.params
        return min(1.0, obs.distance_to_goal() / p.goal_fade_m) ** 2 if p.goal_fade_m > 0 else 1.0

    def _governed(self, force: np.ndarray, obs: Observation) -> Steering:
        """The command for the force (motion/governor.py) among the echoes and the mapped
        cells around it (not swept), which remember what the sensor sees between its beams or
        behind; on a way, no faster than lets the robot turn along the way's next
        `BEND_HORIZON_M`."""
        if self.governor.idle:
            return Steering(force)
        cells = self._mapped_cells_near(obs.position, self.governor.reach_m)
        way = self.escape_way if self.temp_goal is not None else self.follow_way if self.following else NO_WAY
        speed = (
            self.governor.policy.bend_speed(obs.position, obs.yaw, way, BEND_HORIZON_M)
            if len(way)
            else math.inf
        )
        points = np.vstack((obs.static_echo_points(), cells))
        return self.governor.steer(force, obs, points, speed, self._aim(obs, way))

    def _aim(self, obs: Observation, way: np.ndarray) -> np.ndarray:
        """Where the planner is going, for the governor's evasion of moving tracks: the point of
        the way AIM_AHEAD_M along it (its end when shorter; then the objective or the goal it
        leads to), the objective while escaping, else the goal."""
        end = self.temp_goal if self.temp_goal is not None else obs.goal
        if not len(way):
            return end
        travelled = np.cumsum(np.hypot(*np.diff(np.vstack((obs.position, way)), axis=0).T))
        ahead = np.flatnonzero(travelled >= AIM_AHEAD_M)
        return way[ahead[0]] if len(ahead) else end

    def _mapped_cells_near(self, position: np.ndarray, reach_m: float) -> np.ndarray:
        """Centres (N, 2) of the mapped obstacle cells (not swept) within a square of half side
        `reach_m` around a point (m)."""
        return self.map.cells(self.params.map_threshold, position, reach_m, skip_swept=True)[0]

    def _way_is_blocked(self, position: np.ndarray, way: np.ndarray) -> bool:
        """Whether a mapped obstacle cell now lies within the robot's half width of the way's next
        `BLOCK_LOOKAHEAD_M` (the sonar has seen something new on it): the robot drives along the
        way aligned with it."""
        from vplane_mj.kernels.motion import way as way_kernels  # numba: loaded by the first call

        if not len(way):
            return False
        cells = self._mapped_cells_near(position, BLOCK_LOOKAHEAD_M + self.radius)
        x, y = float(position[0]), float(position[1])
        return way_kernels.blocked(x, y, way, BLOCK_LOOKAHEAD_M, cells, self.robot.half_width_m)

    def _nearest_cell_force(self, position: np.ndarray) -> np.ndarray:
        """FIRAS repulsion (eq. 5) of the nearest mapped obstacle cell within `guard_m`: the map
        remembers corners that fall between the sonar's rays at close range."""
        p = self.params
        nearest = self.map.nearest_cell(p.map_threshold, position, p.guard_m, skip_swept=True)
        if nearest is None:
            return np.zeros(2)
        return fields.repulsive_force(position, nearest[None], p.repulse_gain, p.guard_m)

    # -- Algorithm 2 with the map ------------------------------------------------------------
    def _start_escape(self, obs: Observation, decision: Decision) -> bool:
        """Place a map-checked virtual objective and a pending plane, or switch to following."""
        self.avoid_waypoint = None
        self.temp_goal = None
        self.pending_plane = None
        self.detector.reset()
        if self.escapes_tried >= self.params.fallback_after:
            self._start_following(obs, decision, f"after {self.escapes_tried} escapes")
            return True
        trap = self._trap_obstacle(obs.position, obs.goal)
        if trap is None:
            self._start_following(obs, decision, "no mapped obstacle traps the robot")
            return True
        cells, others = trap
        i1, i2, _ = angular_extremes(obs.position, cells)
        e1, e2 = cells[i1], cells[i2]
        # The map's sure cells place the trap's ends: the plane joins them as they are.
        mouth = make_plane(
            e1, e2, cells, obs.position, obs.goal, extend=self._link_m() / 2, to_outermost=False
        )
        clearance = self.radius + self.params.escape_margin_m  # it stands and turns there
        window = self._window(obs.position, obs.goal, self.planes, margin=self.params.search_margin_m)
        plane: VirtualPlane | None = None
        if self._spans_a_gap(mouth, others):
            decision.events.append(plane_refused(e1, e2, "would span a gap between obstacles"))
        elif self._way_exists(obs.position, obs.goal, [*self.planes, mouth]):
            decision.events.append(
                plane_refused(e1, e2, "would close no trap (the map shows another way out)")
            )
        else:
            plane = mouth
        frame = plane or make_plane(e1, e2, cells, obs.position, obs.goal)
        candidate = virtual_objective(obs.position, e1, e2, obs.goal, frame, clearance)
        objective, way = self._reachable_objective(obs.position, candidate, plane, clearance, window)
        if objective is None:
            self._start_following(obs, decision, "no free, reachable cell outside the trap")
            return True
        self.temp_goal, self.escape_way, self.pending_plane = objective, way, plane
        self.escape_started_s = obs.time_s
        self.escapes_tried += 1
        decision.events.append(escape_started(e1, e2, objective))
        return True

    def _finish_escape(self, obs: Observation, decision: Decision) -> None:
        """Objective reached: re-activate the target and add the plane to L, unless the map
        then holds no way from here to the goal (the plane would cut the only known way)."""
        plane, self.temp_goal, self.pending_plane, self.escape_way = self.pending_plane, None, None, NO_WAY
        self.detector.reset()
        decision.escape_completed = True
        if plane is None:
            decision.events.append(
                Event(EventKind.ESCAPE_FINISHED, "objective reached: target re-activated (no virtual plane)")
            )
            return
        if not self._way_exists(obs.position, obs.goal, [*self.planes, plane]):
            decision.events.append(
                Event(
                    EventKind.ESCAPE_FINISHED,
                    "objective reached: target re-activated; no virtual plane, it would cut the only known "
                    "way to the goal",
                )
            )
            return
        self.planes.append(plane)
        if len(self.planes) > self.params.max_planes:
            self.planes.pop(0)
            decision.events.append(Event(EventKind.PLANE_RETIRED, "oldest virtual plane retired"))
        decision.events.append(plane_created(plane))

    def _trap_obstacle(self, position: np.ndarray, goal: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Cell centres of the one obstacle that traps the robot, and of every other obstacle
        cell near it; None when no obstacle cell is near. Only sure cells count: a doubtful
        cell may be a phantom of a wide beam, and must not place a plane.

        Obstacle cells belong to one obstacle when the gaps between them are narrower than
        the robot's width plus clearance (so a gap the robot fits through separates two).
        """
        p = self.params
        occupied = (self.map.grid >= p.map_sure) & ~self.map.swept
        if self.map.origin is None or not occupied.any():
            return None
        reach = round(self._link_m() / 2 / self.map.cell_m)
        offsets = (
            np.hypot(*np.mgrid[-reach : reach + 1, -reach : reach + 1])
            <= self._link_m() / 2 / self.map.cell_m
        )
        labels, _ = ndimage.label(
            ndimage.binary_dilation(occupied, structure=offsets), structure=np.ones((3, 3), bool)
        )
        i, j = mask_cells(occupied)
        centres = self.map.centres_of(i, j)
        rel = centres - position
        distance = np.hypot(rel[:, 0], rel[:, 1])
        near = distance <= TRAP_REACH_M
        if not near.any():
            return None
        centres, rel, distance, cell_labels = (
            centres[near],
            rel[near],
            distance[near],
            labels[i[near], j[near]],
        )
        ahead = dot(rel, unit(goal - position)) > 0.5 * distance
        pool = np.flatnonzero(ahead) if ahead.any() else np.arange(len(centres))
        trap = cell_labels == cell_labels[pool[np.argmin(distance[pool])]]
        return centres[trap], centres[~trap]

    def _spans_a_gap(self, plane: VirtualPlane, others: np.ndarray) -> bool:
        """Whether the plane's segment passes within the robot's width of another obstacle:
        it would then close a gap between two obstacles, not the mouth of one."""
        if not len(others):
            return False
        span = plane.e2 - plane.e1
        t = np.clip(dot(others - plane.e1, span) / max(float(dot(span, span)), 1e-12), 0.0, 1.0)
        gaps = np.hypot(*(others - (plane.e1 + t[:, None] * span)).T)
        return bool(np.min(gaps) < self._link_m() / 2)

    def _reachable_objective(
        self,
        robot: np.ndarray,
        candidate: np.ndarray,
        plane: VirtualPlane | None,
        clearance: float,
        window: gridsearch.Window,
    ) -> tuple[np.ndarray | None, np.ndarray]:
        """The paper's objective if the map has seen it free, clear of obstacles and reachable,
        else the nearest such cell outside the trap; with the map's way there. (None, NO_WAY) when
        there is none."""
        from vplane_mj.kernels.maps.edt import distance_transform  # numba: loaded by the first call

        start = window.free_cell_near(robot, 2 * self.radius)
        if start is None:
            return None, NO_WAY
        origin = np.array([np.ravel_multi_index(start, window.cost.shape)])
        costs = gridsearch.cost_to_go(window.cost, origin, np.zeros(1), window.cell_m)
        # Known free with room around it: far enough from mapped obstacles and from every cell
        # the sonar has not seen free (an obstacle the map has not placed may stand there). The
        # robot turns there: room for its circumscribed radius.
        room = self.radius + OBJECTIVE_ROOM_M
        roomy = gridsearch.clear_step_cost(
            OBJECTIVE_ROOM_M, self.params.inflation_m, self.params.inflation_weight
        )
        seen_around = distance_transform(window.seen) * window.cell_m >= room
        usable = np.isfinite(costs) & seen_around & (window.cost <= roomy)
        centres = window.centres()
        if plane is not None:
            usable &= dot(centres - plane.e1, plane.normal) >= clearance
        cell = window.cell_of(candidate)
        if cell is None or not usable[cell]:
            if not usable.any():
                return None, NO_WAY
            distance = np.hypot(*np.moveaxis(centres - candidate, -1, 0))
            i, j = np.unravel_index(int(np.argmin(np.where(usable, distance, np.inf))), distance.shape)
            cell = (int(i), int(j))
            candidate = window.centre(cell)
        # A usable cell is reachable from the robot's, so the map has a way there; an empty way
        # (straight to the objective) only if not, as when an escape's way is searched again.
        return candidate, _or_no_way(self._way(window, robot, candidate))

    # -- following the map's way -------------------------------------------------------------
    def _start_following(self, obs: Observation, decision: Decision, why: str) -> None:
        self.following = True
        self.next_replan_s = obs.time_s
        decision.events.append(
            Event(EventKind.FOLLOWING_STARTED, f"following the map's way to the goal ({why})")
        )

    def _follow_target(self, obs: Observation, decision: Decision) -> np.ndarray:
        """The waypoint on the map's way to the goal; replanned every `replan_period_s`.

        Planes that close the only known way are retired; with no way at all the robot is
        attracted to the goal itself, and gives up after `no_way_patience_s`.
        """
        p = self.params
        waypoint, self.follow_way = self._next_waypoint(obs.position, self.follow_way, obs.goal)
        if obs.time_s < self.next_replan_s:
            followed, position = self.follow_way, obs.position
            if not len(followed):
                return waypoint
            searched = obs.time_s - (self.next_replan_s - p.replan_period_s)  # since the last search
            left = searched >= OFF_WAY_PERIOD_S and self._off_the_way(position)
            if not (left or self._way_is_blocked(position, followed) or self._way_ends_here(obs)):
                return waypoint
            decision.events.append(
                Event(
                    EventKind.WAY_CHANGED,
                    "the way ahead is blocked on the map, left, or ends short of the goal: searched again",
                )
            )
        self.next_replan_s = obs.time_s + p.replan_period_s
        way = self._way_to_goal(obs, decision)
        if way is None:
            self.follow_way = NO_WAY
            if self.no_way_since is None:
                self.no_way_since = obs.time_s
                decision.events.append(Event(EventKind.WAY_CHANGED, "the map holds no way to the goal"))
            elif obs.time_s - self.no_way_since >= p.no_way_patience_s:
                decision.gave_up = True
                decision.events.append(
                    Event(
                        EventKind.GAVE_UP,
                        f"gave up: the map has held no way to the goal for {p.no_way_patience_s:g} s",
                    )
                )
            return obs.goal
        if self.no_way_since is not None:
            decision.events.append(Event(EventKind.WAY_CHANGED, "the map shows a way to the goal again"))
        self.no_way_since = None
        kept = self._way_cost(obs.position, self.follow_way, obs.goal) if len(self.follow_way) else np.inf
        if kept > KEEP_WAY_RATIO * self._way_cost(obs.position, way, obs.goal) or self._way_ends_here(obs):
            self.follow_way = way  # else the current way stays: no flip-flop between similar ways
        waypoint, self.follow_way = self._next_waypoint(obs.position, self.follow_way, obs.goal)
        return waypoint

    def _way_ends_here(self, obs: Observation) -> bool:
        """Whether the way followed ends within `waypoint_m` of the robot short of the goal: it
        ran to the edge of the map, which has moved with the robot since (a goal farther than
        half the map away)."""
        end = self.follow_way[-1]
        near = math.hypot(end[0] - obs.position[0], end[1] - obs.position[1]) <= self.params.waypoint_m
        return near and math.hypot(end[0] - obs.goal[0], end[1] - obs.goal[1]) > obs.goal_tolerance

    def _off_the_way(self, position: np.ndarray) -> bool:
        """Whether the robot stands farther than OFF_WAY_M from every point of the way it follows."""
        way = self.follow_way
        return bool(np.min(np.hypot(way[:, 0] - position[0], way[:, 1] - position[1])) > OFF_WAY_M)

    def _way_cost(self, position: np.ndarray, way: np.ndarray, goal: np.ndarray) -> float:
        """What a way to the goal costs from `position`: along it on the map, then from its end to
        the goal in a straight line (a way ends short of the goal where the goal lies off the map)."""
        assert self.sight is not None, "the search that found a way keeps its window as the sight"
        return self.sight.path_cost(np.vstack((position, way))) + float(np.hypot(*(goal - way[-1])))

    def _way_to_goal(self, obs: Observation, decision: Decision) -> np.ndarray | None:
        """The map's way to the goal with the planes as walls; planes that leave no way are
        retired (newest first); without planes, places held up twice are only dear instead of
        walls. None when the map holds no way even so."""
        way = self._find_way(obs.position, obs.goal, self.planes)
        while way is None and self.planes:
            self.planes.pop()
            decision.events.append(
                Event(
                    EventKind.PLANE_RETIRED, "virtual plane retired: it closed the only known way to the goal"
                )
            )
            way = self._find_way(obs.position, obs.goal, self.planes)
        if way is None or not len(way):  # none, or one that ends where the robot stands
            way = self._find_way(obs.position, obs.goal, self.planes, relaxed=True)
        return way

    def _find_way(
        self,
        robot: np.ndarray,
        goal: np.ndarray,
        planes: list[VirtualPlane],
        relaxed: bool = False,
    ) -> np.ndarray | None:
        """The map's way from the robot to the goal: searched near them first (quick), then over
        the whole map before concluding there is none."""
        for margin in (self.params.search_margin_m, None):
            way = self._way(self._window(robot, goal, planes, margin, relaxed), robot, goal)
            if way is not None:
                return way
        return None

    def _way_exists(self, robot: np.ndarray, goal: np.ndarray, planes: list[VirtualPlane]) -> bool:
        """Whether `_find_way` finds a way (searched the same way round), without the way itself:
        a flood fill decides instead of the search for the cheapest. Like `_way`, a window
        that holds a way becomes the one the robot's sight is checked on."""
        for margin in (self.params.search_margin_m, None):
            window = self._window(robot, goal, planes, margin)
            if gridsearch.way_exists(window, robot, goal, self.radius):
                self.sight = window
                return True
        return False

    # -- the map -----------------------------------------------------------------------------
    def _window(
        self,
        robot: np.ndarray,
        goal: np.ndarray,
        planes: list[VirtualPlane],
        margin: float | None = None,
        relaxed: bool = False,
    ) -> gridsearch.Window:
        """Step costs for the robot's centre over the map cells within `margin` (m) of the box
        around the robot and the goal (the whole map for None), planes as walls.

        A place where the way was held up twice is a wall; `relaxed` (when the map holds no
        other way) makes it only dear again."""
        p, grid, cell = self.params, self.map.grid, self.map.cell_m
        low, high = np.zeros(2, dtype=int), np.full(2, self.map.n)
        if margin is not None:
            low = np.floor((np.minimum(robot, goal) - margin) / cell).astype(int) - self.map.origin
            high = np.ceil((np.maximum(robot, goal) + margin) / cell).astype(int) - self.map.origin
            low, high = np.clip(low, 0, self.map.n), np.clip(high, 0, self.map.n)
        inside = (slice(low[0], high[0]), slice(low[1], high[1]))
        certainty = np.where(self.map.swept[inside], 0, grid[inside])
        cost = gridsearch.step_costs(
            certainty >= p.map_sure,
            (certainty >= p.map_threshold) & (certainty < p.map_sure),
            cell,
            self._lethal_m(),
            p.inflation_m,
            p.inflation_weight,
            p.doubt_cost,
        )
        seen = self.map.seen[inside].copy()
        window = gridsearch.Window(cost, (self.map.origin + low) * cell, cell, seen)
        for k, stall in enumerate(self.stalls):
            again = any(np.hypot(*(stall - earlier)) < STALL_RADIUS_M for earlier in self.stalls[:k])
            window.charge_disc(stall, STALL_RADIUS_M, np.inf if again and not relaxed else p.doubt_cost)
        window.clear_disc(robot, self.radius)  # the robot stands there: its disc is free
        for plane in planes:  # but no way crosses a virtual plane, even under the robot
            window.block_segment(plane.e1, plane.e2)
        return window

    def _lethal_m(self) -> float:
        """How close (m) the map's ways come to an obstacle cell's centre: ways are driven along,
        aligned, so the robot's half width plus `path_clearance_m`; for a robot that is not round,
        plus the governor's turn margin, which it keeps when it turns toward the way."""
        lethal = self.robot.half_width_m + self.params.path_clearance_m
        return lethal if self.robot.disc else lethal + self.params.turn_margin_m

    def _way(self, window: gridsearch.Window, start: np.ndarray, end: np.ndarray) -> np.ndarray | None:
        """Waypoints (K, 2; m) of the map's shortest way from `start` to `end` (beyond the window:
        toward it in a straight line from the window's edge); None when there is none."""
        cells = gridsearch.way_to(window, start, end, self.radius)
        if cells is None:
            return None
        way = window.centres_of(cells[1:])
        if window.cell_of(end) is not None:
            way = np.vstack((way, np.asarray(end, float)))
        self.sight = window
        return way

    def _next_waypoint(
        self, position: np.ndarray, way: np.ndarray, end: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The farthest point of the way (K, 2; m) within `waypoint_m` that the robot sees in a
        straight line on the map (the way's end when the way is empty), and the way without the
        points before the one nearest the robot: the robot has passed them."""
        from vplane_mj.kernels.motion import way as way_kernels  # numba: loaded by the first call

        if not len(way):
            return end, way
        sight = NO_SIGHT if self.sight is None else self.sight.packed()
        x, y = float(position[0]), float(position[1])
        nearest, chosen = way_kernels.next_waypoint(x, y, way, self.params.waypoint_m, sight)
        return way[chosen], way[nearest:]  # the robot has passed the points before the nearest


def _or_no_way(way: np.ndarray | None) -> np.ndarray:
    """The way, or NO_WAY for none (an empty way)."""
    return NO_WAY if way is None else way
