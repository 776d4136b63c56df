"""The legend of a run's video: every mark that some frame shows, from the scenario and the
log's timeline, drawn as a strip of columns under the plot."""

from __future__ import annotations

import dataclasses
import math

from matplotlib.figure import Figure

from vplane_mj.logs.timeline import FORCE_NAMES, Timeline
from vplane_mj.scenario import Scenario
from vplane_mj.viz import palette
from vplane_mj.viz.handles import legend_handle
from vplane_mj.viz.palette import Mark

COLUMNS = 4
ROW_FRACTION = 0.027
"""Height of a legend row, as a fraction of the video's width."""
TRAIL = palette.trace_mark("its trail, last 2 s")


def video_marks(scenario: Scenario, timeline: Timeline) -> list[Mark]:
    """The marks of the video of a run: the world's, the path's modes in the order they come,
    the virtual objective and planes, the echoes, the robot and the logged forces, each only
    when some frame shows it."""
    world = scenario.world
    marks = [palette.OBSTACLE] if world.obstacles or world.border else []
    if world.moving and timeline.obstacles is not None:
        marks += [palette.MOVING_OBSTACLE, TRAIL]
    marks += [palette.START, palette.GOAL]
    marks += [palette.path_mark(mode) for mode in dict.fromkeys(timeline.modes[:-1])]
    if any(objective is not None for objective in timeline.objectives):
        marks.append(palette.OBJECTIVE)
    if any(timeline.planes):
        marks.append(palette.PLANE)
    if any(len(echoes) for echoes in timeline.echoes):
        marks.append(dataclasses.replace(palette.ECHO, label=f"{scenario.sensors.kind} echo"))
    marks.append(palette.ROBOT)
    logged = {name for forces in timeline.forces for name in forces}
    return marks + [palette.force_mark(name) for name in FORCE_NAMES if name in logged]


def legend_height_px(marks: list[Mark], width_px: int) -> float:
    """The height (px) of the legend's strip in a video `width_px` wide."""
    return math.ceil(len(marks) / COLUMNS) * ROW_FRACTION * width_px


def draw_legend(figure: Figure, marks: list[Mark], top: float, font_pt: float) -> None:
    """The legend of `marks` in COLUMNS columns, its top at `top` (a fraction of the figure's
    height), its text `font_pt` points high."""
    figure.legend(
        [legend_handle(mark, font_pt) for mark in marks],
        [mark.label for mark in marks],
        loc="upper center",
        bbox_to_anchor=(0.5, top),
        ncols=COLUMNS,
        frameon=False,
        fontsize=font_pt,
        borderaxespad=0.0,
        borderpad=0.2,
        handlelength=1.6,
        handletextpad=0.5,
        columnspacing=1.2,
        labelspacing=0.4,
    )
