"""Footprint and disc rasters: windowed kernels and memo against the plain full-map forms."""

import math

import numpy as np
import pytest

from arena.core.geometry import convex_hull, rectangle, transform_points
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import GridMemo, disk_mask, or_disk, polygon_mask, polygon_window

GRID = OccupancyGrid.empty(12.0, 8.0, 0.05, origin=(-6.0, -3.0))


def _reference_convex(p):
    d1 = np.roll(p, -1, axis=0) - p
    d2 = np.roll(d1, -1, axis=0)
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    return bool(np.all(cross >= -1e-12) or np.all(cross <= 1e-12))


def _reference_polygon_mask(grid, polygons):
    """The vectorised form the kernels replaced (per polygon, on its bounding box).

    The box matters: the separating-axis projections are BLAS products, whose last bit may
    depend on the array they are part of, and cells on a tie go either way with it.
    """
    from arena.core.geometry import convex_polygon_overlaps_squares, points_in_polygon

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
        if _reference_convex(p):
            inside |= convex_polygon_overlaps_squares(p, centers, 0.5 * res)
        mask[rows.ravel()[inside], cols.ravel()[inside]] = True
    return mask


def _reference_disk_mask(grid, centers, radii):
    rows, cols = np.indices(grid.data.shape)
    cx = grid.origin[0] + (cols + 0.5) * grid.resolution
    cy = grid.origin[1] + (rows + 0.5) * grid.resolution
    mask = np.zeros(grid.data.shape, dtype=bool)
    for (x, y), r in zip(centers, radii, strict=True):
        mask |= (cx - x) ** 2 + (cy - y) ** 2 <= r * r
    return mask


@pytest.mark.parametrize("seed", range(12))
def test_polygon_mask_matches_reference(seed):
    rng = np.random.default_rng(seed)
    polys = [
        transform_points(rectangle(*rng.uniform(0.05, 2.0, 2)), rng.uniform(-7, 7, 3)),
        convex_hull(rng.normal(size=(7, 2)) + rng.uniform(-5, 5, 2)),
        rng.normal(size=(6, 2)) + rng.uniform(-5, 5, 2),  # usually not convex
        rectangle(0.5, 0.25, center=(0.05 * int(rng.integers(-40, 40)), 0.0)),  # on cell lines
    ]
    assert np.array_equal(polygon_mask(GRID, polys), _reference_polygon_mask(GRID, polys))


def test_polygon_window_is_memoised_read_only_and_per_grid():
    poly = transform_points(rectangle(1.0, 0.4), [0.3, 0.2, 0.5])
    first = polygon_window(GRID, poly)
    assert first is not None
    r0, _, win = first
    assert not win.flags.writeable
    assert polygon_window(GRID, poly.copy()) is first  # same grid, same polygon values
    shifted = OccupancyGrid.empty(12.0, 8.0, 0.05, origin=(-6.0, -3.05))
    other = polygon_window(shifted, poly)
    assert other is not None and other[0] == r0 + 1  # another grid: its own raster
    assert polygon_window(GRID, poly + 100.0) is None  # off the map


def test_grid_memo_drops_least_recent_and_dead_grids():
    memo = GridMemo(2)
    grid = OccupancyGrid.empty(1.0, 1.0, 0.1)
    assert memo.get(grid, "a", lambda: 1) == 1
    assert memo.get(grid, "b", lambda: 2) == 2
    assert memo.get(grid, "a", lambda: 3) == 1  # "a" is now the most recent
    assert memo.get(grid, "c", lambda: 4) == 4  # evicts "b"
    assert len(memo) == 2
    assert memo.get(grid, "b", lambda: 5) == 5


@pytest.mark.parametrize("seed", range(8))
def test_disk_mask_and_or_disk_match_reference(seed):
    rng = np.random.default_rng(seed)
    centers = rng.uniform([-7, -4], [7, 6], size=(6, 2))
    centers[0] = GRID.cell_to_world([10, 20])  # on a cell centre: exact ties
    radii = rng.uniform(0.0, 2.5, size=6)
    radii[1] = 0.25
    want = _reference_disk_mask(GRID, centers, radii)
    assert np.array_equal(disk_mask(GRID, centers, radii), want)
    mask = np.zeros(GRID.data.shape, dtype=bool)
    for (x, y), r in zip(centers, radii, strict=True):
        or_disk(mask, GRID, float(x), float(y), float(r))
    assert np.array_equal(mask, want)
    or_disk(mask, GRID, math.nan, 0.0, 1.0)  # no window: nothing changes
    assert np.array_equal(mask, want)


@pytest.mark.parametrize("seed", range(5))
def test_is_convex_matches_reference(seed):
    from arena.maps.raster import _is_convex

    rng = np.random.default_rng(seed)
    for k in range(0, 8):
        p = rng.normal(size=(k, 2))
        assert _is_convex(p) == _reference_convex(p)
        hull = convex_hull(p)
        assert _is_convex(hull) == _reference_convex(hull)


def test_grid_memo_forgets_collected_grids():
    import gc

    memo = GridMemo(8)
    grid = OccupancyGrid.empty(1.0, 1.0, 0.1)
    memo.get(grid, "a", lambda: np.zeros(3))
    keep = OccupancyGrid.empty(1.0, 1.0, 0.1)
    memo.get(keep, "a", lambda: np.ones(3))
    assert len(memo) == 2
    del grid
    gc.collect()
    assert len(memo) == 1
    assert memo.get(keep, "a", lambda: None)[0] == 1.0
