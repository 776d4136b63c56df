"""The BARN challenge's layout in arena coordinates (docs/barn.md, docs/interface.md section 6).

What `vplane-mj generate barn --protocol` writes and what `vplane-mj import barn` turns BARN's
Gazebo worlds into: a 4.2 x 14 m arena with its border, an obstacle field of 0.15 m cells
filling y in [4.95, 9.6], the start 2.85 m up facing +y, the goal 10 m ahead of it, the Jackal
robot profile. Worlds of this layout are kept only when the Jackal can get through, checked with
the project's reference path (`vplane_mj.geometry.reference`) for a disc of the Jackal's half diagonal.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from vplane_mj.robots.profiles import robot_profile

if TYPE_CHECKING:
    from vplane_mj.scenario import Scenario

ARENA_SIZE_M = (4.2, 14.0)
"""The free arena [0, W] x [0, H] (m), with border walls just outside it."""
CELL_M = 0.15
"""Side of one obstacle cell (m); a cell's cylinder has radius CELL_M / 2 (0.075 m)."""
FIELD_Y_M = (4.95, 9.6)
"""The obstacle field spans the arena's whole width and y in this range (m)."""
FIELD_COLUMNS = round(ARENA_SIZE_M[0] / CELL_M)
"""Cells across the field (28)."""
FIELD_ROWS = round((FIELD_Y_M[1] - FIELD_Y_M[0]) / CELL_M)
"""Cells along the field (31)."""
START_M, START_YAW_DEG = (2.1, 2.85), 90.0
GOAL_M, GOAL_TOLERANCE_M = (2.1, 12.85), 1.0
TIME_LIMIT_S = 100.0
PROFILE = "jackal"
"""The robot profile of the challenge's robot, a Clearpath Jackal."""

JACKAL_RADIUS_M = robot_profile(PROFILE).footprint_radius_m() or 0.0
"""Half the Jackal's diagonal (0.333 m): the disc that covers its outline at any heading, the
size a world of this layout must let through."""

GAZEBO_START_M, GAZEBO_GOAL_M = (-2.25, 3.0), (-2.25, 13.0)
"""Where BARN's Gazebo worlds place the start and the goal (m)."""
GAZEBO_TO_ARENA_M = (START_M[0] - GAZEBO_START_M[0], START_M[1] - GAZEBO_START_M[1])
"""Gazebo (x, y) + this = arena (x, y): the translation (4.35, -0.15) m that takes BARN's start
to START_M, and its goal, 10 m straight ahead of it as GOAL_M is of START_M, to GOAL_M."""


def to_arena(x: float, y: float) -> tuple[float, float]:
    """A Gazebo point of a BARN world in arena coordinates (m), rounded to the micrometre."""
    return round(x + GAZEBO_TO_ARENA_M[0], 6), round(y + GAZEBO_TO_ARENA_M[1], 6)


def cell_center(row: int, column: int) -> list[float]:
    """Centre (m) of the field's cell `row` along y (0 nearest the start), `column` across x."""
    return [round((column + 0.5) * CELL_M, 6), round(FIELD_Y_M[0] + (row + 0.5) * CELL_M, 6)]


def layout_document(name: str, description: str, obstacles: list[dict]) -> dict:
    """A scenario document of the challenge's layout with these obstacles."""
    return {
        "format": 1,
        "name": name,
        "description": description,
        "world": {"size": list(ARENA_SIZE_M), "border": True, "obstacles": obstacles},
        "robot": {
            "profile": PROFILE,
            "start": list(START_M),
            "start_yaw_deg": START_YAW_DEG,
            "goal": list(GOAL_M),
            "goal_tolerance": GOAL_TOLERANCE_M,
        },
        "run": {"time_limit_s": TIME_LIMIT_S},
    }


def jackal_reference_length(scenario: Scenario) -> float | None:
    """The reference path length (m) from start to goal for a disc of JACKAL_RADIUS_M, or None
    when the Jackal cannot get through."""
    from vplane_mj.geometry.reference import shortest_path_length

    return shortest_path_length(scenario, JACKAL_RADIUS_M)
