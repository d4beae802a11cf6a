"""``robots.random``: a random start and goal per robot (Arena specs §2.5).

Unlike Arena (box-filter clearance, garbage positions when the map is full), start and goal
keep ``robot radius + clearance`` from walls, obstacles and forbidden zones exactly, lie in the
same connected free region at that clearance (so a path exists for the robot's body), are at
least ``min_goal_distance`` apart, and become forbidden discs so nothing is placed on them.
"""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import SamplingError
from arena.core.types import Pose2D
from arena.tasks.base import ResetContext, SingleGoal, register_mode
from arena.tasks.episode import RobotSpawn
from arena.tasks.sampling import components
from arena.tasks.world import WorldSampler


def robot_name(k: int, n: int, model_name: str) -> str:
    """``jackal`` for a single robot, ``robot0, robot1, ...`` for several."""
    return f"robot{k}" if n > 1 else model_name


def sample_pose(
    world: WorldSampler,
    clearance: float,
    rng: np.random.Generator,
    *,
    what: str,
    within: np.ndarray | None = None,
    polygon: np.ndarray | None = None,
    forbid: bool = False,
) -> Pose2D:
    """One position with ``clearance`` and a uniform heading in ``[-π, π)``."""
    xy = world.sample(1, clearance, rng, what=what, within=within, polygon=polygon,
                      forbid=forbid)[0]
    return Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-np.pi, np.pi)))


def sample_start_goal(
    world: WorldSampler,
    clearance: float,
    min_distance: float,
    rng: np.random.Generator,
    *,
    what: str,
    max_attempts: int = 50,
) -> tuple[Pose2D, Pose2D]:
    """A start and a goal ≥ ``min_distance`` apart and connected at ``clearance``.

    Both become forbidden discs of radius ``clearance`` afterwards.
    """
    grid = world.grid
    labels = components(world.candidate_mask(clearance))
    rows, cols = np.indices(labels.shape)
    cx = grid.origin[0] + (cols + 0.5) * grid.resolution
    cy = grid.origin[1] + (rows + 0.5) * grid.resolution
    for _ in range(max_attempts):
        start = sample_pose(world, clearance, rng, what=f"{what} start")
        r, c = grid.world_to_cell(start.xy)
        region = labels == labels[r, c]
        # Cells whose every point is ≥ min_distance from the start (half a diagonal margin).
        far = np.hypot(cx - start.x, cy - start.y) >= min_distance + grid.resolution
        try:
            goal = sample_pose(world, clearance, rng, what=f"{what} goal", within=region & far)
        except SamplingError:
            continue  # this start's region is too small: draw another start
        world.forbid(start.xy, clearance)
        world.forbid(goal.xy, clearance)
        return start, goal
    raise SamplingError(
        f"no start/goal pair for {what} {min_distance:g} m apart in one connected free region "
        f"with clearance {clearance:g} m after {max_attempts} starts; lower "
        "task.robots.min_goal_distance or task.robots.clearance, or use a larger map"
    )


def random_spawns(
    ctx: ResetContext, min_goal_distance: float, clearance: float
) -> list[RobotSpawn]:
    """A random start and goal for every robot of ``ctx`` (``clearance`` beyond its radius)."""
    rng = ctx.rng("robots")
    n = len(ctx.robots)
    spawns = []
    for k, model in enumerate(ctx.robots):
        name = robot_name(k, n, model.name)
        start, goal = sample_start_goal(
            ctx.sampler, model.radius + clearance, min_goal_distance, rng, what=f"robot {name!r}"
        )
        spawns.append(RobotSpawn(name, model, start, goal))
    return spawns


@register_mode("robots", "random", tags=("default",))
class RandomRobots(SingleGoal):
    """Random start and goal per robot, reachable for its body, ``min_goal_distance`` apart."""

    class Params(BaseModel):
        """Parameters of ``robots.random``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        min_goal_distance: float = Field(5.0, ge=0, description="m, straight start-goal distance")
        clearance: float = Field(
            0.25, ge=0, description="m kept beyond the robot radius (Arena SPAWN_ROBOT_SAFE_DIST)"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """Start and goal for every robot model of the episode."""
        return random_spawns(ctx, self.params.min_goal_distance, self.params.clearance)
