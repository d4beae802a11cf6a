"""Rasterise world geometry (obstacle footprints, circles) into grid cell masks."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from arena.core.geometry import convex_polygon_overlaps_squares, points_in_polygon
from arena.maps.grid import OccupancyGrid


def polygon_mask(grid: OccupancyGrid, polygons: Sequence[NDArray[np.float64]]) -> NDArray[np.bool_]:
    """``(height, width)`` bool mask of the cells each polygon overlaps.

    A cell is marked when its centre lies inside the polygon or, for convex polygons, when the
    polygon overlaps the cell square at all (so thin obstacles still mark cells).
    """
    mask = np.zeros(grid.data.shape, dtype=bool)
    res = grid.resolution
    for poly in polygons:
        p = np.asarray(poly, dtype=np.float64)
        (c0, r0), (c1, r1) = (
            np.floor((p.min(axis=0) - grid.origin) / res).astype(int),
            np.floor((p.max(axis=0) - grid.origin) / res).astype(int),
        )
        r0, c0 = max(r0, 0), max(c0, 0)
        r1, c1 = min(r1, grid.height - 1), min(c1, grid.width - 1)
        if r0 > r1 or c0 > c1:
            continue
        rows, cols = np.mgrid[r0 : r1 + 1, c0 : c1 + 1]
        centers = grid.cell_to_world(np.stack([rows.ravel(), cols.ravel()], axis=1))
        inside = points_in_polygon(centers, p)
        if _is_convex(p):
            inside |= convex_polygon_overlaps_squares(p, centers, 0.5 * res)
        mask[rows.ravel()[inside], cols.ravel()[inside]] = True
    return mask


def disk_mask(
    grid: OccupancyGrid, centers: NDArray[np.float64], radii: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """``(height, width)`` bool mask of the cells whose centres lie within the given circles."""
    mask = np.zeros(grid.data.shape, dtype=bool)
    res = grid.resolution
    for (x, y), r in zip(
        np.asarray(centers).reshape(-1, 2), np.asarray(radii).reshape(-1), strict=True
    ):
        k = math.ceil(r / res) + 1
        row, col = grid.world_to_cell([x, y])
        r0, r1 = max(row - k, 0), min(row + k + 1, grid.height)
        c0, c1 = max(col - k, 0), min(col + k + 1, grid.width)
        if r0 >= r1 or c0 >= c1:
            continue
        rows, cols = np.mgrid[r0:r1, c0:c1]
        cx = grid.origin[0] + (cols + 0.5) * res
        cy = grid.origin[1] + (rows + 0.5) * res
        mask[r0:r1, c0:c1] |= (cx - x) ** 2 + (cy - y) ** 2 <= r * r
    return mask


def _is_convex(p: NDArray[np.float64]) -> bool:
    d1 = np.roll(p, -1, axis=0) - p
    d2 = np.roll(d1, -1, axis=0)
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    return bool(np.all(cross >= -1e-12) or np.all(cross <= 1e-12))
