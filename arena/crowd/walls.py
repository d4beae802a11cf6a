"""Static walls and obstacles as line segments, and a spatial index over them.

Every crowd model sees the static world as segments: the boundaries of the map's blocking cells
(merged into maximal straight runs, so a 20 m wall is one segment, not 400) plus the edges of
the placed obstacles. :class:`WallIndex` answers "which wall pieces are within r of these
points" and "nearest wall point" for thousands of agents per step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.crowd.neighbors import CellList, Neighbors
from arena.maps.grid import OccupancyGrid
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]


def grid_wall_segments(
    grid: OccupancyGrid, *, border: bool = True
) -> tuple[FloatArray, FloatArray]:
    """Boundaries between blocking and free cells as merged axis-aligned segments.

    Args:
        grid: the map.
        border: treat the outside of the map as blocking, so free cells on the map's edge get a
            wall there (pedestrians cannot walk off the map).

    Returns:
        ``(a, b)``, each ``(s, 2)``: segment end points in metres.
    """
    occ = np.pad(grid.occupied, 1, constant_values=border)
    res = grid.resolution
    ox, oy = grid.origin
    a_list, b_list = [], []
    # Horizontal edges: between padded rows r and r + 1, i.e. at y = oy + r·res.
    diff_h = occ[1:, 1:-1] != occ[:-1, 1:-1]  # (H+1, W)
    for r, c0, c1 in _runs(diff_h):
        y = oy + r * res
        a_list.append((ox + c0 * res, y))
        b_list.append((ox + c1 * res, y))
    diff_v = occ[1:-1, 1:] != occ[1:-1, :-1]  # (H, W+1)
    for c, r0, r1 in _runs(diff_v.T):
        x = ox + c * res
        a_list.append((x, oy + r0 * res))
        b_list.append((x, oy + r1 * res))
    if not a_list:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.array(a_list, dtype=np.float64), np.array(b_list, dtype=np.float64)


_GRID_WALLS: list[tuple[NDArray[np.bool_], tuple[float, ...], float, FloatArray, FloatArray]] = []
"""The last map's wall segments (at most one entry): see :func:`grid_walls`."""


def grid_walls(grid: OccupancyGrid) -> tuple[FloatArray, FloatArray]:
    """:func:`~arena.crowd.walls.grid_wall_segments` of ``grid`` (``border=True``), cached.

    Tracing the walls costs milliseconds and every episode reset asks for them several times
    (simulator, crowd model, social states) on a map that rarely changes. The single-entry
    cache compares the occupancy (a copy, so in-place edits are seen), origin and resolution;
    the arrays it returns are read-only and the same objects while the map stays the same.
    """
    occ = np.asarray(grid.occupied)
    origin = tuple(float(v) for v in grid.origin)
    res = float(grid.resolution)
    if _GRID_WALLS:
        c_occ, c_origin, c_res, a, b = _GRID_WALLS[0]
        if c_origin == origin and c_res == res and c_occ.shape == occ.shape and np.array_equal(
            c_occ, occ
        ):
            return a, b
    a, b = grid_wall_segments(grid)
    a.flags.writeable = False
    b.flags.writeable = False
    _GRID_WALLS[:] = [(occ.copy(), origin, res, a, b)]
    return a, b


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int, int]]:
    """Maximal runs of True in each row: ``(row, start, end_exclusive)``."""
    padded = np.pad(mask, ((0, 0), (1, 1)), constant_values=False).astype(np.int8)
    d = np.diff(padded, axis=1)
    rows_s, starts = np.nonzero(d == 1)
    _, ends = np.nonzero(d == -1)
    # nonzero is row-major and every run has one start and one end, so they pair up in order.
    return list(zip(rows_s.tolist(), starts.tolist(), ends.tolist(), strict=True))


def world_segments(world: StaticWorld, *, border: bool = True) -> tuple[FloatArray, FloatArray]:
    """All static segments of an episode: map wall boundaries plus obstacle edges."""
    ga, gb = grid_wall_segments(world.grid, border=border)
    return np.concatenate([ga, world.segments_a]), np.concatenate([gb, world.segments_b])


class WallIndex:
    """Radius queries over wall segments, split into pieces of at most ``piece`` metres.

    Args:
        a: ``(s, 2)`` segment starts.
        b: ``(s, 2)`` segment ends.
        piece: maximum piece length (m); also the cell size of the underlying cell list.
    """

    def __init__(self, a: FloatArray, b: FloatArray, piece: float = 1.0) -> None:
        a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        self.a, self.b, self.owner = _pieces(a, b, piece)
        self._segments = int(a.shape[0])
        self._piece = piece
        self._index()

    def extended(self, a: FloatArray, b: FloatArray) -> WallIndex:
        """The index of this one's segments followed by ``(s, 2)`` segments ``a`` → ``b``.

        ``WallIndex(concat([own a, a]), concat([own b, b]), piece)`` to the bit, without
        splitting this one's segments again: pieces are cut segment by segment. A reset adds
        the episode's obstacle edges to the map's walls (the same on every episode of a map).
        """
        a = np.asarray(a, dtype=np.float64).reshape(-1, 2)
        b = np.asarray(b, dtype=np.float64).reshape(-1, 2)
        pa, pb, owner = _pieces(a, b, self._piece)
        out = WallIndex.__new__(WallIndex)
        out.a = np.concatenate([self.a, pa])
        out.b = np.concatenate([self.b, pb])
        out.owner = np.concatenate([self.owner, owner + self._segments])
        out._segments = self._segments + int(a.shape[0])
        out._piece = self._piece
        out._index()
        return out

    def _index(self) -> None:
        """The longest half-piece and the cell list over the pieces' midpoints."""
        self.half = 0.5 * float(np.max(np.hypot(*(self.b - self.a).T))) if len(self.a) else 0.0
        self._cells = CellList(0.5 * (self.a + self.b), max(self._piece, 1e-3))

    def __len__(self) -> int:
        return int(self.a.shape[0])

    def query(self, points: FloatArray, radius: float) -> Neighbors:
        """Pieces with any point strictly within ``radius`` of each query point."""
        cand = self._cells.query(points, radius + self.half)
        indptr, indices = _filter(
            np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2),
            self.a,
            self.b,
            cand.indptr,
            cand.indices,
            float(radius),
        )
        return Neighbors(indptr, indices, float(radius))

    def nearest(self, points: FloatArray, max_dist: float) -> tuple[FloatArray, FloatArray]:
        """Closest wall point to each query within ``max_dist``.

        Returns:
            ``(closest, dist)``: ``(n, 2)`` points and ``(n,)`` distances; ``inf`` distance (and
            the query point itself) where no wall is that close.
        """
        pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
        cand = self._cells.query(pts, max_dist + self.half)
        return _nearest(pts, self.a, self.b, cand.indptr, cand.indices, float(max_dist))


def _pieces(
    a: FloatArray, b: FloatArray, piece: float
) -> tuple[FloatArray, FloatArray, NDArray[np.int64]]:
    """Segments ``(s, 2)`` ``a`` → ``b`` cut into equal pieces of at most ``piece`` m.

    Returns:
        ``(pa, pb, owner)``: ``(m, 2)`` piece ends and ``(m,)`` the segment of each piece
        (every segment gives at least one piece, in order).
    """
    lengths = np.hypot(*(b - a).T) if len(a) else np.zeros(0)
    counts = np.maximum(np.ceil(lengths / piece).astype(np.int64), 1)
    owner = np.repeat(np.arange(len(a), dtype=np.int64), counts)
    k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    t0 = k / np.repeat(counts, counts)
    t1 = (k + 1) / np.repeat(counts, counts)
    d = (b - a)[owner]
    return a[owner] + t0[:, None] * d, a[owner] + t1[:, None] * d, owner


@njit(cache=True, inline="always")
def _closest_on_segment(px: float, py: float, ax: float, ay: float, bx: float, by: float):
    ex, ey = bx - ax, by - ay
    ee = ex * ex + ey * ey
    t = ((px - ax) * ex + (py - ay) * ey) / ee if ee > 0.0 else 0.0
    t = min(max(t, 0.0), 1.0)
    return ax + t * ex, ay + t * ey


@njit(cache=True)
def _filter(pts, a, b, indptr, indices, radius):
    n = pts.shape[0]
    r2 = radius * radius
    keep = np.zeros(indices.shape[0], dtype=np.bool_)
    counts = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            cx, cy = _closest_on_segment(pts[i, 0], pts[i, 1], a[j, 0], a[j, 1], b[j, 0], b[j, 1])
            if (cx - pts[i, 0]) ** 2 + (cy - pts[i, 1]) ** 2 < r2:
                keep[k] = True
                counts[i + 1] += 1
    for i in range(n):
        counts[i + 1] += counts[i]
    out = indices[keep]
    return counts, out


@njit(cache=True)
def _nearest(pts, a, b, indptr, indices, max_dist):
    n = pts.shape[0]
    closest = pts.copy()
    dist = np.full(n, math.inf)
    for i in range(n):
        best = max_dist * max_dist
        found = False
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            cx, cy = _closest_on_segment(pts[i, 0], pts[i, 1], a[j, 0], a[j, 1], b[j, 0], b[j, 1])
            d2 = (cx - pts[i, 0]) ** 2 + (cy - pts[i, 1]) ** 2
            if d2 < best:
                best = d2
                closest[i, 0], closest[i, 1] = cx, cy
                found = True
        if found:
            dist[i] = math.sqrt(best)
    return closest, dist
