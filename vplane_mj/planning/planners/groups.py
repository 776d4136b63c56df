"""Parameter groups that several planners share, each with the set-up of what it configures.

A planner's parameters combine them by inheritance (bases listed last group first, see
`PlannerParams`): `FieldParams` (Khatib's fields, eqs. 2-6), `DetectorParams` (the
local-minimum detector), `MinimumParams` (the detector and the patience of a planner without
an escape), `LocalMapParams` (the sonar certainty grid), `SonarMapParams` (the grid and its
polar histogram), `EvasionParams` (the check of motions against moving tracks) and
`MotionParams` (the margins of the governor that drives a force on the robot's body, and its
evasion).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.motion import fields
from vplane_mj.planning.motion.evasion import Evasion
from vplane_mj.planning.motion.governor import Governor
from vplane_mj.planning.perception import scan
from vplane_mj.planning.perception.localmap import LocalMap
from vplane_mj.planning.perception.minima import LocalMinimumDetector
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.params import PlannerParams, param
from vplane_mj.planning.protocol.types import Observation


@dataclass(frozen=True)
class FieldParams(PlannerParams):
    """Khatib's FIRAS attraction and repulsion (the paper's eqs. 2-6).

    Attributes:
        attract_gain: The attraction gain, omega of eqs. 2-3 (1/m).
        attract_radius: Where the attraction turns from quadratic to conic, r of eqs. 2-3 (m).
        repulse_gain: The repulsion gain per sonar echo, eta of eqs. 4-5 (m).
        influence: An echo's distance of influence, f0 of eqs. 4-5 (m).
    """

    attract_gain: float = param(0.5, "1/m", "omega of eqs. 2-3, attraction gain", gt=0)
    attract_radius: float = param(1.0, "m", "r of eqs. 2-3, quadratic-to-conic switch distance", gt=0)
    repulse_gain: float = param(0.02, "m", "eta of eqs. 4-5, repulsion gain per sonar echo", ge=0)
    influence: float = param(0.8, "m", "f0 of eqs. 4-5, distance of influence of an echo", gt=0)

    def firas_components(self, obs: Observation) -> dict[str, np.ndarray]:
        """Eq. 6's two terms at the robot: attraction to the goal and repulsion from the echoes
        (of a dense scan, the nearest in each sonar ring sector: scan.py)."""
        return {
            "attractive": fields.attractive_force(
                obs.position, obs.goal, self.attract_gain, self.attract_radius
            ),
            "repulsive": fields.repulsive_force(
                obs.position, scan.repulsion_points(obs), self.repulse_gain, self.influence
            ),
        }


@dataclass(frozen=True)
class EvasionParams(PlannerParams):
    """How commands are checked against the moving tracks in time (evasion.py).

    Attributes:
        evade_horizon_s: How long a command's motion is checked against the moving tracks (s).
        evade_margin_m: How far the footprint keeps from a moving track's predicted disc (m).
        evade_growth_mps: How much a moving track's predicted disc grows per second ahead (m/s).
    """

    evade_horizon_s: float = param(
        3.0, "s", "how long a command's motion is checked against the moving tracks", gt=0, le=10.0
    )
    evade_margin_m: float = param(
        0.15, "m", "the footprint keeps this far from a moving track's predicted disc", ge=0, le=2.0
    )
    evade_growth_mps: float = param(
        0.15, "m/s", "a moving track's predicted disc grows this much per second ahead", ge=0, le=2.0
    )

    def evasion(self, body: RobotBody) -> Evasion:
        """The check of `body`'s motions against moving tracks with these parameters."""
        return Evasion(body, self.evade_horizon_s, self.evade_margin_m, self.evade_growth_mps)


@dataclass(frozen=True)
class MotionParams(EvasionParams):
    """The margins of the governor that drives a force on the robot's body (motion/governor.py),
    and its check against moving tracks.

    Attributes:
        evade_horizon_s: How long a command's motion is checked against the moving tracks (s).
        evade_margin_m: How far the footprint keeps from a moving track's predicted disc (m).
        evade_growth_mps: How much a moving track's predicted disc grows per second ahead (m/s).
        stop_margin_m: The room a turning robot's disc needs to creep ahead, and in which
            backing off brakes (m).
        turn_margin_m: How far turns and predicted motions keep the footprint from obstacles (m).
    """

    stop_margin_m: float = param(
        0.1,
        "m",
        "a robot turning creeps ahead while its disc has this much room; backing off brakes in it",
        ge=0,
        le=1.0,
    )
    turn_margin_m: float = param(
        0.03, "m", "turns and predicted motions keep the footprint this far from obstacles", ge=0, le=1.0
    )

    def governor(self, body: RobotBody) -> Governor:
        """A governor of forces for `body` with these margins (one per planner: it follows
        the planner's commands), that evades moving tracks (evasion.py)."""
        return Governor(body, self.stop_margin_m, self.turn_margin_m, self.evasion(body))


@dataclass(frozen=True)
class DetectorParams(PlannerParams):
    """The local-minimum detector's parameters (planners with an escape use only these).

    Attributes:
        stuck_window_s: The window of the local-minimum criteria, t (s).
        stuck_displacement_m: The least travel over the window, d_th (m).
        stuck_speed_mps: The speed below which the robot counts as halted, v_th (m/s).
        startup_s: No detection during this time after the start (s).
    """

    stuck_window_s: float = param(4.0, "s", "t: window of the local-minimum criteria", gt=0)
    stuck_displacement_m: float = param(0.2, "m", "d_th: least travel over the window", gt=0)
    stuck_speed_mps: float = param(0.02, "m/s", "v_th: speed below which the robot counts as halted", ge=0)
    startup_s: float = param(2.0, "s", "no detection during this time after the start", ge=0)

    def detector(self) -> LocalMinimumDetector:
        """A fresh local-minimum detector with these parameters."""
        return LocalMinimumDetector(
            window_s=self.stuck_window_s,
            displacement_m=self.stuck_displacement_m,
            speed_mps=self.stuck_speed_mps,
            startup_s=self.startup_s,
        )


@dataclass(frozen=True)
class MinimumParams(DetectorParams):
    """The detector's parameters plus the patience of a planner without an escape.

    Attributes:
        stuck_window_s: The window of the local-minimum criteria, t (s).
        stuck_displacement_m: The least travel over the window, d_th (m).
        stuck_speed_mps: The speed below which the robot counts as halted, v_th (m/s).
        startup_s: No detection during this time after the start (s).
        patience_s: Time spent trapped before giving up, outcome `stuck` (s).
    """

    patience_s: float = param(15.0, "s", "time spent trapped before giving up (outcome stuck)", gt=0)


@dataclass(frozen=True)
class LocalMapParams(PlannerParams):
    """The sonar certainty grid (localmap.py), shared by the planners that keep one.

    Attributes:
        map_cell_m: Cell size of the local sonar map (m).
        map_size_m: Side of the square local map that follows the robot (m).
        map_threshold: Certainty at which a map cell counts as an obstacle.
    """

    map_cell_m: float = param(0.1, "m", "cell size of the local sonar map", ge=0.05, le=1.0)
    map_size_m: float = param(8.0, "m", "side of the square local map that follows the robot", gt=0, le=20.0)
    map_threshold: int = param(
        4, "", "certainty at which a map cell counts as an obstacle", ge=1, integer=True
    )

    def local_map(self, least_size_m: float = 0.0) -> LocalMap:
        """A fresh, empty sonar map of this cell size and side, or of `least_size_m` (m) when
        that is larger (a planner that looks farther than the side allows)."""
        return LocalMap(self.map_cell_m, max(self.map_size_m, least_size_m))


@dataclass(frozen=True)
class SonarMapParams(LocalMapParams):
    """The sonar certainty grid and its polar histogram, shared by the planners that use them.

    The bounds keep the grid (at most 400 x 400 cells) and the histogram (at most 720 sectors)
    small enough to update at the control rate.

    Attributes:
        map_cell_m: Cell size of the local sonar map (m).
        map_size_m: Side of the square local map that follows the robot (m).
        map_threshold: Certainty at which a map cell counts as an obstacle.
        sector_deg: Width of a polar histogram sector (deg).
        window_m: Radius of the histogram's active window (m).
        histogram_threshold: Sector density above which a sector is blocked.
    """

    sector_deg: float = param(5.0, "deg", "polar histogram sector width", ge=0.5, le=45)
    window_m: float = param(2.0, "m", "radius of the histogram's active window", gt=0)
    histogram_threshold: float = param(1.0, "", "sector density above which a sector is blocked", gt=0)

    def sector_count(self) -> int:
        """Sectors of the polar histogram (at least 8)."""
        return max(8, round(360.0 / self.sector_deg))
