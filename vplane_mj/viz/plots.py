"""Matplotlib figure of a run from its MCAP log: the map, the potential field, time series.

`draw_world`, `draw_path` and `label_modes` are public: they draw a scenario's world and a
path coloured by planner mode on any matplotlib axes (examples/paper_figures.py uses them).
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Iterable, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, never a window
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.patches import Circle, Polygon

from vplane_mj.geometry import shapes
from vplane_mj.logs.reader import LogContents, iter_messages
from vplane_mj.logs.writer import METADATA_NAME
from vplane_mj.planning.motion import fields
from vplane_mj.planning.planners.groups import FieldParams
from vplane_mj.planning.protocol.events import EventKind
from vplane_mj.scenario import Scenario
from vplane_mj.sim.loop import Track
from vplane_mj.viz import palette
from vplane_mj.viz.palette import MODE_RGBA, OTHER_MODE_RGBA

FIELD_HALF_WIDTH_M = 2.0
"""Half the side of the square around the local minimum where the field is drawn."""
BOUNDARY_STEP_M = 0.05
"""Spacing of the obstacle boundary points that stand in for sonar echoes in the field."""
PATH_ZORDER = 1.9
"""A path lies above the obstacles and the goal (zorder 1), below the markers (2), whatever the
order they are drawn in."""


def plot_log(path: Path, contents: LogContents, scenario: Scenario, track: Track) -> plt.Figure:
    """Three panels: map with path and events, APF field at the first local minimum, time series."""
    figure = plt.figure(figsize=(15, 5.5))
    grid = figure.add_gridspec(2, 3, height_ratios=[1, 1])
    map_axes = figure.add_subplot(grid[:, 0])
    field_axes = figure.add_subplot(grid[:, 1])
    speed_axes = figure.add_subplot(grid[0, 2])
    mode_axes = figure.add_subplot(grid[1, 2], sharex=speed_axes)
    _draw_map(map_axes, contents, scenario, track)
    _draw_field(field_axes, contents, scenario)
    _draw_series(speed_axes, mode_axes, path)
    figure.suptitle(f"{scenario.name}, planner {scenario.planner}, seed {scenario.run.seed}")
    figure.tight_layout()
    return figure


def draw_world(axes, scenario: Scenario, margin_m: float = 0.2) -> None:
    """Draw a scenario's world on matplotlib axes, in metres, in the render's colours: the
    obstacles and border walls (dark grey), the start (white dot in a black rim, label "start")
    and the goal (yellow disc of the goal tolerance, label "goal"); equal aspect, the arena and
    the margin around it in view.

    Args:
        axes (matplotlib.axes.Axes): The axes to draw on.
        scenario: The scenario whose world, start and goal are drawn.
        margin_m: Room shown around the arena (m).
    """
    _draw_obstacles(axes, scenario)
    start = palette.START
    axes.plot(
        *scenario.robot.start, "o", mfc=start.rgba, mec=start.rim, mew=1.5, ms=9, label="start", zorder=2.5
    )
    goal = Circle(scenario.robot.goal, scenario.robot.goal_tolerance, color=palette.GOAL.rgba, label="goal")
    axes.add_patch(goal)
    w, h = scenario.world.size
    axes.set(
        xlim=(-margin_m, w + margin_m),
        ylim=(-margin_m, h + margin_m),
        aspect="equal",
        xlabel="x (m)",
        ylabel="y (m)",
    )


def draw_path(axes, positions: np.ndarray, modes: Sequence[str], linewidth: float = 2.0) -> None:
    """Draw a path, each segment in the colour of the planner mode at its start, as the render
    colours them: vermillion `normal`, orange `avoiding`, blue `escaping`, reddish purple
    `trapped`, bluish green `following`, grey any other mode; above the world, below markers.

    Args:
        axes (matplotlib.axes.Axes): The axes to draw on.
        positions: The robot's centre at each tick, (n, 2) in m (`Trajectory.positions`).
        modes: The planner's mode at each tick, n of them (`Trajectory.modes`).
        linewidth: The line's width (points).
    """
    points = np.asarray(positions, float)
    segments = list(np.stack([points[:-1], points[1:]], axis=1))  # (2, 2) arrays, as LineCollection takes
    colours = [MODE_RGBA.get(mode, OTHER_MODE_RGBA) for mode in modes[: len(segments)]]
    axes.add_collection(LineCollection(segments, colors=colours, linewidths=linewidth, zorder=PATH_ZORDER))


def label_modes(axes, modes: Iterable[str]) -> None:
    """Add a legend entry "path: MODE" for each mode that `draw_path` has a colour for, in the
    order normal, avoiding, escaping, trapped, following (shown by the next `axes.legend()`).

    Args:
        axes (matplotlib.axes.Axes): The axes that `draw_path` drew on.
        modes: The modes the path shows (`Trajectory.modes`; repeats count once).
    """
    present = set(modes)
    for mode, rgba in MODE_RGBA.items():
        if mode in present:
            axes.plot([], [], color=rgba, lw=2, label=f"path: {mode}")


def draw_objective(axes, point, labelled: bool, size_pt: float = 8.0) -> None:
    """A virtual new objective at `point` (x, y in m), a disc of `size_pt` points; in the
    legend when `labelled`."""
    objective = palette.OBJECTIVE
    label = objective.label if labelled else None
    axes.plot(*point, "o", mfc=objective.rgba, mec=objective.rim, mew=1.5, ms=size_pt, label=label)


def draw_plane(axes, e1, e2, labelled: bool) -> None:
    """A virtual plane from `e1` to `e2` (x, y in m), dashed; in the legend when `labelled`."""
    plane = palette.PLANE
    label = plane.label if labelled else None
    axes.plot(*zip(e1, e2, strict=True), color=plane.rgba, lw=3, ls="--", label=label)


def draw_local_minimum(axes, where, labelled: bool) -> None:
    """Where (x, y in m) the robot was when a local minimum was detected; in the legend when
    `labelled`."""
    axes.plot(*where, "X", color="black", ms=10, label="local minimum" if labelled else None)


def draw_collision(axes, point, labelled: bool) -> None:
    """A collision's point of contact (x, y in m); in the legend when `labelled`."""
    axes.plot(*point, "k+", ms=12, mew=2, label="collision" if labelled else None)


def _draw_obstacles(axes, scenario: Scenario) -> None:
    pieces = [p for ob in scenario.world.obstacles for p in ob.footprint()]
    if scenario.world.border:
        pieces += list(shapes.border_footprint(scenario.world.size))
    for piece in pieces:
        if isinstance(piece, shapes.Disc):
            axes.add_patch(Circle(piece.center, piece.radius, color=palette.OBSTACLE.rgba))
            continue
        axes.add_patch(Polygon(piece.corners(), color=palette.OBSTACLE.rgba))


def _draw_map(axes, contents: LogContents, scenario: Scenario, track: Track) -> None:
    draw_world(axes, scenario)
    points = track.positions
    draw_path(axes, points, track.modes)
    times = contents.times_ns / 1e9
    minima = [e.time_s for e in contents.events if e.kind is EventKind.LOCAL_MINIMUM]
    for k, t in enumerate(minima):
        draw_local_minimum(axes, points[min(int(np.searchsorted(times, t)), len(points) - 1)], k == 0)
    for k, point in enumerate(track.objectives):
        draw_objective(axes, point, k == 0)
    for k, (e1, e2) in enumerate(track.planes):
        draw_plane(axes, e1, e2, k == 0)
    for k, point in enumerate(track.collision_points):
        draw_collision(axes, point, k == 0)
    label_modes(axes, track.modes)
    axes.set_title("travelled path")
    axes.legend(loc="upper left", fontsize=7)


def _draw_field(axes, contents: LogContents, scenario: Scenario) -> None:
    """The FIRAS total force (eqs. 3, 5, 6) around the first local minimum (or the start).

    Obstacle boundaries sampled every 5 cm stand in for the sonar echoes, so this is the
    field a robot with perfect sensing would follow: the trap that APF falls into. The run's
    field gains when its planner has them, APF's defaults otherwise.
    """
    info = contents.metadata[METADATA_NAME]
    logged = json.loads(info.get("planner_params", "{}"))
    params = {key: logged.get(key, default) for key, default in FieldParams().as_dict().items()}
    times = contents.times_ns / 1e9
    minima = [e.time_s for e in contents.events if e.kind is EventKind.LOCAL_MINIMUM]
    if minima:
        centre = contents.positions[min(int(np.searchsorted(times, minima[0])), len(times) - 1)]
        title = f"APF force at the local minimum, t = {minima[0]:.1f} s"
    else:
        centre = np.asarray(scenario.robot.start, float)
        title = "APF force around the start"
    echoes = _boundary_points(scenario)
    goal = np.asarray(scenario.robot.goal, float)
    xs = np.linspace(centre[0] - FIELD_HALF_WIDTH_M, centre[0] + FIELD_HALF_WIDTH_M, 33)
    ys = np.linspace(centre[1] - FIELD_HALF_WIDTH_M, centre[1] + FIELD_HALF_WIDTH_M, 33)
    footprints = shapes.scene_footprints(
        scenario.world.obstacles, scenario.world.size if scenario.world.border else None
    )
    u, v = np.zeros((len(ys), len(xs))), np.zeros((len(ys), len(xs)))
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            p = np.array([x, y])
            if len(footprints) and footprints.distance(p[None, :])[0] <= 0:
                continue
            near = echoes[np.hypot(*(echoes - p).T) <= params["influence"]] if len(echoes) else echoes
            force = fields.attractive_force(p, goal, params["attract_gain"], params["attract_radius"])
            force = force + fields.repulsive_force(p, near, params["repulse_gain"], params["influence"])
            u[i, j], v[i, j] = force
    magnitude = np.hypot(u, v)
    mesh = axes.pcolormesh(xs, ys, np.log10(magnitude + 1e-3), cmap="magma", shading="auto")
    plt.colorbar(mesh, ax=axes, label="log10 |F|")
    axes.quiver(
        xs,
        ys,
        u / np.maximum(magnitude, 1e-9),
        v / np.maximum(magnitude, 1e-9),
        color="white",
        scale=40,
        width=0.003,
    )
    _draw_obstacles(axes, scenario)
    axes.plot(*centre, "X", color="cyan", ms=12)
    axes.set(xlim=(xs[0], xs[-1]), ylim=(ys[0], ys[-1]), aspect="equal", title=title, xlabel="x (m)")


def _boundary_points(scenario: Scenario) -> np.ndarray:
    """Points every BOUNDARY_STEP_M along the outline of every obstacle piece and border wall."""
    pieces = [p for ob in scenario.world.obstacles for p in ob.footprint()]
    if scenario.world.border:
        pieces += list(shapes.border_footprint(scenario.world.size))
    points = []
    for piece in pieces:
        if isinstance(piece, shapes.Disc):
            n = max(8, math.ceil(2 * math.pi * piece.radius / BOUNDARY_STEP_M))
            a = np.linspace(0, 2 * math.pi, n, endpoint=False)
            points.append(
                np.column_stack(
                    (piece.center[0] + piece.radius * np.cos(a), piece.center[1] + piece.radius * np.sin(a))
                )
            )
            continue
        corners = piece.corners()
        for a, b in itertools.pairwise(np.vstack([corners, corners[:1]])):
            n = max(2, math.ceil(np.hypot(*(b - a)) / BOUNDARY_STEP_M) + 1)
            points.append(a + np.linspace(0, 1, n)[:, None] * (b - a))
    return np.vstack(points) if points else np.empty((0, 2))


def _draw_series(speed_axes, mode_axes, path: Path) -> None:
    metrics = [m.message for m in iter_messages(path, ("/metrics",))]
    t = np.array([m["time_s"] for m in metrics])
    # A value left out (or null, in logs of earlier versions) is a gap.
    speed = np.array([m.get("speed_mps") for m in metrics], dtype=float)
    distance = np.array([m.get("distance_to_goal_m") for m in metrics], dtype=float)
    speed_axes.plot(t, speed, color="#1f77b4", label="speed (m/s)")
    speed_axes.set_ylabel("speed (m/s)")
    twin = speed_axes.twinx()
    twin.plot(t, distance, color="#d62728", label="distance to goal (m)")
    twin.set_ylabel("distance to goal (m)")
    speed_axes.set_title("speed and distance to goal")
    modes = [m["mode"] for m in metrics]
    names = sorted(set(modes), key=lambda m: list(MODE_RGBA).index(m) if m in MODE_RGBA else 99)
    level = np.array([names.index(m) for m in modes])
    mode_axes.step(t, level, where="post", color="black")
    for k, name in enumerate(names):
        mask = level == k
        mode_axes.scatter(t[mask], level[mask], s=4, color=MODE_RGBA.get(name, OTHER_MODE_RGBA))
    mode_axes.set(
        yticks=range(len(names)), yticklabels=names, xlabel="simulated time (s)", title="planner mode"
    )
