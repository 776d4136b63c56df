"""`vplane-mj generate dynabarn`: seeded worlds of moving cylinders in DynaBARN's layout
(`vplane_mj.worlds.dynabarn_layout`), their paths and speeds drawn as DynaBARN draws its own.

Source: Nair, Xiao et al., "DynaBARN: Benchmarking Metric Ground Navigation in Dynamic
Environments", SSRR 2022, and its public generator github.com/aninair1905/DynaBARN
(`polynomial_fit.py`: the path and its times; `create_plugin_polynomial.py`: the plugins and the
worlds), read and implemented anew here. Coordinates below are Gazebo's (the square
[-10, 10] x [-10, 10], m); the documents hold them in the arena frame (+ GAZEBO_TO_ARENA_M).

The recipe, per obstacle path:
1. An order n drawn uniformly from the third's `orders`; n + 1 random integer points in the
   square.
2. The least-squares polynomial y = p(x) of degree n through them (numpy's polyfit: where two
   points share an x the fit passes between them, and both points stay keyframes; when every
   x is 0 there is no fit, and the path is drawn again, as DynaBARN's retry does).
3. Candidate keyframes: p at GRID_POINTS evenly spaced x from -10 to 10 (2.22 m apart), the
   integer points, the crossings of p with y = +-10 (a level's crossings only when all its
   solutions are real), and p at x = +-10; those inside the closed square are kept, once each.
4. The border points (x or y = +-10), in order of x and, when there are fewer than two, followed
   by random points on random sides of the square up to two: the first enters, the last leaves,
   any between are dropped. The inner points run in order of x between them; half the paths
   are reversed.
5. Speeds: per path a mean drawn uniformly in the third's [low, high) (rounded to 0.1 m/s) and
   a spread (rounded to 0.01 m/s); per segment a speed from the grid low, low + 0.1, ... below
   high, weighted by the normal density of that mean and spread. Keyframe times are the
   cumulated chord / speed; every keyframe is written with two decimals, and the loop's length
   is the last keyframe's time (Gazebo's PoseAnimation, looping, spline-interpolated).
6. Per difficulty third DynaBARN drew POOL_SIZE paths, and each world an obstacle count and that
   many distinct paths of the pool; so here, from one generator seeded by (seed, third).

The generator's command-line arguments for the published 60 worlds are not in the repository;
THIRDS holds what the measured worlds imply (docs/dynabarn.md: the 60 worlds' table and
world 0's keyframes): counts 5-14, 15-19, 20-24; keyframe speeds on the grids 0.5-0.9, 1.0-1.4
and 1.5-1.9 m/s (world 0's speeds sit on the first); per-path spreads small for easy (world 0's
paths keep nearly one speed) and wide enough for medium and hard to give their narrow ranges of
world mean speeds; orders 1-2 in every third (world 0's 11 paths: 8 lines, 3 parabolas; no
medium or hard path was at hand).

Deviations:
- Points are rounded to two decimals before they are deduplicated and timed (DynaBARN rounds
  only when it writes them); a path whose two-decimal keyframes give equal times, or a speed
  outside KEYFRAME_SPEED_M_S (the range measured over all 469 real plugins), is drawn again.
- For a benchmark: every run starts each loop at a random phase (`phase_s = "random"`), and a
  scenario whose start or goal lies in an obstacle at the run's start is rejected. So a path is
  drawn again when, at any time of its loop, the obstacle's disc grown by CLEARANCE_MARGIN_M
  reaches the Jackal's footprint facing -x at the start or at the goal (the parser checks the
  footprint at the goal, not its point); the spline is sampled at most SAMPLE_STEP_M apart.
  DynaBARN has no such rule: its obstacles may cross the goal.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from vplane_mj.geometry.motion import Motion, catmull_rom_tangents
from vplane_mj.robots.profiles import robot_profile
from vplane_mj.worlds.dynabarn_layout import (
    DIFFICULTIES,
    GAZEBO_TO_ARENA_M,
    GOAL_M,
    OBSTACLE_RADIUS_M,
    PROFILE,
    START_M,
    layout_document,
    moving_cylinder,
)
from vplane_mj.worlds.families import Case


@dataclass(frozen=True)
class Third:
    """One difficulty third's draws: obstacles per world (both ends included), the speed range
    [low, high) of the per-path mean and of the segment speeds' grid (m/s), the range of the
    per-path spread (m/s) and of the polynomial's order."""

    obstacles: tuple[int, int]
    speed_m_s: tuple[float, float]
    spread_m_s: tuple[float, float]
    orders: tuple[int, int] = (1, 2)


THIRDS = {
    "easy": Third(obstacles=(5, 14), speed_m_s=(0.5, 1.0), spread_m_s=(0.03, 0.1)),
    "medium": Third(obstacles=(15, 19), speed_m_s=(1.0, 1.5), spread_m_s=(0.1, 0.25)),
    "hard": Third(obstacles=(20, 24), speed_m_s=(1.5, 2.0), spread_m_s=(0.1, 0.25)),
}
"""The draws of DynaBARN's easy, medium and hard thirds (its worlds 0-19, 20-39, 40-59)."""
HALF_SIDE_M = 10
"""The keyframes' square is [-HALF_SIDE_M, HALF_SIDE_M] on both axes (m, Gazebo frame)."""
GRID_POINTS = 10
"""Evenly spaced x at which the polynomial gives keyframes."""
SPEED_STEP_M_S = 0.1
"""Spacing of the segment speeds' grid (m/s)."""
POOL_SIZE = 200
"""Paths drawn per third, from which each world takes its obstacles."""
KEYFRAME_SPEED_M_S = (0.49, 1.95)
"""Allowed speed between consecutive two-decimal keyframes (m/s)."""
CLEARANCE_MARGIN_M = 0.05
"""Kept between an obstacle's disc and the Jackal's footprint at the start and the goal (m)."""
SAMPLE_STEP_M = 0.05
"""Largest distance between the spline's samples in the clearance check (m); the samples must
clear the footprints by half of it more, so that the path between them does too."""
MAX_DRAWS = 1000
"""Paths drawn for one pool entry before generation gives up."""


def generate_dynabarn(count: int, seed: int, difficulty: str | None = None) -> list[Case]:
    """`count` worlds named `dynabarn_{seed}_{difficulty}_{k:03d}`: all of `difficulty`, or
    (without it) the first ceil(count / 3) easy, then medium, then hard, as DynaBARN numbers
    them. The same arguments give the same documents; each third draws from its own generator,
    so the easy worlds of a mixed call are those of a call for easy alone."""
    if difficulty is not None and difficulty not in DIFFICULTIES:
        raise ValueError(f"difficulty must be one of {DIFFICULTIES}, got {difficulty!r}")
    thirds = [difficulty] * count if difficulty else [DIFFICULTIES[3 * k // count] for k in range(count)]
    rngs = {name: np.random.default_rng((seed, DIFFICULTIES.index(name))) for name in set(thirds)}
    pools = {name: path_pool(rng, THIRDS[name]) for name, rng in rngs.items()}
    return [
        _world(f"dynabarn_{seed}_{name}_{k:03d}", name, rngs[name], pools[name])
        for k, name in enumerate(thirds)
    ]


def _world(name: str, difficulty: str, rng: np.random.Generator, pool: list[np.ndarray]) -> Case:
    """One world: an obstacle count drawn from the third's range and that many distinct paths of
    `pool` (arena-frame keyframes)."""
    low, high = THIRDS[difficulty].obstacles
    chosen = rng.choice(len(pool), size=int(rng.integers(low, high + 1)), replace=False)
    paths = [pool[int(i)] for i in chosen]
    mean = float(np.mean(np.concatenate([keyframe_speeds(p) for p in paths])))
    description = (
        f"DynaBARN-style {difficulty} world: {len(paths)} moving cylinders, "
        f"mean keyframe speed {mean:.2f} m/s"
    )
    obstacles = [moving_cylinder(p.tolist()) for p in paths]
    return Case(name, layout_document(name, description, obstacles))


def path_pool(rng: np.random.Generator, third: Third) -> list[np.ndarray]:
    """POOL_SIZE valid paths of the third, each (K, 3) keyframes [t_s, x_m, y_m], arena frame."""
    return [_valid_path(rng, third) for _ in range(POOL_SIZE)]


def _valid_path(rng: np.random.Generator, third: Third) -> np.ndarray:
    """The first drawn path whose keyframes are valid (`_acceptable`)."""
    for _ in range(MAX_DRAWS):
        points = path_points(rng, int(rng.integers(third.orders[0], third.orders[1] + 1)))
        if points is None:
            continue
        times = np.round(keyframe_times(rng, points, third), 2)
        frames = np.column_stack((times, np.round(points + np.asarray(GAZEBO_TO_ARENA_M), 2)))
        if _acceptable(frames):
            return frames
    raise RuntimeError(f"no valid DynaBARN path in {MAX_DRAWS} draws")


def path_points(rng: np.random.Generator, order: int) -> np.ndarray | None:
    """A path's keyframe points (K, 2; m, Gazebo frame, two decimals): DynaBARN's polynomial
    through order + 1 random integer points, entering and leaving on the square's border; None
    when every point has x = 0 (no fit: DynaBARN's fit raises and it draws again)."""
    anchors = rng.integers(-HALF_SIDE_M, HALF_SIDE_M + 1, size=(order + 1, 2)).astype(float)
    if not anchors[:, 0].any():
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", np.exceptions.RankWarning)  # anchors sharing an x
        coeffs = np.polyfit(anchors[:, 0], anchors[:, 1], order)
    xs = np.concatenate((np.linspace(-HALF_SIDE_M, HALF_SIDE_M, GRID_POINTS), [HALF_SIDE_M, -HALF_SIDE_M]))
    candidates = np.vstack(
        (
            np.column_stack((xs[:GRID_POINTS], np.polyval(coeffs, xs[:GRID_POINTS]))),
            anchors,
            _crossings(coeffs, HALF_SIDE_M),
            _crossings(coeffs, -HALF_SIDE_M),
            np.column_stack((xs[GRID_POINTS:], np.polyval(coeffs, xs[GRID_POINTS:]))),
        )
    )
    inside = np.round(candidates[(np.abs(candidates) <= HALF_SIDE_M).all(axis=1)], 2) + 0.0
    unique = _sorted_by_x(np.array(list(dict.fromkeys(map(tuple, inside.tolist())))))
    on_border = (np.abs(unique) == HALF_SIDE_M).any(axis=1)
    border = unique[on_border]
    while len(border) < 2:
        border = np.vstack((border, _border_point(rng)))
    path = np.vstack((border[:1], unique[~on_border], border[-1:]))
    return path[::-1] if rng.random() < 0.5 else path


def _crossings(coeffs: np.ndarray, level: float) -> np.ndarray:
    """The points (x, level) where the polynomial of `coeffs` (highest power first) equals `level`
    (m); none unless every solution is real."""
    shifted = coeffs.copy()
    shifted[-1] -= level
    roots = np.roots(shifted)
    if np.any(np.imag(roots) != 0):
        return np.empty((0, 2))
    return np.column_stack((np.real(roots), np.full(len(roots), level)))


def _border_point(rng: np.random.Generator) -> np.ndarray:
    """A random point (1, 2; m, two decimals) on a random side of the square."""
    along = round(float(rng.uniform(-HALF_SIDE_M, HALF_SIDE_M)), 2)
    side = HALF_SIDE_M * float(rng.choice((-1.0, 1.0)))
    return np.array([[side, along]] if rng.random() < 0.5 else [[along, side]])


def _sorted_by_x(points: np.ndarray) -> np.ndarray:
    """The points in order of x (stable)."""
    return points[np.argsort(points[:, 0], kind="stable")]


def keyframe_times(rng: np.random.Generator, points: np.ndarray, third: Third) -> np.ndarray:
    """Times (K,; s) at the path's points: chord / a speed per segment drawn as DynaBARN draws it
    (`segment_speeds`), cumulated from 0."""
    chords = np.hypot(*np.diff(points, axis=0).T)
    return np.concatenate(([0.0], np.cumsum(chords / segment_speeds(rng, len(chords), third))))


def segment_speeds(rng: np.random.Generator, count: int, third: Third) -> np.ndarray:
    """`count` speeds (m/s) of one path: a mean and a spread drawn for the path, each speed from
    the third's grid weighted by the normal density of that mean and spread."""
    low, high = third.speed_m_s
    grid = np.round(low + SPEED_STEP_M_S * np.arange(round((high - low) / SPEED_STEP_M_S)), 1)
    mean = round(float(rng.uniform(low, high)), 1)
    spread = round(float(rng.uniform(*third.spread_m_s)), 2)
    weights = np.exp(-0.5 * ((grid - mean) / spread) ** 2)
    return rng.choice(grid, size=count, p=weights / weights.sum())


def keyframe_speeds(keyframes: np.ndarray) -> np.ndarray:
    """Speeds (m/s) between consecutive keyframes [t_s, x_m, y_m]: chord / time."""
    steps = np.diff(np.asarray(keyframes, float), axis=0)
    return np.hypot(steps[:, 1], steps[:, 2]) / steps[:, 0]


def _acceptable(frames: np.ndarray) -> bool:
    """Times strictly increasing, every keyframe speed in KEYFRAME_SPEED_M_S, and the swept discs
    clear of the start and the goal."""
    if not (np.diff(frames[:, 0]) > 0).all():
        return False
    speeds = keyframe_speeds(frames)
    if not ((speeds >= KEYFRAME_SPEED_M_S[0]) & (speeds <= KEYFRAME_SPEED_M_S[1])).all():
        return False
    return bool(robot_clearance(frames) >= OBSTACLE_RADIUS_M + CLEARANCE_MARGIN_M + SAMPLE_STEP_M / 2)


def robot_clearance(frames: np.ndarray) -> float:
    """Least distance (m) from the obstacle's centre, over its whole loop (spline, sampled at
    most SAMPLE_STEP_M apart), to the Jackal's footprint facing -x at the start or the goal."""
    path = Motion(tuple(map(tuple, frames.tolist())), loop=False)  # so the last keyframe's time is its end
    centres = path.position(sample_times(frames))
    half = np.abs(np.asarray(robot_profile(PROFILE).footprint_m, float)).max(axis=0)
    gaps = [
        np.hypot(*np.maximum(np.abs(centres - np.asarray(place)) - half, 0.0).T)
        for place in (START_M, GOAL_M)
    ]
    return float(np.min(gaps))


def sample_times(frames: np.ndarray) -> np.ndarray:
    """Motion times (s) over the loop at which the spline's positions lie at most SAMPLE_STEP_M
    apart: per segment, enough even fractions for the fastest its cubic can run (three times
    its longest Bezier control leg)."""
    times, points = frames[:, 0], frames[:, 1:]
    tangents = catmull_rom_tangents(points)
    legs = np.stack(
        (tangents[:-1] / 3, np.diff(points, axis=0) - (tangents[:-1] + tangents[1:]) / 3, tangents[1:] / 3)
    )
    counts = np.ceil(3 * np.hypot(legs[..., 0], legs[..., 1]).max(axis=0) / SAMPLE_STEP_M).astype(int) + 1
    segment = np.repeat(np.arange(len(counts)), counts)
    fraction = (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)) / (
        counts[segment] - 1
    )
    return times[segment] + fraction * np.diff(times)[segment]
