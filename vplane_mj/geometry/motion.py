"""Obstacles that move: keyframed paths in the arena's plane, as Gazebo-classic animates models.

A `Motion` is keyframes (t, x, y) in seconds and metres, arena frame, with t starting at 0 and
strictly increasing. Its position at motion time t (`position`):

- `"spline"` (the default) is Gazebo-classic's `PoseAnimation`: on the segment between the
  keyframes i and i + 1 around t, the cubic Hermite curve
  h00(f) p_i + h01(f) p_{i+1} + h10(f) m_i + h11(f) m_{i+1} at the time fraction
  f = (t - t_i) / (t_{i+1} - t_i), with Catmull-Rom tangents of tension 0 taken over the
  keyframes' order, not their times (ignition::math::Spline): m_i = (p_{i+1} - p_{i-1}) / 2
  inside, m_0 = (p_1 - p_0) / 2 and m_last = (p_last - p_{last-1}) / 2 at the ends of an open
  path; a closed one (first point = last point) wraps: m_0 = m_last = (p_1 - p_{last-1}) / 2;
- `"linear"`: p_i + f (p_{i+1} - p_i).

A looping motion's time wraps modulo its duration, the last keyframe's time (at the wrap it
jumps back to its first keyframe); one that does not loop stays at its last keyframe. A run
starts `phase_s` seconds into the motion: an obstacle's position at run time t is the
motion's at phase_s + t.

`Moving` is a `Cylinder` or a `Box` that follows a motion (a box keeps its yaw). Moving
obstacles are kinematic: the physics sets them at every step (`vplane_mj.sim`), nothing
pushes them. `MotionTable` packs a world's motions for the compiled evaluation of all of
them at once (`kernels.motion_positions`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vplane_mj.geometry.shapes import Box, Cylinder, Piece

INTERPOLATIONS = ("spline", "linear")
"""How a motion's position runs between its keyframes (see the module docstring)."""
SPLINE, LINEAR = 0, 1
"""The interpolations' codes in a `MotionTable`."""


@dataclass(frozen=True)
class Motion:
    """Keyframes ((t_s, x_m, y_m), ...), whether the motion loops, its interpolation and the
    motion time (s) at the run's start (see the module docstring)."""

    keyframes: tuple[tuple[float, float, float], ...]
    loop: bool = True
    interpolation: str = "spline"
    phase_s: float = 0.0

    def __post_init__(self) -> None:
        frames = np.asarray(self.keyframes, float)
        if frames.ndim != 2 or frames.shape[1] != 3 or len(frames) < 2:
            raise ValueError(f"a motion needs at least 2 keyframes [t, x, y], got {self.keyframes!r}")
        if not np.isfinite(frames).all():
            raise ValueError("every keyframe number must be finite")
        if frames[0, 0] != 0.0 or not (np.diff(frames[:, 0]) > 0).all():
            raise ValueError("keyframe times must start at 0 and strictly increase")
        if self.interpolation not in INTERPOLATIONS:
            raise ValueError(f"interpolation must be one of {INTERPOLATIONS}, got {self.interpolation!r}")
        if not math.isfinite(self.phase_s) or self.phase_s < 0:
            raise ValueError(f"phase_s must be finite and at least 0, got {self.phase_s!r}")

    @property
    def duration_s(self) -> float:
        """The motion's length (s): its last keyframe's time."""
        return float(self.keyframes[-1][0])

    def tangents(self) -> np.ndarray:
        """The spline's Catmull-Rom tangents (K, 2) at the keyframes, per segment of the
        keyframes' order (m per unit time fraction)."""
        return catmull_rom_tangents(np.asarray(self.keyframes, float)[:, 1:])

    def motion_time(self, run_time_s: np.ndarray | float) -> np.ndarray:
        """The motion's own time (s) at run time(s) `run_time_s`: phase added, wrapped or held."""
        t = np.asarray(run_time_s, float) + self.phase_s
        duration = self.duration_s
        return np.mod(t, duration) if self.loop else np.clip(t, 0.0, duration)

    def position(self, run_time_s: np.ndarray | float) -> np.ndarray:
        """The position (..., 2; m) at run time(s) `run_time_s`."""
        return self._evaluate(run_time_s, derivative=False)

    def velocity(self, run_time_s: np.ndarray | float) -> np.ndarray:
        """The velocity (..., 2; m/s) at run time(s) `run_time_s` (between keyframes: the jump of
        a looping motion's wrap has none)."""
        return self._evaluate(run_time_s, derivative=True)

    def _evaluate(self, run_time_s: np.ndarray | float, derivative: bool) -> np.ndarray:
        frames = np.asarray(self.keyframes, float)
        times, points = frames[:, 0], frames[:, 1:]
        t = self.motion_time(run_time_s)
        segment = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
        span = times[segment + 1] - times[segment]
        f = (t - times[segment]) / span
        p0, p1 = points[segment], points[segment + 1]
        if self.interpolation == "linear":
            if derivative:
                return (p1 - p0) / span[..., None]
            return p0 + f[..., None] * (p1 - p0)
        tangents = self.tangents()
        m0, m1 = tangents[segment], tangents[segment + 1]
        weights = hermite_derivative_weights(f) if derivative else hermite_weights(f)
        value = sum(w[..., None] * v for w, v in zip(weights, (p0, p1, m0, m1), strict=True))
        return value / span[..., None] if derivative else value


def catmull_rom_tangents(points: np.ndarray) -> np.ndarray:
    """Tangents (K, 2) of ignition::math::Spline at tension 0 through `points` (K, 2), K >= 2:
    half the chord between each point's neighbours; at the ends of an open path, half the end
    chord; a closed path (first point = last) wraps round its last segment."""
    points = np.asarray(points, float)
    tangents = np.empty_like(points)
    tangents[1:-1] = 0.5 * (points[2:] - points[:-2])
    if (points[0] == points[-1]).all() and len(points) > 2:
        tangents[0] = tangents[-1] = 0.5 * (points[1] - points[-2])
    else:
        tangents[0] = 0.5 * (points[1] - points[0])
        tangents[-1] = 0.5 * (points[-1] - points[-2])
    return tangents


def hermite_weights(f: np.ndarray) -> tuple[np.ndarray, ...]:
    """The cubic Hermite basis (h00, h01, h10, h11) at fraction(s) f in [0, 1]."""
    f2, f3 = f * f, f * f * f
    return 2 * f3 - 3 * f2 + 1, -2 * f3 + 3 * f2, f3 - 2 * f2 + f, f3 - f2


def hermite_derivative_weights(f: np.ndarray) -> tuple[np.ndarray, ...]:
    """d/df of the Hermite basis at fraction(s) f."""
    f2 = f * f
    return 6 * f2 - 6 * f, -6 * f2 + 6 * f, 3 * f2 - 4 * f + 1, 3 * f2 - 2 * f


@dataclass(frozen=True)
class Moving:
    """A cylinder or box that follows `motion`; `shape` stands where the motion puts it at the
    run's start (run time 0), `index` is its place among the scenario's `[[world.obstacles]]`."""

    shape: Cylinder | Box
    motion: Motion
    index: int = 0

    def at(self, run_time_s: float) -> Cylinder | Box:
        """The shape where it is at run time `run_time_s` (s)."""
        x, y = self.motion.position(run_time_s)
        return dataclasses.replace(self.shape, center=(float(x), float(y)))

    def footprint_at(self, run_time_s: float) -> tuple[Piece, ...]:
        """Its footprint pieces at run time `run_time_s` (s)."""
        return self.at(run_time_s).footprint()


class MotionTable:
    """A world's motions packed into arrays, evaluated all at once in compiled code
    (`kernels.motion_positions`): the keyframes of motion m are rows `starts[m]` to
    `starts[m + 1] - 1` of `times` and `points` (and of `tangents`, the spline's)."""

    def __init__(self, motions: Sequence[Motion]):
        self.count = len(motions)
        frames = [np.asarray(m.keyframes, float) for m in motions]
        self.starts = np.cumsum([0] + [len(f) for f in frames]).astype(np.int64)
        self.times = np.concatenate([f[:, 0] for f in frames]) if frames else np.empty(0)
        self.points = np.concatenate([f[:, 1:] for f in frames]) if frames else np.empty((0, 2))
        self.tangents = (
            np.concatenate([catmull_rom_tangents(f[:, 1:]) for f in frames]) if frames else np.empty((0, 2))
        )
        self.loops = np.array([m.loop for m in motions], dtype=np.bool_)
        self.kinds = np.array(
            [SPLINE if m.interpolation == "spline" else LINEAR for m in motions], dtype=np.int64
        )
        self.phases = np.array([m.phase_s for m in motions], dtype=float)

    def positions(self, run_time_s: float, out: np.ndarray | None = None) -> np.ndarray:
        """Every motion's position (count, 2; m) at run time `run_time_s` (s), written into
        `out` when given (any (count, >= 2) float array, a view into MuJoCo's mocap_pos say)."""
        from vplane_mj.kernels import geometry as kernels  # numba: loaded by the first call

        if out is None:
            out = np.empty((self.count, 2))
        kernels.motion_positions(
            float(run_time_s),
            self.starts,
            self.times,
            self.points,
            self.tangents,
            self.loops,
            self.kinds,
            self.phases,
            out,
        )
        return out
