"""APF with virtual obstacles at local minima (`vobs`), after Park et al. (the paper's ref. 9).

On each local-minimum detection a virtual obstacle (a FIRAS repulsive point, eqs. 4-5) is
placed at the robot's position and pushes it out of the minimum. A virtual obstacle is
cleared after `vobs_lifetime_s`; the robot may then fall back into the same minimum, the
weakness the virtual-plane method addresses. After `max_virtual` obstacles the planner
gives up (outcome `stuck`). The governor (motion/governor.py) drives the force on the robot's body.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.motion import fields
from vplane_mj.planning.planners.groups import DetectorParams, FieldParams, MotionParams
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.events import Event, EventKind, point
from vplane_mj.planning.protocol.params import param
from vplane_mj.planning.protocol.types import Decision, Observation


@dataclass(frozen=True)
class VobsParams(MotionParams, DetectorParams, FieldParams):
    """The fields', the detector's and the governor's parameters, and the virtual obstacles'."""

    vobs_gain: float = param(0.3, "m", "eta of eq. 5 for a virtual obstacle", gt=0)
    vobs_influence_m: float = param(1.5, "m", "f0 of eq. 5 for a virtual obstacle", gt=0)
    vobs_lifetime_s: float = param(30.0, "s", "a virtual obstacle is cleared after this time", gt=0)
    max_virtual: int = param(6, "", "virtual obstacles placed before giving up", ge=1, integer=True)


class VobsPlanner(Planner):
    """F = F_A + F_R + the repulsion of the virtual obstacles that are still in force."""

    name = "vobs"
    summary = "APF with a virtual obstacle placed at each local minimum"
    governs_itself = True
    citation = (
        "M. G. Park, J. H. Jeon, M. C. Lee, Obstacle avoidance for mobile robots using "
        "artificial potential field approach with simulated annealing, ISIE 2001 (the paper's ref. 9)"
    )
    Params = VobsParams
    params: VobsParams

    def __init__(self, params: VobsParams, robot: RobotBody | float):
        super().__init__(params, robot)
        self.detector = params.detector()
        self.governor = params.governor(self.robot)
        self.virtual: list[tuple[float, np.ndarray]] = []  # (time placed, position)
        self.placed = 0

    def step(self, obs: Observation) -> Decision:
        p = self.params
        components = p.firas_components(obs)
        decision = Decision(force=np.zeros(2), mode="normal", components=components)
        near_goal = obs.distance_to_goal() <= obs.goal_tolerance
        if self.detector.update(obs.time_s, obs.position, near_goal).new:
            decision.local_minimum = True
            if self.placed >= p.max_virtual:
                decision.gave_up = True
                decision.events.append(Event(EventKind.LOCAL_MINIMUM, "local minimum detected"))
                decision.events.append(
                    Event(EventKind.GAVE_UP, f"gave up after {self.placed} virtual obstacles")
                )
            else:
                self.placed += 1
                self.virtual.append((obs.time_s, obs.position.copy()))
                self.detector.reset()
                x, y = obs.position
                decision.events.append(
                    Event(
                        EventKind.LOCAL_MINIMUM,
                        f"local minimum detected: virtual obstacle at ({x:.2f}, {y:.2f})",
                        {"point": point(obs.position)},
                    )
                )
        expired = [v for v in self.virtual if obs.time_s - v[0] > p.vobs_lifetime_s]
        if expired:
            decision.events.append(
                Event(EventKind.VIRTUAL_OBSTACLES_CLEARED, f"{len(expired)} virtual obstacle(s) cleared")
            )
            self.virtual = [v for v in self.virtual if v not in expired]
        points = np.array([position for _, position in self.virtual]).reshape(-1, 2)
        components["virtual"] = fields.repulsive_force(obs.position, points, p.vobs_gain, p.vobs_influence_m)
        steering = self.governor.steer(sum(components.values(), np.zeros(2)), obs, obs.static_echo_points())
        decision.force, decision.command = steering.force, steering.command
        decision.mode = "escaping" if len(self.virtual) else "normal"
        decision.planes = []
        return decision
