"""Costmap raster and its layers (static, obstacle, inflation, semantic), after ROS costmap_2d.

Cost values follow ``costmap_2d``:

=========  =====================================================================================
``0``      free space
``1..252`` graded cost (inflation decay, personal space of pedestrians)
``253``    inscribed: the robot centre here puts the inscribed circle on an obstacle
``254``    lethal: an obstacle occupies the cell
``255``    no information (unknown)
=========  =====================================================================================

Geometry is that of :class:`~arena.maps.grid.OccupancyGrid`: row 0 at ``origin`` (lowest y),
cell ``(row, col)`` covers ``x ∈ [ox + col·res, ox + (col+1)·res)``,
``y ∈ [oy + row·res, oy + (row+1)·res)``.

Layers are plain functions / kernels on ``(H, W)`` uint8 arrays so that the global and the
rolling-window costmap (:mod:`arena.nav.costmap.costmap`) share them. All are vectorised numpy
or numba kernels; none loops over cells in Python.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from arena.maps.grid import OCCUPIED, UNKNOWN, OccupancyGrid

FREE_SPACE = 0
"""Cost of a free cell."""
INSCRIBED = 253
"""Cost of a cell within the inscribed radius of an obstacle."""
LETHAL = 254
"""Cost of an obstacle cell."""
NO_INFORMATION = 255
"""Cost of an unknown cell."""
MAX_NON_OBSTACLE = 252
"""Highest cost that still lets the robot centre in (``INSCRIBED - 1``)."""

CostArray = NDArray[np.uint8]


class Costmap:
    """A uint8 cost raster with a world placement (mutable: layers write into :attr:`costs`).

    Args:
        costs: ``(height, width)`` uint8 costs (0..254, 255 unknown); row 0 at ``origin``.
        resolution: cell edge (m).
        origin: world position ``(x, y)`` of the lower-left corner of cell ``(0, 0)`` (m).
    """

    def __init__(self, costs: ArrayLike, resolution: float, origin: tuple[float, float]) -> None:
        c = np.asarray(costs)
        if c.ndim != 2:
            raise ValueError(f"costs must be a 2-D array, got shape {c.shape}")
        if not (resolution > 0 and math.isfinite(resolution)):
            raise ValueError(f"resolution must be a positive number of metres, got {resolution}")
        self.costs: CostArray = np.ascontiguousarray(c, dtype=np.uint8)
        self.resolution = float(resolution)
        self.origin = (float(origin[0]), float(origin[1]))

    @classmethod
    def like(cls, grid: OccupancyGrid, value: int = FREE_SPACE) -> Costmap:
        """A costmap with ``grid``'s geometry, every cell set to ``value``."""
        return cls(np.full(grid.data.shape, value, dtype=np.uint8), grid.resolution, grid.origin)

    @property
    def shape(self) -> tuple[int, int]:
        """``(height, width)`` in cells."""
        return int(self.costs.shape[0]), int(self.costs.shape[1])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the covered area (m)."""
        h, w = self.shape
        ox, oy = self.origin
        return ox, oy, ox + w * self.resolution, oy + h * self.resolution

    def world_to_cell(self, xy: ArrayLike) -> NDArray[np.int64]:
        """World points ``(..., 2)`` (m) → ``[row, col]`` cells ``(..., 2)`` (may be off-map)."""
        p = np.asarray(xy, dtype=np.float64)
        col = np.floor((p[..., 0] - self.origin[0]) / self.resolution).astype(np.int64)
        row = np.floor((p[..., 1] - self.origin[1]) / self.resolution).astype(np.int64)
        return np.stack([row, col], axis=-1)

    def cell_to_world(self, cells: ArrayLike) -> NDArray[np.float64]:
        """``[row, col]`` cells ``(..., 2)`` → world centres ``(..., 2)`` (m)."""
        c = np.asarray(cells, dtype=np.float64)
        x = self.origin[0] + (c[..., 1] + 0.5) * self.resolution
        y = self.origin[1] + (c[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def in_bounds(self, cells: ArrayLike) -> NDArray[np.bool_]:
        """Whether ``[row, col]`` cells ``(..., 2)`` lie on the costmap."""
        c = np.asarray(cells)
        h, w = self.shape
        return (c[..., 0] >= 0) & (c[..., 0] < h) & (c[..., 1] >= 0) & (c[..., 1] < w)

    def cost_at(self, xy: ArrayLike, off_map: int = NO_INFORMATION) -> NDArray[np.uint8]:
        """Costs ``(...)`` at world points ``(..., 2)`` (m); ``off_map`` outside the raster."""
        cells = self.world_to_cell(xy)
        inside = self.in_bounds(cells)
        h, w = self.shape
        r = np.clip(cells[..., 0], 0, h - 1)
        c = np.clip(cells[..., 1], 0, w - 1)
        return np.where(inside, self.costs[r, c], np.uint8(off_map)).astype(np.uint8)

    def to_occupancy(
        self, lethal_threshold: int = INSCRIBED, *, unknown_is_occupied: bool = False
    ) -> OccupancyGrid:
        """An :class:`OccupancyGrid` with cells of cost ``≥ lethal_threshold`` (and < 255) occupied.

        Unknown cells (255) become unknown (-1). Grid planners plan on this grid: with the
        default threshold the robot centre may enter every cell below ``INSCRIBED``.
        """
        occ = (self.costs >= lethal_threshold) & (self.costs != NO_INFORMATION)
        data = np.where(occ, OCCUPIED, 0).astype(np.int8)
        data[self.costs == NO_INFORMATION] = UNKNOWN
        return OccupancyGrid(data, self.resolution, self.origin, unknown_is_occupied)


# -- static layer ---------------------------------------------------------------------------------
def static_costs(grid: OccupancyGrid, *, track_unknown: bool = False) -> CostArray:
    """Static layer: ``(H, W)`` uint8, occupied → 254, unknown → 255 (or 0), free → 0.

    ``track_unknown`` follows ``costmap_2d``'s ``track_unknown_space`` (default off).
    """
    out = np.where(grid.data == OCCUPIED, LETHAL, FREE_SPACE).astype(np.uint8)
    if track_unknown:
        out[grid.data == UNKNOWN] = NO_INFORMATION
    elif grid.unknown_is_occupied:
        out[grid.data == UNKNOWN] = LETHAL
    return out


def static_window(
    static: CostArray,
    row0: int,
    col0: int,
    height: int,
    width: int,
    *,
    off_map: int = FREE_SPACE,
) -> CostArray:
    """Cut a full static layer ``(H, W)`` to the cells ``[row0, row0+height) × [col0, col0+width)``.

    Indices are map cells; window cells off the map get ``off_map``. Returns ``(height, width)``.
    """
    out = np.full((height, width), off_map, dtype=np.uint8)
    r0, c0 = max(row0, 0), max(col0, 0)
    r1, c1 = min(row0 + height, static.shape[0]), min(col0 + width, static.shape[1])
    if r1 > r0 and c1 > c0:
        out[r0 - row0 : r1 - row0, c0 - col0 : c1 - col0] = static[r0:r1, c0:c1]
    return out


# -- obstacle layer -------------------------------------------------------------------------------
@njit(cache=True)
def _clear_ray(costs: NDArray[Any], x0: float, y0: float, x1: float, y1: float) -> None:
    """Free the on-map cells crossed by ``(x0, y0)→(x1, y1)`` (cell units), not the end cell.

    Amanatides–Woo traversal.
    """
    h, w = costs.shape
    c = math.floor(x0)
    r = math.floor(y0)
    c_end = math.floor(x1)
    r_end = math.floor(y1)
    dx = x1 - x0
    dy = y1 - y0
    step_c = 1 if dx > 0 else -1
    step_r = 1 if dy > 0 else -1
    t_dx = abs(1.0 / dx) if dx != 0.0 else np.inf
    t_dy = abs(1.0 / dy) if dy != 0.0 else np.inf
    if dx > 0:
        t_mx = (c + 1 - x0) / dx
    elif dx < 0:
        t_mx = (x0 - c) / -dx
    else:
        t_mx = np.inf
    if dy > 0:
        t_my = (r + 1 - y0) / dy
    elif dy < 0:
        t_my = (y0 - r) / -dy
    else:
        t_my = np.inf
    n_steps = abs(c_end - c) + abs(r_end - r)
    for _ in range(n_steps + 1):
        if r == r_end and c == c_end:
            return
        if 0 <= r < h and 0 <= c < w:
            costs[r, c] = 0
        if min(t_mx, t_my) > 1.0:
            return
        if t_mx < t_my:
            c += step_c
            t_mx += t_dx
        else:
            r += step_r
            t_my += t_dy


@njit(cache=True)
def _mark_and_clear(
    costs: NDArray[Any],
    ox: float,
    oy: float,
    ex: NDArray[Any],
    ey: NDArray[Any],
    ranges: NDArray[Any],
    mark: NDArray[Any],
    raytrace_range: float,
) -> None:
    """Clear along every beam up to ``min(range, raytrace_range)``, then mark the flagged ends.

    Coordinates are in cell units of ``costs``; ``ex, ey`` are the beam end points, ``ranges``
    the beam lengths in the same units (used to shorten rays to ``raytrace_range``).
    """
    h, w = costs.shape
    for i in range(ex.shape[0]):
        rng = ranges[i]
        if not (rng > 0.0):
            continue
        f = 1.0
        if rng > raytrace_range:
            f = raytrace_range / rng
        _clear_ray(costs, ox, oy, ox + f * (ex[i] - ox), oy + f * (ey[i] - oy))
    for i in range(ex.shape[0]):
        if mark[i]:
            c = math.floor(ex[i])
            r = math.floor(ey[i])
            if 0 <= r < h and 0 <= c < w:
                costs[r, c] = 254


def update_obstacles(
    layer: Costmap,
    sensor_xy: ArrayLike,
    beam_angles: ArrayLike,
    ranges: ArrayLike,
    *,
    obstacle_range: float,
    raytrace_range: float,
    range_max: float = math.inf,
) -> None:
    """Obstacle layer update from one planar scan, in place (``costmap_2d`` ObstacleLayer).

    Every beam first clears (sets free) the cells between the sensor and its end point, up to
    ``raytrace_range``; the end point's own cell is not cleared. Then returns closer than
    ``obstacle_range`` and shorter than ``range_max`` (a max-range reading has hit nothing) mark
    their cell lethal. Non-finite ranges are treated as max-range readings; a ray is never traced
    past the window.

    Args:
        layer: the obstacle layer raster (its costs are 0 or 254).
        sensor_xy: ``(2,)`` sensor position, world frame (m).
        beam_angles: ``(n,)`` beam directions, world frame (rad).
        ranges: ``(n,)`` measured ranges (m).
        obstacle_range: max range (m) at which a return marks an obstacle.
        raytrace_range: max range (m) up to which free space is cleared.
        range_max: the sensor's maximum range (m).
    """
    o = np.asarray(sensor_xy, dtype=np.float64).reshape(2)
    a = np.asarray(beam_angles, dtype=np.float64).reshape(-1)
    r = np.asarray(ranges, dtype=np.float64).reshape(-1)
    if a.shape != r.shape:
        raise ValueError(f"beam_angles {a.shape} and ranges {r.shape} differ in shape")
    finite = np.isfinite(r)
    hit = finite & (r < range_max) & (r <= obstacle_range)
    rr = np.where(finite, r, min(range_max, raytrace_range))
    res = layer.resolution
    ox = (o[0] - layer.origin[0]) / res
    oy = (o[1] - layer.origin[1]) / res
    ex = ox + rr * np.cos(a) / res
    ey = oy + rr * np.sin(a) / res
    _mark_and_clear(layer.costs, ox, oy, ex, ey, rr / res, hit, raytrace_range / res)


# -- inflation layer ------------------------------------------------------------------------------
def inflation_cost(
    distance: ArrayLike,
    inscribed_radius: float,
    inflation_radius: float,
    cost_scaling_factor: float,
) -> NDArray[np.uint8]:
    """``costmap_2d`` InflationLayer cost for distances (m) to the nearest lethal cell.

    ``254`` at distance 0, ``253`` up to ``inscribed_radius``, then
    ``floor(252 · exp(-cost_scaling_factor · (d - inscribed_radius)))`` up to
    ``inflation_radius``, ``0`` beyond. Shape is that of ``distance``.
    """
    d = np.asarray(distance, dtype=np.float64)
    decay = np.floor(
        MAX_NON_OBSTACLE * np.exp(-cost_scaling_factor * np.maximum(d - inscribed_radius, 0.0))
    )
    cost = np.where(d <= inflation_radius + 1e-9, decay, 0.0)
    cost = np.where(d <= inscribed_radius + 1e-9, INSCRIBED, cost)
    cost = np.where(d <= 0.0, LETHAL, cost)
    return cost.astype(np.uint8)


def inflate(
    costs: CostArray,
    resolution: float,
    *,
    inscribed_radius: float,
    inflation_radius: float,
    cost_scaling_factor: float,
    inflate_unknown: bool = False,
) -> CostArray:
    """Inflation layer over a master raster: returns a new ``(H, W)`` uint8 raster.

    Distances (m) are Euclidean between cell centres, to the nearest lethal (254) cell
    (an exact EDT, where ``costmap_2d`` walks a cell wavefront). Each cell takes the larger of its
    cost and the inflation cost; an unknown cell (255) is overwritten only by an inflation cost
    ``≥ INSCRIBED`` (or by any positive one with ``inflate_unknown``), as in ``costmap_2d``.
    """
    lethal = costs == LETHAL
    if not lethal.any():
        return costs.copy()
    dist = ndimage.distance_transform_edt(~lethal) * resolution
    infl = inflation_cost(dist, inscribed_radius, inflation_radius, cost_scaling_factor)
    unknown = costs == NO_INFORMATION
    out = np.maximum(np.where(unknown, 0, costs), infl).astype(np.uint8)
    keep_unknown = unknown & ((infl == 0) if inflate_unknown else (infl < INSCRIBED))
    out[keep_unknown] = NO_INFORMATION
    return out


# -- semantic layer -------------------------------------------------------------------------------
@njit(cache=True)
def _social_kernel(
    out: NDArray[Any],
    ox: float,
    oy: float,
    res: float,
    px: NDArray[Any],
    py: NDArray[Any],
    vx: NDArray[Any],
    vy: NDArray[Any],
    presence_radius: float,
    presence_cost: float,
    amplitude: float,
    sigma_side: float,
    sigma_rear: float,
    front_gain: float,
    cutoff: float,
) -> None:
    h, w = out.shape
    for k in range(px.shape[0]):
        speed = math.sqrt(vx[k] * vx[k] + vy[k] * vy[k])
        if speed > 1e-9:
            ux = vx[k] / speed
            uy = vy[k] / speed
        else:
            ux = 1.0
            uy = 0.0
        sigma_front = sigma_rear + front_gain * speed
        reach = max(sigma_front, sigma_side, sigma_rear) * cutoff
        reach = max(reach, presence_radius)
        c0 = max(math.floor((px[k] - reach - ox) / res), 0)
        c1 = min(math.floor((px[k] + reach - ox) / res), w - 1)
        r0 = max(math.floor((py[k] - reach - oy) / res), 0)
        r1 = min(math.floor((py[k] + reach - oy) / res), h - 1)
        for r in range(r0, r1 + 1):
            y = oy + (r + 0.5) * res - py[k]
            for c in range(c0, c1 + 1):
                x = ox + (c + 0.5) * res - px[k]
                if x * x + y * y <= presence_radius * presence_radius:
                    val = presence_cost
                else:
                    along = x * ux + y * uy
                    side = -x * uy + y * ux
                    s = sigma_front if along > 0 else sigma_rear
                    e = 0.5 * ((along / s) ** 2 + (side / sigma_side) ** 2)
                    if e > 0.5 * cutoff * cutoff:
                        continue
                    val = math.floor(amplitude * math.exp(-e))
                if val > out[r, c]:
                    out[r, c] = val


def social_costs(
    shape: tuple[int, int],
    resolution: float,
    origin: tuple[float, float],
    positions: ArrayLike,
    velocities: ArrayLike,
    *,
    presence_radius: float = 0.35,
    presence_cost: int = LETHAL,
    amplitude: int = MAX_NON_OBSTACLE,
    sigma_side: float = 0.45,
    sigma_rear: float = 0.45,
    front_gain: float = 1.0,
    cutoff: float = 3.0,
) -> CostArray:
    """Semantic (pedestrian) layer: presence plus a velocity-stretched personal space.

    Each pedestrian at ``p`` with velocity ``v`` contributes, at a cell centre ``x``:

    * ``presence_cost`` if ``|x - p| ≤ presence_radius`` (its body);
    * else ``floor(amplitude · exp(-(a²/σ_a² + s²/σ_side²) / 2))`` with ``a`` the offset along
      ``v̂`` and ``s`` across it; ``σ_a = sigma_rear + front_gain·|v|`` in front (``a > 0``),
      ``sigma_rear`` behind, so a walking pedestrian's space reaches further ahead. Cut off
      beyond ``cutoff`` standard deviations.

    Overlapping pedestrians combine by maximum.

    Args:
        shape: ``(H, W)`` of the raster.
        resolution: cell edge (m).
        origin: lower-left corner of cell ``(0, 0)`` (m).
        positions: ``(m, 2)`` pedestrian positions, world frame (m).
        velocities: ``(m, 2)`` their velocities (m/s).
        presence_radius: body radius (m); Arena's pedestrian obstacle radius ≈ 0.3 m.
        presence_cost: cost of body cells (254 lethal by default: inflated like walls).
        amplitude: personal-space peak cost (≤ 252, so it stays passable).
        sigma_side: lateral standard deviation (m).
        sigma_rear: standard deviation behind and, at rest, in front (m).
        front_gain: extra frontal standard deviation per unit speed (s, i.e. m per m/s).
        cutoff: extent in standard deviations.

    Returns:
        ``(H, W)`` uint8 costs.
    """
    p = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    v = np.asarray(velocities, dtype=np.float64).reshape(-1, 2)
    if p.shape != v.shape:
        raise ValueError(f"positions {p.shape} and velocities {v.shape} differ in shape")
    out = np.zeros(shape, dtype=np.uint8)
    if len(p):
        _social_kernel(
            out, float(origin[0]), float(origin[1]), float(resolution),
            np.ascontiguousarray(p[:, 0]), np.ascontiguousarray(p[:, 1]),
            np.ascontiguousarray(v[:, 0]), np.ascontiguousarray(v[:, 1]),
            float(presence_radius), float(presence_cost), float(min(amplitude, 252)),
            float(sigma_side), float(sigma_rear), float(front_gain), float(cutoff),
        )
    return out
