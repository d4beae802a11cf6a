"""``robots.guided``: robots follow a shared cyclic list of waypoints (Arena specs §2.5).

Robots start at a random pose (or the given ``start``). Without waypoints a robot's goal is its
start: it is *idle*, not done. Every goal a user sets (the ``interactive`` module, Arena's RViz
"2D Nav Goal") is appended to one waypoint list shared by all robots; a robot that reaches a
waypoint heads for the next one (index modulo the list's length), so the robots cycle through the
list forever and the episode ends only by its time limit or a forced reset. Teleporting a robot
clears the list (Arena: setting a position clears ``/guided_waypoints``); the teleported robot
becomes idle where it lands. ``waypoints`` gives a list for scripted runs: robots then start
heading for the first waypoint.
"""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.scene.episode import RobotSpawn
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.robot_modes.random import robot_name, sample_pose, spawn_radius


@register_mode("robots", "guided", tags=("interactive",))
class GuidedRobots:
    """Robots cycle through a shared waypoint list that users extend at run time."""

    class Params(BaseModel):
        """Parameters of ``robots.guided``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        start: tuple[float, float, float] | None = Field(
            None, description="[x m, y m, theta rad] start of robot 0; None draws it at random"
        )
        waypoints: list[tuple[float, float, float]] = Field(
            default_factory=list,
            description="initial shared waypoint list, each [x m, y m, theta rad]",
        )
        clearance: float = Field(
            0.25, ge=0, description="m kept beyond the robot body around random starts"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self.waypoints: list[Pose2D] = []
        self._index: list[int] = []
        self._goal: list[Pose2D] = []

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """Starts (given or random); goal = the first waypoint, or the start (idle)."""
        p = self.params
        rng = ctx.rng("robots")
        n = len(ctx.robots)
        self.waypoints = [Pose2D(*w) for w in p.waypoints]
        for k, w in enumerate(self.waypoints):
            self._check(ctx, w, f"task.robots.waypoints[{k}]")
        spawns = []
        for k, model in enumerate(ctx.robots):
            clearance = spawn_radius(model) + p.clearance
            name = robot_name(k, n, model.name)
            if k == 0 and p.start is not None:
                start = Pose2D(*p.start)
                self._check(ctx, start, "task.robots.start")
                ctx.sampler.forbid(start.xy, clearance)
            else:
                start = sample_pose(
                    ctx.sampler, clearance, rng, what=f"robot {name!r} start", forbid=True
                )
            goal = self.waypoints[0] if self.waypoints else start
            spawns.append(RobotSpawn(name, model, start, goal))
        self._index = [0 if self.waypoints else -1] * n
        self._goal = [s.goal for s in spawns]
        return spawns

    @staticmethod
    def _check(ctx: ResetContext, pose: Pose2D, path: str) -> None:
        grid = ctx.map.grid
        cell = grid.world_to_cell(pose.xy)
        if not bool(grid.in_bounds(cell)):
            raise ConfigError(
                f"({pose.x:g}, {pose.y:g}) lies outside the map {ctx.map.name!r}", path=path
            )
        if not bool(grid.free[int(cell[0]), int(cell[1])]):
            raise ConfigError(
                f"({pose.x:g}, {pose.y:g}) lies in a wall of map {ctx.map.name!r}", path=path
            )

    def next_goal(
        self, ctx: ResetContext, robot: int, pose: Pose2D, rng: np.random.Generator
    ) -> Pose2D | None:
        """The next waypoint (cyclic); the current goal again (idle) while the list is empty."""
        self._ensure(robot)
        if not self.waypoints:
            self._index[robot] = -1
            return self._goal[robot]
        self._index[robot] = (self._index[robot] + 1) % len(self.waypoints)
        self._goal[robot] = self.waypoints[self._index[robot]]
        return self._goal[robot]

    def add_goal(self, ctx: ResetContext, robot: int, goal: Pose2D) -> Pose2D | None:
        """Append ``goal`` to the shared list; the goal ``robot`` should head for now, if new.

        An idle robot (none of the list's waypoints yet) heads for the new waypoint at once; a
        busy one keeps its goal and reaches the new waypoint in turn.
        """
        self._ensure(robot)
        self.waypoints.append(goal)
        if self._index[robot] < 0:
            return self.next_goal(ctx, robot, goal, np.random.default_rng(0))
        return None

    def on_teleport(self, ctx: ResetContext, robot: int, pose: Pose2D) -> Pose2D:
        """Clear the shared list; the teleported robot idles at ``pose`` (its new goal)."""
        self._ensure(robot)
        self.waypoints.clear()
        self._index = [-1] * len(self._index)
        self._goal[robot] = pose
        return pose

    def _ensure(self, robot: int) -> None:
        """Grow the per-robot state for a robot index (hand-built contexts)."""
        while len(self._index) <= robot:
            self._index.append(-1)
            self._goal.append(Pose2D())
