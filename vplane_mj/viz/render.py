"""Offscreen (OSMesa by default) top-down PNG of a run.

The arena from the orthographic top camera, flat (no shading: every mark in its colour of
`vplane_mj.viz.palette`), with the marks of the run over it (`track_marks`, `moving_marks`) and a
panel at its right: the caption, a legend that names every mark the picture holds, and a scale
bar. A `Track` holds what is drawn, from a run or from its log.
"""

from __future__ import annotations

import math
import struct
import zlib
from pathlib import Path

import mujoco
import numpy as np

from vplane_mj.geometry.motion import Moving
from vplane_mj.sim.loop import Track
from vplane_mj.sim.summary import RunSummary
from vplane_mj.sim.world import MOVING_PREFIX, ROBOT_PREFIX, build_model
from vplane_mj.viz import palette
from vplane_mj.viz.flat import add_shapes
from vplane_mj.viz.moving_marks import moving_marks
from vplane_mj.viz.palette import Mark
from vplane_mj.viz.swatches import SWATCH_PX, paint_swatch
from vplane_mj.viz.track_marks import Drawn, track_marks

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_FILTER_UP = 2
"""PNG's row filter "Up": each byte minus the one above it."""
OBSTACLE_MATERIALS = ("obstacle", "border")
"""The world's materials of the obstacles and the border walls, drawn in the palette's colour."""
HIDDEN_GROUP = 5
"""The geom group the robot's own geoms are moved to, which the render leaves out: it draws the
robot's footprint instead."""
LEGEND_PX = 200
"""Width (px) of the panel right of the arena that holds the caption, the legend and the scale."""
ROW_PX = 24
"""Height (px) of one line of the panel."""
CAPTION_LINES = 5
"""The most lines of a caption the panel shows."""
SCALE_PX = 44
"""Height (px) kept free at the bottom of the panel for the scale bar."""
TEXT_DROP_PX = 0
"""How far (px) below the bottom of a line of MuJoCo's text its placing point lies."""


def render_top_view(scenario, track: Track, caption: str = "") -> np.ndarray:
    """RGB image (H, W, 3) of the whole arena from the orthographic top camera, with a panel at
    its right: the `caption` (a few short lines), a legend of what the picture shows and a scale
    bar. The image is taller than the arena (white below it) when the panel needs the room."""
    model = build_model(scenario)
    _flatten(model)
    data = mujoco.MjData(model)
    places = _moving_places(scenario, track)
    if places is not None:
        _stand_moving(model, data, scenario.world.moving, places[-1])
    mujoco.mj_forward(model, data)
    arena_px, width = model.vis.global_.offheight, model.vis.global_.offwidth
    camera = mujoco.MjvCamera()
    camera.type, camera.fixedcamid = mujoco.mjtCamera.mjCAMERA_FIXED, model.camera("top").id
    metres_per_px = model.cam_fovy[camera.fixedcamid] / arena_px  # orthographic: the view's height in m
    world = scenario.world
    drawn: list[Drawn] = [(palette.OBSTACLE, [])] if world.obstacles or world.border else []  # MuJoCo's
    if places is not None:
        drawn += moving_marks(world.moving, track.positions, places, metres_per_px)
    drawn += track_marks(scenario, track, metres_per_px)
    lines = [line for line in caption.splitlines() if line][:CAPTION_LINES]
    height = max(arena_px, _panel_height(len(lines), len(drawn)))
    model.vis.global_.offwidth, model.vis.global_.offheight = width + LEGEND_PX, height
    shapes = [shape for _, marks in drawn for shape in marks]
    drawable = model.ngeom + model.nsite + model.ntendon + model.ncam + model.nlight
    scene = mujoco.MjvScene(model, maxgeom=drawable + len(shapes))
    options = mujoco.MjvOption()
    options.flags[mujoco.mjtVisFlag.mjVIS_RANGEFINDER] = False
    options.sitegroup[:] = 0  # the goal is drawn as a mark, the sensors' sites not at all
    mujoco.mjv_updateScene(model, data, options, None, camera, mujoco.mjtCatBit.mjCAT_ALL, scene)
    add_shapes(scene, shapes)
    image = np.empty((height, width + LEGEND_PX, 3), dtype=np.uint8)
    gl = mujoco.GLContext(width + LEGEND_PX, height)
    gl.make_current()
    context = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
    try:
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, context)
        whole = mujoco.MjrRect(0, 0, width + LEGEND_PX, height)
        mujoco.mjr_rectangle(whole, 1.0, 1.0, 1.0, 1.0)
        mujoco.mjr_render(mujoco.MjrRect(0, height - arena_px, width, arena_px), scene, context)
        _write_panel(context, width, height, lines, [mark for mark, _ in drawn], metres_per_px)
        mujoco.mjr_readPixels(image, None, whole, context)
    finally:
        context.free()
        gl.free()
    image = np.flipud(image)
    for row, (mark, _) in enumerate(drawn):
        paint_swatch(image, _legend_top(len(lines), row), width + 10, mark)
    return image


def _flatten(model: mujoco.MjModel) -> None:
    """Light the model evenly from the camera, so that every surface shows its own colour; paint
    the obstacles and walls in the palette's colour; leave the robot's own geoms out."""
    model.vis.headlight.ambient[:] = 1.0
    model.vis.headlight.diffuse[:] = 0.0
    model.vis.headlight.specular[:] = 0.0
    model.light_active[:] = 0
    for name in OBSTACLE_MATERIALS:
        model.mat_rgba[model.material(name).id] = palette.OBSTACLE.rgba
    robot = model.body(ROBOT_PREFIX).id
    model.geom_group[model.body_rootid[model.geom_bodyid] == robot] = HIDDEN_GROUP


def _panel_height(caption_lines: int, legend_rows: int) -> int:
    """The panel's least height (px): the caption, the legend and the scale bar below them."""
    return _legend_top(caption_lines, legend_rows) + SCALE_PX


def _legend_top(caption_lines: int, row: int) -> int:
    """The image row (from the top, px) of the top of a legend row's swatch."""
    return 8 + ROW_PX * caption_lines + ROW_PX // 2 + ROW_PX * row


def run_caption(summary: RunSummary) -> str:
    """The caption of a run's render: the scenario; the planner, seed and robot; how it ended."""
    travelled = f"{summary.path_length_m:.1f} m"
    if summary.collisions:
        travelled += f", {summary.collisions} collision{'s' if summary.collisions > 1 else ''}"
    return "\n".join(
        (
            summary.scenario,
            f"{summary.planner}, seed {summary.seed}",
            f"robot: {summary.robot_profile}",
            f"{summary.outcome} at {summary.sim_time_s:.1f} s",
            travelled,
        )
    )


def _moving_places(scenario, track: Track) -> np.ndarray | None:
    """Where the moving obstacles stood at each of the track's positions (ticks, count, 2; m);
    None in a world without any, or a track that does not say."""
    places = track.obstacle_places
    if not scenario.world.moving or places is None or len(places) == 0:
        return None
    return places


def _stand_moving(
    model: mujoco.MjModel, data: mujoco.MjData, moving: tuple[Moving, ...], places: np.ndarray
) -> None:
    """Put each moving obstacle's mocap body where `places` (count, 2; m) says."""
    for obstacle, (x, y) in zip(moving, places, strict=True):
        data.mocap_pos[model.body(f"{MOVING_PREFIX}{obstacle.index}").mocapid[0], :2] = (x, y)


def _write_panel(
    context, left: int, height: int, caption: list[str], legend: list[Mark], metres_per_px: float
) -> None:
    """The caption's lines and the legend's labels from the top (their swatches are painted
    after), a scale bar at the bottom.

    MuJoCo places text relative to the last rectangle drawn, and clips it there: a clear
    rectangle over the panel comes first; y is TEXT_DROP_PX below the text's bottom.
    """
    font = mujoco.mjtFont.mjFONT_NORMAL
    panel = mujoco.MjrRect(left, 0, LEGEND_PX, height)

    def text(line: str, x_px: int, y_px: int) -> None:
        """A line whose bottom is `y_px` above the image's bottom."""
        mujoco.mjr_rectangle(panel, 1.0, 1.0, 1.0, 0.0)
        x, y = (x_px - left) / LEGEND_PX, (y_px - TEXT_DROP_PX) / height
        mujoco.mjr_text(font, line, context, x, y, 0.0, 0.0, 0.0)

    for k, line in enumerate(caption):
        text(line, left + 10, height - 8 - ROW_PX * (k + 1))
    for row, mark in enumerate(legend):  # level with the bottom of the swatch
        text(mark.label, left + 18 + SWATCH_PX, height - _legend_top(len(caption), row) - SWATCH_PX + 3)
    bar_m = _scale_length(metres_per_px * (LEGEND_PX - 40))
    bar_px = round(bar_m / metres_per_px)
    mujoco.mjr_rectangle(mujoco.MjrRect(left + 10, 16, bar_px, 6), 0.0, 0.0, 0.0, 1.0)
    text(f"{bar_m:g} m", left + 10, 30)


def _scale_length(longest_m: float) -> float:
    """The longest round length (1, 2 or 5 times a power of ten, m) at most `longest_m`."""
    power = 10.0 ** math.floor(math.log10(longest_m))
    return max(step * power for step in (1.0, 2.0, 5.0) if step * power <= longest_m)


def write_png(image: np.ndarray, path: Path | str) -> None:
    """Save an RGB image (H, W, 3) of uint8 as PNG: 8-bit truecolour, every row with PNG's
    "Up" filter (its difference from the row above), deflated by zlib."""
    Path(path).write_bytes(png_bytes(image))


def png_bytes(image: np.ndarray) -> bytes:
    """The PNG file of an RGB image (H, W, 3) of uint8 (the standard library's zlib, so that
    writing a render loads no imaging library)."""
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(f"an RGB image of uint8 (H, W, 3) is needed, not {image.shape} of {image.dtype}")
    height, width, _ = image.shape
    rows = image.reshape(height, width * 3)
    filtered = np.empty((height, 1 + width * 3), dtype=np.uint8)
    filtered[:, 0] = PNG_FILTER_UP
    filtered[0, 1:] = rows[0]
    np.subtract(rows[1:], rows[:-1], out=filtered[1:, 1:])  # modulo 256, as PNG wants
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8 bits, RGB, no interlace
    return b"".join(
        (
            PNG_SIGNATURE,
            _png_chunk(b"IHDR", header),
            _png_chunk(b"IDAT", zlib.compress(filtered.tobytes(), 6)),
            _png_chunk(b"IEND", b""),
        )
    )


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
