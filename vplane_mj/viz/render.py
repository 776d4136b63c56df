"""Offscreen (OSMesa by default) top-down PNG of a run.

Arena, obstacles, start and goal, the travelled path coloured by planner mode, the
virtual objectives and planes of the paper's escape, and collision points, from the
orthographic top camera. Moving obstacles stand where they were at the end, with the trace of
their centres (older parts lighter) and, outlined, where each came closest to the robot, joined
to the robot's place then. A `Track` holds what is drawn, from a run or from its log.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import struct
import zlib
from pathlib import Path

import mujoco
import numpy as np

from vplane_mj.geometry import shapes
from vplane_mj.geometry.motion import Moving
from vplane_mj.logs.replay import obstacle_distances
from vplane_mj.sim.loop import Track
from vplane_mj.sim.summary import RunSummary
from vplane_mj.sim.world import MOVING_PREFIX, build_model

MODE_RGBA = {
    "normal": (0.85, 0.1, 0.1, 1.0),  # red
    "avoiding": (0.95, 0.5, 0.0, 1.0),  # orange
    "escaping": (0.1, 0.35, 0.9, 1.0),  # blue
    "trapped": (0.55, 0.0, 0.55, 1.0),  # purple
    "following": (0.0, 0.6, 0.3, 1.0),  # green
}
OTHER_MODE_RGBA = (0.3, 0.3, 0.3, 1.0)
START_RGBA = (0.1, 0.6, 0.1, 1.0)
GOAL_RGBA = (0.95, 0.75, 0.0, 1.0)
COLLISION_RGBA = (0.0, 0.0, 0.0, 1.0)
OBJECTIVE_RGBA = (0.1, 0.35, 0.9, 1.0)
PLANE_RGBA = (0.5, 0.1, 0.7, 1.0)
MOVING_RGBA = (0.32, 0.44, 0.72, 1.0)
"""The moving obstacles' legend swatch: the obstacles' colour as lit in the render."""
TRACE_RGBA = (0.0, 0.55, 0.55, 1.0)
CLOSEST_RGBA = (0.85, 0.05, 0.35, 1.0)
MAX_PATH_SEGMENTS = 3000
MAX_TRACE_SEGMENTS = 400
"""A moving obstacle's trace is decimated to at most this many segments."""
TRACE_JUMP_M = 0.5
"""A step between two ticks longer than this (m) is a looping motion's jump, not drawn."""
TRACE_LIGHTEST = 0.12
"""The oldest part of a trace mixes this much of its colour with white (the newest: all of it)."""
TRACE_HEIGHT_M = 0.02
"""Traces lie on the floor, under the obstacles and the path (newer parts up to 1 cm higher, over
older ones they cross)."""
OUTLINE_SEGMENTS = 48
"""Segments of a disc's outline."""
MARKER_HEIGHT_M = 0.6
"""Markers and the path are drawn above the obstacles (0.5 m) so nothing hides them."""
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_FILTER_UP = 2
"""PNG's row filter "Up": each byte minus the one above it."""


LEGEND_PX = 200
"""Width (px) of the panel right of the arena that holds the caption, the legend and the scale."""
ROW_PX = 22
"""Height (px) of one line of the panel."""
CAPTION_LINES = 5
"""The most lines of a caption the panel shows."""
TEXT_DROP_PX = 0
"""How far (px) below the bottom of a line of MuJoCo's text its placing point lies."""
MODE_NAMES = {
    "normal": "path: normal",
    "avoiding": "path: avoiding",
    "escaping": "path: escaping",
    "trapped": "path: trapped",
    "following": "path: following",
}
MOVING_LEGEND = (
    ("moving obstacle (end)", MOVING_RGBA),
    ("its trace, fading", TRACE_RGBA),
    ("closest to the robot", CLOSEST_RGBA),
)


def render_top_view(scenario, track: Track, caption: str = "") -> np.ndarray:
    """RGB image (H, W, 3) of the whole arena from the orthographic top camera, with a panel at
    its right: the `caption` (a few short lines), a legend of what the picture shows and a scale
    bar."""
    model = build_model(scenario)
    data = mujoco.MjData(model)
    x, y, yaw = track.final_pose
    data.qpos[:7] = (x, y, 0.0, math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    places = _moving_places(scenario, track)
    if places is not None:
        _stand_moving(model, data, scenario.world.moving, places[-1])
    mujoco.mj_forward(model, data)
    height, width = model.vis.global_.offheight, model.vis.global_.offwidth
    model.vis.global_.offwidth = width + LEGEND_PX
    scene = mujoco.MjvScene(model, maxgeom=_scene_capacity(model, track, places))
    camera = mujoco.MjvCamera()
    camera.type, camera.fixedcamid = mujoco.mjtCamera.mjCAMERA_FIXED, model.camera("top").id
    options = mujoco.MjvOption()
    options.flags[mujoco.mjtVisFlag.mjVIS_RANGEFINDER] = False
    mujoco.mjv_updateScene(model, data, options, None, camera, mujoco.mjtCatBit.mjCAT_ALL, scene)
    _add_track(scene, scenario, track)
    if places is not None:
        _add_moving(scene, scenario.world.moving, track.positions, places)
    metres_per_px = model.cam_fovy[camera.fixedcamid] / height  # orthographic: the view's height in m
    image = np.empty((height, width + LEGEND_PX, 3), dtype=np.uint8)
    gl = mujoco.GLContext(width + LEGEND_PX, height)
    gl.make_current()
    context = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
    try:
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, context)
        whole = mujoco.MjrRect(0, 0, width + LEGEND_PX, height)
        mujoco.mjr_rectangle(whole, 1.0, 1.0, 1.0, 1.0)
        mujoco.mjr_render(mujoco.MjrRect(0, 0, width, height), scene, context)
        _draw_panel(context, width, height, caption, _legend(track, places is not None), metres_per_px)
        mujoco.mjr_readPixels(image, None, whole, context)
    finally:
        context.free()
        gl.free()
    return np.flipud(image)


def _scene_capacity(model: mujoco.MjModel, track: Track, places: np.ndarray | None) -> int:
    """Geoms the render's scene holds: all that MuJoCo may draw of the model (its geoms, sites,
    tendons, cameras and lights), and every marker `_add_track` and `_add_moving` add."""
    drawn = model.ngeom + model.nsite + model.ntendon + model.ncam + model.nlight
    markers = (
        2 + len(track.planes) + len(track.objectives) + MAX_PATH_SEGMENTS + 1 + len(track.collision_points)
    )
    if places is not None:
        markers += places.shape[1] * (MAX_TRACE_SEGMENTS + 1 + OUTLINE_SEGMENTS + 2)
    return drawn + markers


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


def _add_track(scene: mujoco.MjvScene, scenario, track: Track) -> None:
    """The start, the goal disc, the virtual planes and objectives, the path and the collisions."""
    _add_disc(scene, scenario.robot.start, 0.12, START_RGBA)
    _add_disc(scene, scenario.robot.goal, scenario.robot.goal_tolerance, GOAL_RGBA)
    for e1, e2 in track.planes:
        _add_segment(scene, e1, e2, PLANE_RGBA, width=6.0)
    for objective in track.objectives:
        _add_disc(scene, objective, 0.08, OBJECTIVE_RGBA)
    _add_path(scene, track.positions, track.modes)
    for point in track.collision_points:
        _add_disc(scene, point, 0.06, COLLISION_RGBA)


def _legend(track: Track, moving: bool = False) -> list[tuple[str, tuple[float, float, float, float]]]:
    """The legend's rows (text, colour): start and goal, the path's modes in this run, the
    virtual objectives, planes and collisions when it has any, and the marks of `moving`
    obstacles."""
    rows = [("start", START_RGBA), ("goal (tolerance)", GOAL_RGBA)]
    for mode in dict.fromkeys(track.modes):
        rows.append((MODE_NAMES.get(mode, f"path: {mode}"), MODE_RGBA.get(mode, OTHER_MODE_RGBA)))
    if track.objectives:
        rows.append(("virtual objective", OBJECTIVE_RGBA))
    if track.planes:
        rows.append(("virtual plane", PLANE_RGBA))
    if track.collision_points:
        rows.append(("collision", COLLISION_RGBA))
    if moving:
        rows += MOVING_LEGEND
    return rows


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


def _add_moving(
    scene: mujoco.MjvScene, moving: tuple[Moving, ...], positions: np.ndarray, places: np.ndarray
) -> None:
    """Each moving obstacle's trace, and its outline where it came closest to the robot's centre
    (`positions` (N, 2) and `places` (N, count, 2), m) joined to the robot's place then."""
    gaps = obstacle_distances(moving, positions, places)
    for k, obstacle in enumerate(moving):
        _add_trace(scene, places[:, k])
        nearest = int(np.argmin(gaps[:, k]))
        x, y = places[nearest, k]
        (piece,) = dataclasses.replace(obstacle.shape, center=(float(x), float(y))).footprint()
        outline = _outline(piece)
        for a, b in zip(outline, np.roll(outline, -1, axis=0), strict=True):
            _add_segment(scene, a, b, CLOSEST_RGBA, width=3.0)
        robot = positions[nearest]
        _add_segment(scene, robot, _nearest_on(piece, robot), CLOSEST_RGBA, width=1.5)
        _add_disc(scene, robot, 0.05, CLOSEST_RGBA, z=MARKER_HEIGHT_M + 0.03)  # over the path


def _add_trace(scene: mujoco.MjvScene, centres: np.ndarray) -> None:
    """The path of an obstacle's centre (N, 2; m) on the floor, decimated to MAX_TRACE_SEGMENTS,
    from lightest (oldest) to TRACE_RGBA (newest); a looping motion's jumps left out."""
    if len(centres) < 2:
        return
    jumps = np.concatenate(([0], np.cumsum(np.hypot(*np.diff(centres, axis=0).T) > TRACE_JUMP_M)))
    stride = max(1, int(np.ceil((len(centres) - 1) / MAX_TRACE_SEGMENTS)))
    kept = list(range(0, len(centres), stride))
    if kept[-1] != len(centres) - 1:
        kept.append(len(centres) - 1)
    colour = np.array(TRACE_RGBA[:3])
    for n, (i, j) in enumerate(itertools.pairwise(kept)):
        if jumps[i] != jumps[j]:
            continue
        weight = TRACE_LIGHTEST + (1.0 - TRACE_LIGHTEST) * (n + 1) / (len(kept) - 1)
        rgba = (*(1.0 - weight * (1.0 - colour)), 1.0)
        z = TRACE_HEIGHT_M + 0.01 * n / len(kept)
        _add_segment(scene, centres[i], centres[j], rgba, width=3.0, z=z)


def _outline(piece: shapes.Piece) -> np.ndarray:
    """A footprint piece's outline (k, 2; m): a rectangle's corners, a disc's polygon."""
    if isinstance(piece, shapes.Disc):
        angles = np.linspace(0.0, 2 * math.pi, OUTLINE_SEGMENTS, endpoint=False)
        return np.column_stack((np.cos(angles), np.sin(angles))) * piece.radius + piece.center
    return piece.corners()


def _nearest_on(piece: shapes.Piece, point: np.ndarray) -> np.ndarray:
    """The point of a piece nearest `point` (m): on its edge, or `point` itself inside it."""
    centre = np.asarray(piece.center, float)
    if isinstance(piece, shapes.Disc):
        away = point - centre
        length = float(np.hypot(*away))
        return point if length <= piece.radius else centre + away * (piece.radius / length)
    c, s = math.cos(piece.yaw), math.sin(piece.yaw)
    turn = np.array([[c, -s], [s, c]])
    local = np.clip(turn.T @ (point - centre), -np.asarray(piece.half), piece.half)
    return centre + turn @ local


def _draw_panel(context, left: int, height: int, caption: str, legend, metres_per_px: float) -> None:
    """The caption's lines, the legend's swatches and texts from the top, a scale bar at the bottom.

    MuJoCo places text relative to the last rectangle drawn, and clips it there: a clear
    rectangle over the panel comes first; y is TEXT_DROP_PX below the text's bottom.
    """
    font = mujoco.mjtFont.mjFONT_NORMAL
    panel = mujoco.MjrRect(left, 0, LEGEND_PX, height)

    def text(line: str, x_px: int, y_px: int) -> None:
        mujoco.mjr_rectangle(panel, 1.0, 1.0, 1.0, 0.0)
        x, y = (x_px - left) / LEGEND_PX, (y_px - TEXT_DROP_PX) / height
        mujoco.mjr_text(font, line, context, x, y, 0.0, 0.0, 0.0)

    top = height - 8
    for line in [line for line in caption.splitlines() if line][:CAPTION_LINES]:
        top -= ROW_PX
        text(line, left + 10, top)
    top -= ROW_PX // 2
    for label, (r, g, b, a) in legend:
        top -= ROW_PX
        mujoco.mjr_rectangle(mujoco.MjrRect(left + 10, top, 16, 16), r, g, b, a)
        text(label, left + 34, top)
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


def _add_disc(scene: mujoco.MjvScene, center, radius: float, rgba, z: float = MARKER_HEIGHT_M) -> None:
    mujoco.mjv_initGeom(
        scene.geoms[scene.ngeom],
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=np.array([radius, 0.005, 0.0]),
        pos=np.array([center[0], center[1], z]),
        mat=np.eye(3).flatten(),
        rgba=np.array(rgba, dtype=np.float32),
    )
    scene.ngeom += 1


def _add_segment(
    scene: mujoco.MjvScene, a, b, rgba, width: float = 4.0, z: float = MARKER_HEIGHT_M + 0.01
) -> None:
    geom = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(
        geom,
        type=mujoco.mjtGeom.mjGEOM_LINE,
        size=np.zeros(3),
        pos=np.zeros(3),
        mat=np.eye(3).flatten(),
        rgba=np.array(rgba, dtype=np.float32),
    )
    mujoco.mjv_connector(
        geom, mujoco.mjtGeom.mjGEOM_LINE, width, np.array([a[0], a[1], z]), np.array([b[0], b[1], z])
    )
    scene.ngeom += 1


def _add_path(scene: mujoco.MjvScene, points: np.ndarray, modes: list[str]) -> None:
    """Line segments through `points` (N, 2), each coloured by the mode at its start,
    decimated to at most MAX_PATH_SEGMENTS segments."""
    if len(points) < 2:
        return
    stride = max(1, int(np.ceil((len(points) - 1) / MAX_PATH_SEGMENTS)))
    kept = list(range(0, len(points), stride))
    if kept[-1] != len(points) - 1:
        kept.append(len(points) - 1)
    for i, j in itertools.pairwise(kept):
        _add_segment(scene, points[i], points[j], MODE_RGBA.get(modes[i], OTHER_MODE_RGBA))
