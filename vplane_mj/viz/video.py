"""A run replayed from its MCAP log alone as a top-down video (H.264 MP4 or GIF).

Each frame shows the arena and its obstacles around the start, the goal and the path
(the whole arena when that is most of it), start and goal, the path so far coloured by
planner mode, the virtual planes and objective, the moving obstacles where they stand with
their trails of the last `TRAIL_S` (fading with age), the sensor's echoes, the force arrows as
logged, the robot's footprint and heading, a legend of every mark the video shows, the latest
events as a caption and the simulated time; in the colours of the render
(`vplane_mj.viz.palette`).
Frame k shows the last control tick at or before k * speed / fps simulated seconds; the
last frame is held for `END_HOLD_S` so the end can be seen. Matplotlib (Agg) draws
the frames, blitting everything that moves over a cached background; imageio-ffmpeg's
own ffmpeg encodes them, so no system package is needed.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, never a window
import imageio_ffmpeg
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch, Polygon
from matplotlib.transforms import Bbox

from vplane_mj.errors import VPlaneError
from vplane_mj.files import write_atomically
from vplane_mj.geometry import shapes
from vplane_mj.geometry.motion import Moving
from vplane_mj.logs.replay import load_log
from vplane_mj.logs.timeline import FORCE_NAMES, Timeline, timeline_from_log
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import Scenario
from vplane_mj.terminal import Progress
from vplane_mj.viz import palette
from vplane_mj.viz.moving_marks import TRACE_JUMP_M
from vplane_mj.viz.palette import MODE_RGBA, OTHER_MODE_RGBA, TRACE_RGBA, Mark
from vplane_mj.viz.video_legend import draw_legend, legend_height_px, video_marks


@dataclass(frozen=True)
class VideoFormat:
    """How one kind of file is encoded: frame rate, frame width (px) and ffmpeg options."""

    fps: int
    width_px: int
    codec: str
    pix_fmt: str
    options: tuple[str, ...]


FORMATS = {
    ".mp4": VideoFormat(25, 720, "libx264", "yuv420p", ("-preset", "veryfast", "-crf", "26", "-f", "mp4")),
    # One palette for the whole GIF, from every frame whole (counting only what changes would
    # leave out the colours of the legend and of what is drawn once, the path's), a dither
    # without noise.
    ".gif": VideoFormat(
        10,
        480,
        "gif",
        "pal8",
        (
            "-filter_complex",
            "split[a][b];[a]palettegen=max_colors=64:stats_mode=full[p];"
            "[b][p]paletteuse=dither=bayer:bayer_scale=5:diff_mode=rectangle",
            "-loop",
            "0",
            "-f",
            "gif",
        ),
    ),
}
"""Supported output suffixes."""
MAX_SPEED = 1000.0
MAX_FRAMES = 40_000
"""About 27 minutes of MP4: a longer video needs a higher --speed."""
END_HOLD_S = 1.0
"""Video seconds for which the last frame is held."""
CAPTION_HOLD_S = 2.5
"""Video seconds for which an event stays in the caption."""
CAPTION_LINES = 2
VIEW_MARGIN_M = 1.2
"""Shown around the start, the goal and the path."""
WALL_MARGIN_M = 0.3
"""Shown beyond the arena's sides (where the border walls stand)."""
TRAIL_S = 2.0
"""Simulated seconds of a moving obstacle's trail."""


def video_format(path: Path) -> VideoFormat:
    """The format of an output file by its suffix; VPlaneError for any other."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise VPlaneError(f"{path}: -o must end in {' or '.join(FORMATS)}")
    return fmt


def check_speed(speed: float) -> float:
    """A playback speed (simulated seconds per video second) in (0, MAX_SPEED]."""
    if not (math.isfinite(speed) and 0 < speed <= MAX_SPEED):
        raise VPlaneError(f"--speed: must be greater than 0 and at most {MAX_SPEED:g}, got {speed:g}")
    return speed


def frame_count(duration_s: float, speed: float, fps: int) -> tuple[int, int]:
    """(frames of the run, frames of the final hold) for a run of `duration_s` simulated seconds."""
    return math.floor(duration_s / speed * fps + 1e-9) + 1, round(END_HOLD_S * fps)


def write_video(log: Path, target: Path, speed: float = 1.0, show_progress: bool = True) -> Path:
    """Replay the run of `log` into `target` (.mp4 or .gif), written atomically."""
    fmt = video_format(target)
    check_speed(speed)
    contents, scenario = load_log(log)
    timeline = timeline_from_log(log, contents)
    frames, hold = frame_count(float(timeline.times_s[-1]), speed, fmt.fps)
    if frames > MAX_FRAMES:
        raise VPlaneError(
            f"--speed: {frames} frames at {speed:g}x is too long a video (at most {MAX_FRAMES}); "
            "raise --speed"
        )
    canvas = FrameCanvas(scenario, timeline, fmt.width_px, speed)
    progress = Progress(target.name, frames + hold, "frames") if show_progress else None

    def encode(temporary: Path) -> None:
        writer = imageio_ffmpeg.write_frames(
            str(temporary),
            canvas.size,
            fps=fmt.fps,
            codec=fmt.codec,
            pix_fmt_in="rgba",
            pix_fmt_out=fmt.pix_fmt,
            quality=None,
            macro_block_size=1,
            output_params=list(fmt.options),
        )
        writer.send(None)
        try:
            with progress or contextlib.nullcontext():
                frame = b""
                for k in range(frames + hold):
                    if k < frames:
                        frame = canvas.frame(k * speed / fmt.fps)
                    writer.send(frame)
                    if progress:
                        progress.advance()
        finally:
            writer.close()  # ffmpeg finishes the file (or is stopped, on an interruption)

    try:
        return write_atomically(target, encode)
    finally:
        plt.close(canvas.figure)


class FrameCanvas:
    """The figure of one run: a static background drawn once, the moving parts per frame."""

    def __init__(self, scenario: Scenario, timeline: Timeline, width_px: int, speed: float):
        self.timeline = timeline
        self.speed = speed
        marks = video_marks(scenario, timeline)
        (x0, x1), (y0, y1) = view = _view(scenario, timeline)
        aspect = min(max((y1 - y0) / (x1 - x0), 0.5), 1.6)
        top_px, bottom_px = round(0.06 * width_px), round(0.09 * width_px)  # title and time; caption
        plot_px, legend_px = 0.98 * width_px * aspect, legend_height_px(marks, width_px)
        height_px = 2 * round((top_px + plot_px + legend_px + bottom_px) / 2)  # even, as H.264 wants
        self.size = (width_px, height_px)
        self.figure = plt.figure(figsize=(width_px / 100, height_px / 100), dpi=100)
        top, bottom = 1 - top_px / height_px, bottom_px / height_px
        legend_top = (bottom_px + legend_px) / height_px
        axes = self.figure.add_axes((0.01, legend_top, 0.98, top - legend_top))
        axes.set(xlim=view[0], ylim=view[1], aspect="equal", anchor="C")
        axes.set_axis_off()
        self.axes = axes
        _draw_world(axes, scenario)
        font = max(7.0, width_px / 70)
        draw_legend(self.figure, marks, legend_top, font * 0.9)
        self.figure.text(
            0.02,
            (1 + top) / 2,
            f"{scenario.name}, {scenario.planner}, seed {scenario.run.seed}",
            va="center",
            fontsize=font,
            weight="bold",
        )
        self._animated: list[Artist] = []
        self._add_run_artists(scenario, timeline, font)
        self.clock = self.figure.text(
            0.98, (1 + top) / 2, "", ha="right", va="center", fontsize=font, family="monospace"
        )
        self._animated.append(self.clock)
        self.caption = self.figure.text(0.5, bottom / 2, "", ha="center", va="center", fontsize=font * 0.9)
        self.caption.set_animated(True)
        self._caption_box = Bbox([[0, 0], [width_px, bottom_px]])
        for artist in self._animated:
            artist.set_animated(True)
        canvas = self.figure.canvas
        assert isinstance(canvas, FigureCanvasAgg)  # the backend chosen above: blitting, pixels
        self.canvas = canvas
        canvas.draw()
        self._background = canvas.copy_from_bbox(self.figure.bbox)
        self._path_drawn = 0  # path segments already in the background
        self._caption_shown: tuple[str, object] | None = None  # the caption text and its pixels

    def _add_run_artists(self, scenario: Scenario, timeline: Timeline, font: float) -> None:
        """What changes from frame to frame, in the order drawn: the path (into the background),
        the virtual planes and objective, the start over them, the moving obstacles, the echoes,
        the robot and its heading, the force arrows."""
        axes = self.axes
        self.path = self._add(LineCollection([], linewidths=2.2, capstyle="round"))
        dashes = (0, (2, 1.2))
        self.planes = self._add(
            LineCollection([], colors=[palette.PLANE.rgba], linewidths=3, linestyles=dashes)
        )
        self.objective = self._add(_disc_marker(axes, palette.OBJECTIVE, font * 1.1))
        self.start = self._add(_disc_marker(axes, palette.START, font * 1.2))
        self.start.set_data([scenario.robot.start[0]], [scenario.robot.start[1]])
        self.moving = None
        if scenario.world.moving and timeline.obstacles is not None:
            self.moving = MovingArtists(axes, scenario.world.moving, timeline.times_s, timeline.obstacles)
            self._animated += self.moving.artists
        self.echoes = self._add(axes.scatter([], [], s=font * 1.2, color=[palette.ECHO.rgba], zorder=7))
        robot = palette.ROBOT
        self.footprint = robot_body(scenario.robot.profile).footprint
        self.front_m = float(self.footprint[:, 0].max())
        self.body = self._add(Polygon(self.footprint, fc=robot.rgba, ec=robot.rim, lw=1.2, zorder=8))
        (self.heading,) = axes.plot([], [], color=robot.rim, lw=1.5, zorder=9)
        self._animated.append(self.heading)
        self.forces = axes.quiver(
            np.zeros(len(FORCE_NAMES)),
            np.zeros(len(FORCE_NAMES)),
            np.zeros(len(FORCE_NAMES)),
            np.zeros(len(FORCE_NAMES)),
            color=[palette.FORCE_RGBA[name] for name in FORCE_NAMES],
            edgecolor=palette.BLACK,
            linewidth=0.8,
            angles="xy",
            scale_units="xy",
            scale=1.0,
            units="xy",
            width=0.05,
            headwidth=3.0,
            headlength=3.5,
            headaxislength=3.0,
            zorder=10,
        )
        self._animated.append(self.forces)

    def _add(self, artist):
        if isinstance(artist, LineCollection):
            self.axes.add_collection(artist)
        elif isinstance(artist, Patch):
            self.axes.add_patch(artist)
        self._animated.append(artist)
        return artist

    def frame(self, time_s: float) -> bytes:
        """The RGBA frame (height x width x 4 bytes) at simulated time `time_s`."""
        tl = self.timeline
        k = tl.index_at(time_s)
        canvas = self.canvas
        canvas.restore_region(self._background)
        self._extend_path(k)
        x, y, yaw = tl.poses[k]
        self.planes.set_segments([np.array(plane) for plane in tl.planes[k]])
        objective = tl.objectives[k]
        self.objective.set_data([objective[0]] if objective else [], [objective[1]] if objective else [])
        if self.moving is not None:
            self.moving.show(k)
        self.echoes.set_offsets(tl.echoes[k] if len(tl.echoes[k]) else np.empty((0, 2)))
        c, s = math.cos(yaw), math.sin(yaw)
        self.body.set_xy(self.footprint @ np.array([[c, s], [-s, c]]) + (x, y))
        front = self.front_m
        self.heading.set_data([x, x + front * c], [y, y + front * s])
        arrows = np.array([tl.forces[k].get(name, (x, y, np.nan, np.nan)) for name in FORCE_NAMES])
        self.forces.set_offsets(arrows[:, :2])
        self.forces.set_UVC(arrows[:, 2], arrows[:, 3])
        self.clock.set_text(f"{tl.modes[k]}  {self.speed:g}x  t = {tl.times_s[k]:6.2f} s")
        for artist in self._animated:
            if artist is not self.path:
                self.figure.draw_artist(artist)
        self._draw_caption(self._caption(time_s))
        return bytes(canvas.buffer_rgba())

    def _draw_caption(self, text: str) -> None:
        """The caption strip: its pixels are kept while its text stays the same (text is slow)."""
        canvas = self.canvas
        if self._caption_shown is None or self._caption_shown[0] != text:
            self.caption.set_text(text)
            self.figure.draw_artist(self.caption)
            self._caption_shown = (text, canvas.copy_from_bbox(self._caption_box))
        else:
            canvas.restore_region(self._caption_shown[1])

    def _extend_path(self, k: int) -> None:
        """Draw the path segments up to tick k into the background (they never change)."""
        if k <= self._path_drawn:
            return
        points = self.timeline.poses[self._path_drawn : k + 1, :2]
        modes = self.timeline.modes[self._path_drawn : k]
        self.path.set_segments(np.stack([points[:-1], points[1:]], axis=1))
        self.path.set_color([MODE_RGBA.get(mode, OTHER_MODE_RGBA) for mode in modes])
        self.axes.draw_artist(self.path)
        self._background = self.canvas.copy_from_bbox(self.figure.bbox)
        self._path_drawn = k

    def _caption(self, time_s: float) -> str:
        """The latest events within the last CAPTION_HOLD_S of video."""
        since = time_s - CAPTION_HOLD_S * self.speed
        recent = [e.text for e in self.timeline.events if since < e.time_s <= time_s]
        return "\n".join(recent[-CAPTION_LINES:])


class MovingArtists:
    """The moving obstacles of a video: each where it stands at a tick (drawn as the static ones),
    over its trail of the last TRAIL_S simulated seconds, fading out with age."""

    def __init__(self, axes, moving: tuple[Moving, ...], times_s: np.ndarray, places: np.ndarray):
        self.times_s, self.places = times_s, places
        """The ticks' times (N,; s) and where the obstacles stood then (N, count, 2; m)."""
        self.trail = LineCollection([], linewidths=2.0, capstyle="round", zorder=1.5)
        axes.add_collection(self.trail)
        pieces = [dataclasses.replace(m.shape, center=(0.0, 0.0)).footprint()[0] for m in moving]
        self.shapes = [axes.add_patch(_patch(piece)) for piece in pieces]
        self.corners = [None if isinstance(p, shapes.Disc) else p.corners() for p in pieces]
        """A box's corners about its centre (4, 2; m), None for a disc."""
        self.artists: list[Artist] = [self.trail, *self.shapes]

    def show(self, k: int) -> None:
        """Put the obstacles where they stood at tick k, after their trails up to then."""
        for patch, corners, place in zip(self.shapes, self.corners, self.places[k], strict=True):
            if isinstance(patch, Circle):
                patch.center = (float(place[0]), float(place[1]))
            elif isinstance(patch, Polygon) and corners is not None:
                patch.set_xy(corners + place)
        first = int(np.searchsorted(self.times_s, self.times_s[k] - TRAIL_S))
        starts, ends = self.places[first:k], self.places[first + 1 : k + 1]  # (M, count, 2)
        age = (self.times_s[k] - self.times_s[first:k]) / TRAIL_S
        alpha = np.repeat(np.clip(1.0 - age, 0.0, 1.0), self.places.shape[1])
        segments = np.stack((starts.reshape(-1, 2), ends.reshape(-1, 2)), axis=1)
        kept = np.hypot(*(segments[:, 1] - segments[:, 0]).T) <= TRACE_JUMP_M  # not a loop's jump
        colours = np.tile(TRACE_RGBA, (len(segments), 1))
        colours[:, 3] = alpha
        self.trail.set_segments(segments[kept])
        self.trail.set_color(colours[kept])


def _patch(piece: shapes.Piece) -> Patch:
    """A moving obstacle's shape about the origin, drawn over the path (which it crosses)."""
    if isinstance(piece, shapes.Disc):
        return Circle((0.0, 0.0), piece.radius, color=palette.MOVING_OBSTACLE.rgba, zorder=3)
    return Polygon(piece.corners(), color=palette.MOVING_OBSTACLE.rgba, zorder=3)


def _view(scenario: Scenario, timeline: Timeline) -> tuple[tuple[float, float], tuple[float, float]]:
    """The x and y ranges (m) shown: start, goal, path and wherever the moving obstacles went,
    with VIEW_MARGIN_M around them, within the arena and its walls; the whole arena when that is
    nearly all of it."""
    w, h = scenario.world.size
    points = np.vstack([timeline.poses[:, :2], scenario.robot.start, scenario.robot.goal])
    if timeline.obstacles is not None:
        points = np.vstack([points, timeline.obstacles.reshape(-1, 2)])
    low = np.maximum(points.min(axis=0) - VIEW_MARGIN_M, -WALL_MARGIN_M)
    high = np.minimum(points.max(axis=0) + VIEW_MARGIN_M, (w + WALL_MARGIN_M, h + WALL_MARGIN_M))
    if np.prod(high - low) > 0.7 * (w + 2 * WALL_MARGIN_M) * (h + 2 * WALL_MARGIN_M):
        low, high = np.array([-WALL_MARGIN_M] * 2), np.array([w + WALL_MARGIN_M, h + WALL_MARGIN_M])
    return (float(low[0]), float(high[0])), (float(low[1]), float(high[1]))


def _draw_world(axes, scenario: Scenario) -> None:
    """Arena floor, obstacles, border walls and the goal (the start is drawn over the planes)."""
    w, h = scenario.world.size
    axes.add_patch(Polygon([(0, 0), (w, 0), (w, h), (0, h)], color="#f2f2f2", zorder=0))
    pieces = [piece for obstacle in scenario.world.obstacles for piece in obstacle.footprint()]
    if scenario.world.border:
        pieces += list(shapes.border_footprint(scenario.world.size))
    for piece in pieces:
        if isinstance(piece, shapes.Disc):
            axes.add_patch(Circle(piece.center, piece.radius, color=palette.OBSTACLE.rgba, zorder=1))
        else:
            axes.add_patch(Polygon(piece.corners(), color=palette.OBSTACLE.rgba, zorder=1))
    robot = scenario.robot
    axes.add_patch(Circle(robot.goal, robot.goal_tolerance, color=palette.GOAL.rgba, zorder=2))


def _disc_marker(axes, mark: Mark, size_pt: float) -> Line2D:
    """An empty line that draws a disc of `mark` (its colour within its rim) at each point."""
    (line,) = axes.plot([], [], "o", ms=size_pt, mfc=mark.rgba, mec=mark.rim or mark.rgba, mew=1.5, zorder=6)
    return line
