"""``obstacles.zones``: pedestrians walking between the zones of a world (Arena specs §2.7).

Reads a zones file (default: the world's ``map/zones.yaml``) and a zone scenario (default: the
world's ``zones/default.yaml``; formats in :mod:`arena.tasks.zones`). Per ``pedestrians`` entry
the episode draws ``amount`` pedestrians; each gets ``number of waypoints`` waypoints, and its
start and every waypoint lie in a zone drawn as: a category of ``waypoints in`` uniformly
(``*``: all), a zone of that category uniformly, a point inside its polygon. Starts keep the
body clearance from everything and from each other (they become forbidden discs) and
``agent_robot_clearance`` from the robots' starts; waypoints only keep the body clearance from
walls, obstacles and forbidden zones. Pedestrians loop over their waypoints; the ``type`` sets
the kind, ``model`` is a label. Only pedestrians are produced, no obstacles.

Differences from Arena: a point is sampled exactly inside the polygon with clearance (Arena
samples the polygon's bounding box and parks the shortfall at "garbage positions" off the map);
a zone without room is redrawn, and a request no zone can meet raises a ``SamplingError``.
As in Arena, consecutive waypoints may lie in different rooms: the crowd model walks towards
them through the doors only as far as its wall forces let it.
"""

from __future__ import annotations

import numpy as np
from pydantic import Field, model_validator

from arena.scene.episode import MAX_PERSON_SPEED, WAYPOINT_LOOP, AgentSpawn, speed_range_problem
from arena.scene.state import Obstacle
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.robot_modes.random import spawn_radius
from arena.tasks.zones import ZoneFileParams, ZoneFiles, sample_in_zones


@register_mode("obstacles", "zones", tags=("zones",))
class ZoneObstacles:
    """Pedestrian groups of a zone scenario, starting and walking inside their zones."""

    class Params(ZoneFileParams):
        """Parameters of ``obstacles.zones``."""

        agent_radius: float = Field(0.3, gt=0, description="m, pedestrian body radius")
        agent_speed: tuple[float, float] = Field(
            (0.5, 1.2),
            description=f"m/s, [min, max] vmax; 0 <= min <= max <= {MAX_PERSON_SPEED:g}",
        )
        agent_robot_clearance: float = Field(
            1.5, ge=0, description="m, no pedestrian starts this close to a robot's start"
        )
        max_attempts: int = Field(
            20, ge=1, description="zones drawn per point before giving up (a full zone is redrawn)"
        )

        @model_validator(mode="after")
        def _speed(self) -> ZoneObstacles.Params:
            problem = speed_range_problem(*self.agent_speed)
            if problem:
                raise ValueError(f"agent_speed {problem}")
            return self

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self.files = ZoneFiles(self.params.zones, self.params.scenario, "obstacles.zones")

    def reset(self, ctx: ResetContext) -> tuple[list[Obstacle], AgentSpawn]:
        """The scenario's pedestrians (stream ``pedestrians``); no obstacles."""
        p = self.params
        setup = self.files.get(ctx.map_spec)
        rng = ctx.rng("pedestrians")
        world = ctx.sampler
        body = p.agent_radius + 0.05
        for r in ctx.spawns:
            world.forbid(r.start.xy, spawn_radius(r.model) + p.agent_robot_clearance)
        starts: list[np.ndarray] = []
        routes: list[list[np.ndarray]] = []
        kinds: list[int] = []
        for group in setup.scenario.pedestrians:
            for k in range(group.amount.draw(rng)):
                what = f"pedestrian {group.name}_{k + 1}"
                n_wp = group.number_of_waypoints.draw(rng)
                start = sample_in_zones(
                    world, setup.zones, group.waypoints_in, body, rng,
                    what=f"{what} start", forbid=True, attempts=p.max_attempts,
                )
                route = [
                    sample_in_zones(
                        world, setup.zones, group.waypoints_in, body, rng,
                        what=f"{what} waypoint {j + 1}", forbid=False, attempts=p.max_attempts,
                    )
                    for j in range(n_wp)
                ]
                starts.append(start)
                routes.append(route or [start])  # no waypoints: stand at the start
                kinds.append(group.kind)
        n = len(starts)
        if n == 0:
            return [], AgentSpawn.empty()
        k_max = max(len(r) for r in routes)
        waypoints = np.full((n, k_max, 2), np.nan)
        for i, route in enumerate(routes):
            waypoints[i, : len(route)] = route
        return [], AgentSpawn(
            positions=np.array(starts, dtype=np.float64),
            radii=np.full(n, p.agent_radius),
            vmax=rng.uniform(*p.agent_speed, size=n),
            waypoints=waypoints,
            num_waypoints=np.array([len(r) for r in routes], dtype=np.int64),
            waypoint_mode=np.full(n, WAYPOINT_LOOP, dtype=np.int64),
            kinds=np.array(kinds, dtype=np.int64),
        )
