"""The governor a run offers every planner that does not drive its body itself (a planner of
your own): its forces are driven as `apf`'s are.

The planner's force goes to a `Governor` (motion/governor.py) for the robot's body, which
answers the body speed and turn rate that keep the footprint's predicted motion clear of the
echoes of this tick and the last ones it remembers, and that evades the tracker's moving
obstacles. Its margins are the planner's own where its `Params` inherit `MotionParams`
(`--set planner.turn_margin_m=...`), else `MotionParams`' defaults. A decision that commands
a speed and turn rate itself, or whose force is not finite (the run ends as `error`), is left
as it is; a round robot that brakes short (the default robot) is not governed (the governor is
idle, as for the built-in planners).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vplane_mj.planning.motion.governor import Governor
from vplane_mj.planning.planners.groups import MotionParams
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.types import Decision, Observation


@dataclass(eq=False)
class RunGovernor:
    """Drives a planner's forces on its robot's body (module docstring).

    Attributes:
        governor: The governor, made for the planner's body with its margins.
    """

    governor: Governor

    @classmethod
    def offered(cls, planner: Planner, wanted: bool = True) -> RunGovernor | None:
        """The governor the run drives `planner`'s forces through.

        Args:
            planner: The run's planner.
            wanted: The scenario's `planner.governor`.

        Returns:
            A governor, or None for a planner that drives its body itself (`governs_itself`)
            or with `wanted` False.
        """
        if planner.governs_itself or not wanted:
            return None
        params = planner.params if isinstance(planner.params, MotionParams) else MotionParams()
        return cls(params.governor(planner.robot))

    def drive(self, decision: Decision, obs: Observation) -> None:
        """Give `decision` the command the governor answers to its force (and the force to
        show: the direction the robot steers), unless it commands one itself or its force is
        not finite.

        Args:
            decision: The planner's decision of this tick (changed in place).
            obs: What the planner saw this tick.
        """
        fx, fy = float(decision.force[0]), float(decision.force[1])
        if decision.command is not None or not (math.isfinite(fx) and math.isfinite(fy)):
            return
        steering = self.governor.steer(decision.force, obs, obs.static_echo_points())
        decision.force, decision.command = steering.force, steering.command
