"""Sampling free positions on a grid with clearances (used by every random task)."""

from __future__ import annotations

import numpy as np
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
    padded = np.pad(b, 1, constant_values=True)
    d = ndimage.distance_transform_edt(~padded)[1:-1, 1:-1] * grid.resolution
    return d - 0.5 * grid.resolution


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
