"""The simulation side shared by the single- and multi-robot environments.

:class:`EpisodeDriver` owns a task generator, a backend and the per-robot bookkeeping (laser
stacks, last commands, goal distances) of ``r`` robots in one world, and turns each step into
the arrays of :class:`~arena.learn.observations.ObsInput` and
:class:`~arena.learn.rewards.RewardInput` with the robots on the leading axis.

Episode ``i`` of seed ``s`` is the generator's episode ``i`` for ``cfg.seed = s``; the backend
draws from ``derive_rng(s, "episode", i, "sim")``, as ``arena run`` does, so an RL episode and
a benchmark episode with the same seed and index share map, starts, goals and crowd.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

import arena.plugins  # noqa: F401  (fills the registries)
from arena.config.loader import load_config
from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.core.types import Outcome
from arena.crowd.simulator import CrowdSimulator
from arena.learn.actions import ActionDecoder
from arena.learn.config import EnvConfig
from arena.learn.observations import Obs, ObservationBuilder, ObsInput
from arena.learn.rewards import DoneReason, RewardFunction, RewardInput, RewardOutput
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.sim.backend import BACKENDS, SimulatorBackend
from arena.sim.state import SimState
from arena.tasks.episode import Episode
from arena.tasks.generator import TaskGenerator

FloatArray = NDArray[np.float64]

ConfigLike = ExperimentConfig | str | Path | None


def resolve_config(config: ConfigLike, overrides: Sequence[str] = ()) -> ExperimentConfig:
    """An :class:`ExperimentConfig` from a config, a YAML path (+ overrides) or ``None``."""
    if isinstance(config, ExperimentConfig):
        if overrides:
            raise ValueError("overrides apply to a YAML path, not to a built config")
        return config
    return load_config(config, overrides)


def substeps(env: EnvConfig, dt: float) -> int:
    """Simulation steps per env step; ``action_period`` must be a multiple of ``dt``."""
    if env.action_period is None:
        return 1
    k = env.action_period / dt
    if round(k) < 1 or abs(k - round(k)) > 1e-6:
        raise ConfigError(
            f"{env.action_period} s is not a positive multiple of sim.dt = {dt} s",
            path="learning.env.action_period",
        )
    return round(k)


@dataclass(frozen=True, eq=False)
class StepResult:
    """One env step for ``r`` robots: observation, reward output and status flags ``(r,)``."""

    obs: Obs
    reward: RewardOutput
    goal_reached: NDArray[np.bool_]
    collision: NDArray[np.bool_]
    terminated: NDArray[np.bool_]
    truncated: NDArray[np.bool_]
    goal_distance: FloatArray
    outcomes: list[str | None]


class EpisodeDriver:
    """``r`` robots of one model in one world, stepped together.

    Args:
        cfg: the experiment (``learning.env`` configures observation, action and reward).
        robot: the robot model (default: ``cfg.robot``).
        n_robots: robots in the world (the task's robot mode places each).
    """

    def __init__(
        self, cfg: ExperimentConfig, robot: RobotModel | None = None, n_robots: int = 1
    ) -> None:
        self.cfg = cfg
        self.env_cfg = cfg.learning.env
        self.robot = robot if robot is not None else load_robot(cfg.robot)
        self.n_robots = int(n_robots)
        self.dt = float(cfg.sim.dt)
        self.substeps = substeps(self.env_cfg, self.dt)
        self.period = self.dt * self.substeps
        self.obs_builder = ObservationBuilder(self.env_cfg.observation, self.robot)
        self.decoder = ActionDecoder(self.env_cfg.action, self.robot)
        self.reward_fn = RewardFunction(self.env_cfg.reward)
        self.backend: SimulatorBackend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
        self.seed = cfg.seed
        self.generator = self._generator(self.seed)
        self.next_index = 0
        self.episode: Episode | None = None
        self.state: SimState | None = None
        self.steps = 0
        r = self.n_robots
        self.scans = np.zeros((r, self.env_cfg.observation.laser_stack, self.obs_builder.beams))
        self.last_action = np.zeros((r, 3))
        self.goals = np.zeros((r, 3))
        self.active = np.ones(r, dtype=bool)
        self.radius = float(self.robot.radius)

    def _generator(self, seed: int) -> TaskGenerator:
        cfg = self.cfg.model_copy(update={"seed": int(seed)})
        return TaskGenerator.from_config(cfg, [self.robot] * self.n_robots)

    # -- episodes ---------------------------------------------------------------------------
    def reset(self, seed: int | None = None, index: int | None = None) -> Obs:
        """Start the next episode (episode 0 of ``seed`` when a seed is given)."""
        if seed is not None:
            if seed != self.seed:
                self.seed = int(seed)
                self.generator = self._generator(self.seed)
            self.next_index = 0
        if index is not None:
            self.next_index = int(index)
        idx = self.next_index
        self.next_index += 1
        ep = self.generator.episode(idx)
        self.episode = ep
        crowd = CrowdSimulator.build(self.cfg.crowd, self.cfg.pedestrians)
        self.state = self.backend.reset(ep, crowd, derive_rng(self.seed, "episode", idx, "sim"))
        self.steps = 0
        self.goals = np.array([s.goal.as_array() for s in ep.robots])
        self.last_action[:] = 0.0
        self.active[:] = True
        self.scans[:] = np.stack(self.state.robots.scans)[:, None, :]
        self._renderer: Any = None  # drawn lazily, once per episode (the world changes)
        return self.obs_builder.build(self._obs_input())

    def _peds(self) -> tuple[FloatArray, FloatArray, Any, Any, Any]:
        assert self.state is not None
        a = self.state.agents
        r = self.n_robots
        m = len(a)
        return (
            np.broadcast_to(a.positions, (r, m, 2)),
            np.broadcast_to(a.velocities, (r, m, 2)),
            np.broadcast_to(a.kinds, (r, m)),
            np.broadcast_to(a.states, (r, m)),
            np.ones((r, m), dtype=bool),
        )

    def _obs_input(self) -> ObsInput:
        assert self.state is not None
        pos, vel, kind, st, mask = self._peds()
        rs = self.state.robots
        return ObsInput(
            poses=rs.poses, twists=rs.twists, goals=self.goals[:, :2], scans=self.scans,
            last_action=self.last_action, ped_pos=pos, ped_vel=vel, ped_kind=kind,
            ped_state=st, ped_mask=mask,
        )

    def goal_distance(self) -> FloatArray:
        """``(r,)`` m from each robot to its goal."""
        assert self.state is not None
        d = self.goals[:, :2] - self.state.robots.poses[:, :2]
        return np.hypot(d[:, 0], d[:, 1])

    def step(self, actions: Any) -> StepResult:
        """Apply one action per robot (``(r,)`` indices or ``(r, d)``) for one action period.

        Robots no longer :attr:`active` (done in the multi-robot env) get a zero command.
        """
        assert self.state is not None
        assert self.episode is not None
        cmd = self.decoder.decode(actions)
        cmd[~self.active] = 0.0
        prev_pose = self.state.robots.poses.copy()
        prev_dist = self.goal_distance()
        collision = np.zeros(self.n_robots, dtype=bool)
        for _ in range(self.substeps):
            self.state = self.backend.step(cmd, self.dt)
            collision |= self.state.collisions.any
        self.steps += 1
        scans = np.stack(self.state.robots.scans)
        self.scans = np.concatenate([self.scans[:, 1:], scans[:, None, :]], axis=1)
        dist = self.goal_distance()
        goal_reached = dist < self.episode.goal_radius
        r = self.n_robots
        pos, _, kind, _, mask = self._peds()
        ped_d = np.hypot(*(pos - self.state.robots.poses[:, None, :2]).transpose(2, 0, 1))
        inp = RewardInput(
            action=cmd,
            prev_action=self.last_action.copy(),
            goal_distance=dist,
            prev_goal_distance=prev_dist,
            goal_jump=np.zeros(r),
            goal_radius=np.full(r, self.episode.goal_radius),
            goal_reached=goal_reached,
            min_range=scans.min(axis=1) if scans.shape[1] else np.full(r, np.inf),
            robot_radius=np.full(r, self.radius),
            safe_dist=np.full(r, self.radius + self.env_cfg.safety_distance),
            collision=collision,
            heading=self.state.robots.poses[:, 2].copy(),
            prev_heading=prev_pose[:, 2],
            dt=np.full(r, self.period),
            step=np.full(r, self.steps, dtype=np.int64),
            max_steps=np.full(r, self.env_cfg.max_steps, dtype=np.int64),
            ped_distance=ped_d,
            ped_kind=np.asarray(kind, dtype=np.int64),
            ped_mask=np.asarray(mask),
        )
        out = self.reward_fn(inp)
        self.last_action = cmd
        term_reason = (out.reason == DoneReason.SUCCESS) | (out.reason == DoneReason.COLLISION)
        terminated = goal_reached | collision | (out.done & term_reason)
        limit = (self.steps >= self.env_cfg.max_steps) or (
            self.state.time >= self.episode.time_limit - 1e-9
        )
        truncated = ~terminated & (limit | (out.done & ~term_reason))
        outcomes: list[str | None] = []
        for i in range(r):
            if collision[i] or out.reason[i] == DoneReason.COLLISION:
                outcomes.append(Outcome.COLLISION.value)
            elif terminated[i]:
                outcomes.append(Outcome.SUCCESS.value)
            elif truncated[i]:
                outcomes.append(Outcome.TIMEOUT.value)
            else:
                outcomes.append(None)
        obs = self.obs_builder.build(self._obs_input())
        return StepResult(obs, out, goal_reached, collision, terminated, truncated, dist, outcomes)

    # -- rendering --------------------------------------------------------------------------
    def render(self, width_px: int | None = None) -> NDArray[np.uint8]:
        """An RGB frame ``(H, W, 3)`` of the current state (goals drawn)."""
        from arena.render import FrameRenderer, Overlay

        assert self.state is not None
        if getattr(self, "_renderer", None) is None:
            self._renderer = FrameRenderer(
                self.backend.world,
                lidar_specs=[self.robot.laser] * self.n_robots,
                width_px=width_px or self.cfg.output.width_px,
                show_trails=False,
            )
        text = f"t = {self.state.time:5.1f} s   step {self.steps}"
        return self._renderer.render(self.state, Overlay(goals=self.goals, text=text))

    def info(self, i: int = 0) -> dict[str, Any]:
        """Status of robot ``i``: episode index, time (s), steps, goal distance (m)."""
        assert self.state is not None
        assert self.episode is not None
        return {
            "episode": self.episode.index,
            "time": float(self.state.time),
            "steps": self.steps,
            "goal_distance": float(self.goal_distance()[i]),
            "goal_radius": float(self.episode.goal_radius),
        }


def action_period_fps(period: float) -> float:
    """Frames per second of a rendering at one frame per env step."""
    return 1.0 / period if period > 0 and math.isfinite(period) else 10.0
