"""``obstacles.random``: random static/interactive obstacles and pedestrians (specs §2.6).

Counts are drawn uniformly from ``[min, max]`` per class, as in Arena's ``RANDOM`` block;
the ``staged`` curriculum overrides them. Static models come from the obstacle library
(``arena/maps/obstacle_models.yaml``); ``box`` is a cuboid with random edge lengths
(``box_size``). Obstacles keep ``obstacle_clearance`` from walls, from each other and from the
robots' start and goal zones. Pedestrians start ``agent_robot_clearance`` away from every robot
start and walk round trips between waypoints that see each other (so even a model that
ignores walls never walks through one); Arena instead draws two unconstrained waypoints.
Interactive obstacles are placed like static ones: the 2-D backend has no pushable bodies.
A count that does not fit is an error, or with ``when_full: fewer`` (the demo preset, so that
``arena run --map`` works on a user's small map) as many as fit, after one warning per map.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.core.errors import SamplingError
from arena.core.geometry import point_segment_distance, points_in_polygon, rectangle
from arena.maps.distance import clearance_map, grid_memo
from arena.maps.grid import OccupancyGrid
from arena.maps.obstacles import make_obstacle, obstacle_models
from arena.maps.raster import polygon_mask, polygon_window
from arena.scene.episode import (
    MAX_COUNT,
    MAX_PERSON_SPEED,
    WAYPOINT_LOOP,
    AgentSpawn,
    speed_range_problem,
)
from arena.scene.state import Obstacle
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.robot_modes.random import spawn_radius
from arena.tasks.sampling import MaskRegions, clear_near, max_blocked_sq
from arena.tasks.world import wall_distance_map

BOX = "box"
"""Pseudo-model: a cuboid with random edge lengths."""


class Count(BaseModel):
    """How many of one obstacle class: ``n``, ``[min, max]`` or ``{min, max, models}``."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    min: int = Field(0, ge=0, le=MAX_COUNT, description=f"fewest; 0 to {MAX_COUNT:,}")
    max: int = Field(0, ge=0, le=MAX_COUNT, description=f"most; 0 to {MAX_COUNT:,}")
    models: list[str] = Field(
        default_factory=lambda: [BOX], description="models drawn uniformly (static classes)"
    )

    @model_validator(mode="before")
    @classmethod
    def _shorthand(cls, v: Any) -> Any:
        if isinstance(v, int) and not isinstance(v, bool):
            return {"min": v, "max": v}
        if isinstance(v, list | tuple) and len(v) == 2 and all(isinstance(x, int) for x in v):
            return {"min": v[0], "max": v[1]}
        return v

    @model_validator(mode="after")
    def _order(self) -> Count:
        if self.min > self.max:
            raise ValueError(f"min ({self.min}) must not exceed max ({self.max})")
        unknown = [m for m in self.models if m != BOX and m not in obstacle_models()]
        if unknown:
            known = ", ".join([BOX, *sorted(obstacle_models())])
            raise ValueError(f"unknown obstacle model(s) {unknown}; known: {known}")
        return self

    def draw(self, rng: np.random.Generator, override: int | None) -> int:
        """The count for one episode (``override`` from a curriculum wins)."""
        return override if override is not None else int(rng.integers(self.min, self.max + 1))


class PlacementParams(BaseModel):
    """How obstacles and pedestrians are placed (shared by ``random`` and ``parametrized``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    box_size: tuple[float, float] = Field(
        (0.4, 1.2), description="m, [min, max] edge length of `box` obstacles"
    )
    obstacle_clearance: float = Field(0.6, ge=0, description="m, free gap kept around obstacles")
    agent_radius: float = Field(0.3, gt=0, description="m (Arena's pedestrian body: 0.3-0.32)")
    agent_speed: tuple[float, float] = Field(
        (0.5, 1.2),
        description=f"m/s, [min, max] vmax; 0 <= min <= max <= {MAX_PERSON_SPEED:g}",
    )
    agent_waypoints: int = Field(
        2, ge=1, description="waypoints per pedestrian beside its start"
    )
    agent_leg_length: tuple[float, float] = Field(
        (2.0, 8.0), description="m, [min, max] distance between consecutive waypoints"
    )
    agent_robot_clearance: float = Field(
        1.5, ge=0, description="m, no pedestrian starts this close to a robot's start"
    )
    max_attempts: int = Field(200, ge=1, description="tries per placement before failing")

    @model_validator(mode="after")
    def _ranges(self) -> PlacementParams:
        for name in ("box_size", "agent_leg_length"):
            lo, hi = getattr(self, name)
            if not 0 < lo <= hi:
                raise ValueError(f"{name} must be [min, max] with 0 < min <= max, got {[lo, hi]}")
        problem = speed_range_problem(*self.agent_speed)
        if problem:
            raise ValueError(f"agent_speed {problem}")
        return self


@register_mode("obstacles", "random", tags=("default",))
class RandomObstacles:
    """Random static and interactive obstacles and pedestrians on random round trips."""

    class Params(PlacementParams):
        """Parameters of ``obstacles.random``."""

        static: Count = Field(default_factory=lambda: Count(min=5, max=5), description="static")
        interactive: Count = Field(default_factory=Count, description="interactive obstacles")
        dynamic: Count = Field(
            default_factory=lambda: Count(min=10, max=10, models=[]), description="pedestrians"
        )
        elder_fraction: float = Field(
            0.2, ge=0, le=1, description="share of elder pedestrians (Arena's crowdsim: 0.2)"
        )
        when_full: Literal["error", "fewer"] = Field(
            "error", description="when an obstacle or pedestrian finds no room: error, or "
            "place fewer with a warning (the demo preset, on a user's small map)"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self._warned: set[str] = set()

    def reset(self, ctx: ResetContext) -> tuple[list[Obstacle], AgentSpawn]:
        """Obstacles, then pedestrians, each class with its own random stream."""
        p = self.params
        rng = ctx.rng("obstacles")
        placed: list[Obstacle] = []
        for prefix, cls, count, override in (
            ("S", "static", p.static, ctx.counts.static),
            ("I", "interactive", p.interactive, ctx.counts.interactive),
        ):
            n = count.draw(rng, override)
            field = f"task.obstacles.{cls}"
            if override is not None:
                field = f"the curriculum stage's {cls} count (overriding {field})"
            placed += place_obstacles(
                ctx, prefix, n, count.models, rng, p, field=field,
                fewer=self._warned if p.when_full == "fewer" else None,
            )
        n_agents = p.dynamic.draw(rng, ctx.counts.dynamic)
        return placed, place_pedestrians(
            ctx, n_agents, placed, ctx.rng("pedestrians"), p, elder_fraction=p.elder_fraction,
            fewer=self._warned if p.when_full == "fewer" else None,
        )


# -- static ----------------------------------------------------------------------------------
def place_obstacles(
    ctx: ResetContext,
    prefix: str,
    n: int,
    models: Sequence[str],
    rng: np.random.Generator,
    params: PlacementParams,
    *,
    counter: dict[str, int] | None = None,
    field: str = "the obstacle count",
    fewer: set[str] | None = None,
) -> list[Obstacle]:
    """Place ``n`` obstacles drawn uniformly from ``models`` and add them to ``ctx.sampler``.

    Each keeps ``params.obstacle_clearance`` (m) beyond its circumscribed radius from walls,
    obstacles and forbidden zones. Names are ``<prefix>_<model>_<k>`` (``k`` from 1 per model);
    ``counter`` (``"<prefix>_<model>"`` → last ``k``) continues the numbering across calls.
    ``field`` names where ``n`` came from, for errors. With ``fewer`` (a set of the warnings
    given so far, to which a new one is added: one per map and run) a request that does not fit
    places as many as do, after a warning, instead of raising.

    Raises:
        SamplingError: at once (no draw made) if ``n`` exceeds :func:`obstacle_capacity`, or
            when an obstacle finds no room.
    """
    p = params
    fit = obstacle_capacity(ctx.map.grid, models, p)
    wanted = n
    if fewer is not None:
        n = min(n, fit)
    if n > fit:
        raise SamplingError(
            f"{field}: {n} obstacles cannot fit on map {ctx.map.name!r}: at most ~{fit} fit "
            f"with a free gap of {p.obstacle_clearance:g} m around each "
            f"({_size_text(models, p)}); lower the count or task.obstacles.obstacle_clearance, "
            "or use a larger map"
        )
    out: list[Obstacle] = []
    per_model: dict[str, int] = {} if counter is None else counter
    for k in range(n):
        model = models[int(rng.integers(len(models)))] if models else BOX
        ob = None
        # A box that does not fit is redrawn with another size; a library model cannot be.
        for _ in range(p.max_attempts if model == BOX else 1):
            if model == BOX:
                footprint = rectangle(*rng.uniform(*p.box_size, size=2))
            else:
                footprint = obstacle_models()[model].polygon()
            radius = float(np.linalg.norm(footprint, axis=1).max())
            try:
                xy = ctx.sampler.sample(
                    1, radius + p.obstacle_clearance, rng, what="", forbid=False
                )[0]
            except SamplingError:
                continue
            key = f"{prefix}_{model}"
            per_model[key] = per_model.get(key, 0) + 1
            name = f"{key}_{per_model[key]}"
            pose = [xy[0], xy[1], float(rng.uniform(-np.pi, np.pi))]
            if model == BOX:
                ob = Obstacle(name, "cuboid", np.array(pose), footprint,
                              height=float(rng.uniform(0.5, 1.5)))
            else:
                ob = make_obstacle(name, model, pose)
            break
        if ob is None and fewer is not None:
            break
        if ob is None:
            tries = f" in {p.max_attempts} sizes" if model == BOX else ""
            raise SamplingError(
                f"{field}: only {k} of {n} obstacles fit on map {ctx.map.name!r} with a free "
                f"gap of {p.obstacle_clearance:g} m around each (obstacle {k + 1}, "
                f"{prefix}_{model}, found no room{tries}); lower the obstacle counts or "
                "task.obstacles.obstacle_clearance"
            )
        ctx.sampler.add_obstacles([ob])
        out.append(ob)
    if fewer is not None and len(out) < wanted:
        _warn_fewer(ctx, field, wanted, p, fewer)
    return out


def _warn_fewer(
    ctx: ResetContext, field: str, n: int, p: PlacementParams, warned: set[str],
    *, what: str = "obstacles",
) -> None:
    """Warn (once per map and run) that fewer than ``n`` obstacles (or pedestrians) fit."""
    room = (
        f"with a free gap of {p.obstacle_clearance:g} m around each" if what == "obstacles"
        else "clear of walls, obstacles and the robots' starts"
    )
    text = (
        f"map {ctx.map.name!r}: {field}: not all {n} {what} fit {room}; placed as many as "
        "did (when_full: error makes it an error)"
    )
    if text not in warned:
        warned.add(text)
        warnings.warn(text, UserWarning, stacklevel=3)


def obstacle_capacity(grid: OccupancyGrid, models: Sequence[str], params: PlacementParams) -> int:
    """An upper bound on how many obstacles of ``models`` fit on ``grid`` (empty: ``box``).

    :func:`place_obstacles` puts each centre at least ``R + c`` (its circumscribed radius
    ``R`` plus ``obstacle_clearance`` ``c``) from the walls and from every earlier footprint,
    which holds a disc of radius ``ρ`` (the inradius about its centre). Centres are thus at
    least ``D = R_min + c + ρ_min`` apart, so the discs of radius ``D/2`` about them are
    disjoint and lie where the wall distance is at least ``R_min + c − D/2``; the area there
    (counted in cells, generously) over ``π D²/4`` bounds the count. Random placement fills
    well under this (a quarter to a third of it, e.g. 80 of 311 default boxes on
    ``small_office``): it only turns away requests that can never succeed, without a draw,
    instead of after minutes of searching.
    """
    if models:
        shapes = [_box_limits(params) if m == BOX else _model_limits(m) for m in set(models)]
    else:
        shapes = [_box_limits(params)]
    r_min = min(r for r, _ in shapes)
    inr_min = min(i for _, i in shapes)
    gap = r_min + params.obstacle_clearance + inr_min
    res = grid.resolution
    t = r_min + params.obstacle_clearance - gap / 2.0
    # A cell holding a point at wall distance ≥ t has its centre ≥ t − res/√2 from the
    # centre of every non-free cell.
    cells = np.count_nonzero(wall_distance_map(grid) >= t - res * np.sqrt(0.5))
    return int(cells * res * res / (np.pi * gap * gap / 4.0))


def _box_limits(params: PlacementParams) -> tuple[float, float]:
    """Smallest circumscribed radius and inradius of a ``box`` (m)."""
    lo = params.box_size[0]
    return lo * np.sqrt(0.5), lo / 2.0


def _model_limits(model: str) -> tuple[float, float]:
    """Circumscribed radius and inradius (0 if the origin is outside) of a library model (m)."""
    poly = obstacle_models()[model].polygon()
    radius = float(np.linalg.norm(poly, axis=1).max())
    origin = np.zeros((1, 2))
    if not points_in_polygon(origin, poly)[0]:
        return radius, 0.0
    edges = point_segment_distance(origin, poly, np.roll(poly, -1, axis=0))
    return radius, float(edges.min())


def _size_text(models: Sequence[str], params: PlacementParams) -> str:
    """What the obstacles are, for messages."""
    lo, hi = params.box_size
    names = sorted(set(models)) or [BOX]
    return ", ".join(f"box of {lo:g}-{hi:g} m" if m == BOX else m for m in names)


# -- pedestrians -------------------------------------------------------------------------------
def place_pedestrians(
    ctx: ResetContext,
    n: int,
    placed: Sequence[Obstacle],
    rng: np.random.Generator,
    params: PlacementParams,
    *,
    kinds: NDArray[np.int64] | None = None,
    elder_fraction: float = 0.0,
    fewer: set[str] | None = None,
) -> AgentSpawn:
    """``n`` pedestrians on round trips between mutually visible waypoints.

    Starts keep ``params.agent_robot_clearance`` (m) beyond every robot's body from the robots'
    starts; every leg is ``params.agent_leg_length`` long and in line of sight.

    Args:
        ctx: the episode (its map, sampler and robot spawns).
        n: number of pedestrians.
        placed: obstacles of this episode beside the map's own.
        rng: the pedestrians' random stream.
        params: radius, speeds, waypoints and clearances.
        kinds: ``(n,)`` type codes (0 adult, 1 elder, 2 child); ``None`` draws elders with
            probability ``elder_fraction`` (after all other draws).
        elder_fraction: share of elders when ``kinds`` is ``None``.
        fewer: as in :func:`place_obstacles`: place as many starts as fit, after a warning
            (added to this set of those given), instead of raising.
    """
    p = params
    if n == 0:
        return AgentSpawn.empty()
    if kinds is not None and kinds.shape != (n,):
        raise ValueError(f"kinds must have shape ({n},), got {kinds.shape}")
    grid = ctx.map.grid
    body = p.agent_radius + 0.05
    world = ctx.sampler
    # Starts keep agent_robot_clearance from every robot start (beyond the robot's body).
    for r in ctx.spawns:
        world.forbid(r.start.xy, spawn_radius(r.model) + p.agent_robot_clearance)
    starts = world.sample(n, body, rng, what=f"{n} pedestrians", at_most=fewer is not None)
    if fewer is not None and len(starts) < n:
        _warn_fewer(ctx, "task.obstacles.dynamic", n, p, fewer, what="pedestrians")
        n = len(starts)
        kinds = None if kinds is None else kinds[:n]
        if n == 0:
            return AgentSpawn.empty()
    walkable = walkable_mask(grid, ctx.map.obstacles, placed, body)
    k = p.agent_waypoints
    # Round trip start → w1 → … → wk → … → w1 → start, so a loop never crosses a wall.
    n_wp = 2 * k
    waypoints = np.full((n, n_wp, 2), np.nan)
    # The walkable region (8-connected, cells in row-major order) of each start: nearly all
    # starts share the one big region, and labelling the whole map (then sorting its cells by
    # label) for it was the bulk of a reset.
    regions = MaskRegions(walkable)
    for i in range(n):
        chain = [starts[i]]
        r, c = grid.world_to_cell(starts[i])
        region_cells = regions.cells(r, c)
        for _ in range(k):
            chain.append(_next_waypoint(grid, walkable, region_cells, chain[-1], rng, p))
        trip = chain[1:] + chain[-2::-1]
        waypoints[i, : len(trip)] = trip
    vmax = rng.uniform(*p.agent_speed, size=n)
    if kinds is None:
        kinds = (rng.random(n) < elder_fraction).astype(np.int64)
    return AgentSpawn(
        positions=starts,
        radii=np.full(n, p.agent_radius),
        vmax=vmax,
        waypoints=waypoints,
        num_waypoints=np.full(n, n_wp, dtype=np.int64),
        waypoint_mode=np.full(n, WAYPOINT_LOOP, dtype=np.int64),
        kinds=np.asarray(kinds, dtype=np.int64),
    )


def walkable_mask(
    grid: OccupancyGrid,
    map_obstacles: Sequence[Obstacle],
    placed: Sequence[Obstacle],
    body: float,
) -> NDArray[np.bool_]:
    """``(H, W)`` bool: free cells whose centre is more than ``body`` (m) from every blocked cell.

    Blocked are the map's non-free cells and the cells under any obstacle footprint;
    distances are :func:`~arena.maps.distance.clearance_map`'s. The map's own part is
    computed once per map (:func:`~arena.maps.distance.grid_memo`); this episode's obstacles
    then only clear the cells near them, which gives the same mask as thresholding the
    clearance map of all blocked cells (distances to a union are the minimum of the parts').
    """
    polys = tuple(np.asarray(o.polygon, dtype=np.float64) for o in map_obstacles)
    key = ("walkable", float(body), tuple((q.shape, q.tobytes()) for q in polys))

    def static_part() -> NDArray[np.bool_]:
        blocked = grid.occupied | ~grid.free
        if polys:
            blocked = blocked | polygon_mask(grid, list(polys))
        walkable = (clearance_map(grid, blocked) > body) & grid.free
        walkable.setflags(write=False)
        return walkable

    walkable = grid_memo(grid, key, static_part).copy()
    cells = []
    for o in placed:
        window = polygon_window(grid, o.polygon)
        if window is not None:
            r0, c0, win = window
            cells.append(np.argwhere(win) + np.array([r0, c0]))
    if cells:
        clear_near(walkable, np.concatenate(cells), max_blocked_sq(grid.resolution, body))
    return walkable


def _next_waypoint(
    grid: OccupancyGrid,
    walkable: NDArray[np.bool_],
    region_cells: NDArray[np.int64],
    prev: NDArray[np.float64],
    rng: np.random.Generator,
    p: PlacementParams,
) -> NDArray[np.float64]:
    """A point of the region ``agent_leg_length`` away from ``prev`` and visible from it."""
    lo, hi = p.agent_leg_length
    if len(region_cells) == 0:
        return np.array(prev, dtype=np.float64)
    ax, ay = float(prev[0]), float(prev[1])
    ox, oy = float(grid.origin[0]), float(grid.origin[1])
    out = np.empty(2, dtype=np.float64)
    for near_ok in (False, True):  # second pass: any visible cell ≥ 0.5 m away
        d_min, d_max = (min(lo, 0.5), np.inf) if near_ok else (lo, hi)
        for _ in range(p.max_attempts // 20 + 1):
            # The draws of `jitter(grid, region_cells[pick], rng)`, in its order.
            pick = rng.integers(len(region_cells), size=64)
            u = rng.uniform(-0.5, 0.5, size=(64, 2))
            if _pick_waypoint(
                region_cells, pick, u, ax, ay, float(d_min), float(d_max), bool(near_ok),
                ox, oy, float(grid.resolution), grid.height, grid.width, walkable, out,
            ):
                return out
    # No visible waypoint (a tiny enclosed pocket): stay put rather than cross a wall.
    return np.array(prev, dtype=np.float64)


@njit(cache=True)
def _pick_waypoint(
    region_cells: NDArray[np.int64],
    pick: NDArray[np.int64],
    u: NDArray[np.float64],
    ax: float,
    ay: float,
    d_min: float,
    d_max: float,
    near_ok: bool,
    ox: float,
    oy: float,
    res: float,
    height: int,
    width: int,
    allowed: NDArray[np.bool_],
    out: NDArray[np.float64],
) -> bool:
    """One batch of :func:`_next_waypoint`: jitter, leg-length filter, first visible candidate.

    Candidate ``m`` is ``cell_to_world(region_cells[pick[m]]) + u[m] · res`` and qualifies if
    its distance ``d`` from ``(ax, ay)`` is ``d ≥ d_min`` (and ``d ≤ d_max`` unless
    ``near_ok``) and it is in line of sight (:func:`_visible`). The float operations are those
    of :func:`~arena.tasks.sampling.jitter` and ``np.hypot``, in the same order, so the
    waypoint is bit-identical; one batch used to cost a dozen numpy calls.
    Writes the first qualifying candidate into ``out`` ``(2,)`` and returns whether one did.
    """
    for m in range(pick.shape[0]):
        cell = pick[m]
        px = (ox + (float(region_cells[cell, 1]) + 0.5) * res) + u[m, 0] * res
        py = (oy + (float(region_cells[cell, 0]) + 0.5) * res) + u[m, 1] * res
        dx = px - ax
        dy = py - ay
        d = np.hypot(dx, dy)
        if not (d >= d_min and (near_ok or d <= d_max)):
            continue
        if _visible(ax, ay, dx, dy, d, ox, oy, res, height, width, allowed):
            out[0] = px
            out[1] = py
            return True
    return False


@njit(cache=True)
def _visible(
    ax: float,
    ay: float,
    dx: float,
    dy: float,
    length: float,
    ox: float,
    oy: float,
    res: float,
    height: int,
    width: int,
    allowed: NDArray[np.bool_],
) -> bool:
    """Whether the segment from ``(ax, ay)`` by ``(dx, dy)`` (``length`` m) stays in ``allowed``.

    :func:`~arena.tasks.sampling.line_of_sight` operation for operation (``np.linspace``
    sample parameters ``i · (1/k)`` with the last exactly 1, the same cell flooring), so the
    chosen waypoints are bit-identical; a reset tests thousands of candidate legs, which cost
    ~60 µs each as separate numpy calls.
    """
    k = max(int(np.ceil(length / (res / 3.0))), 1)
    step = 1.0 / k
    for i in range(k + 1):
        t = 1.0 if i == k else float(i) * step + 0.0
        col = int(np.floor((ax + t * dx - ox) / res))
        row = int(np.floor((ay + t * dy - oy) / res))
        if row < 0 or row >= height or col < 0 or col >= width or not allowed[row, col]:
            return False
    return True
