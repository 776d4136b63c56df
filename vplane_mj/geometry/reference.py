"""Reference shortest path: the benchmark a navigation run's path length is compared with.

The reference is the shortest collision-free path of the robot's disc from start to
goal on the exact contract geometry (`vplane_mj.geometry.shapes`) inflated by the robot radius
(plus an optional extra clearance).

Method
------
1. Free-space grid: cell centres ((i + 1/2) * cell_m, (j + 1/2) * cell_m) over the arena
   [0, W] x [0, H]; a cell is free when the signed distance `Footprints.distance` of its
   centre to the obstacles (and to the border walls when `world.border` is true) is
   greater than robot radius + clearance (vectorised, in bounded blocks: see Bounds).
2. Graph search: 8-connected grid graph (diagonal moves only when both orthogonal
   neighbours are free, so no corner is cut), Dijkstra from `scipy.sparse.csgraph`.
   The exact start and goal points are extra nodes joined to the nearby free cells they
   see, and directly to each other when the straight segment between them is clear.
3. Line-of-sight smoothing: from each anchor the path jumps to the farthest later vertex
   whose straight segment is clear, i.e. every sample along it (spacing <= cell_m / 2,
   both ends included) has exact distance > robot radius + clearance; then the taut
   pull described below.

Accuracy: an 8-connected grid path is at most 1 / cos(22.5 deg) ~ 8.2 % longer than the
shortest path through the same cells, and line-of-sight smoothing through its vertices
alone can stay a few per cent long around curved obstacles (3.4 % round a 1 m cylinder).
So a last step pulls the polyline taut: coarse to fine, segments are subdivided, each
vertex moves toward its neighbours' midpoint as far as both of its segments stay clear,
and the line-of-sight pass runs again. Measured at the default 5 cm cell against the
analytic tangent-and-arc answers (tests/test_reference.py): 0.16 % long round an inflated
wall end, 0.01 % round cylinders of radius 0.3 m, 1 m and 2 m, exact (1e-12) on a clear
straight line; the result is never shorter than the optimum by more than the sampling
tolerance. Samples are checked every cell_m / 2, so a chord between two samples may dip
into the inflated obstacle by at most (cell_m / 2)^2 / (8 * robot radius) (< 1 mm), and
an inflated obstacle thinner than cell_m / 2 could be missed (contract walls inflated by
the robot radius are > 0.2 m thick). Segments touching the start (goal) accept the
start's (goal's) own clearance when it is below the threshold (the contract allows a
start exactly one robot radius from an obstacle).
Run time: ~0.15-0.4 s for a 10 x 10 m arena at 5 cm (40,000 cells); ~1.6 s at 2.5 cm.

Bounds: the grid has at most about MAX_GRID_CELLS cells, so an arena larger than about
25 x 25 m gets coarser grid cells, which the graph search and the taut pull use (segments
are still sampled every cell_m / 2, so clearance is checked as finely); on a 100 x 100 m
arena (0.2 m cells) the path comes out 0.1 % longer than with 5 cm cells. Every distance
query measures a point only against the pieces listed in its tile (`_NearDistance`), at
most _MAX_PAIRS point-piece pairs at a time. Measured on one core: a 100 x 100 m arena with
a 90 m wall, ~3.5 s and 160 MiB at peak (without these bounds: 27 s and 4.2 GiB); 1000
cylinders in 12 x 12 m, ~1.1 s and 21 MiB (without: 28 s and 4.6 GiB; in 20 x 20 m it
needed more than 8 GiB).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vplane_mj.geometry import shapes
from vplane_mj.geometry.cache import cached
from vplane_mj.geometry.shapes import Footprints, Rect, scene_footprints

_EPS = 1e-9
_CONNECT_CELLS = 3.0
"""Start and goal connect to free cells within this many cell sizes (more if none is seen)."""
MAX_GRID_CELLS = 250_000
"""The free-space grid has about this many cells at most; larger arenas get coarser cells."""
_MAX_PAIRS = 1 << 20
"""Point-piece pairs measured in one vectorised call (bounds the temporary arrays)."""
_COARSE_STRIDE = 16
_COARSE_FROM = 20_000
"""Segment tests with more samples than _COARSE_FROM look at every _COARSE_STRIDE-th first."""
_FEW_PIECES = 24
"""Scenes with at most this many pieces are measured against all of them (faster than tiles)."""
_TILES_PER_SIDE = 64
"""At most this many tiles along each side of the arena for finding the pieces near a point."""


@dataclass(frozen=True)
class ReferencePath:
    """The reference path: its length (m) and its waypoints (N, 2) from start to goal."""

    length_m: float
    points: np.ndarray


def _rounded_rects(fp: Footprints) -> tuple[np.ndarray, ...]:
    """Every piece as a rounded rectangle: centre (P, 2), half extents (P, 2), cos and sin of its
    yaw (P,), corner radius (P,). A rectangle has radius 0; a disc is a point with its radius."""
    rects = [p if isinstance(p, Rect) else Rect(p.center, (0.0, 0.0)) for p in fp.pieces]
    center = np.array([r.center for r in rects], dtype=float).reshape(-1, 2)
    half = np.array([r.half for r in rects], dtype=float).reshape(-1, 2)
    yaw = np.array([r.yaw for r in rects], dtype=float)
    radius = np.array([0.0 if isinstance(p, Rect) else p.radius for p in fp.pieces], dtype=float)
    return center, half, np.cos(yaw), np.sin(yaw), radius


class _NearDistance:
    """Signed distance from points to a scene's pieces, exact up to `reach` (beyond it: > reach).

    The arena is cut into square tiles; each piece is listed in the tiles that its bounding
    box grown by `reach` overlaps (tile indices clipped to the arena's tiles, so a point
    anywhere is served). A point is measured only against its tile's pieces, at most
    _MAX_PAIRS point-piece pairs at a time: many obstacles and large arenas stay cheap.
    """

    def __init__(self, fp: Footprints, size: tuple[float, float], reach: float):
        self.footprints = fp
        self.tile_m = max(2.0 * reach, max(size) / _TILES_PER_SIDE, 1e-3)
        self.shape = (max(1, math.ceil(size[0] / self.tile_m)), max(1, math.ceil(size[1] / self.tile_m)))
        self.count = len(fp)
        self.center, self.half, self.cos, self.sin, self.radius = _rounded_rects(fp)
        # Bounding boxes: the rotated half extents projected on x and y, plus the radius.
        extent = (
            np.column_stack(
                [
                    np.abs(self.cos) * self.half[:, 0] + np.abs(self.sin) * self.half[:, 1],
                    np.abs(self.sin) * self.half[:, 0] + np.abs(self.cos) * self.half[:, 1],
                ]
            )
            + (self.radius + reach)[:, None]
        )
        first, last = self._tile_xy(self.center - extent), self._tile_xy(self.center + extent)
        spans = last - first + 1
        counts = spans[:, 0] * spans[:, 1]
        piece = np.repeat(np.arange(self.count), counts)
        k = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        tile_x, tile_y = first[piece, 0] + k // spans[piece, 1], first[piece, 1] + k % spans[piece, 1]
        tile = tile_x * self.shape[1] + tile_y
        order = np.argsort(tile, kind="stable")
        self._tile_pieces = piece[order]
        self._tile_start = np.searchsorted(tile[order], np.arange(self.shape[0] * self.shape[1] + 1))

    def __len__(self) -> int:
        return self.count

    def _tile_xy(self, points: np.ndarray) -> np.ndarray:
        """Tile indices (N, 2) of points, clipped to the arena's tiles."""
        cells = np.floor(np.asarray(points, dtype=float) / self.tile_m)
        return np.clip(cells, 0, np.array(self.shape) - 1).astype(int)

    def _pair_distance(self, points: np.ndarray, pieces: np.ndarray) -> np.ndarray:
        """Signed distance from each point (M, 2) to the piece of the same row (M,)."""
        rel = points - self.center[pieces]
        cos, sin = self.cos[pieces], self.sin[pieces]
        qx = np.abs(rel[:, 0] * cos + rel[:, 1] * sin) - self.half[pieces, 0]
        qy = np.abs(-rel[:, 0] * sin + rel[:, 1] * cos) - self.half[pieces, 1]
        outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qy, 0.0))
        return outside + np.minimum(np.maximum(qx, qy), 0.0) - self.radius[pieces]

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Like Footprints.distance where that is at most `reach`; larger (or inf) elsewhere."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        if self.count <= _FEW_PIECES:  # every piece, a block of points at a time
            block = max(1, _MAX_PAIRS // max(1, self.count))
            if len(pts) <= block:
                return self.footprints.distance(pts)
            return np.concatenate(
                [self.footprints.distance(pts[i : i + block]) for i in range(0, len(pts), block)]
            )
        out = np.full(len(pts), np.inf)
        xy = self._tile_xy(pts)
        tiles = xy[:, 0] * self.shape[1] + xy[:, 1]
        begin, counts = self._tile_start[tiles], np.diff(self._tile_start)[tiles]
        ends = np.cumsum(counts)
        lo = 0
        while lo < len(pts):  # blocks of points with at most _MAX_PAIRS pairs (at least one point)
            base = ends[lo - 1] if lo else 0
            hi = max(lo + 1, int(np.searchsorted(ends, base + _MAX_PAIRS, side="right")))
            block = np.arange(lo, hi)[counts[lo:hi] > 0]
            if len(block):
                n = counts[block]
                point = np.repeat(block, n)
                offsets = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
                pieces = self._tile_pieces[begin[point] + offsets]
                d = self._pair_distance(pts[point], pieces)
                out[block] = np.minimum.reduceat(d, np.cumsum(n) - n)
            lo = hi
        return out


def _polyline_length(points: np.ndarray) -> float:
    return float(np.sum(np.hypot(*np.diff(points, axis=0).T)))


def _pairs_clear(fp: _NearDistance, a: np.ndarray, b: np.ndarray, spacing: float, thr) -> np.ndarray:
    """For each segment a[i]..b[i] ((M, 2) each): is every sample farther than thr (scalar or (M,))?

    With more than _COARSE_FROM samples in all, every _COARSE_STRIDE-th sample is tested
    first: most blocked segments fail there, and only those that pass are tested in full.
    """
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    a = np.broadcast_to(a, b.shape) if len(a) == 1 else a
    if len(b) == 0:
        return np.zeros(0, dtype=bool)
    if not len(fp):
        return np.ones(len(b), dtype=bool)
    lengths = np.hypot(b[:, 0] - a[:, 0], b[:, 1] - a[:, 1])
    counts = np.ceil(lengths / spacing).astype(int) + 1
    thr = np.broadcast_to(np.asarray(thr, dtype=float), (len(b),))
    if counts.sum() <= _COARSE_FROM:
        return _samples_clear(fp, a, b, counts, 1, thr)
    ok = _samples_clear(fp, a, b, counts, _COARSE_STRIDE, thr)
    todo = np.flatnonzero(ok)
    ok[todo] = _samples_clear(fp, a[todo], b[todo], counts[todo], 1, thr[todo])
    return ok


def _samples_clear(
    fp: _NearDistance, a: np.ndarray, b: np.ndarray, counts: np.ndarray, stride: int, thr: np.ndarray
) -> np.ndarray:
    """Whether samples 0, stride, 2*stride, ... and the last of each segment's `counts` are all
    farther than thr; in blocks of at most _MAX_PAIRS samples."""
    used = counts if stride == 1 else (counts - 2) // stride + 2  # samples per segment, both ends in
    ends = np.cumsum(used)
    ok = np.zeros(len(b), dtype=bool)
    lo = 0
    while lo < len(b):
        base = ends[lo - 1] if lo else 0
        hi = max(lo + 1, int(np.searchsorted(ends, base + _MAX_PAIRS, side="right")))
        n = used[lo:hi]
        seg = np.repeat(np.arange(lo, hi), n)
        starts = np.cumsum(n) - n
        k = np.arange(int(n.sum())) - np.repeat(starts, n)
        if stride > 1:
            k = np.minimum(k * stride, counts[seg] - 1)
        t = k / np.maximum(counts[seg] - 1, 1)
        pts = a[seg] + t[:, None] * (b[seg] - a[seg])
        ok[lo:hi] = np.logical_and.reduceat(fp.distance(pts) > thr[seg], starts)
        lo = hi
    return ok


class _Clearance:
    """Segment tests against one scene: threshold `thr`, relaxed at the start and the goal."""

    def __init__(self, fp: _NearDistance, spacing: float, thr: float, thr_start: float, thr_goal: float):
        self.fp, self.spacing, self.thr = fp, spacing, thr
        self.thr_start, self.thr_goal = thr_start, thr_goal

    def pairs(self, a: np.ndarray, b: np.ndarray, thr) -> np.ndarray:
        return _pairs_clear(self.fp, a, b, self.spacing, thr)

    def polyline_thresholds(self, n_points: int) -> np.ndarray:
        """The threshold of each segment of a polyline of n_points from start to goal."""
        thr = np.full(n_points - 1, self.thr)
        thr[0] = min(thr[0], self.thr_start)
        thr[-1] = min(thr[-1], self.thr_goal)
        return thr


def _shortcut(path: np.ndarray, clear: _Clearance) -> np.ndarray:
    """Line-of-sight smoothing: from each anchor jump to the farthest later vertex in sight."""
    last = len(path) - 1
    keep = [0]
    while keep[-1] != last:
        i = keep[-1]
        later = path[i + 1 :]
        thr = np.full(len(later), clear.thr_start if i == 0 else clear.thr)
        thr[-1] = min(thr[-1], clear.thr_goal)
        visible = np.flatnonzero(clear.pairs(path[i][None], later, thr))
        keep.append(i + 1 + int(visible[-1]) if len(visible) else i + 1)
    return path[keep]


def _subdivide(path: np.ndarray, max_len: float) -> np.ndarray:
    """Split every segment longer than max_len into equal parts."""
    out = [path[:1]]
    for a, b in itertools.pairwise(path):
        parts = max(1, math.ceil(math.dist(a, b) / max_len))
        out.append(a + np.outer(np.arange(1, parts + 1) / parts, b - a))
    return np.concatenate(out)


def _relax(path: np.ndarray, clear: _Clearance, cell_m: float) -> np.ndarray:
    """Pull the polyline taut: subdivide, move vertices toward their neighbours' midpoint while
    both of their segments stay clear (odd and even vertices in turn), shortcut; coarse to fine."""
    max_len = max(_polyline_length(path) / 4, 8 * cell_m)
    while True:
        path = _subdivide(path, max_len)
        for _ in range(12):
            for parity in (1, 0):
                k = np.arange(1, len(path) - 1)
                k = k[k % 2 == parity]
                if not len(k):
                    continue
                thr = clear.polyline_thresholds(len(path))
                delta = (path[k - 1] + path[k + 1]) / 2 - path[k]
                todo = np.ones(len(k), dtype=bool)
                for alpha in (1.0, 0.5, 0.25, 0.125, 0.0625):
                    kk = k[todo]
                    cand = path[kk] + alpha * delta[todo]
                    ok = clear.pairs(path[kk - 1], cand, thr[kk - 1]) & clear.pairs(
                        cand, path[kk + 1], thr[kk]
                    )
                    path[kk[ok]] = cand[ok]
                    todo[np.flatnonzero(todo)[ok]] = False
                    if not todo.any():
                        break
        path = _shortcut(path, clear)
        if max_len <= 4 * cell_m:
            return path
        max_len /= 2


def shortest_path(
    scenario, robot_radius_m: float, cell_m: float = 0.05, clearance_m: float = 0.0
) -> ReferencePath | None:
    """The shortest collision-free path of the robot's disc from start to goal; None if there is none.

    Segments are checked every cell_m / 2; the grid's cells are cell_m, or coarser when the
    arena would need more than MAX_GRID_CELLS of them.
    """
    from scipy.sparse.csgraph import dijkstra  # here: a cached reference path needs no scipy

    world, robot = scenario.world, scenario.robot
    width, height = world.size
    thr = robot_radius_m + clearance_m
    scene = scene_footprints(world.obstacles, world.size if world.border else None)
    fp = _NearDistance(scene, world.size, thr)
    spacing = cell_m / 2
    cell_m = max(cell_m, math.sqrt(width * height / MAX_GRID_CELLS))
    start = np.asarray(robot.start, dtype=float)
    goal = np.asarray(robot.goal, dtype=float)

    def dist(points: np.ndarray) -> np.ndarray:
        pts = np.atleast_2d(points)
        return fp.distance(pts) if len(fp) else np.full(len(pts), np.inf)

    d_start, d_goal = dist(start)[0], dist(goal)[0]
    if d_start < robot_radius_m - 1e-6 or d_goal < robot_radius_m - 1e-6:
        return None  # the robot's disc overlaps an obstacle at an end point
    clear = _Clearance(fp, spacing, thr, min(thr, d_start - _EPS), min(thr, d_goal - _EPS))

    if clear.pairs(start, goal[None], min(clear.thr_start, clear.thr_goal))[0]:
        return ReferencePath(float(np.hypot(*(goal - start))), np.array([start, goal]))

    # 1. free-space grid
    nx, ny = max(1, math.ceil(width / cell_m)), max(1, math.ceil(height / cell_m))
    xs, ys = (np.arange(nx) + 0.5) * cell_m, (np.arange(ny) + 0.5) * cell_m
    gx, gy = np.meshgrid(xs, ys)  # (ny, nx)
    centres = np.column_stack([gx.ravel(), gy.ravel()])
    free = (dist(centres) > thr).reshape(ny, nx)
    n = nx * ny

    # 2. 8-connected graph without corner cutting, plus the start and goal nodes
    graph = _grid_graph(free, centres, cell_m, (start, goal), clear)
    cost, pred = dijkstra(graph, directed=False, indices=n, return_predecessors=True)
    if not np.isfinite(cost[n + 1]):
        return None
    chain = [n + 1]
    while chain[-1] != n:
        chain.append(int(pred[chain[-1]]))
    path = np.array([start, *centres[chain[-2:0:-1]], goal])

    # 3. line-of-sight smoothing, then pull the polyline taut
    path = _relax(_shortcut(path, clear), clear, cell_m)
    return ReferencePath(_polyline_length(path), path)


def _grid_graph(
    free: np.ndarray,
    centres: np.ndarray,
    cell_m: float,
    ends: tuple[np.ndarray, np.ndarray],
    clear: _Clearance,
):
    """The graph of the free cells (ny, nx) of `cell_m` (m), 8-connected without corner cutting,
    with node n (the start) and n + 1 (the goal) joined to the free cells they see in a straight
    line nearby; edge weights in m. A scipy CSR matrix."""
    from scipy.sparse import coo_matrix

    ny, nx = free.shape
    n = nx * ny
    idx = np.arange(n).reshape(ny, nx)
    rows, cols, weights = [], [], []

    def link(src: np.ndarray, dst: np.ndarray, mask: np.ndarray, w: float) -> None:
        rows.append(src[mask])
        cols.append(dst[mask])
        weights.append(np.full(int(mask.sum()), w))

    link(idx[:, :-1], idx[:, 1:], free[:, :-1] & free[:, 1:], cell_m)
    link(idx[:-1, :], idx[1:, :], free[:-1, :] & free[1:, :], cell_m)
    square = free[:-1, :-1] & free[:-1, 1:] & free[1:, :-1] & free[1:, 1:]
    link(idx[:-1, :-1], idx[1:, 1:], square, cell_m * math.sqrt(2))
    link(idx[:-1, 1:], idx[1:, :-1], square, cell_m * math.sqrt(2))

    free_ids = np.flatnonzero(free.ravel())
    start, goal = ends
    for node, point, threshold in ((n, start, clear.thr_start), (n + 1, goal, clear.thr_goal)):
        radius = _CONNECT_CELLS * cell_m
        seen = np.zeros(0, dtype=int)
        while not len(seen) and radius <= 4 * _CONNECT_CELLS * cell_m:
            near = free_ids[np.hypot(*(centres[free_ids] - point).T) <= radius]
            seen = near[clear.pairs(point[None], centres[near], threshold)]
            radius *= 2
        rows.append(np.full(len(seen), node))
        cols.append(seen)
        weights.append(np.maximum(np.hypot(*(centres[seen] - point).T), _EPS))
    return coo_matrix(
        (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(n + 2, n + 2)
    ).tocsr()


def _source_digest() -> str:
    """SHA-256 of the code that computes a reference path: a change to it is a new cache key."""
    digest = hashlib.sha256()
    for module in (__file__, shapes.__file__):
        digest.update(Path(module).read_bytes())
    return digest.hexdigest()


def world_key(scenario, robot_radius_m: float, clearance_m: float = 0.0) -> dict:
    """Everything the reference path depends on: the arena, its obstacles as footprint pieces,
    start, goal, robot radius and clearance, and the code that computes it (not the planner,
    its parameters, the sensors, the seed or the goal tolerance, which is subtracted
    afterwards)."""
    world = scenario.world
    pieces = [
        ["disc", *piece.center, piece.radius]
        if isinstance(piece, shapes.Disc)
        else ["rect", *piece.center, *piece.half, piece.yaw]
        for piece in scene_footprints(world.obstacles, world.size if world.border else None).pieces
    ]
    return {
        "code": _SOURCE_DIGEST,
        "size": list(world.size),
        "pieces": pieces,
        "start": list(scenario.robot.start),
        "goal": list(scenario.robot.goal),
        "robot_radius_m": float(robot_radius_m),
        "clearance_m": float(clearance_m),
    }


_LENGTHS: dict[str, float | None] = {}
"""Reference lengths by world key, in memory (the most recent MEMORY_WORLDS)."""
MEMORY_WORLDS = 256


def shortest_path_length(scenario, robot_radius_m: float, clearance_m: float = 0.0) -> float | None:
    """The reference path length (m) to the goal point for the robot's disc plus `clearance_m`,
    or None when there is no path.

    Computed once per world (`world_key`) and kept in memory and in the on-disk cache
    (`vplane_mj.geometry.cache`), so every planner, seed and worker of a sweep, and later sweeps,
    share it.
    """
    key = world_key(scenario, robot_radius_m, clearance_m)
    text = json.dumps(key, sort_keys=True)
    if text not in _LENGTHS:

        def compute() -> float | None:
            ref = shortest_path(scenario, robot_radius_m, clearance_m=clearance_m)
            return None if ref is None else ref.length_m

        if len(_LENGTHS) >= MEMORY_WORLDS:
            del _LENGTHS[next(iter(_LENGTHS))]
        _LENGTHS[text] = cached("reference", key, compute)
    return _LENGTHS[text]


_SOURCE_DIGEST = _source_digest()
