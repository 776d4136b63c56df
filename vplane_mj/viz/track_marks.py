"""What the render draws of a run over MuJoCo's obstacles, as flat shapes per legend mark.

The start, the goal, the path coloured by planner mode with arrowheads along it, the virtual
planes and objectives, the collisions and the robot's footprint where it ended. Sizes are in
pixels of the picture (`metres_per_px` turns them into metres), so that marks read the same in
a small arena and a large one; the goal's disc is the goal tolerance, the robot its footprint.
From the bottom up: goal, robot, path, planes, arrowheads, a moving obstacle's closest approach,
objectives, start, collisions (the start above a plane that crosses it).
"""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np

from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import Scenario
from vplane_mj.sim.loop import Track
from vplane_mj.viz import palette
from vplane_mj.viz.flat import Disc, Segment, Shape, Triangle
from vplane_mj.viz.palette import RGBA, Mark

Drawn = tuple[Mark, list[Shape]]
"""A legend mark and the shapes that draw it."""

MARKER_HEIGHT_M = 0.6
"""The lowest mark lies above the obstacles (0.5 m) so that they hide none."""
LAYER_STEP_M = 0.004
"""Height (m) between two layers; within one, a rim lies at its bottom, a fill a quarter up,
lines on top half way up."""
FILL_M, TOP_M = LAYER_STEP_M / 4, LAYER_STEP_M / 2
LAYERS = ("goal", "robot", "path", "plane", "arrow", "closest", "objective", "start", "collision")
"""The marks from the bottom up."""
MAX_PATH_SEGMENTS = 3000
PATH_PX = 4.0
DOT_TICKS = 10
"""A stretch in one mode this many control ticks long, but shorter than the path is wide, is a
dot (a mode of one tick on the way is not)."""
START_RADIUS_PX, OBJECTIVE_RADIUS_PX, RIM_PX = 8.0, 6.0, 2.0
PLANE_PX, DASH_PX, GAP_PX = 5.0, 10.0, 6.0
CROSS_HALF_PX, CROSS_PX = 7.0, 3.0
ARROW_LENGTH_PX, ARROW_HALF_WIDTH_PX = 16.0, 7.0
ARROW_SPACING_PX = 120.0
"""Path length (px) between two arrowheads along a stretch in one mode."""
ROBOT_AT_END = dataclasses.replace(palette.ROBOT, label="robot at the end")


def layer_z(layer: str) -> float:
    """The height (m) of a layer of LAYERS."""
    return MARKER_HEIGHT_M + LAYER_STEP_M * LAYERS.index(layer)


def track_marks(scenario: Scenario, track: Track, metres_per_px: float) -> list[Drawn]:
    """The run's marks that the picture holds, in the legend's order, with their shapes."""
    px = metres_per_px
    robot = scenario.robot
    drawn: list[Drawn] = [
        (palette.START, _disc(robot.start, START_RADIUS_PX * px, palette.START, "start", px)),
        (palette.GOAL, [Disc(robot.goal, robot.goal_tolerance, palette.GOAL.rgba, layer_z("goal"))]),
    ]
    points = _decimated(track.positions)
    modes = [track.modes[k] for k in points.index[:-1]]
    drawn += _path(points, modes, px)
    arrows = _arrows(points.xy, modes, px)
    if arrows:
        drawn.append((palette.DIRECTION, arrows))
    if track.objectives:
        radius = OBJECTIVE_RADIUS_PX * px
        objectives = [
            s for o in track.objectives for s in _disc(o, radius, palette.OBJECTIVE, "objective", px)
        ]
        drawn.append((palette.OBJECTIVE, objectives))
    if track.planes:
        drawn.append((palette.PLANE, [s for e1, e2 in track.planes for s in _dashes(e1, e2, px)]))
    if track.collision_points:
        drawn.append((palette.COLLISION, [s for point in track.collision_points for s in _cross(point, px)]))
    drawn.append((ROBOT_AT_END, _robot(scenario, track.final_pose, px)))
    return drawn


@dataclasses.dataclass(frozen=True)
class _Polyline:
    """Points of a path (N, 2; m) and their indices in the whole path."""

    xy: np.ndarray
    index: list[int]


def _decimated(positions: np.ndarray) -> _Polyline:
    """The path's points at most MAX_PATH_SEGMENTS segments apart, its last point kept."""
    if len(positions) < 2:
        return _Polyline(np.asarray(positions, float).reshape(-1, 2), list(range(len(positions))))
    stride = max(1, math.ceil((len(positions) - 1) / MAX_PATH_SEGMENTS))
    kept = list(range(0, len(positions), stride))
    if kept[-1] != len(positions) - 1:
        kept.append(len(positions) - 1)
    return _Polyline(np.asarray(positions, float)[kept], kept)


def _stretches(modes: list[str]) -> list[tuple[int, int]]:
    """The path's stretches in one mode, as (first, last) point: segment k, from point k to
    k + 1, is in `modes[k]`."""
    if not modes:
        return []
    changes = [k for k in range(1, len(modes)) if modes[k] != modes[k - 1]]
    return list(itertools.pairwise([0, *changes, len(modes)]))


def _path(points: _Polyline, modes: list[str], px: float) -> list[Drawn]:
    """A segment per pair of points, in the colour of the mode at its start, and a dot for a
    stretch in one mode of at least DOT_TICKS ticks too short to show as a line (a robot trapped
    on the spot); a mark per mode, in the order the modes first appear."""
    by_mode: dict[str, list[Shape]] = {}
    xy, z = points.xy, layer_z("path")
    for (a, b), mode in zip(itertools.pairwise(xy), modes, strict=True):
        by_mode.setdefault(mode, []).append(Segment(a, b, palette.path_mark(mode).rgba, PATH_PX, z))
    for first, last in _stretches(modes):
        stretch = xy[first : last + 1]
        ticks = points.index[last] - points.index[first]
        if ticks >= DOT_TICKS and np.hypot(*np.ptp(stretch, axis=0)) < PATH_PX * px:
            dot = Disc(stretch.mean(axis=0), PATH_PX * px, palette.path_mark(modes[first]).rgba, z + TOP_M)
            by_mode[modes[first]].append(dot)
    return [(palette.path_mark(mode), shapes) for mode, shapes in by_mode.items()]


def _arrows(xy: np.ndarray, modes: list[str], px: float) -> list[Shape]:
    """Arrowheads along each stretch of the path (N, 2; m) in one mode: one every
    ARROW_SPACING_PX, evenly spread, or one at the middle of a stretch shorter than that but
    twice an arrowhead's length."""
    arrows: list[Shape] = []
    for first, last in _stretches(modes):
        stretch = xy[first : last + 1]
        along = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(stretch, axis=0).T))))
        length = along[-1]
        if length < 2 * ARROW_LENGTH_PX * px:
            continue
        count = max(1, int(length // (ARROW_SPACING_PX * px)))
        for s in (np.arange(count) + 0.5) * length / count:
            arrow = _arrowhead(stretch, along, s, px)
            if arrow is not None:
                arrows.append(arrow)
    return arrows


def _arrowhead(xy: np.ndarray, along: np.ndarray, s: float, px: float) -> Triangle | None:
    """The arrowhead centred `s` (m) along a polyline (N, 2; m) whose points lie `along` it (m),
    pointing along its chord across the arrowhead's length (a jittering robot's small turns do
    not swing it); None where that chord is too short to say (the robot turned on the spot)."""
    half = ARROW_LENGTH_PX * px / 2
    back, front = (np.array([np.interp(t, along, xy[:, k]) for k in (0, 1)]) for t in (s - half, s + half))
    chord = float(np.hypot(*(front - back)))
    if chord < half:
        return None
    ahead = (front - back) / chord
    side = np.array((-ahead[1], ahead[0])) * ARROW_HALF_WIDTH_PX * px
    centre = (back + front) / 2
    tip, base = centre + ahead * half, centre - ahead * half
    return Triangle(np.array((tip, base + side, base - side)), palette.DIRECTION.rgba, layer_z("arrow"))


def _disc(center, radius_m: float, mark: Mark, layer: str, px: float) -> list[Shape]:
    """A disc of the mark's colour, within its rim when it has one."""
    z = layer_z(layer)
    if mark.rim is None:
        return [Disc(center, radius_m, mark.rgba, z)]
    return [Disc(center, radius_m, mark.rim, z), Disc(center, radius_m - RIM_PX * px, mark.rgba, z + FILL_M)]


def _dashes(e1, e2, px: float) -> list[Shape]:
    """A virtual plane from e1 to e2 (m) as dashes of DASH_PX with gaps of GAP_PX."""
    a, b = np.asarray(e1, float), np.asarray(e2, float)
    length = float(np.hypot(*(b - a)))
    if length == 0.0:
        return []
    dash, period = DASH_PX * px, (DASH_PX + GAP_PX) * px
    starts = np.arange(0.0, length, period)
    z = layer_z("plane")
    ends = [(a + (b - a) * s / length, a + (b - a) * min(s + dash, length) / length) for s in starts]
    return [Segment(start, end, palette.PLANE.rgba, PLANE_PX, z) for start, end in ends]


def _cross(point, px: float) -> list[Shape]:
    """A "+" at a collision point (m)."""
    x, y = point
    arm, z = CROSS_HALF_PX * px, layer_z("collision")
    rgba = palette.COLLISION.rgba
    return [
        Segment((x - arm, y), (x + arm, y), rgba, CROSS_PX, z),
        Segment((x, y - arm), (x, y + arm), rgba, CROSS_PX, z),
    ]


def _robot(scenario: Scenario, pose: tuple[float, float, float], px: float) -> list[Shape]:
    """The robot's footprint where it ended: filled, within a rim, with a line from its centre
    to its front."""
    body = robot_body(scenario.robot.profile)
    x, y, yaw = pose
    mark, z = palette.ROBOT, layer_z("robot")
    rim: RGBA = mark.rim or palette.BLACK
    heading = np.array((math.cos(yaw), math.sin(yaw)))
    if body.disc:
        front = body.radius_m
        shapes: list[Shape] = _disc((x, y), body.radius_m, mark, "robot", px)
    else:
        turn = np.array([[heading[0], -heading[1]], [heading[1], heading[0]]])
        corners = body.footprint @ turn.T + (x, y)
        shapes = [Triangle(corners[[0, k, k + 1]], mark.rgba, z + FILL_M) for k in range(1, len(corners) - 1)]
        shapes += [
            Segment(a, b, rim, RIM_PX, z + TOP_M)
            for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True)
        ]
        front = float(body.footprint[:, 0].max())
    shapes.append(Segment((x, y), np.array((x, y)) + heading * front, rim, RIM_PX, z + TOP_M))
    return shapes
