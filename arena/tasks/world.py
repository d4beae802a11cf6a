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
from numba import njit
from numpy.typing import NDArray

from arena.core.errors import SamplingError
from arena.core.geometry import points_in_polygon
from arena.maps.distance import grid_memo, squared_edt
from arena.maps.grid import OccupancyGrid
from arena.maps.raster import disk_mask, or_disk, polygon_mask, polygon_window
from arena.scene.state import Obstacle
from arena.tasks.sampling import MaskRegions, accept_spaced

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ForbiddenDisc:
    """A circular forbidden zone (m)."""

    x: float
    y: float
    radius: float


def polygon_distance(points: FloatArray, polygon: FloatArray) -> FloatArray:
    """Distance (m) from ``(n, 2)`` points to a filled polygon ``(k, 2)``; 0 inside."""
    return polygons_distance(points, [polygon])


def polygons_distance(
    points: FloatArray, polygons: Sequence[FloatArray], *, cutoff: float = np.inf
) -> FloatArray:
    """Distance (m) from ``(n, 2)`` points to the nearest of some filled polygons; ``inf`` if none.

    The minimum over ``polygons`` (each ``(k, 2)``, ``k ≥ 1``) of :func:`polygon_distance`.
    With a finite ``cutoff`` (m), distances below it are still exact (bit for bit), while one
    of ``cutoff`` or more may come back as any value ``≥ cutoff``: polygons whose bounding box
    is farther than that are skipped, which is all ``distance >= clearance`` tests need.
    """
    return packed_distance(points, pack_polygons(polygons), cutoff=cutoff)


@dataclass(frozen=True, eq=False)
class PackedPolygons:
    """Polygons as one array: polygon ``g`` is ``verts[offsets[g]:offsets[g + 1]]`` (m)."""

    verts: FloatArray
    offsets: NDArray[np.int64]


def pack_polygons(polygons: Sequence[FloatArray]) -> PackedPolygons:
    """Pack ``(k, 2)`` polygons (``k ≥ 1``) for :func:`packed_distance` (callers keep it)."""
    polys = [np.asarray(q, dtype=np.float64) for q in polygons]
    if any(len(q) == 0 for q in polys):  # the vectorised form's error for an empty polygon
        raise ValueError("zero-size array to reduction operation minimum which has no identity")
    offsets = np.cumsum([0] + [len(q) for q in polys]).astype(np.int64)
    verts = np.concatenate(polys).reshape(-1, 2) if polys else np.zeros((0, 2))
    return PackedPolygons(np.ascontiguousarray(verts, dtype=np.float64), offsets)


def packed_distance(
    points: FloatArray, polygons: PackedPolygons, *, cutoff: float = np.inf
) -> FloatArray:
    """:func:`polygons_distance` of packed polygons."""
    p = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 2))
    if len(polygons.offsets) < 2:
        return np.full(len(p), np.inf)
    distance: FloatArray = _polygons_distance(
        p, polygons.verts, polygons.offsets, float(cutoff)
    )
    return distance


@njit(cache=True, error_model="numpy")
def _polygons_distance(
    p: FloatArray, verts: FloatArray, offsets: NDArray[np.int64], cutoff: float
) -> FloatArray:
    """Polygon ``g`` has vertices ``verts[offsets[g]:offsets[g + 1]]``.

    Per polygon: 0 if the point is inside (even-odd rule), else the distance to the nearest
    edge; then the minimum over polygons. The float operations are those of
    :func:`~arena.core.geometry.points_in_polygon` and
    :func:`~arena.core.geometry.point_segment_distance` (``t`` clipped to [0, 1], NaN → 0;
    ``sqrt(dx² + dy²)``), and NaN propagates through the minima as through ``np.minimum``:
    the same distances, without a dozen numpy temporaries per polygon and batch.

    A point whose gap to a polygon's bounding box, along x or y, exceeds ``cutoff`` (with a
    relative margin of 1e-9 of the magnitudes involved, far above rounding) skips that
    polygon: its distance to it is larger still, so the minimum is exact wherever it is
    below ``cutoff``. NaN coordinates never skip.
    """
    n = p.shape[0]
    out = np.full(n, np.inf)
    for g in range(offsets.shape[0] - 1):
        s = offsets[g]
        k = offsets[g + 1] - s
        bx0 = bx1 = verts[s, 0]
        by0 = by1 = verts[s, 1]
        for e in range(1, k):
            bx0, bx1 = min(bx0, verts[s + e, 0]), max(bx1, verts[s + e, 0])
            by0, by1 = min(by0, verts[s + e, 1]), max(by1, verts[s + e, 1])
        for i in range(n):
            px = p[i, 0]
            py = p[i, 1]
            gap = max(bx0 - px, px - bx1, by0 - py, py - by1)
            scale = abs(cutoff) + abs(px) + abs(py) + max(abs(bx0), abs(bx1), abs(by0), abs(by1))
            if gap > cutoff + 1e-9 * scale:
                continue
            crossings = 0
            best = np.inf
            for e in range(k):
                ax = verts[s + e, 0]
                ay = verts[s + e, 1]
                bx = verts[s + (e + 1) % k, 0]
                by = verts[s + (e + 1) % k, 1]
                if (ay > py) != (by > py) and px < ax + (py - ay) * (bx - ax) / (by - ay):
                    crossings += 1
                abx = bx - ax
                aby = by - ay
                t = ((px - ax) * abx + (py - ay) * aby) / (abx * abx + aby * aby)
                if t != t:
                    t = 0.0
                t = min(max(t, 0.0), 1.0)
                dx = px - (ax + t * abx)
                dy = py - (ay + t * aby)
                best = _minimum(best, np.sqrt(dx * dx + dy * dy))
            out[i] = _minimum(out[i], 0.0 if crossings % 2 == 1 else best)
    return out


@njit(cache=True)
def _minimum(a: float, b: float) -> float:
    """``np.minimum`` of two floats: NaN if either is NaN."""
    if a != a or b != b:
        return np.nan
    return a if a <= b else b


def wall_distance_map(grid: OccupancyGrid) -> FloatArray:
    """``(H, W)`` distance (m) between each cell centre and the nearest non-free cell centre.

    Unknown cells and the space outside the map count as walls. Computed once per map (the
    generator, every episode's sampler and multi-robot respawns share it): read-only.
    """

    def compute() -> FloatArray:
        d = np.sqrt(squared_edt(~grid.free)) * grid.resolution
        d.setflags(write=False)
        return d

    return grid_memo(grid, "wall distance", compute)


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
        self._packed: PackedPolygons | None = None  # of _polygons, None once they change
        self._forbidden_discs: list[ForbiddenDisc] = []
        self._forbidden_polygons: list[FloatArray] = []
        self._blocked_cache: NDArray[np.bool_] | None = None
        # (pad, distance map) of the blocked cells for `_surely_taken`; None once they change.
        self._blocked_edt: tuple[int, FloatArray] | None = None
        self._free_cache: NDArray[np.intp] | None = None
        self.add_obstacles(obstacles)

    # -- layers --------------------------------------------------------------------------------
    def add_obstacles(self, obstacles: Sequence[Obstacle]) -> None:
        """Add obstacle footprints to the obstacle layer."""
        polys = [np.asarray(o.polygon, dtype=np.float64) for o in obstacles]
        self._polygons.extend(polys)
        self._packed = None
        self._blocked_edt = None
        if self._blocked_cache is not None:  # update in place: O(new shapes)
            for poly in polys:
                self._or_polygon(self._blocked_cache, poly)

    def forbid(self, xy: Sequence[float] | FloatArray, radius: float) -> None:
        """Add a forbidden disc (Arena adds every robot start and goal this way)."""
        zone = ForbiddenDisc(float(xy[0]), float(xy[1]), float(radius))
        self._forbidden_discs.append(zone)
        self._blocked_edt = None
        if self._blocked_cache is not None:
            or_disk(self._blocked_cache, self.grid, zone.x, zone.y, zone.radius)

    def forbid_polygon(self, polygon: FloatArray) -> None:
        """Add a forbidden polygon (m)."""
        poly = np.asarray(polygon, dtype=np.float64)
        self._forbidden_polygons.append(poly)
        self._blocked_edt = None
        if self._blocked_cache is not None:
            self._or_polygon(self._blocked_cache, poly)

    def _or_polygon(self, mask: NDArray[np.bool_], poly: FloatArray) -> None:
        """``mask |= polygon_mask(grid, [poly])`` on the polygon's bounding box only."""
        window = polygon_window(self.grid, poly)
        if window is not None:
            r0, c0, win = window
            mask[r0 : r0 + win.shape[0], c0 : c0 + win.shape[1]] |= win

    def clear_forbidden(self) -> None:
        """Empty the forbidden layer (module ``clear_forbidden_zones``)."""
        self._forbidden_discs.clear()
        self._forbidden_polygons.clear()
        self._blocked_edt = None
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

    def obstacle_distance(self, points: FloatArray, *, cutoff: float = np.inf) -> FloatArray:
        """Distance (m) from points to the nearest obstacle footprint (``inf`` if none).

        ``cutoff`` as in :func:`polygons_distance`: exact below it.
        """
        if self._packed is None:
            self._packed = pack_polygons(self._polygons)
        return packed_distance(points, self._packed, cutoff=cutoff)

    def forbidden_distance(self, points: FloatArray) -> FloatArray:
        """Distance (m) from points to the nearest forbidden zone (``inf`` if none)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        d = np.full(len(p), np.inf)
        if self._forbidden_discs:
            discs = np.array([[z.x, z.y, z.radius] for z in self._forbidden_discs])
            dd = np.hypot(p[:, None, 0] - discs[None, :, 0], p[:, None, 1] - discs[None, :, 1])
            d = np.minimum(d, np.maximum(dd - discs[None, :, 2], 0.0).min(axis=1))
        if self._forbidden_polygons:
            d = np.minimum(d, polygons_distance(p, self._forbidden_polygons))
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

    def _candidate_at(self, flat: NDArray[np.intp], clearance: float) -> NDArray[np.bool_]:
        """:meth:`candidate_mask` at the given flat cell indices (the same tests, elementwise)."""
        res = self.grid.resolution
        ok = self._wall.ravel()[flat] >= clearance + res * math.sqrt(2.0)
        return ok & self.grid.free.ravel()[flat] & ~self._blocked().ravel()[flat]

    def candidate_regions(self, clearance: float) -> MaskRegions:
        """The 8-connected regions of :meth:`candidate_mask` (what ``components`` labels).

        Memoised per map by the mask's content: a reset's first request (a robot's start and
        goal, before anything is placed) finds the same mask every episode on a fixed map.
        """
        mask = self.candidate_mask(clearance)
        mask.setflags(write=False)
        key = ("candidate regions", mask.shape, np.packbits(mask).tobytes())
        return grid_memo(self.grid, key, lambda: MaskRegions(mask))

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
        cells: NDArray[np.intp] | None = None,
        polygon: FloatArray | None = None,
        forbid: bool = True,
        max_tries: int = 2000,
        at_most: bool = False,
    ) -> FloatArray:
        """``(n, 2)`` positions each keeping ``clearance`` (m) from walls, obstacles and zones.

        Args:
            n: number of positions.
            clearance: the radius each position claims (m).
            rng: the only source of randomness.
            what: names the request in errors ("3 pedestrians").
            within: optional ``(H, W)`` mask the positions must fall in (e.g. one connected
                region).
            cells: optional ascending, distinct flat indices (into the ``(H, W)`` grid) of the
                cells the positions must fall in: ``within`` given as
                ``np.flatnonzero(within)``, with the same result, for callers that have a
                region's cells and not its mask.
            polygon: optional polygon (m) the positions must lie inside (zones).
            forbid: make each accepted position a forbidden disc of radius ``clearance`` (so
                later positions keep away from it); positions of one call are always kept
                ``2·clearance`` apart.
            max_tries: random candidates drawn before the exhaustive last attempt.
            at_most: return as many positions as fit (``(k, 2)``, ``k ≤ n``) instead of
                raising when fewer than ``n`` do.

        Raises:
            SamplingError: if fewer than ``n`` admissible positions exist (unless ``at_most``).
        """
        if n <= 0:
            return np.zeros((0, 2))
        shape = self.grid.data.shape
        flat: NDArray[np.intp] | None = None
        if within is None and cells is None and polygon is None:
            # Fast path: draw from all free cells and filter each batch; the full candidate
            # mask (a pass over the whole grid) is only built if that fails.
            pool = self._free_flat()
            wall_min = clearance + self.grid.resolution * math.sqrt(2.0)
        elif cells is not None:
            # The candidate test on the given cells only (no full-map mask).
            ok = self._candidate_at(np.asarray(cells, dtype=np.intp), clearance)
            if within is not None:
                ok &= within.ravel()[cells]
            if polygon is not None:
                ok &= self._polygon_cells(polygon).ravel()[cells]
            pool = flat = np.asarray(cells, dtype=np.intp)[ok]
        else:
            mask = self.candidate_mask(clearance)
            if within is not None:
                mask = mask & within
            if polygon is not None:
                mask = mask & self._polygon_cells(polygon)
            pool = flat = np.flatnonzero(mask)
        chosen = np.empty((n, 2))  # rows [:count] accepted so far
        count = 0
        tries = 0
        while count < n and pool.size and tries < max_tries:
            batch = min(256, max_tries - tries)
            tries += batch
            idx = rng.choice(pool, size=batch)
            if flat is None:
                idx = idx[(self._wall.flat[idx] >= wall_min) & ~self._blocked().flat[idx]]
            pts = self._jitter(np.stack(np.unravel_index(idx, shape), axis=1), rng)
            ok = self._admissible(pts, clearance, polygon)
            count = accept_spaced(np.ascontiguousarray(pts[ok]), chosen, count, 2 * clearance)
        if count < n:
            if flat is None:
                flat = np.flatnonzero(self.candidate_mask(clearance))
            count = self._exhaustive(
                flat, shape, chosen, count, clearance, polygon, rng, what, at_most=at_most
            )
            chosen = chosen[:count]
        if forbid:
            for p in chosen:
                self.forbid(p, clearance)
        return chosen

    def _free_flat(self) -> NDArray[np.intp]:
        if self._free_cache is None:
            self._free_cache = grid_memo(self.grid, "free cells", self._free_cells)
        return self._free_cache

    def _free_cells(self) -> NDArray[np.intp]:
        flat = np.flatnonzero(self.grid.free)
        flat.setflags(write=False)
        return flat

    def _exhaustive(
        self,
        flat: NDArray[np.intp],
        shape: tuple[int, ...],
        chosen: FloatArray,
        count: int,
        clearance: float,
        polygon: FloatArray | None,
        rng: np.random.Generator,
        what: str,
        *,
        at_most: bool = False,
    ) -> int:
        """Last attempt: every candidate cell centre in random order (fails only if none fit).

        Fills ``chosen`` ``(n, 2)`` beyond its first ``count`` rows, in place, and returns the
        rows filled (``n``, or fewer with ``at_most`` instead of raising). The candidates
        are tested in chunks, in that order, up to the one that completes ``chosen``: a
        request for one position (each placed obstacle) rarely needs more than the first.
        """
        n = len(chosen)
        if flat.size:
            order = rng.permutation(flat)
            order = order[~self._surely_taken(order, clearance)]
            chunk = max(4096, 4 * n)
            for lo in range(0, order.size, chunk):
                cells = np.stack(np.unravel_index(order[lo : lo + chunk], shape), axis=1)
                pts = self.grid.cell_to_world(cells)
                ok = self._admissible(pts, clearance, polygon)
                count = accept_spaced(np.ascontiguousarray(pts[ok]), chosen, count, 2 * clearance)
                if count == n:
                    return count
        if at_most:
            return count
        raise SamplingError(
            f"cannot place {what}: found room for {count} of {n} with clearance "
            f"{clearance:g} m from walls, obstacles and forbidden zones "
            f"({flat.size} candidate cells); reduce counts or clearances, or use a larger map"
        )

    def _surely_taken(self, flat: NDArray[np.intp], clearance: float) -> NDArray[np.bool_]:
        """For flat cell indices: whether the centre is certainly too close to the layers.

        A cell marked by :meth:`_blocked` overlaps an obstacle or forbidden zone, so a centre
        within ``clearance − res/√2`` (less a margin far above rounding) of such a cell's
        centre is closer than ``clearance`` to that zone: :meth:`_admissible` rejects it.
        Dropping those cells first changes nothing but the time a crowded map takes to be
        searched (most of its candidates lie near some obstacle).
        """
        res = self.grid.resolution
        h, w = self.grid.data.shape
        scale = abs(clearance) + float(np.abs(self.grid.origin).max()) + res * max(h, w)
        reach = clearance - res * math.sqrt(0.5) - 1e-9 * scale
        if reach <= 0:
            return np.zeros(flat.shape, dtype=bool)
        # The distance transform of the blocked cells, on the map padded by clear cells so
        # that its border (which `squared_edt` counts as blocked) is out of reach; kept until
        # the layers change (a box that does not fit is redrawn many times).
        pad = math.ceil(reach / res) + 2
        if self._blocked_edt is None or self._blocked_edt[0] < pad:
            blocked = self._blocked()
            if blocked.any():
                d2 = squared_edt(np.pad(blocked, pad))[pad : pad + h, pad : pad + w]
                dist = np.sqrt(d2) * res
            else:
                dist = np.full((h, w), np.inf)
            self._blocked_edt = (pad, dist)
        taken: NDArray[np.bool_] = self._blocked_edt[1].ravel()[flat] < reach
        return taken

    def _admissible(
        self, pts: FloatArray, clearance: float, polygon: FloatArray | None
    ) -> NDArray[np.bool_]:
        ok = np.isfinite(pts).all(axis=1)  # what `accept_spaced` bins
        ok &= self.obstacle_distance(pts, cutoff=clearance) >= clearance
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
