"""One robot's contact tests, for callers outside the simulator (spawn checks, tests).

Thin wrappers over the compiled tests of :mod:`arena.sim.contacts.kernels`: the simulator's
:class:`~arena.sim.contacts.bank.ContactBank` runs the very same functions.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from arena.maps.grid import OccupancyGrid
from arena.sim.contacts import kernels
from arena.sim.contacts.footprint import Footprint, ObstacleIndex


def grid_params(
    grid: OccupancyGrid, bounds: tuple[float, float, float, float] | None = None
) -> NDArray[np.float64]:
    """``(7,)`` ``[origin_x, origin_y, resolution, xmin, ymin, xmax, ymax]`` (m) of ``grid``."""
    xmin, ymin, xmax, ymax = grid.bounds if bounds is None else bounds
    ox, oy = grid.origin
    return np.array([ox, oy, grid.resolution, xmin, ymin, xmax, ymax], dtype=np.float64)


def _xyt(pose: NDArray[np.float64]) -> tuple[float, float, float]:
    return float(pose[0]), float(pose[1]), float(pose[2])


def hits_grid(
    grid: OccupancyGrid,
    fp: Footprint,
    pose: NDArray[np.float64],
    *,
    bounds: tuple[float, float, float, float] | None = None,
) -> bool:
    """Whether the footprint at ``pose`` ``(3,)`` overlaps a blocking cell or leaves the map.

    ``bounds``: ``grid.bounds`` (m) when the caller has it at hand.
    """
    return bool(
        kernels.grid_hit(
            grid.occupied,
            grid.distance,
            grid_params(grid, bounds),
            fp.body,
            fp.radius,
            fp.reach,
            *_xyt(pose),
        )
    )


def first_obstacle_hit(index: ObstacleIndex, fp: Footprint, pose: NDArray[np.float64]) -> int:
    """Index of the first obstacle the footprint at ``pose`` ``(3,)`` overlaps, or -1."""
    if not index.polygons:
        return -1
    return int(
        kernels.first_obstacle(
            index.centers, index.radii, index.vstart, index.verts, fp.body, fp.radius, *_xyt(pose)
        )
    )


def first_agent_hit(
    fp: Footprint,
    pose: NDArray[np.float64],
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
) -> int:
    """Index of the nearest pedestrian circle the footprint at ``pose`` overlaps, or -1.

    ``positions`` ``(n, 2)`` m and ``radii`` ``(n,)`` m are the pedestrians' circles.
    """
    if positions.shape[0] == 0:
        return -1
    pos = np.ascontiguousarray(positions, dtype=np.float64)
    r = np.ascontiguousarray(radii, dtype=np.float64)
    return int(kernels.nearest_agent(fp.body, fp.radius, *_xyt(pose), pos, r))


def footprints_overlap(
    fa: Footprint, pa: NDArray[np.float64], fb: Footprint, pb: NDArray[np.float64]
) -> bool:
    """Whether footprint ``fa`` at ``pa`` ``(3,)`` and ``fb`` at ``pb`` overlap."""
    return bool(
        kernels.robots_overlap(fa.body, fa.radius, *_xyt(pa), fb.body, fb.radius, *_xyt(pb))
    )
