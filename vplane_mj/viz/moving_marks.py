"""What the render draws of the moving obstacles, besides MuJoCo's own where they ended, as
flat shapes per legend mark: the trace of each one's centre on the floor (older parts lighter)
and, outlined, where each came closest to the robot, joined to the robot's place then."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from vplane_mj.geometry import shapes
from vplane_mj.geometry.motion import Moving
from vplane_mj.logs.replay import obstacle_distances
from vplane_mj.viz import palette
from vplane_mj.viz.flat import Disc, Segment, Shape
from vplane_mj.viz.track_marks import TOP_M, Drawn, layer_z

MAX_TRACE_SEGMENTS = 400
"""A moving obstacle's trace is decimated to at most this many segments."""
TRACE_JUMP_M = 0.5
"""A step between two ticks longer than this (m) is a looping motion's jump, not drawn."""
TRACE_LIGHTEST = 0.12
"""The oldest part of a trace mixes this much of its colour with white (the newest: all of it)."""
TRACE_HEIGHT_M = 0.02
"""Traces lie on the floor, under the obstacles and the path (newer parts up to 1 cm higher, over
older ones they cross)."""
TRACE_PX, OUTLINE_PX, LINK_PX, PLACE_RADIUS_PX = 3.0, 3.0, 1.5, 4.0
OUTLINE_SEGMENTS = 48
"""Segments of a disc's outline."""
MOVING_AT_END = dataclasses.replace(palette.MOVING_OBSTACLE, label="moving obstacle (end)")
TRACE = palette.trace_mark("its trace, fading")


def moving_marks(
    moving: tuple[Moving, ...], positions: np.ndarray, places: np.ndarray, metres_per_px: float
) -> list[Drawn]:
    """The moving obstacles (MuJoCo draws them where `places` (N, count, 2; m) ends), their traces
    and their closest approaches to the robot's centre at `positions` (N, 2; m)."""
    gaps = obstacle_distances(moving, positions, places)
    traces: list[Shape] = []
    closest: list[Shape] = []
    z = layer_z("closest")
    rgba = palette.CLOSEST.rgba
    for k, obstacle in enumerate(moving):
        traces += _trace(places[:, k])
        nearest = int(np.argmin(gaps[:, k]))
        x, y = places[nearest, k]
        (piece,) = dataclasses.replace(obstacle.shape, center=(float(x), float(y))).footprint()
        outline = _outline(piece)
        closest += [
            Segment(a, b, rgba, OUTLINE_PX, z)
            for a, b in zip(outline, np.roll(outline, -1, axis=0), strict=True)
        ]
        robot = positions[nearest]
        closest.append(Segment(robot, _nearest_on(piece, robot), rgba, LINK_PX, z))
        closest.append(Disc(robot, PLACE_RADIUS_PX * metres_per_px, rgba, z + TOP_M))  # over the path
    drawn: list[Drawn] = [(MOVING_AT_END, [])]  # MuJoCo draws them
    if traces:
        drawn.append((TRACE, traces))
    drawn.append((palette.CLOSEST, closest))
    return drawn


def _trace(centres: np.ndarray) -> list[Shape]:
    """The path of an obstacle's centre (N, 2; m) on the floor, decimated to MAX_TRACE_SEGMENTS,
    from lightest (oldest) to the trace's colour (newest); a looping motion's jumps left out."""
    if len(centres) < 2:
        return []
    jumps = np.concatenate(([0], np.cumsum(np.hypot(*np.diff(centres, axis=0).T) > TRACE_JUMP_M)))
    stride = max(1, int(np.ceil((len(centres) - 1) / MAX_TRACE_SEGMENTS)))
    kept = list(range(0, len(centres), stride))
    if kept[-1] != len(centres) - 1:
        kept.append(len(centres) - 1)
    colour = np.array(TRACE.rgba[:3])
    segments: list[Shape] = []
    for n, (i, j) in enumerate(itertools.pairwise(kept)):
        if jumps[i] != jumps[j]:
            continue
        weight = TRACE_LIGHTEST + (1.0 - TRACE_LIGHTEST) * (n + 1) / (len(kept) - 1)
        r, g, b = 1.0 - weight * (1.0 - colour)
        z = TRACE_HEIGHT_M + 0.01 * n / len(kept)
        segments.append(Segment(centres[i], centres[j], (r, g, b, 1.0), TRACE_PX, z))
    return segments


def _outline(piece: shapes.Piece) -> np.ndarray:
    """A footprint piece's outline (k, 2; m): a rectangle's corners, a disc's polygon."""
    if isinstance(piece, shapes.Disc):
        angles = np.linspace(0.0, 2 * math.pi, OUTLINE_SEGMENTS, endpoint=False)
        return np.column_stack((np.cos(angles), np.sin(angles))) * piece.radius + piece.center
    return piece.corners()


def _nearest_on(piece: shapes.Piece, point: np.ndarray) -> np.ndarray:
    """The point of a piece nearest `point` (m): on its edge, or `point` itself inside it."""
    centre = np.asarray(piece.center, float)
    if isinstance(piece, shapes.Disc):
        away = point - centre
        length = float(np.hypot(*away))
        return point if length <= piece.radius else centre + away * (piece.radius / length)
    c, s = math.cos(piece.yaw), math.sin(piece.yaw)
    turn = np.array([[c, -s], [s, c]])
    local = np.clip(turn.T @ (point - centre), -np.asarray(piece.half), piece.half)
    return centre + turn @ local
