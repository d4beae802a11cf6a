"""Rasterise world geometry (obstacle footprints, circles) into grid cell masks."""

from __future__ import annotations

import functools
import math
import threading
import weakref
from collections import OrderedDict
from collections.abc import Callable, Hashable, Sequence
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.core.geometry import convex_polygon_overlaps_squares, points_in_polygon
from arena.maps.grid import OccupancyGrid

if TYPE_CHECKING:
    from arena.scene.episode import Episode

T = TypeVar("T")


class GridMemo:
    """Values derived from a map, computed once per grid object and key (an LRU of ``size``).

    Grids are immutable and a map is shared by every episode drawn on it, so rasters derived
    from it need not be rebuilt per reset. An entry is tied to the grid *object* through a weak
    reference (another grid misses, even one that reuses a dead grid's ``id``) and ``key`` must
    name every other input by value. Entries of a grid that was garbage collected are dropped
    at the next lookup, so a run that builds a new map per episode holds no dead maps' rasters.
    Values are shared: freeze arrays before returning them.

    Args:
        size: entries kept; the least recently used goes first.
    """

    def __init__(self, size: int) -> None:
        self.size = size
        self._entries: OrderedDict[tuple[int, Hashable], tuple[weakref.ref[OccupancyGrid], Any]]
        self._entries = OrderedDict()
        self._dead: list[int] = []  # ids of collected grids (appended by weakref callbacks)
        self._lock = threading.Lock()

    def get(self, grid: OccupancyGrid, key: Hashable, compute: Callable[[], T]) -> T:
        """The value for ``(grid, key)``: ``compute()`` on the first request, then the same."""
        full = (id(grid), key)
        with self._lock:
            self._drop_dead()
            hit = self._entries.get(full)
            if hit is not None and hit[0]() is grid:
                self._entries.move_to_end(full)
                return hit[1]  # type: ignore[no-any-return]
        value = compute()
        ref = weakref.ref(grid, functools.partial(_note_dead, self._dead, full[0]))
        with self._lock:
            self._entries[full] = (ref, value)
            while len(self._entries) > self.size:
                self._entries.popitem(last=False)
        return value

    def _drop_dead(self) -> None:
        # The callbacks only append (they may run inside any allocation, even under the lock);
        # the entries are dropped here. A dead id reused by a new grid costs that grid a miss.
        if self._dead:
            gone = set()
            while self._dead:
                gone.add(self._dead.pop())
            for full in [k for k in self._entries if k[0] in gone]:
                del self._entries[full]

    def __len__(self) -> int:
        with self._lock:
            self._drop_dead()
            return len(self._entries)


def _note_dead(dead: list[int], grid_id: int, _: weakref.ref[OccupancyGrid]) -> None:
    dead.append(grid_id)


_WINDOWS = GridMemo(256)
"""Footprint rasters: a reset rasterises each new obstacle for its sampler and its crowd."""


def polygon_mask(grid: OccupancyGrid, polygons: Sequence[NDArray[np.float64]]) -> NDArray[np.bool_]:
    """``(height, width)`` bool mask of the cells each polygon overlaps.

    A cell is marked when its centre lies inside the polygon or, for convex polygons, when the
    polygon overlaps the cell square at all (so thin obstacles still mark cells).
    """
    mask = np.zeros(grid.data.shape, dtype=bool)
    for poly in polygons:
        window = polygon_window(grid, poly)
        if window is not None:
            r0, c0, win = window
            mask[r0 : r0 + win.shape[0], c0 : c0 + win.shape[1]] |= win
    return mask


def burn_obstacles(grid: OccupancyGrid, obstacles: Sequence[Any]) -> OccupancyGrid:
    """A copy of ``grid`` with the cells the obstacles' polygons overlap marked occupied.

    What the global planner plans on, and what ``arena maps generate --burn-obstacles`` writes
    so that map-only tools (ROS ``map_server``, RViz) see placed obstacles. ``obstacles``: any
    objects with a ``polygon`` ``(k, 2)`` in metres (:class:`~arena.scene.state.Obstacle`).
    """
    if not obstacles:
        return grid
    return grid.with_occupied(polygon_mask(grid, [o.polygon for o in obstacles]))


def planning_grid(episode: Episode) -> OccupancyGrid:
    """The episode's map with its known static obstacles burnt in: what the global planner plans on.

    One definition for every episode loop (``arena run``, the learning envs, value training) and
    the trajectory report, so all of them plan on the same grid.
    """
    return burn_obstacles(episode.grid, episode.obstacles)


def polygon_window(
    grid: OccupancyGrid, polygon: NDArray[np.float64]
) -> tuple[int, int, NDArray[np.bool_]] | None:
    """One polygon's part of :func:`polygon_mask`, on its bounding box only.

    Callers that add a few shapes to a mask they keep OR this block in (a full-map mask per
    shape cost more than the shape). Results are memoised per grid and polygon: a reset
    rasterises each obstacle it places for the position sampler and again for the crowd.

    Returns:
        ``(row0, col0, window)``: ``window`` ``(h, w)`` bool (read-only) is the mask's block
        whose cell ``(0, 0)`` is ``(row0, col0)``; ``None`` where the polygon misses the map.
    """
    p = np.asarray(polygon, dtype=np.float64)
    return _WINDOWS.get(grid, (p.shape, p.tobytes()), lambda: _polygon_window(grid, p))


def _polygon_window(
    grid: OccupancyGrid, p: NDArray[np.float64]
) -> tuple[int, int, NDArray[np.bool_]] | None:
    res = grid.resolution
    (c0, r0), (c1, r1) = (
        np.floor((p.min(axis=0) - grid.origin) / res).astype(int),
        np.floor((p.max(axis=0) - grid.origin) / res).astype(int),
    )
    r0, c0 = max(r0, 0), max(c0, 0)
    r1, c1 = min(r1, grid.height - 1), min(c1, grid.width - 1)
    if r0 > r1 or c0 > c1:
        return None
    centers = _cell_centers(int(r0), int(r1) + 1, int(c0), int(c1) + 1, *grid.origin, res)
    inside = points_in_polygon(centers, p)
    if _is_convex(p):
        inside |= convex_polygon_overlaps_squares(p, centers, 0.5 * res)
    window = inside.reshape(r1 - r0 + 1, c1 - c0 + 1)
    window.setflags(write=False)
    return int(r0), int(c0), window


def disk_mask(
    grid: OccupancyGrid, centers: NDArray[np.float64], radii: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """``(height, width)`` bool mask of the cells whose centres lie within the given circles."""
    mask = np.zeros(grid.data.shape, dtype=bool)
    for (x, y), r in zip(
        np.asarray(centers).reshape(-1, 2), np.asarray(radii).reshape(-1), strict=True
    ):
        or_disk(mask, grid, float(x), float(y), float(r))
    return mask


@njit(cache=True)
def _cell_centers(
    r0: int, r1: int, c0: int, c1: int, ox: float, oy: float, res: float
) -> NDArray[np.float64]:
    """``(m, 2)`` centres of the cells of rows ``r0:r1``, columns ``c0:c1``, row-major.

    ``grid.cell_to_world`` of the block's cells, the same float operations in one pass.
    """
    out = np.empty(((r1 - r0) * (c1 - c0), 2))
    k = 0
    for r in range(r0, r1):
        y = oy + (float(r) + 0.5) * res
        for c in range(c0, c1):
            out[k, 0] = ox + (float(c) + 0.5) * res
            out[k, 1] = y
            k += 1
    return out


def or_disk(mask: NDArray[np.bool_], grid: OccupancyGrid, x: float, y: float, r: float) -> None:
    """``mask |= disk_mask(grid, [[x, y]], [r])`` in place, touching only the disc's window.

    ``mask`` is ``(height, width)`` bool; the disc has centre ``(x, y)`` and radius ``r`` (m).
    A reset forbids a few dozen discs, and a full-map mask per disc cost most of their time.
    """
    if not (math.isfinite(x) and math.isfinite(y)):
        return  # no window on the map (numpy's float → int cast gave an empty one)
    res = grid.resolution
    k = math.ceil(r / res) + 1
    row = math.floor((y - grid.origin[1]) / res)
    col = math.floor((x - grid.origin[0]) / res)
    r0, r1 = max(row - k, 0), min(row + k + 1, grid.height)
    c0, c1 = max(col - k, 0), min(col + k + 1, grid.width)
    if r0 < r1 and c0 < c1:
        _or_disk(mask, grid.origin[0], grid.origin[1], res, x, y, r, r0, r1, c0, c1)


@njit(cache=True)
def _or_disk(
    mask: NDArray[np.bool_],
    ox: float,
    oy: float,
    res: float,
    x: float,
    y: float,
    r: float,
    r0: int,
    r1: int,
    c0: int,
    c1: int,
) -> None:
    """Set the cells of rows ``r0:r1``, columns ``c0:c1`` whose centre is within the disc.

    The cell test of the vectorised original, ``(cx - x)² + (cy - y)² <= r²`` with centres
    ``origin + (index + 0.5) · res``: the same float operations, so the same cells.
    """
    r2 = r * r
    for i in range(r0, r1):
        dy = (oy + (float(i) + 0.5) * res) - y
        dy2 = dy * dy
        for j in range(c0, c1):
            dx = (ox + (float(j) + 0.5) * res) - x
            if dx * dx + dy2 <= r2:
                mask[i, j] = True


def _is_convex(p: NDArray[np.float64]) -> bool:
    return bool(_turns_one_way(np.ascontiguousarray(p, dtype=np.float64)))


@njit(cache=True)
def _turns_one_way(p: NDArray[np.float64]) -> bool:
    """Whether all turns ``d_i × d_{i+1}`` of the edges ``d_i = p_{i+1} - p_i`` share a sign.

    Up to 1e-12 (collinear edges count as either sign); an empty polygon counts as convex.
    """
    k = p.shape[0]
    left = True
    right = True
    for i in range(k):
        j = (i + 1) % k
        n = (i + 2) % k
        d1x = p[j, 0] - p[i, 0]
        d1y = p[j, 1] - p[i, 1]
        d2x = p[n, 0] - p[j, 0]
        d2y = p[n, 1] - p[j, 1]
        cross = d1x * d2y - d1y * d2x
        if not cross >= -1e-12:
            left = False
        if not cross <= 1e-12:
            right = False
    return left or right
