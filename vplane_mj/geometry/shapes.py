"""Obstacle geometry: the one source of truth for the contract's obstacle kinds.

Every obstacle kind of the scenario format is reduced to a footprint, a union
of oriented rectangles and discs in the world's xy plane (metres, radians).
The MJCF builder turns footprints into geoms, the run loop measures clearance
against them and tests check them against hand-computed points. Pure numpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

Vec2 = tuple[float, float]

BORDER_THICKNESS_M = 0.1
"""Thickness of the border walls placed just outside the free arena."""
BOUND_SLACK_M = 1e-9
"""What the bounds that choose the pieces a footprint is measured against are widened by, far
above their rounding (`Footprints.outline_distance`)."""


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
        x, y = np.array([-hx, hx, hx, -hx]), np.array([-hy, -hy, hy, hy])
        turned = np.column_stack((x * c - y * s, x * s + y * c))  # not @: no BLAS in a tick
        return np.asarray(self.center) + turned


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

    @classmethod
    def packed_rects(cls, centers: np.ndarray, packed: np.ndarray) -> Footprints:
        """Rectangles at `centers` (R, 2; m) of `packed` (R, 4: half x, half y, cos and sin of
        yaw), without making a `Rect` of each (their `pieces` stay empty)."""
        footprints = cls(())
        footprints._rect_center = np.asarray(centers, float)
        footprints._rect_half = np.asarray(packed[:, :2], float)
        footprints._rect_cos, footprints._rect_sin = packed[:, 2].copy(), packed[:, 3].copy()
        return footprints

    def _paired_point_distances(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (m) from point k (R, 2) to rectangle k alone (the arithmetic of
        `_piece_distances`)."""
        dx, dy = points[:, 0] - self._rect_center[:, 0], points[:, 1] - self._rect_center[:, 1]
        lx = dx * self._rect_cos + dy * self._rect_sin
        ly = -dx * self._rect_sin + dy * self._rect_cos
        qx = np.abs(lx) - self._rect_half[:, 0]
        qy = np.abs(ly) - self._rect_half[:, 1]
        return np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0)) + np.minimum(np.maximum(qx, qy), 0.0)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (m) from each point (N, 2) to the union; negative inside.

        Inside a piece the value is minus the depth to that piece's boundary; where
        pieces overlap this is exact outside and a lower bound on depth inside.
        """
        rects, discs = self._piece_distances(np.atleast_2d(np.asarray(points, dtype=float)))
        return np.minimum(rects.min(axis=1, initial=np.inf), discs.min(axis=1, initial=np.inf))

    def outline_distance(self, outline: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Signed distance (m) from a robot's convex outline to the union at each pose; negative
        when they overlap, then minus the depth of the overlap (the shortest move that parts them).

        `outline` (k, 2) is the footprint polygon, counter-clockwise in the robot's frame, about
        an origin inside it; `poses` (N, 3) are x, y (m) and yaw (rad). Only pieces that can be
        the nearest are measured exactly: the outline lies within its circumradius R of the
        origin and holds the disc of its inradius r about it, so piece p is at least d_p - R
        away when the origin is d_p away, and the nearest at most max(d_p - r, 0) away (it
        overlaps p where the disc does). Exact: separating axes for rectangles (whose overlap
        along an axis is taken as the depth), the outline's distance to the centre for discs.
        """
        poses = np.atleast_2d(np.asarray(poses, dtype=float))
        result = np.full(len(poses), np.inf)
        if not len(self.pieces):
            return result
        reach = float(np.max(np.hypot(outline[:, 0], outline[:, 1])))
        rects, discs = self._piece_distances(poses[:, :2], _quick_norm)  # bounds: the slack covers rounding
        nearest = np.minimum(rects.min(axis=1, initial=np.inf), discs.min(axis=1, initial=np.inf))
        bound = (np.maximum(nearest - _inradius(outline), 0.0) + (reach + BOUND_SLACK_M))[:, None]
        for table, measure in ((rects, self._outline_to_rects), (discs, self._outline_to_discs)):
            pose_index, piece_index = np.nonzero(table <= bound)
            if len(pose_index):
                distances = measure(outline, poses[pose_index], piece_index)
                np.minimum.at(result, pose_index, distances)
        return result

    def _piece_distances(
        self, points: np.ndarray, norm: Callable[[np.ndarray, np.ndarray], np.ndarray] = np.hypot
    ) -> tuple[np.ndarray, np.ndarray]:
        """Signed distances (m) from each point (N, 2) to each rectangle (N, R) and disc (N, D),
        lengths by `norm` (x, y)."""
        x, y = points[:, 0, None], points[:, 1, None]
        dx, dy = x - self._rect_center[:, 0], y - self._rect_center[:, 1]
        lx = dx * self._rect_cos + dy * self._rect_sin
        ly = -dx * self._rect_sin + dy * self._rect_cos
        qx = np.abs(lx) - self._rect_half[:, 0]
        qy = np.abs(ly) - self._rect_half[:, 1]
        rects = norm(np.maximum(qx, 0.0), np.maximum(qy, 0.0)) + np.minimum(np.maximum(qx, qy), 0.0)
        discs = norm(x - self._disc_center[:, 0], y - self._disc_center[:, 1]) - self._disc_radius
        return rects, discs

    def _outline_to_discs(self, outline: np.ndarray, poses: np.ndarray, discs: np.ndarray) -> np.ndarray:
        """Signed distance (m) from the outline at each pose (M, 3) to disc `discs[m]`."""
        centres = _to_body(self._disc_center[discs], poses)
        return _polygon_distance(outline, centres) - self._disc_radius[discs]

    def _outline_to_rects(self, outline: np.ndarray, poses: np.ndarray, rects: np.ndarray) -> np.ndarray:
        """Signed distance (m) from the outline at each pose (M, 3) to rectangle `rects[m]`."""
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        world = np.einsum("kj,mij->mki", outline, np.stack((np.stack((c, -s), -1), np.stack((s, c), -1)), 1))
        world += poses[:, None, :2]  # (M, k, 2) the outline in the world
        rc, rs = self._rect_cos[rects], self._rect_sin[rects]
        half = self._rect_half[rects]
        signs = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)], dtype=float)
        local = signs[None] * half[:, None, :]
        corners = (
            np.stack(
                (
                    local[..., 0] * rc[:, None] - local[..., 1] * rs[:, None],
                    local[..., 0] * rs[:, None] + local[..., 1] * rc[:, None],
                ),
                -1,
            )
            + self._rect_center[rects][:, None, :]
        )  # (M, 4, 2)
        edges = np.roll(outline, -1, axis=0) - outline
        normals = np.column_stack((edges[:, 1], -edges[:, 0]))  # outward, counter-clockwise outline
        outline_axes = np.stack(
            (
                normals[None, :, 0] * c[:, None] - normals[None, :, 1] * s[:, None],
                normals[None, :, 0] * s[:, None] + normals[None, :, 1] * c[:, None],
            ),
            -1,
        )
        rect_axes = np.stack((np.column_stack((rc, rs)), np.column_stack((-rs, rc))), 1)
        axes = np.concatenate((outline_axes, rect_axes), axis=1)
        axes /= np.linalg.norm(axes, axis=-1, keepdims=True)  # (M, k + 2, 2)
        along_outline = np.einsum("mad,mkd->mak", axes, world)
        along_rect = np.einsum("mad,mkd->mak", axes, corners)
        overlap = np.minimum(along_outline.max(-1), along_rect.max(-1)) - np.maximum(
            along_outline.min(-1), along_rect.min(-1)
        )
        depth = overlap.min(axis=1)
        # Parted: the nearest pair of features includes a vertex of one of the two (convex) shapes.
        rel = world - self._rect_center[rects][:, None, :]
        lx = rel[..., 0] * rc[:, None] + rel[..., 1] * rs[:, None]
        ly = -rel[..., 0] * rs[:, None] + rel[..., 1] * rc[:, None]
        qx, qy = np.abs(lx) - half[:, None, 0], np.abs(ly) - half[:, None, 1]
        vertex_to_rect = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0)).min(axis=1)
        corner_to_outline = _polygon_distance(
            outline, _to_body(corners.reshape(-1, 2), np.repeat(poses, 4, 0))
        )
        parted = np.minimum(vertex_to_rect, corner_to_outline.reshape(-1, 4).min(axis=1))
        return np.where(depth < 0.0, parted, -depth)


def moving_distances(
    discs: np.ndarray,
    rects: np.ndarray,
    places: np.ndarray,
    poses: np.ndarray,
    outline: np.ndarray | None = None,
) -> np.ndarray:
    """Signed distance (m) at each pose (N, 3: x, y, yaw; or (N, 2) points) to the nearest of
    pieces that move: `discs` (D, 3: x, y, radius) and `rects` (R, 6: x, y, half x, half y, cos
    and sin of yaw; packed as the laser packs them), where `places` (N, D + R, 2; m) says their
    centres stood at each pose, discs first. From the point, or with `outline` (k, 2; the
    robot's convex counter-clockwise footprint in its frame) from the outline, negative when
    it overlaps (then minus the overlap's depth, as `Footprints.outline_distance`)."""
    poses = np.atleast_2d(np.asarray(poses, float))
    count, found = len(poses), np.full(len(poses), np.inf)
    d = len(discs)
    if d:
        centres = places[:, :d]
        beyond = (
            np.hypot(centres[..., 0] - poses[:, None, 0], centres[..., 1] - poses[:, None, 1]) - discs[:, 2]
        )
        if outline is None:
            found = np.minimum(found, beyond.min(axis=1))
        else:
            found = np.minimum(found, _outline_to_discs(outline, discs[:, 2], centres, poses, beyond))
    r = len(rects)
    if r:
        repeated = np.repeat(poses, r, 0)
        placed = Footprints.packed_rects(places[:, d:].reshape(-1, 2), np.tile(rects[:, 2:], (count, 1)))
        if outline is None:
            gaps = placed._paired_point_distances(repeated[:, :2])
        else:
            gaps = placed._outline_to_rects(outline, repeated, np.arange(len(repeated)))
        found = np.minimum(found, gaps.reshape(count, r).min(axis=1))
    return found


def _outline_to_discs(
    outline: np.ndarray, radii: np.ndarray, centres: np.ndarray, poses: np.ndarray, beyond: np.ndarray
) -> np.ndarray:
    """Signed distance (m) from the outline (k, 2; convex, counter-clockwise, robot frame) at
    each pose (N, 3) to the nearest disc of `radii` (D,) centred at `centres` (N, D, 2), whose
    gaps to each pose's origin are `beyond` (N, D; m). The outline's signed distance to a point
    is never less than the point's distance from the origin less the outline's circumscribed
    radius R, so only the discs whose gaps come within R of the exact gap to the disc nearest
    by centre are measured."""
    count = len(poses)
    nearest = beyond.argmin(axis=1)
    rows = np.arange(count)
    best = _polygon_distance(outline, _to_body(centres[rows, nearest], poses)) - radii[nearest]
    circumradius = float(np.hypot(outline[:, 0], outline[:, 1]).max())
    rows, columns = np.nonzero(beyond - circumradius <= best[:, None] + 1e-9)
    gaps = _polygon_distance(outline, _to_body(centres[rows, columns], poses[rows])) - radii[columns]
    found = np.full(count, np.inf)
    np.minimum.at(found, rows, gaps)
    return found


def _to_body(points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """World points (M, 2) in the frame of the pose beside each (M, 3)."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    dx, dy = points[:, 0] - poses[:, 0], points[:, 1] - poses[:, 1]
    return np.column_stack((c * dx + s * dy, -s * dx + c * dy))


def _quick_norm(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """sqrt(x^2 + y^2), some times quicker than `np.hypot` and within a few parts in 1e16 of it."""
    return np.sqrt(x * x + y * y)


def _inradius(polygon: np.ndarray) -> float:
    """The distance (m) from the origin to the nearest edge line of a convex counter-clockwise
    polygon (k, 2) about it: the radius of the disc about the origin it holds (0 for an origin
    outside it)."""
    edge = np.roll(polygon, -1, axis=0) - polygon
    inward = edge[:, 1] * polygon[:, 0] - edge[:, 0] * polygon[:, 1]  # edge x (origin - start)
    return max(0.0, float(np.min(inward / np.hypot(edge[:, 0], edge[:, 1]))))


def _polygon_distance(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Signed distance (m) from each point (M, 2) to a convex counter-clockwise polygon (k, 2);
    negative inside."""
    start = polygon[None, :, :]
    edge = (np.roll(polygon, -1, axis=0) - polygon)[None, :, :]
    rel = points[:, None, :] - start
    t = np.clip((rel * edge).sum(-1) / (edge * edge).sum(-1), 0.0, 1.0)
    gap = np.hypot(*np.moveaxis(rel - t[..., None] * edge, -1, 0)).min(axis=1)
    outside = (edge[..., 0] * rel[..., 1] - edge[..., 1] * rel[..., 0] < 0.0).any(axis=1)
    return np.where(outside, gap, -gap)


def scene_footprints(obstacles: Iterable[Obstacle], arena_size: Vec2 | None = None) -> Footprints:
    """All obstacle pieces, plus the border walls when `arena_size` is given."""
    pieces: list[Piece] = [p for ob in obstacles for p in ob.footprint()]
    if arena_size is not None:
        pieces.extend(border_footprint(arena_size))
    return Footprints(pieces)
