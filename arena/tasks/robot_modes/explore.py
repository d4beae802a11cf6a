"""``robots.explore``: random goals forever; a robot stuck too long is teleported (specs §2.5).

Robots start like ``robots.random``. On arrival a robot gets a new random goal at least
``min_goal_distance`` away (in the free region connected to it at the robot's clearance, when it
stands in one), so a robot is never *done*: the episode runs until its time limit. A robot that
has not reached its goal within ``goal_timeout`` seconds is teleported to a random free pose with
a new goal (Arena teleports on its task timeout). New positions do not become forbidden zones
(Arena: ``forbid=False``), so they never use up the map.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import SamplingError
from arena.core.types import Pose2D
from arena.scene.episode import RobotSpawn
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.robot_modes.random import random_spawns, spawn_radius
from arena.tasks.sampling import components
from arena.tasks.world import WorldSampler


def sample_far_pose(
    world: WorldSampler,
    clearance: float,
    origin: Pose2D | None,
    min_distance: float,
    rng: np.random.Generator,
    *,
    what: str,
    avoid: NDArray[np.float64] | None = None,
    avoid_radius: float = 0.0,
) -> Pose2D:
    """A pose with ``clearance`` (m), ≥ ``min_distance`` (m) from ``origin`` and connected to it.

    The position lies in the free region (at ``clearance``) that contains ``origin`` when
    ``origin`` stands in one; otherwise anywhere. Nothing becomes forbidden. ``avoid`` is an
    ``(k, 2)`` array of points (m) kept ``avoid_radius`` (m) away (other robots, pedestrians).
    The distance and connection requirements are dropped, in that order, if nothing fits.

    Raises:
        SamplingError: no position keeps ``clearance`` anywhere on the map.
    """
    grid = world.grid
    mask = world.candidate_mask(clearance)
    rows, cols = np.indices(mask.shape)
    cx = grid.origin[0] + (cols + 0.5) * grid.resolution
    cy = grid.origin[1] + (rows + 0.5) * grid.resolution
    region: NDArray[np.bool_] | None = None
    far: NDArray[np.bool_] | None = None
    clear: NDArray[np.bool_] | None = None
    if origin is not None:
        labels = components(mask)
        r, c = (int(v) for v in grid.world_to_cell(origin.xy))
        if 0 <= r < mask.shape[0] and 0 <= c < mask.shape[1] and labels[r, c] > 0:
            region = labels == labels[r, c]
        far = np.hypot(cx - origin.x, cy - origin.y) >= min_distance + grid.resolution
    if avoid is not None and len(avoid):
        clear = np.ones(mask.shape, dtype=bool)
        for p in np.asarray(avoid, dtype=np.float64).reshape(-1, 2):
            clear &= np.hypot(cx - p[0], cy - p[1]) >= avoid_radius + grid.resolution
    # Requirements dropped one by one when nothing fits: distance, then connection.
    masks = [_all(region, far, clear), _all(region, clear), _all(clear), _all(region), None]
    for within in masks:
        try:
            xy = world.sample(1, clearance, rng, what=what, within=within, forbid=False)[0]
        except SamplingError:
            continue
        return Pose2D(float(xy[0]), float(xy[1]), float(rng.uniform(-np.pi, np.pi)))
    raise SamplingError(
        f"cannot place {what}: no position keeps {clearance:g} m from walls, obstacles and "
        "forbidden zones"
    )


def _all(*masks: NDArray[np.bool_] | None) -> NDArray[np.bool_] | None:
    """Cell-wise AND of the given masks (``None`` entries ignored; all ``None`` → ``None``)."""
    out: NDArray[np.bool_] | None = None
    for m in masks:
        if m is not None:
            out = m if out is None else out & m
    return out


@register_mode("robots", "explore", tags=("continuous",))
class ExploreRobots:
    """Random start and goal; a new random goal on every arrival; never done."""

    class Params(BaseModel):
        """Parameters of ``robots.explore``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        min_goal_distance: float = Field(
            3.0, ge=0, description="m, straight distance from the robot to each new goal"
        )
        clearance: float = Field(
            0.25, ge=0, description="m kept beyond the robot body (Arena SPAWN_ROBOT_SAFE_DIST)"
        )
        goal_timeout: float | None = Field(
            60.0, gt=0,
            description="s without reaching the goal before the robot is teleported to a random "
            "pose with a new goal (Arena: the task timeout); None never teleports",
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()

    @property
    def goal_timeout(self) -> float | None:
        """Seconds (s) a robot may take per goal before it is teleported; ``None``: unlimited."""
        return self.params.goal_timeout

    def _clearance(self, ctx: ResetContext, robot: int) -> float:
        return spawn_radius(ctx.robots[robot]) + self.params.clearance

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """Start and goal per robot, as ``robots.random`` draws them."""
        return random_spawns(ctx, self.params.min_goal_distance, self.params.clearance)

    def next_goal(
        self, ctx: ResetContext, robot: int, pose: Pose2D, rng: np.random.Generator
    ) -> Pose2D | None:
        """A new random goal ≥ ``min_goal_distance`` from ``pose``, reachable from it."""
        return sample_far_pose(
            ctx.sampler, self._clearance(ctx, robot), pose, self.params.min_goal_distance, rng,
            what=f"a new goal for robot {robot}",
        )

    def on_goal_timeout(
        self,
        ctx: ResetContext,
        robot: int,
        rng: np.random.Generator,
        avoid: NDArray[np.float64] | None = None,
    ) -> tuple[Pose2D, Pose2D]:
        """A random free pose to teleport ``robot`` to, and its new goal.

        ``avoid``: ``(k, 2)`` positions (m) of other robots and pedestrians; the new pose keeps
        1 m plus the clearance away from them when the map allows.
        """
        c = self._clearance(ctx, robot)
        start = sample_far_pose(
            ctx.sampler, c, None, 0.0, rng, what=f"a teleport pose for robot {robot}",
            avoid=avoid, avoid_radius=c + 1.0,
        )
        goal = sample_far_pose(
            ctx.sampler, c, start, self.params.min_goal_distance, rng,
            what=f"a new goal for robot {robot}",
        )
        return start, goal
