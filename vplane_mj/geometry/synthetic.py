"""Synthetic sonar scans without physics: exact ray casts against obstacle footprints.

The default 16-sonar ring with 3 rays over a 20 degree beam, like the simulator's, for
exercising the planners in pure numpy (tests, figures). Ranges are from the robot's centre.
"""

import math

import numpy as np

from vplane_mj.geometry import shapes

BEARINGS = np.arange(16) * (2 * math.pi / 16)
BEAM = math.radians(20.0)


def cast(pieces, origin, angles: np.ndarray, range_max: float) -> np.ndarray:
    """Distance (m) along rays from `origin` to the first rectangle hit, NaN beyond `range_max`.

    The slab method in each rectangle's own frame, for all rays and rectangles at once.
    """
    rects = [p for p in pieces if isinstance(p, shapes.Rect)]
    best = np.full(len(angles), np.inf)
    for rect in rects:
        c, s = math.cos(rect.yaw), math.sin(rect.yaw)
        ox, oy = origin[0] - rect.center[0], origin[1] - rect.center[1]
        lo = np.array([c * ox + s * oy, -s * ox + c * oy])
        dx, dy = np.cos(angles), np.sin(angles)
        ld = np.array([c * dx + s * dy, -s * dx + c * dy])
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = (-np.array(rect.half)[:, None] - lo[:, None]) / ld
            t2 = (np.array(rect.half)[:, None] - lo[:, None]) / ld
        near = np.nanmax(np.minimum(t1, t2), axis=0)
        far = np.nanmin(np.maximum(t1, t2), axis=0)
        hit = (far >= np.maximum(near, 0.0)) & (near >= 0.0)
        best = np.where(hit & (near < best), near, best)
    return np.where(best < range_max, best, np.nan)


def scan(footprints, position, yaw, range_max=3.0, rays=(-10.0, 0.0, 10.0)) -> np.ndarray:
    """One sonar ring reading like the simulator's: the shortest of each sonar's rays."""
    offsets = np.radians(rays)
    angles = (yaw + BEARINGS[:, None] + offsets[None, :]).ravel()
    hits = cast(footprints.pieces, position, angles, range_max).reshape(len(BEARINGS), len(rays))
    with np.errstate(all="ignore"):
        shortest = np.nanmin(np.where(np.isnan(hits), np.inf, hits), axis=1)
    return np.where(np.isfinite(shortest), shortest, np.nan)
