"""A legend's swatch of a mark, painted into an RGB image (H, W, 3) of uint8: its shape (a
square, a disc, a line, dashes, a cross, an arrowhead...) in its colour, within its rim."""

from __future__ import annotations

import numpy as np

from vplane_mj.viz.palette import RGBA, Mark, Swatch

SWATCH_PX = 20
"""The side of a swatch's square (px)."""
RIM_PX = 2
LINE_PX = 4
DASH_PX = 6
FADED = 0.12
"""How much of its colour a fading swatch's left end has (its right end: all of it)."""


def paint_swatch(image: np.ndarray, top: int, left: int, mark: Mark) -> None:
    """Paint `mark`'s swatch into `image` in the SWATCH_PX square whose top left pixel is
    (top, left) (row, column): its shape in its rim's colour, that shape shrunk by RIM_PX in its
    own colour (or the whole shape in its colour when it has no rim)."""
    square = image[top : top + SWATCH_PX, left : left + SWATCH_PX]
    rows, columns = np.mgrid[0:SWATCH_PX, 0:SWATCH_PX] + 0.5
    x, y = columns - SWATCH_PX / 2, rows - SWATCH_PX / 2  # from the square's centre (px)
    colour = np.array(_bytes(mark.rgba), float)
    if mark.rim is None:
        inside = _mask(mark.swatch, x, y, 0)
    else:
        square[_mask(mark.swatch, x, y, 0)] = _bytes(mark.rim)
        inside = _mask(mark.swatch, x, y, RIM_PX)
    if mark.swatch == "fading":  # from nearly white at the left to the colour at the right
        weight = (FADED + (1 - FADED) * (x + SWATCH_PX / 2) / SWATCH_PX)[..., None]
        square[inside] = np.round(255 - weight * (255 - colour))[inside].astype(np.uint8)
    else:
        square[inside] = colour.astype(np.uint8)


def _mask(shape: Swatch, x: np.ndarray, y: np.ndarray, inset: float) -> np.ndarray:
    """The pixels of a swatch's shape, shrunk by `inset` (px), at the offsets x, y (px) from the
    square's centre (y down)."""
    half = SWATCH_PX / 2 - 1 - inset
    box = np.maximum(np.abs(x), np.abs(y))
    line = (np.abs(y) <= LINE_PX / 2) & (np.abs(x) <= half)
    masks = {
        "area": box <= half,
        "disc": np.hypot(x, y) <= half,
        "dot": np.hypot(x, y) <= half / 3,
        "line": line,
        "fading": line,
        "dashes": line & ((x + SWATCH_PX / 2) // DASH_PX % 2 == 0),
        "cross": ((np.abs(y) <= 1.5) | (np.abs(x) <= 1.5)) & (box <= half),
        "arrow": (x >= -half) & (np.abs(y) <= (half - x) / 2),  # pointing right
        "outline": (box <= half) & (box >= half - RIM_PX),
    }
    return masks[shape]


def _bytes(rgba: RGBA) -> tuple[int, int, int]:
    """A colour's 8-bit RGB."""
    red, green, blue, _ = rgba
    return round(red * 255), round(green * 255), round(blue * 255)
