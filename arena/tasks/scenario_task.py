"""The ``scenario`` task: every episode is the one an Arena scenario JSON file describes.

    arena run --map path/to/arena_world task.type=scenario task.file=path/to/scenarios/1.json

The file is read once and checked against the map (positions off the map or inside walls are
errors naming the entry). Obstacles placed by a map generator are kept alongside the file's.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from arena.maps.sources import MapResult
from arena.robots.model import RobotModel
from arena.tasks.base import TASKS
from arena.tasks.episode import Episode
from arena.tasks.scenario import Scenario, load_scenario, scenario_episode, validate_against_map


@TASKS.register("scenario", tags=("file",))
class ScenarioTask:
    """Robots, obstacles and pedestrians from an Arena scenario JSON file, every episode alike."""

    class Params(BaseModel):
        """Parameters of :class:`ScenarioTask`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        file: str = Field(description="path to an Arena scenario JSON file")
        time_limit: float = Field(60.0, gt=0, description="s, episode timeout (Arena: 60 s)")
        goal_radius: float = Field(0.3, gt=0, description="m, goal reached within this distance")
        check_map: bool = Field(True, description="reject positions off the map or in walls")

    def __init__(self, params: Params) -> None:
        self.params = params
        self._scenario: Scenario | None = None
        self._checked: int | None = None  # id of the grid the scenario was checked against

    @property
    def scenario(self) -> Scenario:
        """The loaded file (read on first use)."""
        if self._scenario is None:
            self._scenario = load_scenario(Path(self.params.file).expanduser())
        return self._scenario

    def sample(
        self,
        map_result: MapResult,
        robots: Sequence[RobotModel],
        *,
        index: int,
        seed: int,
        rng: np.random.Generator,
    ) -> Episode:
        """The scenario's episode on ``map_result`` (``rng`` is unused: nothing is random)."""
        p = self.params
        if p.check_map and self._checked != id(map_result.grid):
            validate_against_map(self.scenario, map_result.grid, source=p.file)
            self._checked = id(map_result.grid)
        ep = scenario_episode(
            self.scenario,
            map_result.grid,
            robots,
            index=index,
            seed=seed,
            time_limit=p.time_limit,
            goal_radius=p.goal_radius,
            map_name=map_result.name,
        )
        if map_result.obstacles:
            ep = dataclasses.replace(ep, obstacles=tuple(map_result.obstacles) + ep.obstacles)
        return ep
