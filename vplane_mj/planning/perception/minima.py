"""Local-minimum detection: the paper's two criteria, made robust for a wheeled robot.

The paper declares a local minimum when the speed v_r <= v_th, or when the distance
d_t travelled in a time t is <= d_th. A differential-drive robot has near-zero speed
while it turns in place, so both criteria are judged over a whole window of
`window_s` seconds: the largest speed in the window, and the net displacement
across it. Detection is off for `startup_s` after the start and inside the goal
tolerance. Once trapped, the robot counts as trapped until it has moved more than
twice `displacement_m` from where the trap was detected (hysteresis), so one trap
is one detection.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from vplane_mj.planning.protocol.events import Event, EventKind
from vplane_mj.planning.protocol.types import Decision, Observation


@dataclass(frozen=True)
class MinimumState:
    """`trapped`: in a local minimum now; `new`: detected this tick; `trapped_for_s`: since when."""

    trapped: bool
    new: bool
    trapped_for_s: float


_FREE = MinimumState(False, False, 0.0)


class LocalMinimumDetector:
    """Feeds on (time, position) samples at the control rate; see the module docstring.

    Args:
        window_s: t, the window of the criteria (s).
        displacement_m: d_th, the least travel over the window (m).
        speed_mps: v_th, the speed below which the robot counts as halted (m/s).
        startup_s: No detection during this time after the start (s).
    """

    def __init__(self, window_s: float, displacement_m: float, speed_mps: float, startup_s: float):
        self.window_s = window_s
        self.displacement_m = displacement_m
        self.speed_mps = speed_mps
        self.startup_s = startup_s
        self._samples: deque[tuple[float, float, float, float]] = deque()  # t, x, y, speed
        self._fast = 0  # samples in the window faster than speed_mps
        self._trap_position: np.ndarray | None = None
        self._trap_time = 0.0

    def reset(self) -> None:
        """Forget the history (after an escape manoeuvre starts, for instance)."""
        self._samples.clear()
        self._fast = 0
        self._trap_position = None

    def update(self, time_s: float, position: np.ndarray, near_goal: bool) -> MinimumState:
        x, y = float(position[0]), float(position[1])
        speed = math.inf  # unknown for the first sample
        if self._samples:
            t0, x0, y0, _ = self._samples[-1]
            if time_s > t0:
                speed = math.hypot(x - x0, y - y0) / (time_s - t0)
        self._samples.append((time_s, x, y, speed))
        self._fast += not speed <= self.speed_mps
        while self._samples[0][0] < time_s - self.window_s - 1e-9:
            self._fast -= not self._samples.popleft()[3] <= self.speed_mps

        if self._trap_position is not None:
            trap_x, trap_y = self._trap_position
            if near_goal or np.hypot(x - trap_x, y - trap_y) > 2 * self.displacement_m:
                self._trap_position = None
            else:
                return MinimumState(True, False, time_s - self._trap_time)

        if near_goal or time_s < self.startup_s or not self._window_full(time_s):
            return _FREE
        if self._slow_throughout() or self._displacement() <= self.displacement_m:
            self._trap_position = np.array([x, y])
            self._trap_time = time_s
            return MinimumState(True, True, 0.0)
        return _FREE

    def _window_full(self, time_s: float) -> bool:
        return time_s - self._samples[0][0] >= self.window_s - 1e-9

    def _displacement(self) -> float:
        """d_t: net distance (m) between the oldest and newest sample of the window."""
        _, x0, y0, _ = self._samples[0]
        _, x1, y1, _ = self._samples[-1]
        return math.hypot(x1 - x0, y1 - y0)

    def _slow_throughout(self) -> bool:
        """v_r <= v_th at every step of the window (speeds from successive samples, m/s).

        A window of one sample (window_s of about zero) has no step: it is not slow.
        """
        if len(self._samples) < 2:
            return False
        # The oldest sample's speed belongs to the step before the window.
        return self._fast == (not self._samples[0][3] <= self.speed_mps)


def report_trap(
    detector: LocalMinimumDetector, obs: Observation, decision: Decision, patience_s: float
) -> None:
    """Feed the detector and mark the decision: a new local minimum (with its event), the
    trapped mode, and giving up once trapped for `patience_s` (for planners without an escape).

    Args:
        detector: The planner's local-minimum detector.
        obs: This tick's observation (its time, pose and goal).
        decision: This tick's decision, changed in place.
        patience_s: How long (s) a trapped planner waits before it gives up.
    """
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
