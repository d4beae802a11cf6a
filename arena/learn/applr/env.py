"""``ApplrEnv``: choosing DWA's parameters once per period, as a Gymnasium environment.

Description:
    APPLR's training task (Xu et al. 2021): a robot crosses a cluttered map with the navigation
    stack (A* global path, replanning, recovery) and our DWA as the local planner; the agent
    does not drive, it sets DWA's parameters once per ``period``. Episodes are the benchmark's:
    the task generator draws them from the config (default
    ``arena/learn/data/train/applr.yaml``: generated ``barn`` maps, a new map per episode) and
    :class:`~arena.episode.runner.EpisodeRunner` runs them with the same
    :class:`~arena.episode.navigation.NavigationController` as ``arena bench``; only the local
    planner is the env's :class:`~arena.learn.applr.tuned_dwa.TunedDWA`. Unlike a benchmark
    episode, one ends at the first contact (APPLR's training episodes do).

Action Space:
    ``Box(-1, 1, (9,))``: the tuned parameters, mapped by
    :func:`~arena.learn.applr.space.parameter_values` (``0`` = DWA's defaults).

Observation Space:
    ``Box(-1, 1, (B + 2 + 9,))`` float32, :func:`~arena.learn.applr.space.observation` of the
    last control cycle's observation with the action in force.

Rewards:
    Per step, after APPLR: ``progress ×`` the decrease of the straight-line distance to the goal
    (m), ``- time`` (a constant per step, so that dawdling costs), ``+ success`` on arrival and
    ``- collision`` on a contact.

Starting State:
    The episode's start at rest; one control cycle with DWA's defaults has run (the planner's
    first cycle, :class:`~arena.learn.planners.applr.ApplrPlanner`).

Episode End:
    Terminated on arrival (the task's goal check) or at the first contact; truncated at the
    task's timeout, when the stack gives up (``stuck``) or the task aborts.
    ``info["outcome"]`` is the :class:`~arena.core.types.Outcome` value at the end.

Arguments:
    config: an :class:`~arena.config.schema.ExperimentConfig`, a YAML path or ``None`` (the
        packaged training config); ``overrides`` (``key.path=value``) apply to a path.
    period: s per step, a multiple of ``sim.dt`` (APPLR: 1 s).
    beams: beams of the policy's scan, spread over the robot's laser.
    reward: :class:`ApplrReward` weights.

Each step steps the runner ``period / dt`` cycles; the parameters of a step are applied
before its first cycle, exactly when the deployed planner applies them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

import arena.plugins  # noqa: F401  (fills the registries)
from arena.core.errors import ArenaError, ConfigError
from arena.core.types import Outcome
from arena.crowd.driver import build_driver
from arena.episode.navigation import NavigationController, build_stack
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.learn.applr.space import PARAMETERS, FeatureSpec, observation, spread_beams
from arena.learn.applr.tuned_dwa import TunedDWA
from arena.learn.keywords import ConfigLike, resolve_config
from arena.robots.presets import load_robot
from arena.sim.backend import BACKENDS
from arena.tasks.generator import TaskGenerator

TRAIN_CONFIG = Path(__file__).resolve().parents[1] / "data" / "train" / "applr.yaml"
"""The packaged training config (``arena/learn/data/train/applr.yaml``)."""


class ApplrReward(BaseModel):
    """Reward weights of :class:`ApplrEnv` (APPLR's terms)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    progress: float = Field(1.0, ge=0, description="1/m, per metre closer to the goal")
    time: float = Field(0.5, ge=0, description="per step (a period)")
    success: float = Field(20.0, ge=0, description="on arrival")
    collision: float = Field(20.0, ge=0, description="on the first contact (ends the episode)")


class _EndOnContact(EpisodeHooks):
    """Ends the episode at robot 0's first contact."""

    def after_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        if bool(runner.state.collisions.any[0]):
            runner.end(Outcome.COLLISION)


class ApplrEnv(gym.Env[NDArray[np.float32], NDArray[np.float32]]):
    """One robot, DWA driving, the agent setting its parameters; see the module docstring."""

    def __init__(
        self,
        config: ConfigLike = None,
        overrides: Sequence[str] = (),
        *,
        period: float = 1.0,
        beams: int = 72,
        reward: ApplrReward | None = None,
    ) -> None:
        self.cfg = resolve_config(config if config is not None else TRAIN_CONFIG, overrides,
                                  owner=type(self).__name__)
        dt = float(self.cfg.sim.dt)
        k = period / dt
        if round(k) < 1 or abs(k - round(k)) > 1e-6:
            raise ConfigError(f"ApplrEnv: period {period} s is not a positive multiple of "
                              f"sim.dt = {dt} s")
        self.period = float(period)
        self.reward_weights = reward if reward is not None else ApplrReward()
        robot = load_robot(self.cfg.robot)
        laser = robot.lidar(self.cfg.navigation.scan_sensor, path="navigation.scan_sensor")
        angles = np.asarray(laser.angles(), dtype=np.float64) + float(laser.mount[2])
        self.features = FeatureSpec(spread_beams(angles[0], angles[-1], beams))
        self.tuned = TunedDWA(params=PARAMETERS)
        self.backend = BACKENDS.build(self.cfg.sim.backend, path="sim.backend")
        n = self.features.size(len(PARAMETERS))
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (n,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (len(PARAMETERS),), np.float32)
        self.seed_ = int(self.cfg.seed)
        self.generator = TaskGenerator.from_config(self.cfg)
        self.next_index = 0
        self.runner: EpisodeRunner | None = None
        self._goal = np.zeros(2)

    # -- episodes ---------------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start the next episode; ``seed`` restarts at episode 0 of that seed.

        ``options={"episode": i}`` picks episode ``i`` of the current seed.
        """
        super().reset(seed=seed)
        if seed is not None:
            if int(seed) != self.seed_:
                self.seed_ = int(seed)
                self.generator = TaskGenerator.from_config(
                    self.cfg.model_copy(update={"seed": self.seed_}))
            self.next_index = 0
        index = (options or {}).get("episode")
        if index is not None:
            self.next_index = int(index)
        episode = self.generator.episode(self.next_index)
        self.next_index += 1
        robot = episode.robots[0].model
        stack = build_stack(self.cfg.navigation, robot, episode, local_planner=self.tuned)
        nav = NavigationController(stack, self.generator.runtime(episode), robot,
                                   self.cfg.navigation.scan_sensor)
        self.runner = EpisodeRunner(self.backend, self.cfg.sim.dt, [nav, _EndOnContact()], nav)
        self.runner.reset(episode, build_driver(self.cfg.crowd, self.cfg.pedestrians),
                          self.seed_)
        self._goal = episode.robots[0].goal.xy.copy()
        self.runner.tick()  # the planner's first cycle: DWA's defaults
        self._raise_bug()
        return self._observe(), {"episode_index": episode.index, "outcome": None}

    def step(
        self, action: NDArray[Any]
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        """Apply ``action`` and run the control cycles of one period."""
        runner = self.runner
        if runner is None:
            raise RuntimeError("call reset() before step()")
        values = self.tuned.set_action(np.asarray(action, dtype=np.float64))
        d0 = self._goal_distance()
        assert runner.state is not None
        end = float(runner.state.time) + self.period - 1e-9
        while runner.running and float(runner.state.time) < end:
            runner.tick()
        self._raise_bug()
        d1 = self._goal_distance()
        w = self.reward_weights
        reward = w.progress * (d0 - d1) - w.time
        outcome = runner.outcome
        terminated = outcome in (Outcome.SUCCESS, Outcome.COLLISION)
        truncated = outcome is not None and not terminated
        if outcome is Outcome.SUCCESS:
            reward += w.success
        elif outcome is Outcome.COLLISION:
            reward -= w.collision
        info = {
            "outcome": outcome.value if outcome is not None else None,
            "is_success": outcome is Outcome.SUCCESS,
            "parameters": values,
            "time": float(runner.state.time),
        }
        return self._observe(), float(reward), terminated, truncated, info

    # -- internals ----------------------------------------------------------------------------
    def _observe(self) -> NDArray[np.float32]:
        last = self.tuned.last_obs
        if last is None:  # the episode ended before the first cycle (an aborted task)
            return np.zeros(self.features.size(len(PARAMETERS)), dtype=np.float32)
        return np.clip(observation(last, self.tuned.action, self.features), -1.0, 1.0)

    def _goal_distance(self) -> float:
        assert self.runner is not None
        assert self.runner.state is not None
        p = self.runner.state.robots.poses[0, :2]
        return math.hypot(float(p[0] - self._goal[0]), float(p[1] - self._goal[1]))

    def _raise_bug(self) -> None:
        """A non-Arena exception inside the episode is a bug: raise it, do not train on it."""
        assert self.runner is not None
        e = self.runner.exception
        if e is not None and not isinstance(e, ArenaError):
            raise e
