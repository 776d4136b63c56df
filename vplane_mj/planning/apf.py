"""The plain Khatib APF planner (`apf`): FIRAS attraction plus repulsion from every sonar echo.

This is the baseline the paper improves on: it has no escape, so once the
local-minimum detector has held it trapped for `patience_s` it gives up (outcome
`stuck`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from vplane_mj.planning import fields
from vplane_mj.planning.events import Event, EventKind
from vplane_mj.planning.minima import LocalMinimumDetector
from vplane_mj.planning.params import Param, PlannerInfo
from vplane_mj.planning.types import Decision, Observation

FIELD_PARAMS: dict[str, Param] = {
    "attract_gain": Param(0.5, "1/m", "omega of eqs. 2-3, attraction gain", gt=0),
    "attract_radius": Param(1.0, "m", "r of eqs. 2-3, quadratic-to-conic switch distance", gt=0),
    "repulse_gain": Param(0.02, "m", "eta of eqs. 4-5, repulsion gain per sonar echo", ge=0),
    "influence": Param(0.8, "m", "f0 of eqs. 4-5, distance of influence of an echo", gt=0),
}

DETECTOR_PARAMS: dict[str, Param] = {
    "stuck_window_s": Param(4.0, "s", "t: window of the local-minimum criteria", gt=0),
    "stuck_displacement_m": Param(0.2, "m", "d_th: least travel over the window", gt=0),
    "stuck_speed_mps": Param(0.02, "m/s", "v_th: speed below which the robot counts as halted", ge=0),
    "startup_s": Param(2.0, "s", "no detection during this time after the start", ge=0),
}
"""The local-minimum detector's parameters (planners with an escape use only these)."""

MINIMUM_PARAMS: dict[str, Param] = {
    **DETECTOR_PARAMS,
    "patience_s": Param(15.0, "s", "time spent trapped before giving up (outcome stuck)", gt=0),
}
"""The detector's parameters plus the patience of a planner without an escape."""

INFO = PlannerInfo(
    name="apf",
    summary="Khatib's artificial potential field from the sonar ring, no escape",
    citation="O. Khatib, Real-time obstacle avoidance for manipulators and mobile robots, IJRR 5(1), 1986",
    params={**FIELD_PARAMS, **MINIMUM_PARAMS},
)


def detector_from(params: Mapping[str, float]) -> LocalMinimumDetector:
    """The local-minimum detector configured by a planner's parameters."""
    return LocalMinimumDetector(
        window_s=params["stuck_window_s"],
        displacement_m=params["stuck_displacement_m"],
        speed_mps=params["stuck_speed_mps"],
        startup_s=params["startup_s"],
    )


def firas_components(obs: Observation, params: Mapping[str, float]) -> dict[str, np.ndarray]:
    """Eq. 6's two terms at the robot: attraction to the goal and repulsion from the echoes."""
    return {
        "attractive": fields.attractive_force(
            obs.position, obs.goal, params["attract_gain"], params["attract_radius"]
        ),
        "repulsive": fields.repulsive_force(
            obs.position, obs.echo_points(), params["repulse_gain"], params["influence"]
        ),
    }


class ApfPlanner:
    """Follows F_T = F_A + F_R (eq. 6); reports local minima and gives up after `patience_s`."""

    def __init__(self, params: Mapping[str, float]):
        self.params = dict(params)
        self.detector = detector_from(self.params)

    def step(self, obs: Observation) -> Decision:
        components = firas_components(obs, self.params)
        total = components["attractive"] + components["repulsive"]
        decision = Decision(force=total, mode="normal", components=components)
        report_trap(self.detector, obs, decision, self.params["patience_s"])
        return decision


def report_trap(
    detector: LocalMinimumDetector, obs: Observation, decision: Decision, patience_s: float
) -> None:
    """Feed the detector; mark a new local minimum, the trapped mode, and giving up after
    `patience_s` trapped (for planners that have no escape)."""
    near_goal = obs.distance_to_goal() <= obs.goal_tolerance
    state = detector.update(obs.time_s, obs.position, near_goal)
    if state.new:
        decision.local_minimum = True
        decision.events.append(Event(EventKind.LOCAL_MINIMUM, "local minimum detected"))
    if state.trapped:
        decision.mode = "trapped"
        if state.trapped_for_s >= patience_s:
            decision.gave_up = True
            decision.events.append(
                Event(EventKind.GAVE_UP, f"gave up: trapped for {state.trapped_for_s:.1f} s")
            )
