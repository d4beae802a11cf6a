"""``modules.benchmark``: play a benchmark suite's stages one after another (specs §2.9).

The run's episode ``i`` is episode ``k`` of stage ``s`` (stages in order, each with
``int(episodes × scale_episodes)`` episodes). Before the reset the module puts the stage's map,
robot, task modes, time limit and goal radius into the context, numbers the episode ``k`` and
seeds it from the run seed and the stage seed (:func:`~arena.tasks.suite.stage_run_seed`), so
episode ``k`` of a stage is the same whatever stages come before it, and equal to episode ``k``
of the stage's own experiment (:meth:`~arena.tasks.suite.Suite.stage_experiments`). Arena
relaunches the simulation per stage; here the stage's modes are built once and reused.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from arena.config.schema import ExperimentConfig
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.tasks.base import ModuleBase, ResetContext, build_mode, register_mode
from arena.tasks.config import TaskConfig
from arena.tasks.obstacle_modes.random import RandomObstacles
from arena.tasks.suite import Suite, load_suite


@dataclass
class _Stage:
    """A stage ready to reset episodes: its experiment and built modes."""

    cfg: ExperimentConfig
    robots: list[RobotModel] | None
    robot_mode: Any
    obstacle_mode: Any
    modules: list[Any]


@register_mode("modules", "benchmark")
class Benchmark(ModuleBase):
    """Episodes from a benchmark suite: each stage's map, robot, modes and seed in turn."""

    class Params(BaseModel):
        """Parameters of ``modules.benchmark``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        suite: str = Field("paper", description="packaged suite (paper, quick) or a YAML path")
        scale_episodes: float = Field(
            1.0, gt=0, description="factor on every stage's episodes (Arena: int(n × scale))"
        )
        worlds: str | None = Field(
            None, description="folder of worlds in Arena's layout that the suite's world names "
            "are looked up in first (arena bench --worlds; default: the suite's worlds key)",
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = p = params or self.Params()
        self.suite: Suite = load_suite(p.suite, scale_episodes=p.scale_episodes,
                                       worlds=p.worlds, worlds_option="modules.benchmark.worlds")
        self.num_episodes: int = self.suite.total_episodes
        """Episodes of the whole suite (the run plays exactly these)."""
        self._stages: dict[tuple[int, int], _Stage] = {}

    def stage_of(self, index: int) -> tuple[int, int]:
        """``(stage, local episode)`` of the run's episode ``index``."""
        return self.suite.locate(index)

    def before_reset(self, ctx: ResetContext) -> None:
        """Switch the context to the stage of ``ctx.index``."""
        s, k = self.suite.locate(ctx.index)
        stage = self._stage(s, ctx)
        cfg = stage.cfg
        ctx.index = k
        ctx.seed = cfg.seed
        ctx.map_spec = dict(cfg.map)
        ctx.map_key = 0
        if stage.robots is not None:
            ctx.robots = list(stage.robots)
        ctx.robot_mode = stage.robot_mode
        ctx.obstacle_mode = stage.obstacle_mode
        ctx.timeout = cfg.task.timeout
        ctx.goal_radius = cfg.task.goal_radius
        ctx.goal_tolerance_angle = cfg.task.goal_tolerance_angle
        ctx.forbidden = list(cfg.task.forbidden_zones)
        ctx.label = self.suite.stages[s].name
        for m in stage.modules:
            m.before_reset(ctx)

    def after_reset(self, ctx: ResetContext, episode: Episode) -> Episode:
        """Let the stage's own modules edit the episode."""
        s, _ = self.suite.locate(episode.index)
        stage = self._stages.get((s, self._run_seed))
        for m in stage.modules if stage else ():
            episode = m.after_reset(ctx, episode)
        return episode

    def on_episode_end(self, index: int, outcome: str) -> None:
        """Forward the outcome (with the stage-local index) to the stage's modules."""
        s, k = self.suite.locate(index)
        stage = self._stages.get((s, self._run_seed))
        for m in stage.modules if stage else ():
            m.on_episode_end(k, outcome)

    _run_seed: int = 0

    def _stage(self, s: int, ctx: ResetContext) -> _Stage:
        """Build stage ``s`` for the run seed in ``ctx`` (once)."""
        self._run_seed = ctx.seed
        key = (s, ctx.seed)
        if key in self._stages:
            return self._stages[key]
        base = self._base_config(ctx)
        exps = dict(zip(
            [i for i, n in enumerate(self.suite.episode_counts) if n > 0],
            self.suite.stage_experiments(base),
            strict=True,
        ))
        src = self.suite.source
        for i, (st, cfg) in exps.items():
            self._stages[(i, ctx.seed)] = _Stage(
                cfg=cfg,
                robots=[load_robot(cfg.robot)] if st.robot is not None else None,
                robot_mode=build_mode("robots", cfg.task.robots, source=src,
                                      path=f"stages[{i}].tm_robots"),
                obstacle_mode=build_mode("obstacles", cfg.task.obstacles, source=src,
                                         path=f"stages[{i}].tm_obstacles"),
                modules=[
                    build_mode("modules", m, source=src, path=f"stages[{i}].task.modules[{j}]")
                    for j, m in enumerate(cfg.task.modules)
                ],
            )
        return self._stages[key]

    @staticmethod
    def _base_config(ctx: ResetContext) -> ExperimentConfig:
        """The run's settings that a stage does not override, read from the context."""
        task: dict[str, Any] = {
            "timeout": ctx.timeout,
            "goal_radius": ctx.goal_radius,
            "goal_tolerance_angle": ctx.goal_tolerance_angle,
        }
        if isinstance(ctx.obstacle_mode, RandomObstacles):
            task["obstacles"] = {"type": "random",
                                 **ctx.obstacle_mode.params.model_dump(mode="json")}
        return ExperimentConfig(
            seed=ctx.seed, map=dict(ctx.map_spec), task=TaskConfig.model_validate(task)
        )
