"""The render's PNG writer: lossless, readable by other libraries, strict about its input."""

import matplotlib.image
import numpy as np
import pytest

from vplane_mj.viz.render import png_bytes, write_png


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
