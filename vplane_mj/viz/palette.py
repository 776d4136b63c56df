"""The colours and legend marks that every picture of a run shares: render, video and plots.

Defined once here, so that the pictures cannot drift apart. The hues are Okabe and Ito's
palette, told apart with every common colour-vision deficiency; obstacles are a neutral dark
grey that no path shares; the marks that share black differ by shape (a dashed line, a cross,
an arrowhead, a rim). Colours are RGBA in [0, 1], as MuJoCo and matplotlib take them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

RGBA = tuple[float, float, float, float]


def _hex(code: str) -> RGBA:
    """An opaque colour from its `#RRGGBB` code."""
    red, green, blue = (int(code[k : k + 2], 16) / 255 for k in (1, 3, 5))
    return (red, green, blue, 1.0)


BLACK = _hex("#000000")
WHITE = _hex("#FFFFFF")
ORANGE = _hex("#E69F00")
SKY_BLUE = _hex("#56B4E9")
BLUISH_GREEN = _hex("#009E73")
YELLOW = _hex("#F0E442")
BLUE = _hex("#0072B2")
VERMILLION = _hex("#D55E00")
REDDISH_PURPLE = _hex("#CC79A7")
DARK_GREY = _hex("#505050")
"""Obstacles and border walls."""
GREY = _hex("#999999")
"""The robot, and a path in a mode without a colour of its own."""

Swatch = Literal["area", "disc", "dot", "line", "dashes", "fading", "cross", "arrow", "outline"]
"""The shape of a mark's legend swatch: a filled square, a disc, a small dot, a line, a dashed
line, a line fading from white, a cross, an arrowhead, a square's outline."""


@dataclass(frozen=True)
class Mark:
    """One kind of mark a picture draws: its legend label, its colour, the shape of its legend
    swatch and the colour of its rim (None: no rim)."""

    label: str
    rgba: RGBA
    swatch: Swatch
    rim: RGBA | None = None


MODE_RGBA: dict[str, RGBA] = {
    "normal": VERMILLION,
    "avoiding": ORANGE,
    "escaping": BLUE,
    "trapped": REDDISH_PURPLE,
    "following": BLUISH_GREEN,
}
"""A path's colour by the planner's mode; any other mode is OTHER_MODE_RGBA."""
OTHER_MODE_RGBA = GREY

OBSTACLE = Mark("obstacle", DARK_GREY, "area")
MOVING_OBSTACLE = Mark("moving obstacle", DARK_GREY, "area")
START = Mark("start", WHITE, "disc", rim=BLACK)
GOAL = Mark("goal (tolerance)", YELLOW, "disc")
DIRECTION = Mark("direction of travel", BLACK, "arrow")
OBJECTIVE = Mark("virtual objective", SKY_BLUE, "disc", rim=BLACK)
PLANE = Mark("virtual plane", BLACK, "dashes")
COLLISION = Mark("collision", BLACK, "cross")
ROBOT = Mark("robot", GREY, "area", rim=BLACK)
ECHO = Mark("echo", BLACK, "dot")
CLOSEST = Mark("closest to the robot", BLACK, "outline")
TRACE_RGBA = DARK_GREY
"""A moving obstacle's trace or trail: its own colour, fading with age."""
FORCE_RGBA: dict[str, RGBA] = {
    "attractive": YELLOW,  # toward the goal, in the goal's colour
    "repulsive": DARK_GREY,  # away from the obstacles, in theirs
    "virtual": SKY_BLUE,  # the virtual objective's and plane's pull and push
    "total": WHITE,
}
"""The force arrows' colours by the `/forces` name; every arrow has a black rim."""


def path_mark(mode: str) -> Mark:
    """The mark of a path in planner mode `mode`: "path: MODE", in its colour."""
    return Mark(f"path: {mode}", MODE_RGBA.get(mode, OTHER_MODE_RGBA), "line")


def force_mark(name: str) -> Mark:
    """The mark of the force arrow `name` (attractive, repulsive, virtual or total)."""
    return Mark(f"force: {name}", FORCE_RGBA[name], "arrow", rim=BLACK)


def trace_mark(label: str) -> Mark:
    """The mark of the moving obstacles' traces (render) or trails (video), labelled `label`."""
    return Mark(label, TRACE_RGBA, "fading")
