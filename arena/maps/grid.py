"""The occupancy grid: one map raster with its world placement.

Cell values follow ``nav_msgs/OccupancyGrid``: ``0`` free, ``100`` occupied, ``-1`` unknown.
Row 0 of :attr:`OccupancyGrid.data` is the row at the map origin (lowest y), as in ROS messages;
images on disk have row 0 at the top, so :mod:`arena.maps.io` flips them on load and save.

The cell ``(row, col)`` covers ``x ∈ [ox + col·res, ox + (col+1)·res)`` and
``y ∈ [oy + row·res, oy + (row+1)·res)``; its centre is half a cell further.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from arena.core.errors import MapError

FREE = 0
OCCUPIED = 100
UNKNOWN = -1

MAX_CELLS = 50_000_000
"""Most cells a map may have (e.g. 350 × 350 m at 5 cm): the grid and its distance map take
about 9 bytes a cell (450 MB here), and larger requests are mistakes (``map.width=1e9``)."""
MIN_CELLS = 3
"""Fewest cells per side: a walled map needs a free cell inside its one-cell border."""
MAX_COORDINATE = 1e6
"""m; largest map origin coordinate accepted. Beyond ~1e7 m a float64 cannot tell 5 cm
cells apart any more (1e20 + 0.05 == 1e20); 1000 km covers any building's map frame."""


def check_grid_size(width_m: float, height_m: float, resolution: float, *,
                    min_cells: int = MIN_CELLS) -> tuple[int, int]:
    """The ``(rows, cols)`` of a ``width_m × height_m`` map at ``resolution`` (m).

    ``min_cells`` is the fewest cells a side may have (a map without walls may have 1).

    Raises:
        MapError: a size is not a finite positive number, a side has fewer than
            :data:`MIN_CELLS` cells or the map more than :data:`MAX_CELLS` cells (with the
            memory it would take).
    """
    for label, v in (("width", width_m), ("height", height_m), ("resolution", resolution)):
        if not (isinstance(v, int | float) and np.isfinite(v) and v > 0):
            raise MapError(f"{label} must be a finite number > 0 (m), got {v!r}")
    rows, cols = round(height_m / resolution), round(width_m / resolution)
    if min(rows, cols) < min_cells:
        raise MapError(
            f"a {width_m:g} × {height_m:g} m map at resolution {resolution:g} m has "
            f"{cols} × {rows} cells; each side needs at least {min_cells} (lower the resolution)"
        )
    if rows * cols > MAX_CELLS:
        raise MapError(
            f"a {width_m:g} × {height_m:g} m map at resolution {resolution:g} m has "
            f"{rows * cols:.3g} cells (~{9 * rows * cols / 2**30:.3g} GiB); at most "
            f"{MAX_CELLS:,} cells are allowed (a smaller map or a coarser resolution)"
        )
    return rows, cols


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """An occupancy grid map.

    Attributes:
        data: ``(height, width)`` int8 cells: 0 free, 100 occupied, -1 unknown; row 0 at ``origin``.
        resolution: cell edge length (m).
        origin: world position ``(x, y)`` of the lower-left corner of cell ``(0, 0)`` (m).
        unknown_is_occupied: whether unknown cells block motion and lidar (default: no, as
            Arena's flatland treats only occupied pixels as walls).
    """

    data: NDArray[np.int8]
    resolution: float
    origin: tuple[float, float] = (0.0, 0.0)
    unknown_is_occupied: bool = False

    def __post_init__(self) -> None:
        raw = np.asarray(self.data)
        if raw.ndim != 2 or raw.shape[0] < 1 or raw.shape[1] < 1:
            raise MapError(f"occupancy data must be a non-empty 2-D array, got shape {raw.shape}")
        # Check before casting: int8 would wrap 255 to -1 and 356 to 100, and truncate 0.5 to 0.
        bad = ~np.isin(raw, (FREE, OCCUPIED, UNKNOWN))
        if np.any(bad):
            raise MapError(
                f"occupancy values must be 0 (free), 100 (occupied) or -1 (unknown); "
                f"found {sorted(set(np.unique(raw[bad]).tolist()))[:5]}"
            )
        if not (self.resolution > 0 and np.isfinite(self.resolution)):
            raise MapError(
                f"resolution must be a positive number of metres, got {self.resolution!r}"
            )
        if len(self.origin) != 2 or not np.all(np.isfinite(self.origin)):
            raise MapError(f"origin must be two finite coordinates (m), got {self.origin!r}")
        if max(abs(float(v)) for v in self.origin) > MAX_COORDINATE:
            raise MapError(
                f"origin coordinates must lie within ±{MAX_COORDINATE:g} m, got {self.origin!r}"
            )
        if raw.size > MAX_CELLS:
            raise MapError(f"a map has at most {MAX_CELLS:,} cells, got {raw.shape}")
        # Own copy: freezing the caller's array in place would make *their* array read-only.
        data = np.array(raw, dtype=np.int8, order="C", copy=True)
        data.setflags(write=False)
        object.__setattr__(self, "data", data)
        object.__setattr__(self, "resolution", float(self.resolution))
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))

    # -- construction ---------------------------------------------------------------------------
    @classmethod
    def from_occupied(
        cls, occupied: ArrayLike, resolution: float, origin: tuple[float, float] = (0.0, 0.0)
    ) -> OccupancyGrid:
        """Build from a boolean ``(height, width)`` mask (True = occupied), row 0 at ``origin``."""
        mask = np.asarray(occupied, dtype=bool)
        return cls(np.where(mask, OCCUPIED, FREE).astype(np.int8), resolution, origin)

    @classmethod
    def empty(
        cls,
        width_m: float,
        height_m: float,
        resolution: float = 0.05,
        *,
        walls: bool = True,
        origin: tuple[float, float] = (0.0, 0.0),
    ) -> OccupancyGrid:
        """Build a free ``width_m × height_m`` (m) map, with a one-cell wall border if asked.

        Raises:
            MapError: see :func:`check_grid_size`.
        """
        h, w = check_grid_size(width_m, height_m, resolution, min_cells=MIN_CELLS if walls else 1)
        occ = np.zeros((h, w), dtype=bool)
        if walls:
            occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
        return cls.from_occupied(occ, resolution, origin)

    # -- shape ----------------------------------------------------------------------------------
    @property
    def height(self) -> int:
        """Number of rows."""
        return int(self.data.shape[0])

    @property
    def width(self) -> int:
        """Number of columns."""
        return int(self.data.shape[1])

    @property
    def size_m(self) -> tuple[float, float]:
        """World extent ``(width, height)`` in metres."""
        return self.width * self.resolution, self.height * self.resolution

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the mapped area (m)."""
        w, h = self.size_m
        return self.origin[0], self.origin[1], self.origin[0] + w, self.origin[1] + h

    # -- masks ----------------------------------------------------------------------------------
    @cached_property
    def occupied(self) -> NDArray[np.bool_]:
        """``(height, width)`` bool: cells that block motion and lidar."""
        occ = self.data == OCCUPIED
        if self.unknown_is_occupied:
            occ |= self.data == UNKNOWN
        occ.setflags(write=False)
        return occ

    @cached_property
    def free(self) -> NDArray[np.bool_]:
        """``(height, width)`` bool: cells known to be free."""
        m = self.data == FREE
        m.setflags(write=False)
        return m

    @cached_property
    def distance(self) -> NDArray[np.float64]:
        """Euclidean distance (m) from each cell centre to the nearest blocking cell centre.

        Blocking cells get 0. A map with no blocking cell gets ``inf`` everywhere. Cells outside
        the map are not treated as walls here: the simulator bounds positions separately.
        """
        occ = self.occupied
        if not occ.any():
            d = np.full(occ.shape, np.inf)
        else:
            d = ndimage.distance_transform_edt(~occ) * self.resolution
        d.setflags(write=False)
        return d

    # -- transforms ------------------------------------------------------------------------------
    def world_to_cell(self, xy: ArrayLike) -> NDArray[np.int64]:
        """World points ``(..., 2)`` (m) → ``[row, col]`` cells ``(..., 2)`` (may be off-map)."""
        p = np.asarray(xy, dtype=np.float64)
        col = np.floor((p[..., 0] - self.origin[0]) / self.resolution).astype(np.int64)
        row = np.floor((p[..., 1] - self.origin[1]) / self.resolution).astype(np.int64)
        return np.stack([row, col], axis=-1)

    def cell_to_world(self, cells: ArrayLike) -> NDArray[np.float64]:
        """``[row, col]`` cells ``(..., 2)`` → world points ``(..., 2)`` of their centres (m)."""
        c = np.asarray(cells, dtype=np.float64)
        x = self.origin[0] + (c[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (c[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def in_bounds(self, cells: ArrayLike) -> NDArray[np.bool_]:
        """Whether ``[row, col]`` cells ``(..., 2)`` lie on the map."""
        c = np.asarray(cells)
        rows_ok = (c[..., 0] >= 0) & (c[..., 0] < self.height)
        return rows_ok & (c[..., 1] >= 0) & (c[..., 1] < self.width)

    def contains(self, xy: ArrayLike) -> NDArray[np.bool_]:
        """Whether world points ``(..., 2)`` lie on the map."""
        return self.in_bounds(self.world_to_cell(xy))

    def is_occupied(self, xy: ArrayLike) -> NDArray[np.bool_]:
        """Whether world points ``(..., 2)`` lie in blocking cells; off-map points are blocked."""
        cells = self.world_to_cell(xy)
        inside = self.in_bounds(cells)
        r = np.clip(cells[..., 0], 0, self.height - 1)
        c = np.clip(cells[..., 1], 0, self.width - 1)
        return ~inside | self.occupied[r, c]

    def distance_at(self, xy: ArrayLike) -> NDArray[np.float64]:
        """:attr:`distance` looked up at world points ``(..., 2)``; 0 off the map."""
        cells = self.world_to_cell(xy)
        inside = self.in_bounds(cells)
        r = np.clip(cells[..., 0], 0, self.height - 1)
        c = np.clip(cells[..., 1], 0, self.width - 1)
        return np.where(inside, self.distance[r, c], 0.0)

    # -- derived maps -----------------------------------------------------------------------------
    def inflate(self, radius: float) -> OccupancyGrid:
        """Return a copy with every cell within ``radius`` (m) of a blocking cell occupied.

        Distances are centre to centre (:attr:`distance`). Unknown cells stay unknown unless
        inflated over.
        """
        if not radius >= 0:  # also rejects NaN, which would silently inflate nothing
            raise MapError(f"inflation radius must be >= 0 m, got {radius}")
        grown = self.distance <= radius + 1e-9
        data = np.where(grown, OCCUPIED, self.data).astype(np.int8)
        return OccupancyGrid(data, self.resolution, self.origin, self.unknown_is_occupied)

    def with_occupied(self, mask: ArrayLike) -> OccupancyGrid:
        """Return a copy with the cells of a boolean ``(height, width)`` mask set occupied."""
        m = np.asarray(mask, dtype=bool)
        if m.shape != self.data.shape:
            raise MapError(f"mask shape {m.shape} does not match the map {self.data.shape}")
        data = np.where(m, OCCUPIED, self.data).astype(np.int8)
        return OccupancyGrid(data, self.resolution, self.origin, self.unknown_is_occupied)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, OccupancyGrid):
            return NotImplemented
        return (
            self.resolution == other.resolution
            and self.origin == other.origin
            and self.unknown_is_occupied == other.unknown_is_occupied
            and np.array_equal(self.data, other.data)
        )

    __hash__ = None  # type: ignore[assignment]
