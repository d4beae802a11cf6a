"""The experiment config: one pydantic model for everything ``arena run`` needs.

Polymorphic blocks (``map``, ``task.robots|obstacles|modules``, ``crowd``,
``navigation.*_planner``, ``sim.backend``) are flat mappings ``{type: name, **params}``;
:func:`arena.config.loader.validate_plugins` checks each against its registry so that every
error names the file and the key path.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, StrictInt, field_validator, model_validator

from arena.core.names import RULE, SafeLabel
from arena.core.rng import Seed
from arena.crowd.simulator import PedestrianConfig
from arena.learn.config import LearningConfig
from arena.nav.config import NavigationConfig
from arena.tasks.config import TaskConfig


def non_finite_key(data: Any) -> tuple[str, float] | None:
    """The key path and value of the first infinite or NaN number in a config (``None``: none).

    No setting of an experiment means "unbounded" by infinity (``task.timeout: .inf`` would run
    an episode forever), and NaN compares false with every bound, so configs hold finite numbers
    only. Checked on the raw data, so that plugin blocks (plain mappings here) are covered too.
    """
    stack: list[tuple[str, Any]] = [("", data)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, float) and not math.isfinite(value):
            return path, value
        if isinstance(value, dict):
            stack.extend((f"{path}.{k}" if path else str(k), v) for k, v in value.items())
        elif isinstance(value, list | tuple):
            stack.extend((f"{path}[{i}]", v) for i, v in enumerate(value))
    return None


class _Strict(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class SimConfig(_Strict):
    """Simulation settings."""

    backend: dict[str, Any] = Field(
        default_factory=lambda: {"type": "native2d"}, description="{type: backend name, ...params}"
    )
    dt: float = Field(0.1, gt=0, le=1.0, description="s, simulation and control period")


class OutputConfig(_Strict):
    """Where and what to write."""

    dir: Path | None = Field(None, description="output folder; default runs/<timestamp>")
    video: bool = Field(True, description="write a video per episode")
    video_format: Literal["mp4", "gif"] = "mp4"
    video_episodes: int = Field(3, ge=0, description="write videos for the first N episodes only")
    frame_every: int = Field(1, ge=1, description="render every N-th simulation step")
    width_px: int = Field(800, ge=200, le=4000, description="video frame width")
    video_3d: Literal["auto", "none", "chase", "overview"] = Field(
        "auto", description="a 3-D video per episode too (needs arena[3d]): chase camera behind "
        "robot 0 or overview of the map; auto = chase on the mujoco backend, else none",
    )
    video_3d_size: tuple[int, int] = Field(
        (640, 480), description="px, width and height of the 3-D video (even, 64..1920)"
    )

    @field_validator("video_3d_size")
    @classmethod
    def _even_size(cls, v: tuple[int, int]) -> tuple[int, int]:
        if not all(64 <= n <= 1920 and n % 2 == 0 for n in v):
            raise ValueError(f"expected two even sizes in 64..1920 px, got {list(v)}")
        return v

    def camera_3d(self, backend: str) -> Literal["chase", "overview"] | None:
        """The 3-D video's camera for a run on ``backend`` (``None``: no 3-D video)."""
        if not self.video or self.video_3d == "none":
            return None
        if self.video_3d == "auto":
            return "chase" if backend == "mujoco" else None
        return self.video_3d


class EvaluationConfig(_Strict):
    """What is recorded with each episode besides the simulated steps."""

    counterfactual: bool = Field(
        True,
        description="replay the crowd without the robot (same seed) so that the cf_* metrics "
        "measure how far the robot displaced people; one crowd-only simulation per episode",
    )


class ExperimentConfig(_Strict):
    """One experiment: a robot, a map, a task, a crowd, a navigation stack, a simulator."""

    name: SafeLabel = Field(
        "default",
        description=f"label for outputs, part of the run folder's name: {RULE} "
        "('/' separates sub-folders)",
    )
    seed: Seed = Field(
        0, description="master seed: every random draw derives from it; an int in [0, 2**63)"
    )
    episodes: StrictInt = Field(1, ge=1, description="number of episodes")
    robot: str = Field("jackal", description="robot preset name or path to a robot YAML")
    map: dict[str, Any] = Field(
        default_factory=lambda: {"type": "world", "name": "small_office"},
        description="{type: map source, ...params}",
    )
    task: TaskConfig = Field(default_factory=TaskConfig)
    crowd: dict[str, Any] = Field(
        default_factory=lambda: {"type": "pysocial"}, description="{type: crowd model, ...}"
    )
    pedestrians: PedestrianConfig = Field(default_factory=PedestrianConfig)
    navigation: NavigationConfig = Field(default_factory=NavigationConfig)
    sim: SimConfig = Field(default_factory=SimConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)
    evaluation: EvaluationConfig = Field(default_factory=EvaluationConfig)
    learning: LearningConfig = Field(
        default_factory=LearningConfig, description="RL environments (arena.learn)"
    )

    @model_validator(mode="before")
    @classmethod
    def _finite(cls, data: Any) -> Any:
        found = non_finite_key(data)
        if found is not None:
            raise ValueError(f"{found[0]}: must be a finite number, got {found[1]}")
        return data
