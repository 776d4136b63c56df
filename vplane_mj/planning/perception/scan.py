"""A dense scan (a laser's hundreds of beams) seen as the sonar ring the fields were made for.

Khatib's repulsion (fields.py, eqs. 4-5) sums one term per echo, and its gain is set per
sonar echo of the default 16-sonar ring. A 720-beam laser returns some 45 echoes where a
sonar returns one, so summing them all would repel 45 times as hard, and costs 45 times as
much. `repulsion_points` keeps, of a scan denser than `DENSE_BEAMS`, the nearest echo in each
of `RING_SECTORS` sectors about the ring's bearings: what a sonar of the ring would report
there. A scan of at most `DENSE_BEAMS` beams (every sonar ring) is used as it is.

"""

from __future__ import annotations

import numpy as np

from vplane_mj.planning.protocol.types import Observation

RING_SECTORS = 16
"""Sectors of the full circle a dense scan is reduced to (the default sonar ring's 22.5 deg)."""
DENSE_BEAMS = 64
"""A scan of more beams than this is dense."""


def is_dense(obs: Observation) -> bool:
    """Whether the scan has more than `DENSE_BEAMS` beams (a laser's, not a sonar ring's)."""
    return len(obs.bearings) > DENSE_BEAMS


def repulsion_points(obs: Observation) -> np.ndarray:
    """World points (N, 2) of the echoes the fields' repulsion sums over (module docstring);
    computed once per observation, read-only."""
    points = obs.__dict__.get("_repulsion_points")
    if points is None:
        points = obs.echo_points()
        if is_dense(obs):
            points = _nearest_per_sector(obs)
            points.flags.writeable = False
        obs.__dict__["_repulsion_points"] = points  # a frozen dataclass: cache outside its fields
    return points


def _nearest_per_sector(obs: Observation) -> np.ndarray:
    """The nearest echo of each sector k (bearings within half a sector of k 2 pi / RING_SECTORS,
    robot frame), in world coordinates; sectors without an echo give none (`kernels.points`)."""
    from vplane_mj.kernels.maps import points  # numba: loaded by the first call

    return points.nearest_per_sector(
        np.asarray(obs.position, float),
        float(obs.yaw),
        np.asarray(obs.bearings, float),
        np.asarray(obs.ranges, float),
        RING_SECTORS,
    )
