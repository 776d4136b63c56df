"""The plain Khatib APF planner (`apf`): FIRAS attraction plus repulsion from every sonar echo.

This is the baseline the paper improves on: it has no escape, so once the
local-minimum detector has held it trapped for `patience_s` it gives up (outcome
`stuck`). The governor (motion/governor.py) drives the force on the robot's body.
"""

from __future__ import annotations

from dataclasses import dataclass

from vplane_mj.planning.perception.minima import report_trap
from vplane_mj.planning.planners.groups import FieldParams, MinimumParams, MotionParams
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.types import Decision, Observation


@dataclass(frozen=True)
class ApfParams(MotionParams, MinimumParams, FieldParams):
    """The fields' parameters, then the detector's and the patience, then the governor's."""


class ApfPlanner(Planner):
    """Follows F_T = F_A + F_R (eq. 6); reports local minima and gives up after `patience_s`."""

    name = "apf"
    summary = "Khatib's artificial potential field from the sonar ring, no escape"
    governs_itself = True
    citation = "O. Khatib, Real-time obstacle avoidance for manipulators and mobile robots, IJRR 5(1), 1986"
    Params = ApfParams
    params: ApfParams

    def __init__(self, params: ApfParams, robot: RobotBody | float):
        super().__init__(params, robot)
        self.detector = params.detector()
        self.governor = params.governor(self.robot)

    def step(self, obs: Observation) -> Decision:
        components = self.params.firas_components(obs)
        total = components["attractive"] + components["repulsive"]
        steering = self.governor.steer(total, obs, obs.static_echo_points())
        decision = Decision(
            force=steering.force, mode="normal", components=components, command=steering.command
        )
        report_trap(self.detector, obs, decision, self.params.patience_s)
        return decision
