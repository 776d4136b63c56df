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
from vplane_mj.viz.render import LEGEND_PX, png_bytes, render_top_view, write_png


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


def arena_pixels(image: np.ndarray, scenario) -> np.ndarray:
    """The render's arena: the image left of the panel, as tall as the arena is."""
    width_m, height_m = top_view_extent(scenario.world.size)
    width_px = image.shape[1] - LEGEND_PX
    return image[: round(width_px * height_m / width_m), :width_px]


def count(pixels: np.ndarray, colour: tuple[int, int, int]) -> int:
    """The pixels of exactly `colour` (8-bit RGB)."""
    return int((pixels.reshape(-1, 3) == colour).all(axis=1).sum())


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
