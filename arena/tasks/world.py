"""Free positions with clearances: Arena's ``WorldManager``, done exactly.

Arena samples positions on a box-filtered distance map with three layers (walls, obstacles,
forbidden zones; specs §2.4) and, when it runs out of room, parks the remainder at "garbage
positions" outside the map. Here:

* walls are the map's non-free cells (occupied *and* unknown: nothing is placed in unmapped
  space), obstacles are their real footprint polygons, forbidden zones are discs or polygons;
* a sampled point keeps its ``clearance`` from all three, checked with exact point-to-polygon
  distances (the grid only pre-selects candidate cells, conservatively);
* with ``forbid=True`` every accepted point becomes a forbidden disc of radius ``clearance``,
  so two entities sampled that way are at least the sum of their clearances apart;
* a request that cannot be met raises :class:`~arena.core.errors.SamplingError` naming what was
  asked for; nothing is ever placed off the map or inside a wall.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import SamplingError
from arena.core.geometry import point_segment_distance, points_in_polygon
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import disk_mask, polygon_mask
from arena.sim.state import Obstacle
from arena.tasks.sampling import squared_edt

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ForbiddenDisc:
    """A circular forbidden zone (m)."""

    x: float
    y: float
    radius: float


def polygon_distance(points: FloatArray, polygon: FloatArray) -> FloatArray:
    """Distance (m) from ``(n, 2)`` points to a filled polygon ``(k, 2)``; 0 inside."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    poly = np.asarray(polygon, dtype=np.float64)
    d = point_segment_distance(p, poly, np.roll(poly, -1, axis=0)).min(axis=1)
    return np.where(points_in_polygon(p, poly), 0.0, d)


def wall_distance_map(grid: OccupancyGrid) -> FloatArray:
    """``(H, W)`` distance (m) between each cell centre and the nearest non-free cell centre.

    Unknown cells and the space outside the map count as walls.
    """
    return np.sqrt(squared_edt(~grid.free)) * grid.resolution


class WorldSampler:
    """Samples positions that keep clearances from walls, obstacles and forbidden zones.

    Args:
        grid: the static map.
        obstacles: placed obstacles (their footprints are a layer of their own).
        wall_distance: precomputed :func:`wall_distance_map` of ``grid`` (maps are reused over
            many episodes, so callers cache it).
    """

    def __init__(
        self,
        grid: OccupancyGrid,
        obstacles: Sequence[Obstacle] = (),
        *,
        wall_distance: FloatArray | None = None,
    ) -> None:
        self.grid = grid
        self._wall = wall_distance if wall_distance is not None else wall_distance_map(grid)
        self._polygons: list[FloatArray] = []
        self._forbidden_discs: list[ForbiddenDisc] = []
        self._forbidden_polygons: list[FloatArray] = []
        self._blocked_cache: NDArray[np.bool_] | None = None
        self._free_cache: NDArray[np.intp] | None = None
        self.add_obstacles(obstacles)

    # -- layers --------------------------------------------------------------------------------
    def add_obstacles(self, obstacles: Sequence[Obstacle]) -> None:
        """Add obstacle footprints to the obstacle layer."""
        polys = [np.asarray(o.polygon, dtype=np.float64) for o in obstacles]
        self._polygons.extend(polys)
        if self._blocked_cache is not None and polys:  # update in place: O(new shapes)
            self._blocked_cache |= polygon_mask(self.grid, polys)

    def forbid(self, xy: Sequence[float] | FloatArray, radius: float) -> None:
        """Add a forbidden disc (Arena adds every robot start and goal this way)."""
        zone = ForbiddenDisc(float(xy[0]), float(xy[1]), float(radius))
        self._forbidden_discs.append(zone)
        if self._blocked_cache is not None:
            _or_disk(self._blocked_cache, self.grid, zone.x, zone.y, zone.radius)

    def forbid_polygon(self, polygon: FloatArray) -> None:
        """Add a forbidden polygon (m)."""
        poly = np.asarray(polygon, dtype=np.float64)
        self._forbidden_polygons.append(poly)
        if self._blocked_cache is not None:
            self._blocked_cache |= polygon_mask(self.grid, [poly])

    def clear_forbidden(self) -> None:
        """Empty the forbidden layer (module ``clear_forbidden_zones``)."""
        self._forbidden_discs.clear()
        self._forbidden_polygons.clear()
        self._blocked_cache = None

    @property
    def forbidden_discs(self) -> tuple[ForbiddenDisc, ...]:
        """The forbidden discs, in the order they were added."""
        return tuple(self._forbidden_discs)

    # -- queries -------------------------------------------------------------------------------
    def wall_distance(self, points: FloatArray) -> FloatArray:
        """Exact distance (m) from points to the nearest non-free cell square (0 inside one).

        Looks at the cells within the grid distance of each point's cell; off-map points get 0.
        """
        g = self.grid
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        cells = g.world_to_cell(p)
        inside = g.in_bounds(cells)
        out = np.zeros(len(p))
        res = g.resolution
        blocked = ~g.free
        for i in np.flatnonzero(inside):
            r, c = cells[i]
            if blocked[r, c]:
                continue
            # The nearest blocked centre is self._wall away; any blocked square closer than
            # that lies within this window (+1 cell for the square's extent).
            k = math.ceil(self._wall[r, c] / res) + 1
            r0, r1 = max(r - k, 0), min(r + k + 1, g.height)
            c0, c1 = max(c - k, 0), min(c + k + 1, g.width)
            win = blocked[r0:r1, c0:c1]
            x0 = g.origin[0] + c0 * res
            y0 = g.origin[1] + r0 * res
            # Border: outside the map counts as blocked.
            edge = min(
                p[i, 0] - g.origin[0],
                g.origin[0] + g.width * res - p[i, 0],
                p[i, 1] - g.origin[1],
                g.origin[1] + g.height * res - p[i, 1],
            )
            best = edge
            if win.any():
                rr, cc = np.nonzero(win)
                lo_x = x0 + cc * res
                lo_y = y0 + rr * res
                dx = np.maximum(np.maximum(lo_x - p[i, 0], p[i, 0] - (lo_x + res)), 0.0)
                dy = np.maximum(np.maximum(lo_y - p[i, 1], p[i, 1] - (lo_y + res)), 0.0)
                best = min(best, float(np.min(np.hypot(dx, dy))))
            out[i] = best
        return out

    def obstacle_distance(self, points: FloatArray) -> FloatArray:
        """Distance (m) from points to the nearest obstacle footprint (``inf`` if none)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        d = np.full(len(p), np.inf)
        for poly in self._polygons:
            d = np.minimum(d, polygon_distance(p, poly))
        return d

    def forbidden_distance(self, points: FloatArray) -> FloatArray:
        """Distance (m) from points to the nearest forbidden zone (``inf`` if none)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        d = np.full(len(p), np.inf)
        if self._forbidden_discs:
            discs = np.array([[z.x, z.y, z.radius] for z in self._forbidden_discs])
            dd = np.hypot(p[:, None, 0] - discs[None, :, 0], p[:, None, 1] - discs[None, :, 1])
            d = np.minimum(d, np.maximum(dd - discs[None, :, 2], 0.0).min(axis=1))
        for poly in self._forbidden_polygons:
            d = np.minimum(d, polygon_distance(p, poly))
        return d

    def clearance(self, points: FloatArray) -> FloatArray:
        """Distance (m) from points to the nearest wall, obstacle or forbidden zone."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        return np.minimum(
            self.wall_distance(p),
            np.minimum(self.obstacle_distance(p), self.forbidden_distance(p)),
        )

    # -- sampling ------------------------------------------------------------------------------
    def candidate_mask(self, clearance: float) -> NDArray[np.bool_]:
        """Candidate cells: all their points keep ``clearance`` from walls, nothing covers them.

        Obstacles and forbidden zones are then checked exactly on each candidate point.
        """
        res = self.grid.resolution
        # Any point of a cell is within res/√2 of its centre, any point of a blocked square
        # within res/√2 of that centre: centre distance ≥ clearance + res·√2 is sufficient.
        ok = (self._wall >= clearance + res * math.sqrt(2.0)) & self.grid.free
        return ok & ~self._blocked()

    def _blocked(self) -> NDArray[np.bool_]:
        """Cells covered by an obstacle or a forbidden zone (a cheap pre-filter)."""
        if self._blocked_cache is None:
            polys = self._polygons + self._forbidden_polygons
            blocked = np.zeros(self.grid.data.shape, dtype=bool)
            if polys:
                blocked |= polygon_mask(self.grid, polys)
            if self._forbidden_discs:
                discs = self._forbidden_discs
                blocked |= disk_mask(
                    self.grid,
                    np.array([[z.x, z.y] for z in discs]),
                    np.array([z.radius for z in discs]),
                )
            self._blocked_cache = blocked
        return self._blocked_cache

    def sample(
        self,
        n: int,
        clearance: float,
        rng: np.random.Generator,
        *,
        what: str,
        within: NDArray[np.bool_] | None = None,
        polygon: FloatArray | None = None,
        forbid: bool = True,
        max_tries: int = 2000,
    ) -> FloatArray:
        """``(n, 2)`` positions each keeping ``clearance`` (m) from walls, obstacles and zones.

        Args:
            n: number of positions.
            clearance: the radius each position claims (m).
            rng: the only source of randomness.
            what: names the request in errors ("3 pedestrians").
            within: optional ``(H, W)`` mask the positions must fall in (e.g. one connected
                region).
            polygon: optional polygon (m) the positions must lie inside (zones).
            forbid: make each accepted position a forbidden disc of radius ``clearance`` (so
                later positions keep away from it); positions of one call are always kept
                ``2·clearance`` apart.
            max_tries: random candidates drawn before the exhaustive last attempt.

        Raises:
            SamplingError: if fewer than ``n`` admissible positions exist.
        """
        if n <= 0:
            return np.zeros((0, 2))
        shape = self.grid.data.shape
        flat: NDArray[np.intp] | None = None
        if within is None and polygon is None:
            # Fast path: draw from all free cells and filter each batch; the full candidate
            # mask (a pass over the whole grid) is only built if that fails.
            pool = self._free_flat()
            wall_min = clearance + self.grid.resolution * math.sqrt(2.0)
        else:
            mask = self.candidate_mask(clearance)
            if within is not None:
                mask = mask & within
            if polygon is not None:
                mask = mask & self._polygon_cells(polygon)
            pool = flat = np.flatnonzero(mask)
        chosen: list[FloatArray] = []
        tries = 0
        while len(chosen) < n and pool.size and tries < max_tries:
            batch = min(256, max_tries - tries)
            tries += batch
            idx = rng.choice(pool, size=batch)
            if flat is None:
                idx = idx[(self._wall.flat[idx] >= wall_min) & ~self._blocked().flat[idx]]
            pts = self._jitter(np.stack(np.unravel_index(idx, shape), axis=1), rng)
            ok = self._admissible(pts, clearance, polygon)
            for p in pts[ok]:
                if all(np.hypot(*(p - q)) >= 2 * clearance for q in chosen):
                    chosen.append(p)
                    if len(chosen) == n:
                        break
        if len(chosen) < n:
            if flat is None:
                flat = np.flatnonzero(self.candidate_mask(clearance))
            chosen = self._exhaustive(flat, shape, n, chosen, clearance, polygon, rng, what)
        out = np.array(chosen[:n], dtype=np.float64).reshape(n, 2)
        if forbid:
            for p in out:
                self.forbid(p, clearance)
        return out

    def _free_flat(self) -> NDArray[np.intp]:
        if self._free_cache is None:
            self._free_cache = np.flatnonzero(self.grid.free)
        return self._free_cache

    def _exhaustive(
        self, flat, shape, n, chosen, clearance, polygon, rng, what: str
    ) -> list[FloatArray]:
        """Last attempt: every candidate cell centre in random order (fails only if none fit)."""
        if flat.size:
            order = rng.permutation(flat)
            cells = np.stack(np.unravel_index(order, shape), axis=1)
            pts = self.grid.cell_to_world(cells)
            ok = self._admissible(pts, clearance, polygon)
            for p in pts[ok]:
                if all(np.hypot(*(p - q)) >= 2 * clearance for q in chosen):
                    chosen.append(p)
                    if len(chosen) == n:
                        return chosen
        raise SamplingError(
            f"cannot place {what}: found room for {len(chosen)} of {n} with clearance "
            f"{clearance:g} m from walls, obstacles and forbidden zones "
            f"({flat.size} candidate cells); reduce counts or clearances, or use a larger map"
        )

    def _admissible(self, pts: FloatArray, clearance: float, polygon: FloatArray | None):
        ok = self.obstacle_distance(pts) >= clearance
        ok &= self.forbidden_distance(pts) >= clearance
        if polygon is not None:
            ok &= points_in_polygon(pts, polygon)
        return ok

    def _jitter(self, cells: NDArray[np.int64], rng: np.random.Generator) -> FloatArray:
        centers = self.grid.cell_to_world(cells)
        return centers + rng.uniform(-0.5, 0.5, size=centers.shape) * self.grid.resolution

    def _polygon_cells(self, polygon: FloatArray) -> NDArray[np.bool_]:
        """Cells whose centre lies inside ``polygon`` (only its bounding box is tested)."""
        g = self.grid
        poly = np.asarray(polygon, dtype=np.float64)
        mask = np.zeros(g.data.shape, dtype=bool)
        (r0, c0), (r1, c1) = g.world_to_cell(poly.min(axis=0)), g.world_to_cell(poly.max(axis=0))
        r0, c0 = max(int(r0), 0), max(int(c0), 0)
        r1, c1 = min(int(r1), g.height - 1), min(int(c1), g.width - 1)
        if r0 > r1 or c0 > c1:
            return mask
        rows, cols = np.mgrid[r0 : r1 + 1, c0 : c1 + 1]
        cells = np.stack([rows.ravel(), cols.ravel()], axis=1)
        inside = points_in_polygon(g.cell_to_world(cells), poly)
        mask[cells[inside, 0], cells[inside, 1]] = True
        return mask


def _or_disk(mask: NDArray[np.bool_], grid: OccupancyGrid, x: float, y: float, r: float) -> None:
    """``mask |= disk_mask(grid, [[x, y]], [r])``, touching only the disc's window.

    The same window and cell test as :func:`~arena.maps.raster.disk_mask`; a reset forbids a
    few dozen discs, and a full-map mask per disc cost most of their time.
    """
    res = grid.resolution
    k = math.ceil(r / res) + 1
    row, col = grid.world_to_cell([x, y])
    r0, r1 = max(row - k, 0), min(row + k + 1, grid.height)
    c0, c1 = max(col - k, 0), min(col + k + 1, grid.width)
    if r0 >= r1 or c0 >= c1:
        return
    rows, cols = np.mgrid[r0:r1, c0:c1]
    cx = grid.origin[0] + (cols + 0.5) * res
    cy = grid.origin[1] + (rows + 0.5) * res
    mask[r0:r1, c0:c1] |= (cx - x) ** 2 + (cy - y) ** 2 <= r * r
