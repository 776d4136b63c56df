"""Moving obstacles met in time: which command keeps a robot clear of the tracked obstacles.

The governor (motion.py) checks a command's motion against obstacle points that stand still;
a moving obstacle needs a check in time instead: where will it be when the robot gets there?
`Evasion` takes the tracks of the planner's tracker (`perception.tracker`) that move, and
checks commands held for `horizon_s` against their constant-velocity predictions
(`kernels.motion.evasion.candidate_risks`): the robot's footprint against each track's disc at every
time step, the disc grown by the track's position doubt and by `growth_mps` per second of
prediction (obstacles turn; their paths are not straight). This is the time-indexed collision
check of the velocity-obstacle family (Fiorini and Shiller 1998, "Motion Planning in Dynamic
Environments Using Velocity Obstacles"; sampled as the dynamic window samples commands, Fox,
Burgard and Thrun 1997, with the obstacles' motion, as Seder and Petrovic 2007).

A candidate is a motion: a command (speed and turn rate) held for a while, a dodge, after which
the robot makes for where its planner is going (the aim: the goal, or a point of its way) as
the heading controller drives it. The command asked for stays when its motion meets no moving
track within the horizon. Otherwise the candidates (speeds forward, standing and backing, turn
rates either way, held half a second or longer) are ranked by how much nearer they take the
robot to the aim before they meet a track, by how soon they would meet one and how deep into
it within the first second, and a little by the room they keep and by keeping the last
evasion's command. Standing still is no refuge from an obstacle that comes on. Only a robot
that some moving track can reach within the horizon is checked: in a world that stands still
nothing changes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vplane_mj.planning.perception.tracker import Track, moving_tracks
from vplane_mj.planning.protocol.body import RobotBody

STEP_S = 0.1
"""Time step (s) of the check along a candidate's motion."""
SPEED_SHARES = (-0.3, 0.0, 0.35, 0.7, 1.0)
"""The candidates' speeds, as shares of the top speed (negative: backing)."""
TURN_SHARES = (-1.0, -0.6, -0.3, -0.1, 0.0, 0.1, 0.3, 0.6, 1.0)
"""The candidates' turn rates, as shares of the top turn rate."""
HOLDS_S = (0.5, 1.5)
"""How long (s) a candidate holds its command before it makes for the aim."""
HIT_WEIGHT = 3.0
"""What meeting a track at once costs, against a whole horizon's progress at the top speed (1):
HIT_WEIGHT (1 - t / horizon)^2 for a meeting at t, so a meeting far ahead, which later ticks can
still avoid, costs little."""
DOUBT_CAP_M, DOUBT_CAP_MPS = 0.1, 0.2
"""A track's doubt grows its disc by at most this (m), and its growth by at most this (m/s): a
track that coasts unseen behind the robot grows doubtful, and a disc grown by all of its doubt
would cover the robot and leave no motion clear of anything."""
HIT_EXPONENT = 2.0
"""The power of (1 - t / horizon) in what meeting a track at t costs (HIT_WEIGHT)."""
ROOM_WEIGHT = 0.2
"""What room up to ROOM_CAP_M over the horizon earns, against a whole horizon's progress."""
NEAR_S = 1.0
"""The first seconds (s) of a motion, whose room is what a robot already in danger saves."""
DEPTH_WEIGHT = 4.0
"""What each metre of a predicted overlap within NEAR_S costs."""
ROOM_CAP_M = 1.0
"""Room beyond this (m) earns nothing more."""
KEEP_BONUS = 0.1
"""What keeping the last evasion's command earns: no dithering between equals."""


@dataclass(frozen=True)
class Threat:
    """The moving tracks that can reach the robot within the horizon, packed for the kernel:
    (N, 6) x, y (m), vx, vy (m/s), radius (m) and its growth (m/s)."""

    tracks: np.ndarray

    def __bool__(self) -> bool:
        return len(self.tracks) > 0


@dataclass
class Evasion:
    """The check of motions against moving tracks for one robot body (module docstring)."""

    body: RobotBody
    horizon_s: float
    margin_m: float
    growth_mps: float
    kept: tuple[float, float] | None = None
    """The command (m/s, rad/s) of the last evasion, None when the last tick needed none."""
    _grid: np.ndarray = field(init=False, repr=False)
    """`candidates` but for its first row (the command asked for): the robot's limits' alone."""

    def __post_init__(self) -> None:
        limits = self.body.limits
        top, turn = limits.max_speed_mps, limits.max_turn_rate_radps
        rows = [(v * top, w * turn, hold) for v in SPEED_SHARES for w in TURN_SHARES for hold in HOLDS_S]
        self._grid = np.array([(0.0, 0.0, HOLDS_S[0]), *rows], dtype=float)

    def threat(self, position: np.ndarray, tracks: tuple[Track, ...], time_s: float) -> Threat:
        """The moving tracks that could come within the margin of the robot at `position` (m)
        within the horizon from `time_s` (s), whatever it does (each closing at its speed plus
        the robot's top); each where it is predicted at `time_s`, its disc and its growth wider
        by its doubt (up to DOUBT_CAP_M and DOUBT_CAP_MPS)."""
        moving = moving_tracks(tracks, time_s)
        if not len(moving):
            return Threat(np.empty((0, 6)))
        from vplane_mj.kernels.motion import evasion  # numba: loaded by the first call

        limits = (
            self.body.limits.max_speed_mps,
            self.horizon_s,
            self.body.radius_m,
            self.margin_m,
            self.growth_mps,
        )
        at = (float(position[0]), float(position[1]))
        return Threat(evasion.threat_rows(moving, at, limits, (DOUBT_CAP_M, DOUBT_CAP_MPS)))

    def candidates(self, wanted: tuple[float, float]) -> np.ndarray:
        """The motions to rank (C, 3: speed m/s, turn rate rad/s, held s; then on for the aim):
        the command asked for (`wanted`, held HOLDS_S[0]) first, then SPEED_SHARES x TURN_SHARES
        of the robot's limits, each held HOLDS_S."""
        rows = self._grid.copy()
        rows[0, :2] = wanted
        return rows

    def risks(
        self, candidates: np.ndarray, pose: tuple[float, float, float], state: tuple[float, float],
        threat: Threat, aim: np.ndarray,
    ) -> np.ndarray:  # fmt: skip
        """(C, 6) per candidate: the first time (s) a track comes within the margin (inf: none),
        the least room (m) over the horizon, the progress (m) toward the point `aim` (m, world)
        until then, the first command (m/s, rad/s), and the least room within NEAR_S
        (`kernels.evasion.candidate_risks`)."""
        from vplane_mj.kernels.motion import evasion  # numba: loaded by the first call

        limits = self.body.limits
        return evasion.candidate_risks(
            np.ascontiguousarray(candidates, float),
            pose,
            state,
            (
                limits.max_speed_mps,
                limits.max_turn_rate_radps,
                limits.max_accel_mps2,
                limits.braking_in_turn_mps2,
                limits.max_turn_accel_radps2,
                self.body.gains.turn_gain,
            ),
            (self.horizon_s, STEP_S),
            np.ascontiguousarray(self.body.footprint, float),
            float(self.body.radius_m),
            threat.tracks,
            float(self.margin_m),
            (float(aim[0]), float(aim[1])),
            NEAR_S,
            ROOM_CAP_M,
        )

    def ranking(self, candidates: np.ndarray, risks: np.ndarray) -> np.ndarray:
        """The candidates' indices, best first, by their score: the progress toward the aim over
        the horizon as a share of the top speed's, plus ROOM_WEIGHT of the room kept (up to
        ROOM_CAP_M), plus KEEP_BONUS for the last evasion's command, less HIT_WEIGHT
        (1 - t / horizon)^HIT_EXPONENT for meeting a track at t and DEPTH_WEIGHT times the
        overlap predicted within NEAR_S."""
        from vplane_mj.kernels.motion import evasion  # numba: loaded by the first call

        kept = (0.0, 0.0, False) if self.kept is None else (*self.kept, True)
        return evasion.ranking(
            candidates,
            risks,
            (self.body.limits.max_speed_mps * self.horizon_s, self.horizon_s, ROOM_CAP_M),
            (ROOM_WEIGHT, HIT_WEIGHT, HIT_EXPONENT, DEPTH_WEIGHT, KEEP_BONUS),
            kept,
        )
