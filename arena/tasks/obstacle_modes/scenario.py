"""``obstacles.scenario``: static, interactive and dynamic obstacles from an Arena scenario file.

Interactive obstacles are placed like static ones (the 2-D backend has no pushable bodies).
Pedestrian ``vmax`` ranges are drawn from the episode's seed.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.scene.episode import AgentSpawn
from arena.scene.state import Obstacle
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.robot_modes.scenario import ScenarioFile, ScenarioRobots
from arena.tasks.scenario_checks import check_robot_bodies
from arena.tasks.scenario_convert import scenario_agents, scenario_obstacles


@register_mode("obstacles", "scenario", tags=("file",))
class ScenarioObstacles:
    """Obstacles and pedestrians exactly as the scenario file lists them."""

    class Params(BaseModel):
        """Parameters of ``obstacles.scenario``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        file: str = Field(description="path to an Arena scenario JSON file")
        check_map: bool = Field(True, description="reject positions off the map or in walls")

    def __init__(self, params: Params) -> None:
        self.params = params
        self._file = ScenarioFile(params.file, params.check_map)
        self._obstacles: list[Obstacle] | None = None

    def reset(self, ctx: ResetContext) -> tuple[list[Obstacle], AgentSpawn]:
        """The file's obstacles (built once) and pedestrians."""
        sc = self._file.get(ctx)
        if self._obstacles is None:
            try:
                self._obstacles = scenario_obstacles(sc)
            except ConfigError as e:
                raise e.located(source=self.params.file) from None
        if self.params.check_map and isinstance(ctx.robot_mode, ScenarioRobots):
            # The robots come from the file too: their bodies must clear its obstacles (robots
            # of other modes were placed around them by the sampler).
            assert ctx.map_result is not None
            check_robot_bodies(ctx.spawns, ctx.map_result.grid, self._obstacles,
                               source=self.params.file)
        ctx.sampler.add_obstacles(self._obstacles)
        return list(self._obstacles), scenario_agents(sc.obstacles.dynamic, ctx.rng("scenario"))
