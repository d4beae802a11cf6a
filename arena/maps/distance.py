"""Distances on a grid (exact Euclidean transform) and a per-map memo of rasters.

Used by task sampling (clearances), the crowd (wall distances) and anything else that needs a
raster of the map alone once per map: they sit in ``maps`` so every layer above can share them.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TypeVar

import numpy as np
from numba import njit
from numpy.typing import NDArray

from arena.maps.grid import OccupancyGrid
from arena.maps.raster import GridMemo

T = TypeVar("T")


def clearance_map(
    grid: OccupancyGrid, blocked: NDArray[np.bool_] | None = None
) -> NDArray[np.float64]:
    """Distance (m) from each cell centre to the nearest blocked cell centre, minus half a cell.

    Subtracting half a cell turns the centre-to-centre distance into a conservative distance to
    the blocked cell's edge (for axis-aligned neighbours). Cells outside the map count as blocked.
    """
    b = grid.occupied if blocked is None else blocked
    d = np.sqrt(squared_edt(b)) * grid.resolution
    return d - 0.5 * grid.resolution


def squared_edt(blocked: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Exact squared Euclidean distance (cells²) from each cell to the nearest blocked cell.

    Cells outside the array count as blocked. ``np.sqrt`` of it equals
    ``ndimage.distance_transform_edt(~np.pad(blocked, 1, constant_values=True))[1:-1, 1:-1]``
    bit for bit (both are exact; scipy takes the root of the same integer sum), in a fraction
    of the time (a reset needs two of them).
    """
    return _squared_edt(np.ascontiguousarray(blocked, dtype=np.bool_))


@njit(cache=True)
def _squared_edt(blocked: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Felzenszwalb–Huttenlocher: column distances, then the lower envelope per row.

    Every value is an integer below 2⁵³, so float64 arithmetic is exact.
    """
    h, w = blocked.shape
    # Pass 1: squared distance along each column to a blocked cell or the border (rows -1, h).
    g = np.empty((h, w), dtype=np.float64)
    for r in range(h):  # row-major sweeps (cache friendly): down, then up
        for c in range(w):
            if blocked[r, c]:
                g[r, c] = 0.0
            elif r == 0:
                g[r, c] = 1.0
            else:
                g[r, c] = g[r - 1, c] + 1.0
    for r in range(h - 1, -1, -1):
        for c in range(w):
            up = (h - r) * 1.0 if r == h - 1 else g[r + 1, c] + 1.0
            if up < g[r, c]:
                g[r, c] = up
    for r in range(h):
        for c in range(w):
            g[r, c] = g[r, c] * g[r, c]
    # Pass 2: per row, min over q of g[q] + (c - q)², with virtual blocked columns -1 and w.
    out = np.empty((h, w), dtype=np.float64)
    v = np.empty(w, dtype=np.int64)
    z = np.empty(w + 1, dtype=np.float64)
    for r in range(h):
        f = g[r]
        lower_envelope(f, v, z)  # every f[q] is finite: the border is blocked
        k = 0
        for c in range(w):
            while z[k + 1] < c:
                k += 1
            p = v[k]
            best = f[p] + (c - p) * (c - p)
            left = (c + 1.0) * (c + 1.0)  # the border column -1
            right = (w - c) * 1.0 * (w - c)  # the border column w
            if left < best:
                best = left
            if right < best:
                best = right
            out[r, c] = best
    return out


@njit(cache=True)
def lower_envelope(f: NDArray[np.float64], v: NDArray[np.int64], z: NDArray[np.float64]) -> int:
    """Lower envelope of the parabolas ``x ↦ f[q] + (x − q)²`` over the finite ``f[q]``.

    Felzenszwalb–Huttenlocher's second pass. Fills ``v`` (the apexes ``q`` of the envelope's
    parabolas, left to right) and ``z`` (``z[k]``..``z[k+1]``: where parabola ``v[k]`` is
    lowest; ``z[0] = -inf``, the last one ends at ``inf``); returns the last index ``k``, or -1
    if every ``f[q]`` is ``inf``. ``f`` ``(w,)`` holds exact integers (squared cells).
    """
    k = -1
    for q in range(f.shape[0]):
        if f[q] == np.inf:
            continue
        if k < 0:
            k = 0
            v[0] = q
            z[0] = -np.inf
            z[1] = np.inf
            continue
        while True:
            p = v[k]
            s = ((f[q] + q * q) - (f[p] + p * p)) / (2.0 * q - 2.0 * p)
            if s <= z[k] and k > 0:
                k -= 1
            else:
                break
        if s <= z[k]:  # k == 0 and q dominates the first parabola everywhere
            v[0] = q
            z[1] = np.inf
            continue
        k += 1
        v[k] = q
        z[k] = s
        z[k + 1] = np.inf
    return k


_STATIC = GridMemo(32)


def grid_memo(grid: OccupancyGrid, key: Hashable, compute: Callable[[], T]) -> T:
    """``compute()`` once per map: rasters of the map alone, shared by all its episodes.

    See :class:`~arena.maps.raster.GridMemo`; ``key`` names every input beside the grid by
    value, and the value must not be modified (freeze arrays).
    """
    return _STATIC.get(grid, key, compute)
