"""The ``random`` task: random start and goal, random box obstacles, random walking people.

Follows Arena's random task modes (specs §2.5–2.6) with exact clearances instead of Arena's
box-filter approximation: starts and goals keep ``robot radius + clearance`` from walls and
obstacles and lie in the same connected free region; obstacles keep ``obstacle_clearance``
from walls and from each other; pedestrians walk round trips between waypoints that see each
other, so even a model that ignores walls never walks through one. Everything is placed in
cells known to be free: the unknown space around a mapped building is never used.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.core.errors import SamplingError
from arena.core.geometry import rectangle
from arena.core.types import Pose2D
from arena.maps.raster import disk_mask, polygon_mask
from arena.maps.sources import MapResult
from arena.robots.model import RobotModel
from arena.sim.state import Obstacle
from arena.tasks.base import TASKS
from arena.tasks.episode import WAYPOINT_LOOP, AgentSpawn, Episode, RobotSpawn
from arena.tasks.sampling import clearance_map, components, jitter, line_of_sight, sample_cells


@TASKS.register("random", tags=("default",))
class RandomTask:
    """Random start/goal per robot, random box obstacles and pedestrians on random round trips."""

    class Params(BaseModel):
        """Parameters of :class:`RandomTask`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        agents: int = Field(10, ge=0, description="number of pedestrians")
        obstacles: int = Field(5, ge=0, description="number of placed box obstacles")
        min_goal_distance: float = Field(5.0, ge=0, description="m, start-goal straight distance")
        clearance: float = Field(0.25, ge=0, description="m, beyond the robot radius (Arena: 0.25)")
        obstacle_size: tuple[float, float] = Field(
            (0.4, 1.2), description="m, [min, max] edge length of the box obstacles"
        )
        obstacle_clearance: float = Field(
            0.6, ge=0, description="m, free gap kept around obstacles"
        )
        agent_radius: float = Field(0.3, gt=0, description="m (Arena's pedestrian body: 0.3-0.32)")
        agent_speed: tuple[float, float] = Field((0.5, 1.2), description="m/s, [min, max] vmax")
        agent_waypoints: int = Field(
            2, ge=1, description="waypoints per pedestrian beside its start"
        )
        agent_leg_length: tuple[float, float] = Field(
            (2.0, 8.0), description="m, [min, max] distance between consecutive waypoints"
        )
        agent_robot_clearance: float = Field(
            1.5, ge=0, description="m, no pedestrian starts this close to a robot's start"
        )
        elder_fraction: float = Field(
            0.2, ge=0, le=1, description="share of elder pedestrians (Arena's crowdsim: 0.2)"
        )
        goal_radius: float = Field(0.3, gt=0, description="m, goal reached within this distance")
        time_limit: float = Field(60.0, gt=0, description="s, episode timeout (Arena: 60 s)")
        max_attempts: int = Field(200, ge=1, description="tries per placement before failing")

        @model_validator(mode="after")
        def _ranges(self) -> RandomTask.Params:
            for name in ("obstacle_size", "agent_speed", "agent_leg_length"):
                lo, hi = getattr(self, name)
                if not 0 < lo <= hi:
                    raise ValueError(
                        f"{name} must be [min, max] with 0 < min <= max, got {[lo, hi]}"
                    )
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()

    def sample(
        self,
        map_result: MapResult,
        robots: Sequence[RobotModel],
        *,
        index: int,
        seed: int,
        rng: np.random.Generator,
    ) -> Episode:
        """Draw one episode on ``map_result`` for ``robots``."""
        p = self.params
        grid = map_result.grid
        obstacles = list(map_result.obstacles) + self._place_obstacles(map_result, rng)
        blocked = grid.occupied | polygon_mask(grid, [o.polygon for o in obstacles])
        clear = clearance_map(grid, blocked)

        spawns: list[RobotSpawn] = []
        taken = np.zeros_like(blocked)
        for k, model in enumerate(robots):
            start, goal = self._start_goal(
                grid, clear, taken, model.radius + p.clearance, rng, model
            )
            spawns.append(
                RobotSpawn(f"robot{k}" if len(robots) > 1 else model.name, model, start, goal)
            )
            # Later robots keep their whole footprint away from earlier starts and goals.
            keep = 2 * model.radius + p.clearance
            taken |= disk_mask(grid, np.array([start.xy, goal.xy]), np.array([keep, keep]))

        agents = self._place_agents(grid, clear, spawns, rng)
        return Episode(
            index=index,
            seed=seed,
            map_name=map_result.name,
            grid=grid,
            obstacles=tuple(obstacles),
            robots=tuple(spawns),
            agents=agents,
            time_limit=p.time_limit,
            goal_radius=p.goal_radius,
        )

    # -- parts ---------------------------------------------------------------------------------
    def _place_obstacles(self, map_result: MapResult, rng: np.random.Generator) -> list[Obstacle]:
        p = self.params
        if p.obstacles == 0:
            return []
        grid = map_result.grid
        base_clear = clearance_map(grid)
        placed: list[tuple[np.ndarray, float]] = [
            (o.pose[:2], float(np.linalg.norm(o.footprint, axis=1).max()))
            for o in map_result.obstacles
        ]
        out: list[Obstacle] = []
        for k in range(p.obstacles):
            for _ in range(p.max_attempts):
                length, width = rng.uniform(*p.obstacle_size, size=2)
                half_diag = 0.5 * float(np.hypot(length, width))
                mask = (base_clear > half_diag + p.obstacle_clearance) & grid.free
                if not mask.any():
                    continue  # this size does not fit anywhere; draw another
                xy = jitter(grid, sample_cells(mask, 1, rng, what="an obstacle"), rng)[0]
                yaw = rng.uniform(-np.pi, np.pi)
                if all(
                    np.hypot(*(xy - c)) > half_diag + r + p.obstacle_clearance for c, r in placed
                ):
                    break
            else:
                raise SamplingError(
                    f"could not place obstacle {k + 1} of {p.obstacles} on map "
                    f"{map_result.name!r} after {p.max_attempts} tries (sizes "
                    f"{list(p.obstacle_size)} m, clearance {p.obstacle_clearance} m); lower "
                    "task.obstacles, task.obstacle_size or task.obstacle_clearance"
                )
            placed.append((xy, half_diag))
            out.append(
                Obstacle(
                    name=f"S_box_{k + 1}",
                    model="cuboid",
                    pose=np.array([xy[0], xy[1], yaw]),
                    footprint=rectangle(length, width),
                    height=float(rng.uniform(0.5, 1.5)),
                )
            )
        return out

    def _start_goal(
        self,
        grid,
        clear: np.ndarray,
        taken: np.ndarray,
        margin: float,
        rng: np.random.Generator,
        model: RobotModel,
    ) -> tuple[Pose2D, Pose2D]:
        p = self.params
        ok = (clear > margin) & ~taken & grid.free
        labels = components(ok)
        for _ in range(p.max_attempts):
            start_cell = sample_cells(ok, 1, rng, what=f"robot {model.name!r} start")[0]
            region = labels == labels[start_cell[0], start_cell[1]]
            start_xy = jitter(grid, start_cell[None], rng)[0]
            centers = grid.cell_to_world(np.argwhere(region))
            far = np.hypot(*(centers - start_xy).T) >= p.min_goal_distance
            if not far.any():
                continue
            cells = np.argwhere(region)[far]
            goal_cell = cells[rng.integers(len(cells))]
            goal_xy = jitter(grid, goal_cell[None], rng)[0]
            start = Pose2D(start_xy[0], start_xy[1], rng.uniform(-np.pi, np.pi))
            goal = Pose2D(goal_xy[0], goal_xy[1], rng.uniform(-np.pi, np.pi))
            return start, goal
        raise SamplingError(
            f"no start/goal pair {p.min_goal_distance} m apart in one free region for robot "
            f"{model.name!r} (radius {model.radius} m + clearance {p.clearance} m); "
            "lower task.min_goal_distance or use a larger map"
        )

    def _place_agents(
        self, grid, clear: np.ndarray, robots: list[RobotSpawn], rng: np.random.Generator
    ) -> AgentSpawn:
        p = self.params
        n = p.agents
        if n == 0:
            return AgentSpawn.empty()
        walkable = (clear > p.agent_radius + 0.05) & grid.free
        start_ok = walkable.copy()
        for r in robots:
            start_ok &= ~disk_mask(
                grid,
                r.start.xy[None],
                np.array([r.model.radius + p.agent_radius + p.agent_robot_clearance]),
            )
        labels = components(walkable)
        starts = jitter(grid, sample_cells(start_ok, n, rng, what=f"{n} pedestrians"), rng)
        k = p.agent_waypoints
        # Round trip start → w1 → … → wk → … → w1 → start, so a loop never crosses a wall.
        n_wp = 2 * k
        waypoints = np.full((n, n_wp, 2), np.nan)
        for i in range(n):
            chain = [starts[i]]
            cell = grid.world_to_cell(starts[i])
            region = labels == labels[cell[0], cell[1]]
            region_cells = np.argwhere(region & walkable)
            for _ in range(k):
                chain.append(self._next_waypoint(grid, walkable, region_cells, chain[-1], rng))
            trip = chain[1:] + chain[-2::-1]
            waypoints[i, : len(trip)] = trip
        num = np.full(n, n_wp, dtype=np.int64)
        return AgentSpawn(
            positions=starts,
            radii=np.full(n, p.agent_radius),
            vmax=rng.uniform(*p.agent_speed, size=n),
            waypoints=waypoints,
            num_waypoints=num,
            waypoint_mode=np.full(n, WAYPOINT_LOOP, dtype=np.int64),
            kinds=(rng.random(n) < p.elder_fraction).astype(np.int64),
        )

    def _next_waypoint(self, grid, walkable, region_cells, prev, rng) -> np.ndarray:
        p = self.params
        lo, hi = p.agent_leg_length
        centers = grid.cell_to_world(region_cells)
        d = np.hypot(*(centers - prev).T)
        candidates = region_cells[(d >= lo) & (d <= hi)]
        if len(candidates) == 0:
            candidates = region_cells[d >= min(lo, 0.5)]
        for _ in range(p.max_attempts):
            if len(candidates) == 0:
                break
            xy = jitter(grid, candidates[rng.integers(len(candidates))][None], rng)[0]
            if line_of_sight(grid, walkable, prev, xy):
                return xy
        # No visible waypoint (a tiny enclosed pocket): stay put rather than cross a wall.
        return np.array(prev, dtype=np.float64)
