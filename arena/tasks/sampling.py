"""Sampling free positions on a grid with clearances (used by every random task)."""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray
from scipy import ndimage

from arena.core.errors import SamplingError
from arena.maps.grid import OccupancyGrid


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
        k = 0
        v[0] = 0
        z[0] = -np.inf
        z[1] = np.inf
        for q in range(1, w):
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


def components(mask: NDArray[np.bool_]) -> NDArray[np.int32]:
    """8-connected component labels of a bool mask (0 = not in the mask)."""
    labels, _ = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    return labels


def sample_cells(
    mask: NDArray[np.bool_], n: int, rng: np.random.Generator, *, what: str
) -> NDArray[np.int64]:
    """``n`` distinct ``[row, col]`` cells drawn uniformly from a mask."""
    flat = np.flatnonzero(mask)
    if flat.size < n:
        raise SamplingError(
            f"cannot place {what}: only {flat.size} admissible cells, {n} needed "
            "(reduce counts or clearances, or use a larger map)"
        )
    pick = rng.choice(flat, size=n, replace=False)
    return np.stack(np.unravel_index(pick, mask.shape), axis=1).astype(np.int64)


def jitter(
    grid: OccupancyGrid, cells: NDArray[np.int64], rng: np.random.Generator
) -> NDArray[np.float64]:
    """World positions uniformly inside the given cells (no grid-aligned artefacts)."""
    centers = grid.cell_to_world(cells)
    return centers + rng.uniform(-0.5, 0.5, size=centers.shape) * grid.resolution


def line_of_sight(
    grid: OccupancyGrid, allowed: NDArray[np.bool_], a: NDArray[np.float64], b: NDArray[np.float64]
) -> bool:
    """Whether the segment ``a→b`` stays inside the ``allowed`` mask (sampled every 1/3 cell)."""
    length = float(np.hypot(*(b - a)))
    k = max(int(np.ceil(length / (grid.resolution / 3.0))), 1)
    t = np.linspace(0.0, 1.0, k + 1)[:, None]
    pts = a + t * (b - a)
    cells = grid.world_to_cell(pts)
    if not np.all(grid.in_bounds(cells)):
        return False
    return bool(np.all(allowed[cells[:, 0], cells[:, 1]]))
