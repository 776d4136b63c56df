"""Synthetic range scans without physics: exact ray casts against obstacle footprints.

The default 16-sonar ring with 3 rays over a 20 degree beam, like the simulator's, and the
other sensors' layouts (`LAYOUTS`), for exercising the planners in pure numpy (tests,
figures, benchmarks). Ranges are from the robot's centre.
"""

import math
from dataclasses import dataclass

import numpy as np

from vplane_mj.geometry import shapes

BEARINGS = np.arange(16) * (2 * math.pi / 16)
BEAM = math.radians(20.0)


@dataclass(frozen=True)
class ScanLayout:
    """A range sensor: bearings (rad, robot frame), beam width (rad), range (m) and the ray
    offsets (deg) whose shortest echo is a beam's reading."""

    name: str
    bearings: np.ndarray
    beam: float
    range_max: float
    rays: tuple[float, ...]

    def scan(self, footprints, position, yaw) -> np.ndarray:
        """One reading of every beam (m; NaN: no echo within the range)."""
        return scan(footprints, position, yaw, self.range_max, self.rays, self.bearings)


_PIONEER_DEG = (90, 50, 30, 10, -10, -30, -50, -90, -90, -130, -150, -170, 170, 150, 130, 90)
LAYOUTS = {
    layout.name: layout
    for layout in (
        ScanLayout("sonar_ring", BEARINGS, BEAM, 3.0, (-10.0, 0.0, 10.0)),
        # Pioneer 3-DX: front and rear arrays of 8; both arrays look along +-90 degrees.
        ScanLayout("pioneer_sonars", np.radians(_PIONEER_DEG), math.radians(15.0), 5.0, (-7.5, 0.0, 7.5)),
        # TurtleBot3 Burger's LDS: 360 degrees in 1 degree steps, 0.12-3.5 m.
        ScanLayout("turtlebot_laser", np.radians(np.arange(360.0)), math.radians(1.0), 3.5, (0.0,)),
        # Clearpath Jackal's laser: 270 degrees in 720 steps of 0.375 degrees, 0.1-30 m.
        ScanLayout(
            "jackal_laser", np.radians(-135.0 + 0.375 * np.arange(720)), math.radians(0.375), 30.0, (0.0,)
        ),
    )
}
"""The sensors the planners are exercised with: the default ring, uneven sonars, two lasers."""


def cast(pieces, origin, angles: np.ndarray, range_max: float) -> np.ndarray:
    """Distance (m) along rays from `origin` to the first piece hit, NaN beyond `range_max`.

    Rectangles by the slab method in each rectangle's own frame, discs by the nearer root of
    the ray's quadratic; a piece that holds `origin` is not seen. All rays at once.
    """
    best = np.full(len(angles), np.inf)
    dx, dy = np.cos(angles), np.sin(angles)
    for piece in pieces:
        if isinstance(piece, shapes.Disc):
            near = _disc_entry(piece, origin, dx, dy)
        else:
            near = _rect_entry(piece, origin, dx, dy)
        best = np.where(near < best, near, best)
    return np.where(best < range_max, best, np.nan)


def _rect_entry(rect: shapes.Rect, origin, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Where each ray enters the rectangle (m), inf if it misses or starts inside."""
    c, s = math.cos(rect.yaw), math.sin(rect.yaw)
    ox, oy = origin[0] - rect.center[0], origin[1] - rect.center[1]
    lo = np.array([c * ox + s * oy, -s * ox + c * oy])
    ld = np.array([c * dx + s * dy, -s * dx + c * dy])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-np.array(rect.half)[:, None] - lo[:, None]) / ld
        t2 = (np.array(rect.half)[:, None] - lo[:, None]) / ld
    near = np.nanmax(np.minimum(t1, t2), axis=0)
    far = np.nanmin(np.maximum(t1, t2), axis=0)
    hit = (far >= np.maximum(near, 0.0)) & (near >= 0.0)
    return np.where(hit, near, np.inf)


def _disc_entry(disc: shapes.Disc, origin, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Where each ray enters the disc (m), inf if it misses or starts inside."""
    cx, cy = disc.center[0] - origin[0], disc.center[1] - origin[1]
    along = cx * dx + cy * dy  # the ray's point nearest the centre
    across2 = cx * cx + cy * cy - along * along
    inside = disc.radius * disc.radius - across2
    near = along - np.sqrt(np.maximum(inside, 0.0))
    start_outside = cx * cx + cy * cy > disc.radius * disc.radius
    return np.where((inside >= 0.0) & (near >= 0.0) & start_outside, near, np.inf)


def scan(footprints, position, yaw, range_max=3.0, rays=(-10.0, 0.0, 10.0), bearings=BEARINGS) -> np.ndarray:
    """One reading of each beam along `bearings` (rad, robot frame), like the simulator's sonar:
    the shortest of the beam's rays (offsets in deg)."""
    offsets = np.radians(rays)
    angles = (yaw + np.asarray(bearings)[:, None] + offsets[None, :]).ravel()
    hits = cast(footprints.pieces, position, angles, range_max).reshape(len(bearings), len(rays))
    with np.errstate(all="ignore"):
        shortest = np.nanmin(np.where(np.isnan(hits), np.inf, hits), axis=1)
    return np.where(np.isfinite(shortest), shortest, np.nan)
