"""``robots.scenario``: robot starts and goals from an Arena scenario JSON file (specs §1).

If the file has more robots than the episode, the extra entries are ignored; if it has fewer,
that is an error (Arena warns and leaves the other robots where they were).
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.core.types import Pose2D
from arena.scene.episode import RobotSpawn
from arena.tasks.base import ResetContext, SingleGoal, register_mode
from arena.tasks.robot_modes.random import robot_name, spawn_radius
from arena.tasks.scenario import Scenario, load_scenario
from arena.tasks.scenario_checks import check_layout, check_robot_bodies, validate_against_map


class ScenarioFile:
    """A scenario file read once and checked once per map grid."""

    def __init__(self, file: str, check_map: bool) -> None:
        self.file = file
        self.check_map = check_map
        self._scenario: Scenario | None = None
        self._checked: int | None = None

    def get(self, ctx: ResetContext) -> Scenario:
        """The scenario, checked against ``ctx.map`` (positions on the map, not in walls)."""
        if self._scenario is None:
            self._scenario = load_scenario(Path(self.file).expanduser())
        grid = ctx.map.grid
        if self.check_map and self._checked != id(grid):
            validate_against_map(self._scenario, grid, source=self.file)
            self._checked = id(grid)
        return self._scenario


@register_mode("robots", "scenario", tags=("file",))
class ScenarioRobots(SingleGoal):
    """Start and goal of each robot as the scenario file gives them."""

    class Params(BaseModel):
        """Parameters of ``robots.scenario``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        file: str = Field(description="path to an Arena scenario JSON file")
        check_map: bool = Field(
            True,
            description="reject positions off the map or in walls, and starts/goals where the "
            "robot's footprint overlaps a wall or an obstacle",
        )
        clearance: float = Field(
            0.25, ge=0, description="m beyond the robot body forbidden around start and goal"
        )

    def __init__(self, params: Params) -> None:
        self.params = params
        self._file = ScenarioFile(params.file, params.check_map)

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """The file's starts and goals for the episode's robots."""
        sc = self._file.get(ctx)
        n = len(ctx.robots)
        if len(sc.robots) < n:
            raise ConfigError(
                f"the scenario has {len(sc.robots)} robot(s), the episode needs {n}",
                source=self.params.file,
                path="robots",
            )
        spawns = []
        for k, model in enumerate(ctx.robots):
            entry = sc.robots[k]
            start, goal = Pose2D.from_array(list(entry.start)), Pose2D.from_array(list(entry.goal))
            for p in (start, goal):
                ctx.sampler.forbid(p.xy, spawn_radius(model) + self.params.clearance)
            spawns.append(RobotSpawn(robot_name(k, n, model.name), model, start, goal))
        if self.params.check_map:
            check_layout(sc, goal_radius=ctx.goal_radius, source=self.params.file)
            assert ctx.map_result is not None  # the generator builds the map first
            check_robot_bodies(spawns, ctx.map_result.grid, ctx.map_result.obstacles,
                               source=self.params.file)
        return spawns
