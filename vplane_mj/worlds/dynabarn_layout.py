"""The DynaBARN layout in arena coordinates (docs/interface.md section 7, docs/dynabarn.md).

What `vplane-mj generate dynabarn` writes and what `vplane-mj import dynabarn` turns DynaBARN's
Gazebo worlds into (Nair, Xiao et al., "DynaBARN: Benchmarking Metric Ground Navigation in
Dynamic Environments", SSRR 2022; the BARN challenge runs them as its worlds 300-359): an open
23 x 22 m plane without border walls, moving cylinders of radius 0.5 m whose keyframes lie in
the square [1, 21] x [1, 21], the Jackal starting just outside the square's east side facing
west, its goal 20 m ahead, 1 m inside the west side. Every motion loops, is interpolated as
Gazebo's PoseAnimation does, and starts at a phase drawn from the run's seed: the harness's
robot starts seconds after Gazebo set the obstacles moving, at no fixed point of their loops.
"""

from __future__ import annotations

ARENA_SIZE_M = (23.0, 22.0)
"""The arena [0, W] x [0, H] (m); it has no border walls."""
GAZEBO_TO_ARENA_M = (11.0, 11.0)
"""Gazebo (x, y) + this = arena (x, y) (m)."""
SQUARE_M = (1.0, 21.0)
"""The obstacles' keyframes lie in this range on both axes (m, arena frame): Gazebo's
[-10, 10] x [-10, 10]."""
OBSTACLE_RADIUS_M = 0.5
"""Every DynaBARN obstacle is a cylinder of this radius (m), 1 m tall in Gazebo."""
START_M, START_YAW_DEG = (22.0, 11.0), 180.0
GOAL_M, GOAL_TOLERANCE_M = (2.0, 11.0), 1.0
TIME_LIMIT_S = 100.0
PROFILE = "jackal"
DIFFICULTIES = ("easy", "medium", "hard")
"""DynaBARN's thirds: its worlds 0-19, 20-39 and 40-59."""


def to_arena(x: float, y: float) -> tuple[float, float]:
    """A Gazebo point of a DynaBARN world in arena coordinates (m), rounded to the micrometre."""
    return round(x + GAZEBO_TO_ARENA_M[0], 6), round(y + GAZEBO_TO_ARENA_M[1], 6)


def moving_cylinder(keyframes: list[list[float]], radius: float = OBSTACLE_RADIUS_M) -> dict:
    """A `[[world.obstacles]]` table of the layout: a cylinder that follows `keyframes`
    ([t_s, x_m, y_m], arena frame) in a loop, as Gazebo's PoseAnimation, from a random phase."""
    return {
        "kind": "cylinder",
        "radius": radius,
        "motion": {
            "keyframes": [[float(t), float(x), float(y)] for t, x, y in keyframes],
            "loop": True,
            "interpolation": "spline",
            "phase_s": "random",
        },
    }


def layout_document(name: str, description: str, obstacles: list[dict]) -> dict:
    """A scenario document of the DynaBARN layout with these (moving) obstacles."""
    return {
        "format": 1,
        "name": name,
        "description": description,
        "world": {"size": list(ARENA_SIZE_M), "border": False, "obstacles": obstacles},
        "robot": {
            "profile": PROFILE,
            "start": list(START_M),
            "start_yaw_deg": START_YAW_DEG,
            "goal": list(GOAL_M),
            "goal_tolerance": GOAL_TOLERANCE_M,
        },
        "run": {"time_limit_s": TIME_LIMIT_S},
    }
