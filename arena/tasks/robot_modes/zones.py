"""``robots.zones``: robots with roles whose start and goals lie in their zones (specs §2.7).

Reads the same files as ``obstacles.zones`` (a zones file and a zone scenario, by default the
world's ``map/zones.yaml`` and ``zones/default.yaml``). Every robot gets a role drawn uniformly
from the scenario's ``robots`` entries; its start and goal lie inside zones of the role's
``waypoints in`` categories (a category uniformly, then a zone of it), keep ``robot body +
clearance`` from walls, obstacles and forbidden zones, are connected at that clearance and at
least ``min_goal_distance`` apart. Like ``robots.explore`` a robot is never done: on arrival it
gets a new goal in its role's zones, connected to where it stands when possible.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from arena.core.errors import ConfigError, SamplingError
from arena.core.types import Pose2D
from arena.scene.episode import RobotSpawn
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.robot_modes.random import robot_name, spawn_radius
from arena.tasks.sampling import components
from arena.tasks.world import WorldSampler
from arena.tasks.zones import RobotRole, ZoneFileParams, ZoneFiles, ZoneMap, sample_in_zones


def _masks(
    world: WorldSampler, clearance: float, origin: Pose2D, min_distance: float
) -> list[NDArray[np.bool_] | None]:
    """``within`` masks, strictest first: connected to ``origin`` and far from it, connected."""
    grid = world.grid
    labels = components(world.candidate_mask(clearance))
    r, c = (int(v) for v in grid.world_to_cell(origin.xy))
    if not (0 <= r < labels.shape[0] and 0 <= c < labels.shape[1]) or labels[r, c] == 0:
        return [None]
    region = labels == labels[r, c]
    rows, cols = np.indices(labels.shape)
    cx = grid.origin[0] + (cols + 0.5) * grid.resolution
    cy = grid.origin[1] + (rows + 0.5) * grid.resolution
    far = np.hypot(cx - origin.x, cy - origin.y) >= min_distance + grid.resolution
    return [region & far, region]


@register_mode("robots", "zones", tags=("continuous", "zones"))
class ZoneRobots:
    """Robots with zone-scenario roles: start and endless goals inside the role's zones."""

    class Params(ZoneFileParams):
        """Parameters of ``robots.zones``."""

        clearance: float = Field(
            0.25, ge=0, description="m kept beyond the robot body (Arena SPAWN_ROBOT_SAFE_DIST)"
        )
        min_goal_distance: float = Field(
            2.0, ge=0, description="m, straight distance from the start (or robot) to each goal"
        )
        max_attempts: int = Field(20, ge=1, description="starts drawn before giving up")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self.files = ZoneFiles(self.params.zones, self.params.scenario, "robots.zones")

    def roles(self, ctx: ResetContext) -> list[RobotRole]:
        """The role of every robot of the episode (a pure function of the episode)."""
        setup = self.files.get(ctx.map_spec)
        roles = setup.scenario.robots
        if not roles:
            raise ConfigError(
                "the zone scenario defines no robot roles (a 'robots' list of {name, "
                "waypoints in})",
                source=str(setup.scenario_file),
                path="robots",
            )
        picks = ctx.rng("robots", "roles").integers(len(roles), size=len(ctx.robots))
        return [roles[int(k)] for k in picks]

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """Start and goal per robot inside its role's zones (stream ``robots``)."""
        zones = self.files.get(ctx.map_spec).zones
        rng = ctx.rng("robots")
        n = len(ctx.robots)
        spawns = []
        for k, (model, role) in enumerate(zip(ctx.robots, self.roles(ctx), strict=True)):
            name = robot_name(k, n, model.name)
            c = spawn_radius(model) + self.params.clearance
            start, goal = self._start_goal(ctx.sampler, zones, role, c, rng, f"robot {name!r}")
            spawns.append(RobotSpawn(name, model, start, goal))
        return spawns

    def _start_goal(
        self,
        world: WorldSampler,
        zones: ZoneMap,
        role: RobotRole,
        clearance: float,
        rng: np.random.Generator,
        what: str,
    ) -> tuple[Pose2D, Pose2D]:
        p = self.params
        for _ in range(p.max_attempts):
            xy = sample_in_zones(
                world, zones, role.waypoints_in, clearance, rng,
                what=f"{what} start ({role.name})", forbid=False,
            )
            start = Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-np.pi, np.pi)))
            within = _masks(world, clearance, start, p.min_goal_distance)[0]
            try:
                gxy = sample_in_zones(
                    world, zones, role.waypoints_in, clearance, rng,
                    what=f"{what} goal ({role.name})", forbid=False, within=within,
                )
            except SamplingError:
                continue  # no goal far enough and connected: draw another start
            goal = Pose2D(float(gxy[0]), float(gxy[1]), float(rng.uniform(-np.pi, np.pi)))
            world.forbid(start.xy, clearance)
            world.forbid(goal.xy, clearance)
            return start, goal
        raise SamplingError(
            f"no start/goal pair for {what} (role {role.name!r}) in zones of "
            f"{', '.join(zones.expand(role.waypoints_in))} {p.min_goal_distance:g} m apart and "
            f"connected at clearance {clearance:g} m after {p.max_attempts} starts; lower "
            "task.robots.min_goal_distance or task.robots.clearance, or enlarge the zones"
        )

    def next_goal(
        self, ctx: ResetContext, robot: int, pose: Pose2D, rng: np.random.Generator
    ) -> Pose2D | None:
        """A new goal in the robot's role zones, connected to ``pose`` when possible; never done."""
        zones = self.files.get(ctx.map_spec).zones
        role = self.roles(ctx)[robot]
        c = spawn_radius(ctx.robots[robot]) + self.params.clearance
        masks = _masks(ctx.sampler, c, pose, self.params.min_goal_distance)
        if masks[-1] is not None:
            masks.append(None)  # last resort: anywhere in the role's zones
        for within in masks:
            try:
                xy = sample_in_zones(
                    ctx.sampler, zones, role.waypoints_in, c, rng,
                    what=f"a new goal for robot {robot} ({role.name})", forbid=False,
                    within=within,
                )
            except SamplingError:
                if within is None:
                    raise
                continue
            return Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-np.pi, np.pi)))
        raise AssertionError("unreachable: the last mask is None")
