"""Arena-Rosnav's ``rosmap`` generators: outdoor, canteen, warehouse and office rooms.

After Arena-Rosnav PR #118 (``utils/misc/map_generator/map_generator/rosmap``; see
``arena_specs.md`` §3.1). Each generator returns a walled empty room plus a list of obstacle
placements from the model library (:mod:`arena.maps.obstacles`); the obstacles are the product and
are NOT burnt into the grid (the simulator, lidar and planners see them as obstacles).

Conventions:
    * Arena's placement logic runs on *generator cells* of ``cell_size`` (0.5 m in PR #118); a
      cell ``(row, col)`` maps to the world point ``x = col * cell_size``,
      ``y = height - row * cell_size`` (metres, map origin at the lower-left corner), exactly as
      Arena converts its placements (row 0 is the top of Arena's image).
    * Every placement is checked against the real footprints already placed: footprints must not
      overlap and must keep a gap of ``2 * robot_radius + clearance_margin`` to footprints of
      other placements (a table and its own chairs are one placement, as are the desks, chairs and
      separator of one office workplace) and to the walls. As the inflated placements are then
      pairwise disjoint and clear of the walls, their complement is connected: the room stays
      navigable for the robot (small pockets inside one placement aside).
    * Random placements get up to ``max_tries`` (20, as Arena) draws; one that never fits is
      dropped, as in Arena.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict, Field

from arena.core.geometry import point_segment_distance, polygon_edges, polygons_overlap
from arena.maps.generators.base import register_generator
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle, obstacle_model
from arena.maps.sources import GridSizeParams, MapResult
from arena.scene.state import Obstacle

Placement = tuple[str, float, float, float]
"""One obstacle of a placement: ``(model, x, y, yaw)`` in metres / radians."""


class RoomParams(GridSizeParams):
    """Parameters shared by every ``rosmap`` generator."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    width: float = Field(20.0, gt=0, description="m; PR #118 map_properties: 40 cells x 0.5 m")
    height: float = Field(20.0, gt=0, description="m; PR #118 map_properties: 40 cells x 0.5 m")
    resolution: float = Field(0.05, gt=0, description="m per cell of the output grid")
    cell_size: float = Field(
        0.5, gt=0, description="m per generator cell (Arena's placement grid, PR #118 resolution)"
    )
    robot_radius: float = Field(
        0.3, ge=0, description="m; placements keep a gap of one robot diameter (+ margin)"
    )
    clearance_margin: float = Field(
        0.2,
        ge=0,
        description="m added to the robot diameter in the gap between placements and to the walls; "
        "covers the rasterisation of footprints and inflation (about one cell per side at 0.05 m)",
    )
    max_tries: int = Field(20, ge=1, description="random draws per placement (Arena: 20)")

    @property
    def gap(self) -> float:
        """Minimum distance (m) between footprints of different placements and to the walls."""
        return 2.0 * self.robot_radius + self.clearance_margin


class _Placer:
    """Keeps the placed footprints and tests new placements against them (real geometry).

    Args:
        p: the room parameters (size, wall thickness = one output cell, gap).
    """

    def __init__(self, p: RoomParams) -> None:
        self.p = p
        wall = p.resolution  # OccupancyGrid.empty draws one-cell walls
        self.lo = np.array([wall + p.gap, wall + p.gap])
        self.hi = np.array([p.width - wall - p.gap, p.height - wall - p.gap])
        self.polys: list[NDArray[np.float64]] = []
        self.centres: list[NDArray[np.float64]] = []
        self.radii: list[float] = []
        self.obstacles: list[Obstacle] = []
        self._counts: dict[str, int] = {}

    def world(self, row: float, col: float) -> tuple[float, float]:
        """World point (m) of generator cell ``(row, col)``: ``x = col*c, y = H - row*c``."""
        return col * self.p.cell_size, self.p.height - row * self.p.cell_size

    def clamp(self, x: float, y: float, half_x: float, half_y: float) -> tuple[float, float]:
        """Shift ``(x, y)`` (m) so a box of half extents ``half_x, half_y`` (m) keeps the wall gap.

        A no-op when the box already keeps it; the box is assumed to fit the room.
        """
        x = min(max(x, self.lo[0] + half_x), self.hi[0] - half_x)
        y = min(max(y, self.lo[1] + half_y), self.hi[1] - half_y)
        return float(x), float(y)

    @staticmethod
    def _polygon(model: str, x: float, y: float, yaw: float) -> NDArray[np.float64]:
        local = obstacle_model(model).polygon()
        c, s = math.cos(yaw), math.sin(yaw)
        return local @ np.array([[c, s], [-s, c]]) + np.array([x, y])

    def try_place(self, items: list[Placement]) -> bool:
        """Add the obstacles ``items`` as one placement if it fits; return whether it did.

        A placement fits when each footprint lies inside the room at least ``gap`` from the walls,
        and keeps ``gap`` to every footprint already placed. The items of one placement are laid
        out by the caller so that they do not overlap each other.
        """
        polys = [self._polygon(*it) for it in items]
        for q in polys:
            if np.any(q.min(axis=0) < self.lo) or np.any(q.max(axis=0) > self.hi):
                return False
        if self.polys:
            centres = np.asarray(self.centres)
            radii = np.asarray(self.radii)
            for q in polys:
                qc = 0.5 * (q.min(axis=0) + q.max(axis=0))
                qr = float(np.max(np.hypot(*(q - qc).T)))
                # Bounding circles farther apart than the gap cannot violate it: skip them.
                near = np.flatnonzero(np.hypot(*(centres - qc).T) < radii + qr + self.p.gap)
                for k in near:
                    if _too_close(q, self.polys[k], self.p.gap):
                        return False
        for (model, x, y, yaw), q in zip(items, polys, strict=True):
            qc = 0.5 * (q.min(axis=0) + q.max(axis=0))
            self.polys.append(q)
            self.centres.append(qc)
            self.radii.append(float(np.max(np.hypot(*(q - qc).T))))
            k = self._counts.get(model, 0)
            self._counts[model] = k + 1
            self.obstacles.append(make_obstacle(f"{model}_{k}", model, [x, y, yaw]))
        return True

    def result(self, name: str) -> MapResult:
        """The walled room and the placed obstacles."""
        p = self.p
        grid = OccupancyGrid.empty(p.width, p.height, p.resolution)
        return MapResult(name, grid, tuple(self.obstacles))


def _too_close(p: NDArray[np.float64], q: NDArray[np.float64], gap: float) -> bool:
    """Whether two polygons overlap or come closer than ``gap`` (m)."""
    pa, pb = polygon_edges(p)
    qa, qb = polygon_edges(q)
    # For polygons that do not intersect, the distance is attained at a vertex of one of them.
    if point_segment_distance(p, qa, qb).min() < gap:
        return True
    if point_segment_distance(q, pa, pb).min() < gap:
        return True
    return polygons_overlap(p, q)


def _cell_range(p: RoomParams, extent: float, size: float) -> tuple[int, int]:
    """Integer generator cells ``[lo, hi]`` whose point keeps ``extent`` (m) clear of the walls.

    Samples only where a placement of bounding radius ``extent`` can fit, so the 20 tries are not
    wasted on spots that the wall test rejects for sure.
    """
    margin = p.resolution + p.gap + extent
    lo = math.ceil(margin / p.cell_size)
    hi = math.floor((size - margin) / p.cell_size)
    return lo, max(lo, hi)


def _grid_axis(
    rng: np.random.Generator, size_cells: int, d_min: int, d_max: int, layout: str = "arena"
) -> list[float]:
    """A jittered grid along one axis, in generator cells.

    ``d = randint(d_min, d_max) / 2`` in both layouts. ``"arena"`` (PR #118):
    ``start = randint(floor(d/2) + 1, 2d)``, ``n = int((size - start + d/2) / d)``, then reduced
    to ``U[floor(n/2), n]`` (at least 1) — sparse, often one or two rows in a 20 m room.
    ``"dense"``: as many slots as fit with half a pitch to each wall, centred in the room.
    """
    d = int(rng.integers(d_min, d_max + 1)) / 2.0
    if layout == "dense":
        n = max(int(size_cells // d), 1)
        start = 0.5 * (size_cells - (n - 1) * d)
        return [start + i * d for i in range(n)]
    start = int(rng.integers(math.floor(d / 2) + 1, int(2 * d) + 1))
    n = max(int((size_cells - start + d / 2) / d), 1)
    n = max(int(rng.integers(n // 2, n + 1)), 1)
    return [start + i * d for i in range(n)]


# -- outdoor ------------------------------------------------------------------------------------
@register_generator("outdoor", tags=("rosmap", "outdoor"))
class OutdoorMap:
    """Single trees spread over an open room, none closer than Arena's exclusion block."""

    class Params(RoomParams):
        """Parameters of :class:`OutdoorMap`."""

        obstacle_num: int = Field(15, ge=0, description="trees tried (PR #118 obstacle_num)")
        obstacle_extra_radius: int = Field(
            1,
            ge=0,
            description="generator cells; each tree reserves a (2r+1)^2-cell block that no other "
            "block overlaps (Jun 2024 yaml: 1; PR #118's 5 fits only 4-7 trees in 20 m)",
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def build(self, rng: np.random.Generator) -> MapResult:
        """Place up to ``obstacle_num`` trees (``max_tries`` draws each)."""
        p = self.params
        pl = _Placer(p)
        r = p.obstacle_extra_radius
        rows = round(p.height / p.cell_size)
        cols = round(p.width / p.cell_size)
        # Arena samples block centres in [r + 2, N - r - 2] cells.
        blocks: list[tuple[int, int]] = []
        for _ in range(p.obstacle_num):
            for _ in range(p.max_tries):
                row = int(rng.integers(r + 2, max(rows - r - 2, r + 2) + 1))
                col = int(rng.integers(r + 2, max(cols - r - 2, r + 2) + 1))
                # Non-overlapping (2r+1)-cell blocks: Chebyshev distance >= 2r + 1 cells.
                if any(max(abs(row - a), abs(col - b)) <= 2 * r for a, b in blocks):
                    continue
                x, y = pl.world(row, col)
                if pl.try_place([("tree", x, y, 0.0)]):
                    blocks.append((row, col))
                    break
        return pl.result("outdoor")


# -- canteen ------------------------------------------------------------------------------------
@register_generator("canteen", tags=("rosmap", "indoor"))
class CanteenMap:
    """Round tables at random spots, each with up to four chairs facing it (Arena "indoor").

    Arena puts the chairs one generator cell (0.5 m) from the table centre, which would put a
    0.45 m chair inside our 0.9 m table; the offsets are instead scaled to
    ``table radius + chair half length + chair_gap`` (0.725 m with the library models), along the
    same four directions rotated by the table's yaw. A table and its chairs are one placement.
    """

    class Params(RoomParams):
        """Parameters of :class:`CanteenMap`."""

        obstacle_num: int = Field(15, ge=0, description="tables tried (PR #118 obstacle_num)")
        chair_chance: float = Field(
            0.6, ge=0, le=1, description="probability of each of the 4 chairs (PR #118 yaml 0.6)"
        )
        chair_gap: float = Field(
            0.05, ge=0, description="m between the table edge and a chair's front (ours)"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def build(self, rng: np.random.Generator) -> MapResult:
        """Place up to ``obstacle_num`` tables with their chairs."""
        p = self.params
        pl = _Placer(p)
        chair = obstacle_model("chair")
        offset = obstacle_model("table").radius + 0.5 * chair.footprint.length + p.chair_gap  # type: ignore[union-attr]
        extent = offset + chair.radius
        rlo, rhi = _cell_range(p, extent, p.height)
        clo, chi = _cell_range(p, extent, p.width)
        # Arena's offsets (-1,0), (0,-1), (+1,0), (0,+1): directions pi, -pi/2, 0, pi/2; each chair
        # faces the table (yaw = table yaw + 0, pi/2, pi, 3pi/2 in Arena's order).
        dirs = np.array([math.pi, -0.5 * math.pi, 0.0, 0.5 * math.pi])
        for _ in range(p.obstacle_num):
            present = rng.random(4) < p.chair_chance
            for _ in range(p.max_tries):
                row = int(rng.integers(rlo, rhi + 1))
                col = int(rng.integers(clo, chi + 1))
                yaw = float(rng.uniform(0.0, math.pi))
                x, y = pl.world(row, col)
                items: list[Placement] = [("table", x, y, yaw)]
                for phi in dirs[present]:
                    a = yaw + float(phi)
                    items.append(
                        ("chair", x + offset * math.cos(a), y + offset * math.sin(a), a + math.pi)
                    )
                if pl.try_place(items):
                    break
        return pl.result("canteen")


# -- warehouse ----------------------------------------------------------------------------------
@register_generator("warehouse", tags=("rosmap", "indoor"))
class WarehouseMap:
    """Racks of shelves on a jittered grid plus pallet jacks at random free spots.

    Arena's logic (§3.1): global orientation 0 or pi/2 (p = 0.5); grid spacing
    ``randint(min, max) / 2`` cells, start offsets and counts as :func:`_grid_axis`; a shelf at
    every grid point with yaw ``orientation + pi/2``. Decisions for the library's 1.0 x 2.7 m
    "warehouse_shelf" bay (the PR #118 spacing, 8.5-9.5 m along the rack, 4.5-6 m across, was
    made for a longer shelf and leaves single bays lost in the room):

    * each grid point holds a rack of ``shelf_bays`` (2) bays side by side (5.4 m), one placement;
    * the grid is laid out in the rack frame: ``hor_dist`` runs along the racks and ``vert_dist``
      across them, so orientation pi/2 transposes the layout instead of turning the racks into
      each other. Aisles are then 3.1-4.1 m between rack ends and 3.5-5 m between rows;
    * a rack that would come closer than the gap to a wall is shifted inward just enough (Arena's
      start offset reaches 2 d, i.e. the far wall); if it then meets another rack it is dropped.
    """

    class Params(RoomParams):
        """Parameters of :class:`WarehouseMap`."""

        pallet_jacks: int = Field(5, ge=0, description="pallet jacks tried (PR #118 yaml 5)")
        layout: Literal["dense", "arena"] = Field(
            "dense",
            description="'dense': centred grid filling the hall; 'arena': PR #118's "
            "random start offset and row-count reduction (sparse)",
        )
        rack_chance: float = Field(
            0.85, ge=0, le=1, description="probability that each grid point holds a rack"
        )
        hor_dist_shelfs_min: int = Field(
            30,
            ge=1,
            description="cells x 2 along the racks: 7.5 m pitch for 5.4 m racks "
            "(PR #118 yaml 34, with its 1-bay racks)",
        )
        hor_dist_shelfs_max: int = Field(32, ge=1, description="cells x 2 (PR #118 yaml 38)")
        vert_dist_shelfs_min: int = Field(
            14,
            ge=1,
            description="cells x 2 across the racks: 3.5 m pitch = 2.5 m aisles (PR #118 yaml 18)",
        )
        vert_dist_shelfs_max: int = Field(16, ge=1, description="cells x 2 (PR #118 yaml 24)")
        shelf_bays: int = Field(
            2, ge=1, description="warehouse_shelf bays per rack at each grid point (ours)"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def build(self, rng: np.random.Generator) -> MapResult:
        """Place the shelf grid, then the pallet jacks."""
        p = self.params
        pl = _Placer(p)
        orientation = 0.0 if rng.random() < 0.5 else 0.5 * math.pi
        along_x = orientation == 0.0
        size_u = p.width if along_x else p.height  # extent along the racks (m)
        size_v = p.height if along_x else p.width
        us = _grid_axis(
            rng,
            round(size_u / p.cell_size),
            p.hor_dist_shelfs_min,
            p.hor_dist_shelfs_max,
            p.layout,
        )
        vs = _grid_axis(
            rng,
            round(size_v / p.cell_size),
            p.vert_dist_shelfs_min,
            p.vert_dist_shelfs_max,
            p.layout,
        )
        keep = rng.random((len(vs), len(us))) < p.rack_chance
        bay = obstacle_model("warehouse_shelf").footprint.width  # type: ignore[union-attr]
        offsets = (np.arange(p.shelf_bays) - 0.5 * (p.shelf_bays - 1)) * bay
        ux, uy = math.cos(orientation), math.sin(orientation)
        half_u = 0.5 * bay * p.shelf_bays
        half_v = 0.5 * obstacle_model("warehouse_shelf").footprint.length  # type: ignore[union-attr]
        # The bay's y axis (its 2.7 m width) lies along the rack when yaw = orientation + pi/2.
        yaw = orientation + 0.5 * math.pi
        for iv, v in enumerate(vs):
            for iu, u in enumerate(us):
                if not keep[iv, iu]:
                    continue
                x, y = pl.world(v, u) if along_x else pl.world(u, v)
                x, y = pl.clamp(x, y, *((half_u, half_v) if along_x else (half_v, half_u)))
                pl.try_place(
                    [("warehouse_shelf", x + o * ux, y + o * uy, yaw) for o in offsets.tolist()]
                )
        models = ("pallet_jack_1", "pallet_jack_2", "pallet_jack_3")
        extent = max(obstacle_model(m).radius for m in models)
        rlo, rhi = _cell_range(p, extent, p.height)
        clo, chi = _cell_range(p, extent, p.width)
        for _ in range(p.pallet_jacks):
            model = models[int(rng.integers(len(models)))]
            for _ in range(p.max_tries):
                x, y = pl.world(int(rng.integers(rlo, rhi + 1)), int(rng.integers(clo, chi + 1)))
                if pl.try_place([(model, x, y, float(rng.uniform(0.0, 2.0 * math.pi)))]):
                    break
        return pl.result("warehouse")


# -- office -------------------------------------------------------------------------------------
@register_generator("office", tags=("rosmap", "indoor"))
class OfficeMap:
    """Rows of workplaces: two facing desks split by a separator, a chair at each desk.

    Grid logic as the warehouse with the table distances (PR #118 yaml: 6-6.5 cells = 3-3.25 m
    between slots along a row, 10-10.5 cells = 5-5.25 m between rows). Desks face each other
    along y. Arena's offsets (desks 2 cells apart, chairs at -1 and +3 cells) are scaled to the
    library models: desk centres ``desk_offset`` (0.5 m, Arena's 1 cell) either side of the
    separator and chairs ``desk_offset + desk depth / 2 + chair radius + chair_gap`` (1.25 m) from
    it, so nothing overlaps (Arena's 1 m would put the 0.33 m chair over the 0.8 m deep desk).
    Each row is kept with ``row_chance`` and trimmed by ``U[0, floor(n/2))`` slots at each end.
    A workplace that would come closer than the gap to a wall is shifted inward just enough, and
    dropped if it then meets another.
    """

    class Params(RoomParams):
        """Parameters of :class:`OfficeMap`."""

        row_chance: float = Field(
            0.7, ge=0, le=1, description="probability of each row (PR #118 yaml 0.7)"
        )
        layout: Literal["dense", "arena"] = Field(
            "dense",
            description="'dense': centred rows filling the room; 'arena': PR #118's "
            "random start offset and row-count reduction (often one or two rows)",
        )
        hor_dist_table_min: int = Field(12, ge=1, description="cells x 2 (PR #118 yaml 12)")
        hor_dist_table_max: int = Field(13, ge=1, description="cells x 2 (PR #118 yaml 13)")
        vert_dist_table_min: int = Field(20, ge=1, description="cells x 2 (PR #118 yaml 20)")
        vert_dist_table_max: int = Field(21, ge=1, description="cells x 2 (PR #118 yaml 21)")
        desk_offset: float = Field(
            0.5, gt=0, description="m from the separator to each desk centre (Arena: 1 cell)"
        )
        chair_gap: float = Field(0.02, ge=0, description="m between desk front and chair (ours)")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def _slot(self, x: float, y: float) -> list[Placement]:
        """The five obstacles of one workplace centred on the separator at ``(x, y)``."""
        p = self.params
        desk = obstacle_model("office_desk").footprint
        chair_r = obstacle_model("office_chair").radius
        d = p.desk_offset
        c = d + 0.5 * desk.length + chair_r + p.chair_gap  # type: ignore[union-attr]
        half = 0.5 * math.pi
        # Desk model x = depth, pointing at its user: the lower desk faces -y, the upper +y.
        return [
            ("separator", x, y, half),
            ("office_desk", x, y - d, -half),
            ("office_desk", x, y + d, half),
            ("office_chair", x, y - c, half),
            ("office_chair", x, y + c, -half),
        ]

    def build(self, rng: np.random.Generator) -> MapResult:
        """Place the rows of workplaces."""
        p = self.params
        pl = _Placer(p)
        rows = _grid_axis(
            rng,
            round(p.height / p.cell_size),
            p.vert_dist_table_min,
            p.vert_dist_table_max,
            p.layout,
        )
        cols = _grid_axis(
            rng,
            round(p.width / p.cell_size),
            p.hor_dist_table_min,
            p.hor_dist_table_max,
            p.layout,
        )
        n = len(cols)
        half_x = 0.5 * obstacle_model("office_desk").footprint.width  # type: ignore[union-attr]
        half_y = (
            max(abs(it[2]) for it in self._slot(0.0, 0.0)) + obstacle_model("office_chair").radius
        )
        for row in rows:
            if rng.random() >= p.row_chance:
                continue
            k = n // 2
            left = int(rng.integers(0, k)) if k > 0 else 0
            right = int(rng.integers(0, k)) if k > 0 else 0
            for col in cols[left : n - right]:
                x, y = pl.clamp(*pl.world(row, col), half_x, half_y)
                pl.try_place(self._slot(x, y))
        return pl.result("office")
