"""A planar laser rangefinder: exact 2D ray casting against the world's footprint pieces.

Every obstacle and border wall is a vertical prism standing on the floor (`vplane_mj.sim.world`
builds it `OBSTACLE_HEIGHT_M` = 0.5 m tall) over a footprint of `shapes.Rect` and
`shapes.Disc` pieces. A horizontal laser mounted on the robot's vertical axis between the
floor and the obstacles' tops (the tests compare with MuJoCo at MOUNT_HEIGHT_M) therefore
sees an exact 2D problem: the first point of each beam's ray in the union of the pieces.

`RayCaster` packs a world's pieces once and casts a fan of evenly spaced beams from a point;
its cost scales with what lies within range (pieces beyond `range_max` are skipped, and each
piece is tested only against the beams inside its angular extent seen from the origin).
`LaserScanner` is the sensor: its beams in the robot's frame, the range limits and the faults.

Pieces are closed sets: a beam that grazes a disc or runs along a box's edge hits it, and a
beam starting inside or on the boundary of a piece reads 0 m (the first point of the ray in
the piece is its start). MuJoCo's ray caster differs there alone: from inside a geom it
reads the distance to where the ray leaves it.

Importing this module imports numba (its kernels: `vplane_mj.kernels.laser`). `import vplane_mj`
does not import numba.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from vplane_mj.geometry.shapes import Disc, Footprints, Piece, Rect
from vplane_mj.kernels.laser import cast_fan

MOUNT_HEIGHT_M = 0.2
"""The laser's height above the floor (m) assumed when comparing with MuJoCo's 3D ray caster:
any height strictly between the floor and the obstacles' tops (0.5 m) sees the same ranges."""
TWO_PI = 2.0 * math.pi


class RayCaster:
    """The pieces of one world, packed for casting fans of horizontal beams (m, rad)."""

    def __init__(self, pieces: Footprints | Sequence[Piece]):
        if isinstance(pieces, Footprints):
            pieces = pieces.pieces
        discs = [p for p in pieces if isinstance(p, Disc)]
        rects = [p for p in pieces if isinstance(p, Rect)]
        self.discs = np.array([(*d.center, d.radius) for d in discs], dtype=float).reshape(-1, 3)
        """One row per disc: centre x, y and radius (m)."""
        self.rects = np.array(
            [(*r.center, *r.half, math.cos(r.yaw), math.sin(r.yaw)) for r in rects], dtype=float
        ).reshape(-1, 6)
        """One row per rectangle: centre x, y, half extents (m), cos and sin of its yaw."""
        self._fan_key: tuple[float, int] | None = None
        self._fan = np.zeros((2, 0))

    def cast(
        self,
        origin: tuple[float, float],
        first_angle: float,
        step: float,
        beams: int,
        range_max: float,
        moving: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> np.ndarray:
        """Ranges (beams,) in m from `origin` of the beams at `first_angle + k * step` (rad, world
        frame, k = 0 .. beams - 1) to the nearest piece; inf where nothing lies within `range_max`.
        `moving`: pieces besides the world's, where they stand for this cast (discs and
        rectangles packed as `discs` and `rects`: the moving obstacles).

        The beams span less than a full turn: `(beams - 1) * step < 2 pi`, `step > 0`.
        """
        ox, oy = float(origin[0]), float(origin[1])
        if not (math.isfinite(ox) and math.isfinite(oy) and math.isfinite(first_angle)):
            raise ValueError(f"origin and first_angle must be finite, got {origin} and {first_angle}")
        if beams < 1 or not step > 0 or not (beams - 1) * step < TWO_PI:
            raise ValueError(f"need beams >= 1 and 0 < (beams - 1) * step < 2 pi, got {beams} x {step}")
        if not range_max > 0:
            raise ValueError(f"range_max must be positive, got {range_max}")
        ranges = np.empty(beams)
        fan = self._fan_offsets(float(step), int(beams))
        discs, rects = self.discs, self.rects
        if moving is not None:
            discs = np.concatenate((discs, moving[0])) if len(discs) else moving[0]
            rects = np.concatenate((rects, moving[1])) if len(rects) else moving[1]
        cast_fan(discs, rects, ox, oy, float(first_angle), float(step), fan, float(range_max), ranges)
        return ranges

    def _fan_offsets(self, step: float, beams: int) -> np.ndarray:
        """cos and sin (2, beams) of `k * step`: the beams' directions relative to the first.

        A sensor casts the same fan at every scan, so the last fan's table is kept."""
        if self._fan_key != (step, beams):
            offsets = np.arange(beams) * step
            self._fan = np.stack([np.cos(offsets), np.sin(offsets)])
            self._fan_key = (step, beams)
        return self._fan


def laser_bearings(fov_deg: float, beams: int) -> tuple[np.ndarray, float]:
    """The bearings (rad, robot frame) of `beams` beams evenly spaced over `fov_deg` (degrees)
    about the heading, and the step (rad) between two: the ends at +-fov/2 below 360 degrees;
    all round without a repeated beam at 360 degrees."""
    fov = math.radians(fov_deg)
    step = fov / beams if fov_deg == 360.0 else fov / (beams - 1)
    return (np.arange(beams) - (beams - 1) / 2) * step, step


class LaserScanner:
    """A laser rangefinder on the robot's vertical axis: `beams` beams evenly spaced over `fov_deg`
    (degrees, (0, 360]), centred on the heading; returns between `range_min` and `range_max` (m).

    Below 360 degrees the first and last beams lie at -fov/2 and +fov/2; at 360 degrees the
    beams are 360/beams degrees apart all round, so no beam is repeated at +-180 degrees.
    `rate_hz` is the scan rate, held for the run loop (the scan itself takes no time). `moving`
    gives the moving obstacles' pieces where they stand when a scan is cast.

    Faults, drawn from `rng` (the same seed gives the same scans): Gaussian noise of
    `noise_std` (m) on every return, then the range rules on the noisy range, then `dropout`,
    the probability that a return is lost. A fault that is on draws one number per beam at
    every scan, whatever the beams see.
    """

    def __init__(
        self,
        caster: RayCaster,
        *,
        fov_deg: float,
        beams: int,
        range_min: float,
        range_max: float,
        rate_hz: float,
        rng: np.random.Generator,
        noise_std: float = 0.0,
        dropout: float = 0.0,
        moving: Callable[[], tuple[np.ndarray, np.ndarray]] | None = None,
    ):
        checks = (
            (0.0 < fov_deg <= 360.0, f"fov_deg must lie in (0, 360], got {fov_deg}"),
            (
                float(beams).is_integer() and 2 <= beams <= 2048,
                f"beams must be an integer in [2, 2048], got {beams}",
            ),
            (
                0.0 <= range_min < range_max < math.inf,
                f"need 0 <= range_min < range_max, got {range_min}, {range_max}",
            ),
            (0.0 < rate_hz < math.inf, f"rate_hz must be positive, got {rate_hz}"),
            (0.0 <= noise_std < math.inf, f"noise_std must be >= 0, got {noise_std}"),
            (0.0 <= dropout <= 1.0, f"dropout must lie in [0, 1], got {dropout}"),
        )
        for ok, reason in checks:
            if not ok:
                raise ValueError(reason)
        self.caster = caster
        self.fov_deg = fov_deg
        self.beams = int(beams)
        self.range_min = range_min
        self.range_max = range_max
        self.rate_hz = rate_hz
        self.rng = rng
        self.noise_std = noise_std
        self.dropout = dropout
        self.moving = moving
        """Where the moving obstacles stand at the moment of a cast (`RayCaster.cast`'s
        `moving`), None in a world without any."""
        self.bearings, self.angle_step = laser_bearings(fov_deg, self.beams)
        """Each beam's bearing (rad) in the robot's frame, counter-clockwise from the heading, and
        the angle (rad) between neighbouring beams."""

    @property
    def beam_width(self) -> float:
        """The angle (rad) each beam stands for: the step between two beams."""
        return self.angle_step

    def read(self, x: float, y: float, yaw: float) -> np.ndarray:
        """Ranges (beams,) in m from the robot's centre at (x, y) (m) heading `yaw` (rad); NaN
        where there is no return: nothing within range_max, a return closer than range_min
        (after the noise), or a lost return."""
        ranges = self.caster.cast(
            (x, y),
            yaw + self.bearings[0],
            self.angle_step,
            self.beams,
            self.range_max,
            None if self.moving is None else self.moving(),
        )
        if self.noise_std > 0.0:
            ranges += self.rng.normal(0.0, self.noise_std, self.beams)
        ranges[~((ranges >= self.range_min) & (ranges <= self.range_max))] = np.nan
        if self.dropout > 0.0:
            ranges[self.rng.random(self.beams) < self.dropout] = np.nan
        return ranges
