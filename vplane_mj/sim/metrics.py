"""The numbers a run is judged by, computed from its path and outcome (no MuJoCo): clearance,
smoothness, the trajectory's digest, the reference path's ratio and the BARN score."""

from __future__ import annotations

import hashlib
import math
from typing import TypedDict

import numpy as np

from vplane_mj.geometry import shapes
from vplane_mj.geometry.reference import shortest_path_length
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.planning.protocol.vectors import wrap_angle
from vplane_mj.scenario import Scenario

CLEARANCE_BATCH = 200
"""Positions collected before one vectorised clearance query (2 s at the 100 Hz motor rate)."""
TURN_NOISE_RAD = 1e-3
"""Heading changes per tick smaller than this do not count as turning (oscillation metric)."""


class Clearance:
    """Smallest and mean distance (m) to any obstacle or border, batched over poses (x, y in m,
    yaw in rad): from base_link's centre, or with `outline` (the robot's footprint polygon in
    base_link, m) from the outline (negative: it overlaps). The robot's own clearance
    (`robot_minimum`, `robot_mean`) is that less `from_centre_m`, a round robot's radius.

    With `moving` (the moving obstacles' pieces as `shapes.moving_distances` takes them),
    each pose comes with where those stood then, and counts them too; `moving_minimum` is the
    smallest over them alone."""

    def __init__(
        self,
        footprints: shapes.Footprints,
        outline: np.ndarray | None = None,
        from_centre_m: float = 0.0,
        moving: tuple[np.ndarray, np.ndarray] | None = None,
    ):
        self._footprints = footprints
        self._outline = outline
        self._from_centre = from_centre_m
        self._moving = moving
        self._pending: list[np.ndarray] = []
        self._pending_places: list[np.ndarray] = []
        self._pending_count = 0
        self.minimum = math.inf
        self.moving_minimum = math.inf
        self._total = 0.0
        self._count = 0

    @property
    def mean(self) -> float:
        return self._total / self._count if self._count else math.inf

    @property
    def robot_minimum(self) -> float:
        """The robot's smallest clearance (m; inf before any pose or without obstacles)."""
        return self.minimum - self._from_centre

    @property
    def robot_mean(self) -> float:
        """The robot's mean clearance (m; inf before any pose or without obstacles)."""
        return self.mean - self._from_centre

    @property
    def robot_moving_minimum(self) -> float:
        """The robot's smallest clearance to the moving obstacles (m; inf without any)."""
        return self.moving_minimum - self._from_centre

    def add(self, poses: np.ndarray, places: np.ndarray | None = None) -> None:
        """Poses (N, 3) of the robot, or positions (N, 2) of a robot measured from its centre;
        with moving obstacles, where their centres stood at each (N, count, 2; m)."""
        self._pending.append(poses)
        if self._moving is not None:
            assert places is not None, "a world with moving obstacles: poses come with their places"
            self._pending_places.append(places)
        self._pending_count += len(poses)
        if self._pending_count >= CLEARANCE_BATCH:
            self.flush()

    def flush(self) -> None:
        if self._pending and (len(self._footprints) or self._moving is not None):
            poses = np.vstack(self._pending)
            distances = np.full(len(poses), np.inf)
            if len(self._footprints):
                if self._outline is None:
                    distances = self._footprints.distance(poses[:, :2])
                else:
                    distances = self._footprints.outline_distance(self._outline, poses)
            if self._moving is not None:
                places = np.concatenate(self._pending_places)
                moving = shapes.moving_distances(*self._moving, places, poses, self._outline)
                self.moving_minimum = min(self.moving_minimum, float(moving.min()))
                distances = np.minimum(distances, moving)
            self.minimum = min(self.minimum, float(distances.min()))
            self._total += float(distances.sum())
            self._count += len(distances)
        self._pending.clear()
        self._pending_places.clear()
        self._pending_count = 0


def robot_clearance(
    scenario: Scenario, body: RobotBody, radius_m: float, moving: tuple[np.ndarray, np.ndarray] | None = None
) -> Clearance:
    """The clearance of the scenario's robot among its obstacles and border, and its `moving`
    obstacles' pieces (packed as `shapes.moving_distances` takes them): from its footprint
    polygon, or for a round robot from its centre less `radius_m` (m)."""
    world = scenario.world
    footprints = shapes.scene_footprints(world.obstacles, world.size if world.border else None)
    if body.disc:
        return Clearance(footprints, None, radius_m, moving)
    return Clearance(footprints, body.footprint, moving=moving)


class MotionQuality(TypedDict):
    """The summary's keys for how the robot moved (`motion_quality`)."""

    smoothness_rad_per_m: float | None
    oscillation_per_m: float | None


class PathQuality(TypedDict):
    """The summary's keys for the path against the reference path (`path_quality`)."""

    reference_length_m: float | None
    optimal_length_m: float | None
    path_ratio: float | None
    score: float | None
    score_path_m: float | None
    score_path_source: str | None


def motion_quality(yaws: np.ndarray, path_length: float) -> MotionQuality:
    """Smoothness: total absolute heading change per metre travelled (rad/m); oscillation:
    reversals of the turning direction per metre (1/m). None when the robot did not move."""
    if len(yaws) < 2 or path_length < 1e-6:
        return {"smoothness_rad_per_m": None, "oscillation_per_m": None}
    turns = wrap_angle(np.diff(yaws))
    signs = np.sign(turns[np.abs(turns) > TURN_NOISE_RAD])
    reversals = int(np.count_nonzero(np.diff(signs)))
    return {
        "smoothness_rad_per_m": float(np.sum(np.abs(turns))) / path_length,
        "oscillation_per_m": reversals / path_length,
    }


def trajectory_digest(positions: list[np.ndarray], final: np.ndarray, final_yaw: float) -> str:
    """SHA-256 of the positions at every control tick and the final pose, bit for bit:
    equal digests mean identical trajectories (the determinism check of bench sweeps)."""
    digest = hashlib.sha256()
    for position in positions:
        digest.update(np.asarray(position, dtype=np.float64).tobytes())
    digest.update(np.array([final[0], final[1], final_yaw], dtype=np.float64).tobytes())
    return digest.hexdigest()


def path_quality(
    scenario: Scenario,
    radius: float,
    success: bool,
    path_length: float,
    time_to_goal: float | None,
    top_speed_mps: float,
) -> PathQuality:
    """The reference shortest path to the goal (for a robot that needs `radius`, m, of room on
    each side), the part of it to the goal tolerance disc, the path length over that part, and
    the BARN score (`barn_score`), whose OT is the whole reference path over the top speed, as
    BARN's own OT runs to the goal point, or the world's own path (`WorldSpec.score_path_m`, a
    BARN world's): `score_path_m` and `score_path_source` ("world" or "reference") say which."""
    reference = shortest_path_length(scenario, radius)
    optimal = None if reference is None else max(reference - scenario.robot.goal_tolerance, 0.0)
    ratio = path_length / optimal if time_to_goal is not None and optimal else None
    own = scenario.world.score_path_m
    score_path = reference if own is None else own
    return {
        "reference_length_m": reference,
        "optimal_length_m": optimal,
        "path_ratio": ratio,
        "score": barn_score(success, score_path, time_to_goal, top_speed_mps),
        "score_path_m": score_path,
        "score_path_source": "world" if own is not None else None if reference is None else "reference",
    }


def barn_score(
    success: bool, reference_length_m: float | None, time_to_goal_s: float | None, top_speed_mps: float
) -> float | None:
    """The BARN benchmark's score (Perille et al. 2020; Xiao et al. 2022): success x OT / clip(T,
    2 OT, 8 OT), with OT the reference path length (m) over the top speed (m/s) and T the time to
    goal (s). In [1/8, 1/2] for a success, 0 otherwise; None when no reference path exists."""
    if reference_length_m is None:
        return None
    if not success or time_to_goal_s is None:
        return 0.0
    optimal_time = reference_length_m / top_speed_mps
    if optimal_time <= 0:
        return 0.5  # the run began within the goal tolerance
    return optimal_time / min(max(time_to_goal_s, 2 * optimal_time), 8 * optimal_time)
