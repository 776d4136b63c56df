"""The render: every marker drawn in any world; its PNG writer lossless, readable by other
libraries, strict about its input."""

import matplotlib.image
import numpy as np
import pytest
import tomli_w

from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.loop import Track
from vplane_mj.sim.world import top_view_extent
from vplane_mj.viz.render import png_bytes, render_top_view, write_png


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


def window(image: np.ndarray, scenario, xy, half_px: int = 6) -> np.ndarray:
    """The render's pixels around the point xy (m)."""
    width_m, height_m = top_view_extent(scenario.world.size)
    scale, margin = height_m / image.shape[0], (width_m - scenario.world.size[0]) / 2
    column, row = int((xy[0] + margin) / scale), int((height_m - margin - xy[1]) / scale)
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
