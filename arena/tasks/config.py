"""The ``task`` block of an experiment (Arena's ``task_generator.yaml`` + launch arguments).

    task:
      robots: {type: random, min_goal_distance: 5.0}       # tm_robots
      obstacles: {type: random, static: 5, dynamic: [3, 15]}  # tm_obstacles
      modules: [{type: dynamic_map, episodes_per_map: 5}]  # tm_modules
      timeout: 60.0                  # s per episode (Arena: 60)
      goal_radius: 0.3               # m
      goal_tolerance_angle: 0.5236   # rad (Arena: 30°); null ignores the heading
      forbidden_zones: [{center: [2, 3], radius: 1.0}, {polygon: [[0, 0], [1, 0], [1, 1]]}]

Mode and module blocks are checked against :data:`~arena.tasks.base.TASK_MODES` by the config
loader, where the file and key path are known.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator


class ForbiddenZone(BaseModel):
    """A keep-out area: nothing is sampled inside it. Either a disc or a polygon (m)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    center: tuple[float, float] | None = Field(None, description="m, disc centre [x, y]")
    radius: float | None = Field(None, gt=0, description="m, disc radius")
    polygon: list[tuple[float, float]] | None = Field(None, description="m, [[x, y], ...]")

    @model_validator(mode="after")
    def _one_shape(self) -> ForbiddenZone:
        disc = self.center is not None and self.radius is not None
        poly = self.polygon is not None and len(self.polygon) >= 3
        if disc == poly:
            raise ValueError(
                "give either center and radius (a disc) or polygon (>= 3 points), not both"
            )
        return self


def _block(value: Any) -> Any:
    """``"random"`` → ``{"type": "random"}``."""
    return {"type": value} if isinstance(value, str) else value


class TaskConfig(BaseModel):
    """Which task modes and modules make the episodes, and when an episode ends."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    robots: dict[str, Any] = Field(
        default_factory=lambda: {"type": "random"},
        description="robot task mode {type: random|scenario|guided|explore|zones, ...}",
    )
    obstacles: dict[str, Any] = Field(
        default_factory=lambda: {"type": "random"},
        description="obstacle task mode {type: random|scenario|parametrized|zones, ...}",
    )
    modules: list[dict[str, Any]] = Field(
        default_factory=list,
        description="modules [{type: staged|dynamic_map|benchmark|clear_forbidden_zones|"
        "interactive, ...}] applied in order",
    )
    timeout: float = Field(60.0, gt=0, description="s of simulated time per episode (Arena: 60)")
    goal_radius: float = Field(
        0.3, gt=0, description="m; the goal is reached within this distance (Arena: 1.0)"
    )
    goal_tolerance_angle: float | None = Field(
        math.radians(30.0),
        gt=0,
        description="rad; heading error allowed at the goal (Arena: 30°); null ignores heading",
    )

    forbidden_zones: list[ForbiddenZone] = Field(
        default_factory=list,
        description="keep-out discs/polygons where nothing is sampled (a doorway, a dock)",
    )

    @field_validator("robots", "obstacles", mode="before")
    @classmethod
    def _shorthand(cls, v: Any) -> Any:
        return _block(v)

    @field_validator("modules", mode="before")
    @classmethod
    def _module_shorthand(cls, v: Any) -> Any:
        if isinstance(v, str):  # "staged,dynamic_map" as in Arena's tm_modules launch arg
            v = [s.strip() for s in v.split(",") if s.strip()]
        if isinstance(v, list):
            return [_block(m) for m in v]
        return v
