"""Obstacle geometry: the one source of truth for the contract's obstacle kinds.

Every obstacle kind of the scenario format is reduced to a footprint, a union
of oriented rectangles and discs in the world's xy plane (metres, radians).
The MJCF builder turns footprints into geoms, the run loop measures clearance
against them and tests check them against hand-computed points. Pure numpy.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

Vec2 = tuple[float, float]

BORDER_THICKNESS_M = 0.1
"""Thickness of the border walls placed just outside the free arena."""


@dataclass(frozen=True)
class Rect:
    """An oriented rectangle: centre (m), half extents along its own axes (m), yaw (rad)."""

    center: Vec2
    half: Vec2
    yaw: float = 0.0

    def corners(self) -> np.ndarray:
        """The four corners (4, 2) in world coordinates, counter-clockwise."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        hx, hy = self.half
        local = np.array([(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)])
        return np.asarray(self.center) + local @ np.array([[c, s], [-s, c]])


@dataclass(frozen=True)
class Disc:
    """A disc: centre and radius (m)."""

    center: Vec2
    radius: float


Piece = Rect | Disc


def _place(local: Iterable[Rect], center: Vec2, yaw: float) -> tuple[Rect, ...]:
    """Rotate local rectangles by `yaw` about the origin, then translate them to `center`."""
    c, s = math.cos(yaw), math.sin(yaw)
    placed = []
    for rect in local:
        lx, ly = rect.center
        placed.append(
            Rect(
                center=(center[0] + c * lx - s * ly, center[1] + s * lx + c * ly),
                half=rect.half,
                yaw=yaw + rect.yaw,
            )
        )
    return tuple(placed)


def _span(lo_x: float, hi_x: float, lo_y: float, hi_y: float) -> Rect:
    """The axis-aligned local rectangle [lo_x, hi_x] x [lo_y, hi_y]."""
    return Rect(
        center=((lo_x + hi_x) / 2, (lo_y + hi_y) / 2),
        half=((hi_x - lo_x) / 2, (hi_y - lo_y) / 2),
    )


@dataclass(frozen=True)
class Box:
    """kind = "box": x in [-sx/2, sx/2], y in [-sy/2, sy/2], rotated by yaw."""

    center: Vec2
    size: Vec2
    yaw: float = 0.0

    def footprint(self) -> tuple[Piece, ...]:
        sx, sy = self.size
        return _place([_span(-sx / 2, sx / 2, -sy / 2, sy / 2)], self.center, self.yaw)


@dataclass(frozen=True)
class Wall:
    """kind = "wall": a rectangle of width `thickness` centred on the segment start..end."""

    start: Vec2
    end: Vec2
    thickness: float = 0.05

    def footprint(self) -> tuple[Piece, ...]:
        dx, dy = self.end[0] - self.start[0], self.end[1] - self.start[1]
        length = math.hypot(dx, dy)
        mid = ((self.start[0] + self.end[0]) / 2, (self.start[1] + self.end[1]) / 2)
        return (Rect(center=mid, half=(length / 2, self.thickness / 2), yaw=math.atan2(dy, dx)),)


@dataclass(frozen=True)
class Cylinder:
    """kind = "cylinder": the disc of `radius` around `center`."""

    center: Vec2
    radius: float

    def footprint(self) -> tuple[Piece, ...]:
        return (Disc(center=self.center, radius=self.radius),)


@dataclass(frozen=True)
class Cup:
    """kind = "u" (or "c"): back wall at local +x, two arms, the mouth facing local -x."""

    center: Vec2
    width: float
    depth: float
    yaw: float = 0.0
    thickness: float = 0.05

    def footprint(self) -> tuple[Piece, ...]:
        w, d, t = self.width, self.depth, self.thickness
        local = [
            _span(d / 2 - t, d / 2, -w / 2, w / 2),  # back wall
            _span(-d / 2, d / 2, w / 2 - t, w / 2),  # left arm (+y)
            _span(-d / 2, d / 2, -w / 2, -w / 2 + t),  # right arm (-y)
        ]
        return _place(local, self.center, self.yaw)

    def interior(self) -> tuple[Rect, ...]:
        """The open space inside the cup, from the mouth to the back wall (the trap)."""
        w, d, t = self.width, self.depth, self.thickness
        return _place([_span(-d / 2, d / 2 - t, -w / 2 + t, w / 2 - t)], self.center, self.yaw)


@dataclass(frozen=True)
class HShape:
    """kind = "h": two posts along local x joined by a crossbar; cups open to -x and +x."""

    center: Vec2
    length: float
    width: float
    yaw: float = 0.0
    thickness: float = 0.05

    def footprint(self) -> tuple[Piece, ...]:
        ln, w, t = self.length, self.width, self.thickness
        local = [
            _span(-ln / 2, ln / 2, w / 2 - t, w / 2),  # post at +y
            _span(-ln / 2, ln / 2, -w / 2, -w / 2 + t),  # post at -y
            _span(-t / 2, t / 2, -w / 2, w / 2),  # crossbar
        ]
        return _place(local, self.center, self.yaw)

    def interior(self) -> tuple[Rect, ...]:
        """The open space of both cups, each between the crossbar and the posts' ends."""
        ln, w, t = self.length, self.width, self.thickness
        local = [
            _span(-ln / 2, -t / 2, -w / 2 + t, w / 2 - t),
            _span(t / 2, ln / 2, -w / 2 + t, w / 2 - t),
        ]
        return _place(local, self.center, self.yaw)


Obstacle = Box | Wall | Cylinder | Cup | HShape


def border_footprint(size: Vec2, thickness: float = BORDER_THICKNESS_M) -> tuple[Rect, ...]:
    """Four walls just outside the free arena [0, W] x [0, H], corners covered."""
    w, h, t = size[0], size[1], thickness
    return (
        _span(-t, 0.0, -t, h + t),
        _span(w, w + t, -t, h + t),
        _span(0.0, w, -t, 0.0),
        _span(0.0, w, h, h + t),
    )


class Footprints:
    """A union of pieces packed into arrays for vectorised distance queries."""

    def __init__(self, pieces: Sequence[Piece]):
        rects = [p for p in pieces if isinstance(p, Rect)]
        discs = [p for p in pieces if isinstance(p, Disc)]
        self.pieces = tuple(pieces)
        self._rect_center = np.array([r.center for r in rects], dtype=float).reshape(-1, 2)
        self._rect_half = np.array([r.half for r in rects], dtype=float).reshape(-1, 2)
        yaw = np.array([r.yaw for r in rects], dtype=float)
        self._rect_cos, self._rect_sin = np.cos(yaw), np.sin(yaw)
        self._disc_center = np.array([d.center for d in discs], dtype=float).reshape(-1, 2)
        self._disc_radius = np.array([d.radius for d in discs], dtype=float)

    def __len__(self) -> int:
        return len(self.pieces)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (m) from each point (N, 2) to the union; negative inside.

        Inside a piece the value is minus the depth to that piece's boundary; where
        pieces overlap this is exact outside and a lower bound on depth inside.
        """
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        best = np.full(len(pts), np.inf)
        if len(self._rect_center):
            rel = pts[:, None, :] - self._rect_center[None, :, :]
            lx = rel[..., 0] * self._rect_cos + rel[..., 1] * self._rect_sin
            ly = -rel[..., 0] * self._rect_sin + rel[..., 1] * self._rect_cos
            qx = np.abs(lx) - self._rect_half[:, 0]
            qy = np.abs(ly) - self._rect_half[:, 1]
            outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
            inside = np.minimum(np.maximum(qx, qy), 0.0)
            best = np.minimum(best, (outside + inside).min(axis=1))
        if len(self._disc_center):
            rel = pts[:, None, :] - self._disc_center[None, :, :]
            d = np.hypot(rel[..., 0], rel[..., 1]) - self._disc_radius
            best = np.minimum(best, d.min(axis=1))
        return best


def scene_footprints(obstacles: Iterable[Obstacle], arena_size: Vec2 | None = None) -> Footprints:
    """All obstacle pieces, plus the border walls when `arena_size` is given."""
    pieces: list[Piece] = [p for ob in obstacles for p in ob.footprint()]
    if arena_size is not None:
        pieces.extend(border_footprint(arena_size))
    return Footprints(pieces)
