"""The crowd's distance map to walls and obstacles: :func:`crowd_clearance`, cheap per episode.

The integrator keeps pedestrians out of walls with a clearance map of the map's walls and the
episode's obstacles. The map's own part is computed once per map; each episode lowers it near
its obstacles only.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.maps.distance import clearance_map, grid_memo, lower_envelope, squared_edt
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import polygon_window

FloatArray = NDArray[np.float64]


def crowd_clearance(grid: OccupancyGrid, polygons: list[FloatArray]) -> FloatArray:
    """The integrator's distance map: ``clearance_map(grid, occupied | polygon_mask(polygons))``.

    Bit for bit that map, without its full-map distance transform per episode. Squared
    distance transforms are exact integers and that of a union of blocked sets is the per-cell
    minimum of the parts', and ``clearance_map``'s ``sqrt(d²)·res − res/2`` is non-decreasing in
    ``d²``; so the map's own clearance (computed once per map, :func:`grid_memo`) is lowered
    near each obstacle by that obstacle's alone. An obstacle only matters where it is nearer
    than the map's walls, within ``R`` cells of its footprint where ``R²`` bounds the map's
    squared distance over that neighbourhood (see :func:`_obstacle_reach`).

    Args:
        grid: the map.
        polygons: ``(k, 2)`` obstacle footprints (m), as :func:`~arena.maps.raster.polygon_mask`
            rasterises them.

    Returns:
        ``(height, width)`` m, a new array.
    """
    sq, base, peak = grid_memo(grid, "crowd clearance", lambda: _map_clearance(grid))
    out = base.copy()
    half = 0.5 * grid.resolution  # the same float as clearance_map's
    for poly in polygons:
        window = polygon_window(grid, poly)
        if window is None:
            continue
        r0, c0, win = window
        br0, br1, bc0, bc1 = _obstacle_reach(sq, peak, r0, c0, win.shape[0], win.shape[1])
        _lower_clearance(
            out, sq, win, r0, c0, br0, br1, bc0, bc1, float(grid.resolution), half
        )
    return out


def _map_clearance(grid: OccupancyGrid) -> tuple[FloatArray, FloatArray, float]:
    """``(squared_edt, clearance_map, max of squared_edt)`` of the map's occupied cells."""
    sq = squared_edt(grid.occupied)
    base = clearance_map(grid, grid.occupied)
    sq.setflags(write=False)
    base.setflags(write=False)
    return sq, base, float(sq.max())


@njit(cache=True)
def _obstacle_reach(
    sq: FloatArray, peak: float, r0: int, c0: int, hh: int, ww: int
) -> tuple[int, int, int, int]:
    """Rows ``[br0, br1)`` and columns ``[bc0, bc1)`` outside which a footprint changes nothing.

    ``sq`` is the map's ``(H, W)`` squared distance (cells²), ``peak`` its maximum; the
    footprint covers rows ``r0 : r0 + hh``, columns ``c0 : c0 + ww``. A cell outside the
    window grown by ``R`` lies at least ``(R + 1)²`` from every footprint cell, more than its
    own ``sq`` when ``R² ≥ max(sq)`` over that grown window. Starting from the map's maximum,
    ``R`` shrinks to the local one: the bound of a smaller box still holds for the cells
    between the two.
    """
    h, w = sq.shape
    reach = -1
    m = peak
    br0, br1, bc0, bc1 = 0, h, 0, w
    while True:
        new = 0
        while new * new < m:  # the smallest R with R² ≥ m (m is an integer)
            new += 1
        if reach >= 0 and new >= reach:
            break
        reach = new
        br0, br1 = max(r0 - reach, 0), min(r0 + hh + reach, h)
        bc0, bc1 = max(c0 - reach, 0), min(c0 + ww + reach, w)
        m = 0.0
        for r in range(br0, br1):
            for c in range(bc0, bc1):
                if sq[r, c] > m:
                    m = sq[r, c]
    return br0, br1, bc0, bc1


@njit(cache=True)
def _lower_clearance(
    out: FloatArray,
    sq: FloatArray,
    win: NDArray[np.bool_],
    r0: int,
    c0: int,
    br0: int,
    br1: int,
    bc0: int,
    bc1: int,
    res: float,
    half: float,
) -> None:
    """``out = min(out, sqrt(d²)·res − half)`` on the box, ``d²`` to the footprint ``win``.

    ``win`` ``(h, w)`` bool has its cell ``(0, 0)`` at map cell ``(r0, c0)``; the box is map
    rows ``[br0, br1)``, columns ``[bc0, bc1)`` and contains it. ``d²`` is the exact squared
    distance (cells²) to the nearest ``win`` cell (Felzenszwalb–Huttenlocher, as
    :func:`~arena.maps.distance.squared_edt` but with no blocked border, over the footprint's
    columns only: the others hold no footprint cell). Cells where ``d²`` is not below the
    map's own ``sq`` keep their value without a square root (``out`` is at most the map's).
    """
    h = br1 - br0
    nw = win.shape[1]
    # Pass 1: squared distance along each footprint column to its nearest footprint cell
    # (inf: none), rows of the box.
    g = np.empty((h, nw), dtype=np.float64)
    for j in range(nw):
        d = np.inf
        for r in range(h):
            i = br0 + r - r0
            d = 0.0 if 0 <= i < win.shape[0] and win[i, j] else d + 1.0
            g[r, j] = d
        d = np.inf
        for r in range(h - 1, -1, -1):
            d = 0.0 if g[r, j] == 0.0 else d + 1.0
            if d < g[r, j]:
                g[r, j] = d
            g[r, j] = g[r, j] * g[r, j]
    # Pass 2: per row, the lower envelope of the finite parabolas (map columns c0 + q).
    v = np.empty(nw, dtype=np.int64)
    z = np.empty(nw + 1, dtype=np.float64)
    for r in range(h):
        f = g[r]
        if lower_envelope(f, v, z) < 0:
            continue
        k = 0
        row = out[br0 + r]
        own = sq[br0 + r]
        for c in range(bc0, bc1):
            x = c - c0  # the column in footprint coordinates
            while z[k + 1] < x:
                k += 1
            p = v[k]
            d2 = f[p] + (x - p) * (x - p)
            if d2 < own[c]:
                val = math.sqrt(d2) * res - half
                if val < row[c]:
                    row[c] = val
