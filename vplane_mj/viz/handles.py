"""Matplotlib legend handles of the palette's marks: each mark's swatch as an artist that
`legend` draws (a square, a disc, a line, dashes, a cross, an arrow...)."""

from __future__ import annotations

from matplotlib.artist import Artist
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.path import Path

from vplane_mj.viz.palette import Mark

LINE_WIDTH_PT = 2.5
RIM_PT = 1.2
ARROW = Path(
    [(-1.0, -0.2), (0.1, -0.2), (0.1, -0.55), (1.0, 0.0), (0.1, 0.55), (0.1, 0.2), (-1.0, 0.2), (-1.0, -0.2)],
    closed=True,
)
"""An arrow pointing right, as a marker."""


def legend_handle(mark: Mark, size_pt: float) -> Artist:
    """The handle of `mark` for a legend whose markers are `size_pt` points across."""
    rim = mark.rim if mark.rim is not None else "none"
    match mark.swatch:
        case "area":
            return Patch(facecolor=mark.rgba, edgecolor=rim, linewidth=RIM_PT if mark.rim else 0.0)
        case "outline":
            return Patch(facecolor="none", edgecolor=mark.rgba, linewidth=RIM_PT)
        case "line" | "fading":
            return Line2D([], [], color=mark.rgba, linewidth=LINE_WIDTH_PT)
        case "dashes":
            return Line2D([], [], color=mark.rgba, linewidth=LINE_WIDTH_PT, linestyle=(0, (1.5, 1.0)))
    markers: dict[str, tuple[str | Path, float]] = {
        "disc": ("o", size_pt),
        "dot": ("o", size_pt * 0.4),
        "cross": ("+", size_pt),
        "arrow": (ARROW, size_pt * 1.6),
    }
    marker, size = markers[mark.swatch]
    return Line2D(
        [],
        [],
        linestyle="",
        marker=marker,
        markersize=size,
        markerfacecolor=mark.rgba,
        markeredgecolor=mark.rim if mark.rim is not None else mark.rgba,
        markeredgewidth=RIM_PT if mark.rim is not None or mark.swatch == "cross" else 0.0,
    )
