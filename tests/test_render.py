"""The render: every marker drawn in any world; its PNG writer lossless, readable by other
libraries, strict about its input."""

import matplotlib.image
import numpy as np
import pytest
import tomli_w

from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.loop import Track
from vplane_mj.sim.world import top_view_extent
from vplane_mj.viz import palette
from vplane_mj.viz.render import LEGEND_PX, SCALE_PX, png_bytes, render_top_view, write_png
from vplane_mj.viz.swatches import SWATCH_PX


@pytest.mark.parametrize("shape", [(1, 1, 3), (1, 7, 3), (5, 1, 3), (37, 53, 3)])
def test_a_written_png_reads_back_pixel_for_pixel(tmp_path, shape):
    image = np.random.default_rng(sum(shape)).integers(0, 256, shape, dtype=np.uint8)
    path = tmp_path / "image.png"
    write_png(image, str(path))  # a str or a Path
    back = matplotlib.image.imread(path)  # floats in [0, 1] for an 8-bit PNG
    assert back.shape == shape
    np.testing.assert_array_equal(np.round(back * 255).astype(np.uint8), image)


def test_flat_colour_compresses_well():
    image = np.full((400, 400, 3), (200, 30, 90), dtype=np.uint8)
    assert len(png_bytes(image)) < 2_000  # 480,000 bytes of pixels


@pytest.mark.parametrize(
    "image", [np.zeros((4, 4, 4), np.uint8), np.zeros((4, 4, 3), np.float32), np.zeros((4, 4), np.uint8)]
)
def test_anything_but_rgb_bytes_is_refused(image):
    with pytest.raises(ValueError, match="RGB image of uint8"):
        png_bytes(image)


def world(obstacles: list[dict]):
    doc = {
        "format": 1,
        "name": "forest",
        "world": {"size": [42.0, 27.0], "obstacles": obstacles},
        "robot": {"start": [0.4, 0.4], "goal": [41.6, 26.6]},
    }
    return parse_scenario(tomli_w.dumps(doc), "forest.toml")


def pixel(image: np.ndarray, scenario, xy) -> tuple[int, int]:
    """The (row, column) of the render's pixel at the point xy (m)."""
    width_m, _ = top_view_extent(scenario.world.size)
    scale, margin = width_m / (image.shape[1] - LEGEND_PX), (width_m - scenario.world.size[0]) / 2
    height_m = scale * len(arena_pixels(image, scenario))
    return int((height_m - margin - xy[1]) / scale), int((xy[0] + margin) / scale)


def window(image: np.ndarray, scenario, xy, half_px: int = 6) -> np.ndarray:
    """The render's pixels around the point xy (m)."""
    row, column = pixel(image, scenario, xy)
    return image[row - half_px : row + half_px, column - half_px : column + half_px].astype(int)


def test_a_world_of_4000_obstacles_keeps_every_marker_of_the_render():
    """The scene holds the model's geoms and all the markers, however many obstacles there are:
    the start, the goal, the path and a collision look as they do in an empty world."""
    forest = world(
        [
            {"kind": "cylinder", "center": [1.0 + 0.5 * i, 1.0 + 0.5 * j], "radius": 0.05}
            for i in range(80)
            for j in range(50)
        ]
    )
    assert len(forest.world.obstacles) == 4000
    positions = np.column_stack((np.linspace(0.4, 41.6, 200), np.full(200, 0.6)))
    track = Track(positions, ["normal"] * 200, (41.6, 0.6, 0.0), collision_points=[(20.0, 0.6)])
    crowded, empty = render_top_view(forest, track), render_top_view(world([]), track)
    background = window(
        render_top_view(world([]), Track(positions[:1], ["normal"], (0.4, 0.4, 0.0))), forest, (20.0, 0.6)
    )
    for xy in ((0.4, 0.4), (41.6, 26.6), (20.0, 0.6), (10.0, 0.6)):  # start, goal, collision, path
        np.testing.assert_array_equal(window(crowded, forest, xy), window(empty, forest, xy))
    assert np.abs(window(empty, forest, (20.0, 0.6)) - background).max() > 100


def rgb(rgba) -> tuple[int, int, int]:
    """A palette colour's 8-bit RGB, as the flat render shows it."""
    return tuple(round(channel * 255) for channel in rgba[:3])


def small_world():
    """An 8 x 6 m arena with a box, the start at its left, the goal at its lower right."""
    doc = {
        "format": 1,
        "name": "marks",
        "world": {
            "size": [8.0, 6.0],
            "obstacles": [{"kind": "box", "center": [6.0, 5.0], "size": [0.6, 0.4]}],
        },
        "robot": {"start": [1.0, 3.0], "goal": [7.0, 1.0]},
    }
    return parse_scenario(tomli_w.dumps(doc), "marks.toml")


MODES = ("normal", "avoiding", "escaping", "trapped", "following")


def every_mark_track() -> Track:
    """A path from the start 1 m in each mode to the right, a virtual objective and plane, a
    collision."""
    xs = np.linspace(1.0, 6.0, 501)
    positions = np.column_stack((xs, np.full(len(xs), 3.0)))
    modes = [MODES[min(int(x - 1.0), 4)] for x in xs]
    return Track(
        positions,
        modes,
        (6.0, 3.0, 0.0),
        collision_points=[(6.0, 4.7)],
        objectives=[(6.5, 2.0)],
        planes=[((2.5, 2.0), (2.5, 4.0))],
    )


def arena_pixels(image: np.ndarray, scenario) -> np.ndarray:
    """The render's arena: the image left of the panel, as tall as the arena is."""
    width_m, height_m = top_view_extent(scenario.world.size)
    width_px = image.shape[1] - LEGEND_PX
    return image[: round(width_px * height_m / width_m), :width_px]


def swatches(image: np.ndarray) -> list[np.ndarray]:
    """The legend's swatches from the top: the non-white runs of rows of the swatch column (its
    pixels), above the scale bar."""
    left = image.shape[1] - LEGEND_PX + 10
    band = image[: image.shape[0] - SCALE_PX, left : left + SWATCH_PX]
    inked = (band != 255).any(axis=(1, 2))
    edges = np.flatnonzero(np.diff(np.concatenate(([0], inked.astype(int), [0]))))
    return [band[start:end] for start, end in zip(edges[::2], edges[1::2], strict=True)]


def count(pixels: np.ndarray, colour: tuple[int, int, int]) -> int:
    """The pixels of exactly `colour` (8-bit RGB)."""
    return int((pixels.reshape(-1, 3) == colour).all(axis=1).sum())


def test_the_legend_names_every_mark_the_render_draws_and_nothing_else():
    scenario = small_world()
    image = render_top_view(scenario, every_mark_track())
    legend = [
        palette.OBSTACLE,
        palette.START,
        palette.GOAL,
        *(palette.path_mark(mode) for mode in MODES),
        palette.DIRECTION,
        palette.OBJECTIVE,
        palette.PLANE,
        palette.COLLISION,
        palette.ROBOT,
    ]
    rows = swatches(image)
    assert len(rows) == len(legend)
    for mark, swatch in zip(legend, rows, strict=True):  # each row's swatch in its colours
        assert count(swatch, rgb(mark.rgba)) >= 8, mark.label
        if mark.rim is not None:
            assert count(swatch, rgb(mark.rim)) >= 8, mark.label
    arena = arena_pixels(image, scenario)
    named = {rgb(colour) for mark in legend for colour in (mark.rgba, mark.rim) if colour is not None}
    for mark in legend:
        assert count(arena, rgb(mark.rgba)) >= 20, mark.label  # drawn
    marks = [value for value in vars(palette).values() if isinstance(value, palette.Mark)]
    colours = {
        rgb(c) for c in [*palette.MODE_RGBA.values(), *(m.rgba for m in marks), *palette.FORCE_RGBA.values()]
    }
    shown = {colour for colour in colours if count(arena, colour) >= 20}
    assert shown <= named  # every colour of the palette the arena shows is a legend row's


def test_a_render_without_virtual_marks_or_collisions_leaves_them_out_of_the_legend():
    scenario = small_world()
    positions = np.column_stack((np.linspace(1.0, 3.0, 50), np.full(50, 3.0)))
    rows = swatches(render_top_view(scenario, Track(positions, ["normal"] * 50, (3.0, 3.0, 0.0))))
    legend = [
        palette.OBSTACLE,
        palette.START,
        palette.GOAL,
        palette.path_mark("normal"),
        palette.DIRECTION,
        palette.ROBOT,
    ]
    assert len(rows) == len(legend)
    for mark, swatch in zip(legend, rows, strict=True):
        assert count(swatch, rgb(mark.rgba)) >= 8, mark.label


def test_the_start_shows_above_a_virtual_plane_that_crosses_it():
    scenario = small_world()
    start = scenario.robot.start
    plane = ((start[0], start[1] - 1.0), (start[0], start[1] + 1.0))
    positions = np.column_stack((np.linspace(1.0, 3.0, 50), np.full(50, 3.0)))
    track = Track(positions, ["escaping"] * 50, (3.0, 3.0, 0.0), planes=[plane])
    image = render_top_view(scenario, track)
    centre = window(image, scenario, start, half_px=3)
    assert count(centre, rgb(palette.START.rgba)) == centre.shape[0] * centre.shape[1]  # its fill, whole
    rim = window(image, scenario, start, half_px=9)
    assert count(rim, rgb(palette.START.rim)) >= 20
    beside = window(image, scenario, (start[0], start[1] + 0.5), half_px=8)
    assert count(beside, rgb(palette.PLANE.rgba)) >= 20  # the plane is drawn, under the start


@pytest.mark.parametrize("rightwards", [True, False])
def test_arrowheads_point_the_way_the_robot_went(rightwards):
    scenario = small_world()
    xs = np.linspace(1.5, 5.5, 200)[:: 1 if rightwards else -1]
    positions = np.column_stack((xs, np.full(200, 2.0)))
    track = Track(positions, ["normal"] * 200, (xs[-1], 2.0, 0.0 if rightwards else np.pi))
    image = render_top_view(scenario, track)
    (row, left), (_, right) = pixel(image, scenario, (1.8, 2.0)), pixel(image, scenario, (5.2, 2.0))
    band = image[row - 12 : row + 12, left:right]  # along the path, across it
    black = (band == rgb(palette.DIRECTION.rgba)).all(axis=2)
    heights = black.sum(axis=0)  # per column: the arrowhead's width across the path
    assert heights.max() >= 10  # arrowheads, wider than the path
    columns = np.flatnonzero(heights >= 3)
    first = columns[np.diff(columns, prepend=columns[0] - 2) > 1]  # each arrowhead's first column
    assert len(first) >= 2
    for start in first:
        head = heights[start : start + 14]
        wide_at_left = int(np.argmax(head)) < len(head) / 2
        assert wide_at_left == rightwards  # the base behind, the tip ahead
