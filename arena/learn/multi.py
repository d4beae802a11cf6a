"""Several robots in one world as a PettingZoo ``ParallelEnv``.

Agents ``robot_0 … robot_{n−1}`` share the map, the crowd and the robot model; each has its
own goal (placed by the task's robot mode), observation, action and reward, with the spaces
and terms of :class:`~arena.learn.env.SocialNavEnv`. Other robots are not in the
``pedestrians`` observation (they are seen by the lidar). A robot that is done (goal reached,
collision) leaves :attr:`agents` and stands still where it is for the rest of the episode;
the episode ends when every robot is done or at the step/time limit.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from arena.learn.driver import ConfigLike, EpisodeDriver, action_period_fps, resolve_config
from arena.robots.model import RobotModel


class MultiRobotEnv(ParallelEnv[str, Any, Any]):
    """``n_robots`` robots of one model in one world.

    Args:
        config: experiment config, YAML path or ``None``; ``overrides`` apply to a path.
        n_robots: number of robots (≥ 1).
        robot: a robot model replacing ``cfg.robot``.
        render_mode: ``None`` or ``"rgb_array"``.
    """

    metadata: ClassVar[dict[str, Any]] = {
        "name": "arena_multi_robot_v0", "render_modes": ["rgb_array"], "render_fps": 10,
    }

    def __init__(
        self,
        config: ConfigLike = None,
        overrides: Sequence[str] = (),
        *,
        n_robots: int = 2,
        robot: RobotModel | None = None,
        render_mode: str | None = None,
    ) -> None:
        if n_robots < 1:
            raise ValueError("n_robots must be >= 1")
        self.cfg = resolve_config(config, overrides)
        self.driver = EpisodeDriver(self.cfg, robot, n_robots=n_robots)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": action_period_fps(self.driver.period)}
        self.possible_agents = [f"robot_{i}" for i in range(n_robots)]
        self.agents: list[str] = []
        self._index = {a: i for i, a in enumerate(self.possible_agents)}

    @functools.cache  # noqa: B019  (PettingZoo wants the same object back)
    def observation_space(self, agent: str) -> spaces.Space[Any]:
        """The observation space of ``agent`` (the same for every robot)."""
        return self.driver.obs_builder.space

    @functools.cache  # noqa: B019
    def action_space(self, agent: str) -> spaces.Space[Any]:
        """The action space of ``agent`` (the same for every robot)."""
        return self.driver.decoder.space

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        """Start the next episode (episode 0 of ``seed`` when a seed is given)."""
        obs = self.driver.reset(seed=seed, index=(options or {}).get("episode"))
        self.agents = list(self.possible_agents)
        build = self.driver.obs_builder
        return (
            {a: build.single(obs, i) for i, a in enumerate(self.agents)},
            {a: {**self.driver.info(i), "outcome": None} for i, a in enumerate(self.agents)},
        )

    def step(self, actions: dict[str, Any]) -> tuple[
        dict[str, Any],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        """One action per live agent; done agents get a zero command."""
        d = self.driver
        sample = d.decoder.space.sample() if d.decoder.table is None else 0
        batch = []
        for a in self.possible_agents:
            act = actions.get(a) if a in self.agents else None
            batch.append(np.asarray(sample if act is None else act))
        d.active[:] = [a in self.agents for a in self.possible_agents]
        res = d.step(np.stack(batch))
        obs, rew, term, trunc, info = {}, {}, {}, {}, {}
        for a in self.agents:
            i = self._index[a]
            obs[a] = d.obs_builder.single(res.obs, i)
            rew[a] = float(res.reward.total[i])
            term[a] = bool(res.terminated[i])
            trunc[a] = bool(res.truncated[i])
            info[a] = {
                **d.info(i),
                "outcome": res.outcomes[i],
                "reward_terms": {k: float(v[i]) for k, v in res.reward.terms.items()},
                "collision": bool(res.collision[i]),
            }
        self.agents = [a for a in self.agents if not (term[a] or trunc[a])]
        return obs, rew, term, trunc, info

    def respawn(self, agent: str, min_goal_distance: float, clearance: float) -> Any | None:
        """Bring a done ``agent`` back with a new start and goal (:meth:`EpisodeDriver.respawn`).

        Returns:
            Its first observation, or ``None`` when no start/goal pair was found (it stays
            done).
        """
        i = self._index[agent]
        if not self.driver.respawn(i, min_goal_distance, clearance):
            return None
        if agent not in self.agents:
            self.agents = [a for a in self.possible_agents if a in self.agents or a == agent]
        return self.driver.obs_builder.single(self.driver.observe(), i)

    def render(self) -> Any:
        """An RGB frame in ``rgb_array`` mode, else ``None``."""
        if self.render_mode != "rgb_array" or self.driver.state is None:
            return None
        return self.driver.render()

    def close(self) -> None:
        """Nothing to release."""
