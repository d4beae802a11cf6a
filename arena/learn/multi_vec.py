"""Multi-robot PPO with shared parameters: a Stable-Baselines3 ``VecEnv`` over robot slots.

:class:`MultiRobotVecEnv` runs ``len(robots_per_world)`` :class:`~arena.learn.multi.MultiRobotEnv`
worlds in-process; every robot of every world is one slot of the vector env, so one PPO policy
acts for all of them, each robot from its own observation (Long et al. 2018's decentralised,
parameter-shared training). Slots are ordered world by world, robot by robot.

Episode ends: SB3 needs every slot to step every step, while in
:class:`~arena.learn.multi.MultiRobotEnv` a robot that is done (goal, collision) parks where it
stands until the others finish. A parked robot's slot would feed PPO transitions its actions
do not influence, so a finished robot's slot must restart at once, in one of two ways:

* ``respawn=True`` (Long et al.'s training): the finished robot gets a new start and goal in
  the running world (:meth:`~arena.learn.driver.EpisodeDriver.respawn`) while the others
  drive on; its slot reports ``done`` and continues with the new start's observation. Only the
  world's time limit (``task.timeout``) restarts the whole world. A robot's own episode ends at
  arrival, contact or ``max_steps`` of its own. Should no start/goal pair be found (a crowded
  map), the world restarts as below.
* ``respawn=False``: the first robot to finish ends its world's episode: the finished robots
  report ``done`` as terminated, the others as truncated, and the world restarts with its next
  episode; the cut robots' ``info["outcome"]`` reads ``"cut"``.

Either way a slot that ends without terminating is truncated (``TimeLimit.truncated``, so PPO
bootstraps its value from ``terminal_observation``) and the restart happens in the same step
(SB3's autoreset convention). Each ending slot's info carries SB3's ``episode`` record (return,
length) and ``is_success``.

The robots of one world are obstacles to each other: native2d's lidar sees the other robots'
footprints and its contacts include robot-robot collisions.

Seeding: ``seed(s)`` makes world ``k`` replay seed ``s + k`` from episode 0 at the next
:meth:`reset`; same seed and actions → same rollout.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from arena.config.schema import ExperimentConfig
from arena.core.types import Outcome
from arena.learn.multi import MultiRobotEnv
from arena.robots.model import RobotModel
from arena.tasks.modules.staged import Staged
from arena.tasks.robot_modes.random import RandomRobots


class MultiRobotVecEnv(VecEnv):
    """One SB3 slot per robot of several :class:`MultiRobotEnv` worlds; see the module docstring.

    Args:
        config: the experiment (``learning.env`` configures each robot's observation/reward).
        robots_per_world: robots in each world, e.g. ``[2, 3, 4]`` (9 slots).
        robot: a robot model replacing ``cfg.robot``.
        respawn: finished robots restart in the running world (module docstring); the start
            and goal keep the ``task.robots`` mode's ``min_goal_distance`` and ``clearance``
            (``robots.random``'s defaults for modes without them).
    """

    def __init__(
        self,
        config: ExperimentConfig,
        robots_per_world: Sequence[int],
        robot: RobotModel | None = None,
        respawn: bool = False,
    ) -> None:
        if not robots_per_world or any(int(r) < 1 for r in robots_per_world):
            raise ValueError("robots_per_world needs at least one world of >= 1 robots")
        self.worlds = [MultiRobotEnv(config, n_robots=int(r), robot=robot)
                       for r in robots_per_world]
        # slot range of each world
        ends = np.cumsum([int(r) for r in robots_per_world])
        self.slices = [slice(int(e - r), int(e)) for e, r in zip(ends, robots_per_world,
                                                                  strict=True)]
        first = self.worlds[0]
        agent = first.possible_agents[0]
        self.render_mode: str | None = None  # read back by VecEnv.__init__
        super().__init__(int(ends[-1]), first.observation_space(agent), first.action_space(agent))
        self.keys = tuple(first.driver.obs_builder.keys)
        self.respawn = bool(respawn)
        params = getattr(first.driver.generator.robot_mode, "params", None)
        defaults = RandomRobots.Params()
        self._min_goal = float(getattr(params, "min_goal_distance", defaults.min_goal_distance))
        self._clearance = float(getattr(params, "clearance", defaults.clearance))
        self._world_seeds: list[int | None] = [None] * len(self.worlds)
        self._actions: NDArray[Any] | None = None
        self._obs: list[dict[str, Any]] = [{} for _ in self.worlds]
        self._ret = np.zeros(self.num_envs)
        self._len = np.zeros(self.num_envs, dtype=np.int64)
        self._t0 = time.perf_counter()

    # -- VecEnv API -----------------------------------------------------------------------------
    def seed(self, seed: int | None = None) -> Sequence[int | None]:
        """World ``k`` restarts at episode 0 of ``seed + k`` at the next :meth:`reset`."""
        if seed is None:
            return list(self._world_seeds)
        self._world_seeds = [int(seed) + k for k in range(len(self.worlds))]
        return list(self._world_seeds)

    def reset(self) -> Any:
        """Restart every world; returns the stacked observations of all slots."""
        for k, env in enumerate(self.worlds):
            self._obs[k], _ = env.reset(seed=self._world_seeds[k])
        self._world_seeds = [None] * len(self.worlds)
        self._ret[:] = 0.0
        self._len[:] = 0
        return self._stack()

    def step_async(self, actions: NDArray[Any]) -> None:
        """Remember the ``(num_envs, ...)`` actions of the next :meth:`step_wait`."""
        self._actions = np.asarray(actions)

    def step_wait(self) -> Any:
        """Step every world; a world whose first robot finished restarts (module docstring)."""
        assert self._actions is not None, "step_async first"
        rewards = np.zeros(self.num_envs, np.float32)
        dones = np.zeros(self.num_envs, dtype=bool)
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for k, (env, sl) in enumerate(zip(self.worlds, self.slices, strict=True)):
            agents = env.possible_agents
            acts = {a: self._actions[sl.start + i] for i, a in enumerate(agents)}
            obs, rew, term, trunc, info = env.step(acts)
            finished = [a for a in agents if term[a] or trunc[a]]
            respawned: dict[str, Any] = {}
            if self.respawn and finished and len(finished) < len(agents):
                for a in finished:
                    first_obs = env.respawn(a, self._min_goal, self._clearance)
                    if first_obs is None:
                        respawned = {}  # no room: restart the world instead
                        break
                    respawned[a] = first_obs
            ended = bool(finished) and not respawned
            for i, a in enumerate(agents):
                j = sl.start + i
                rewards[j] = rew[a]
                self._ret[j] += rew[a]
                self._len[j] += 1
                d = infos[j]
                d.update(info[a])
                d["is_success"] = info[a]["outcome"] == Outcome.SUCCESS.value
                if ended or a in respawned:
                    dones[j] = True
                    d["terminal_observation"] = obs[a]
                    d["TimeLimit.truncated"] = not term[a]
                    if not (term[a] or trunc[a]):
                        d["outcome"] = "cut"  # another robot of the world finished first
                    d["episode"] = {"r": float(self._ret[j]), "l": int(self._len[j]),
                                    "t": round(time.perf_counter() - self._t0, 6)}
                    self._ret[j] = 0.0
                    self._len[j] = 0
            if ended:
                obs, _ = env.reset()
            elif respawned:
                # the others' observations now show the respawned robots where they stand
                full = env.driver.observe()
                obs = {a: env.driver.obs_builder.single(full, i) for i, a in enumerate(agents)}
            self._obs[k] = obs
        return self._stack(), rewards, dones, infos

    def _stack(self) -> Any:
        rows: list[Any] = []
        for env, obs in zip(self.worlds, self._obs, strict=True):
            rows.extend(obs[a] for a in env.possible_agents)
        if isinstance(rows[0], dict):
            return {k: np.stack([r[k] for r in rows]) for k in self.keys}
        return np.stack(rows)

    def close(self) -> None:
        """Close the worlds."""
        for env in self.worlds:
            env.close()

    # -- curriculum and SB3 plumbing ------------------------------------------------------------
    def _staged(self, k: int) -> list[Staged]:
        return [m for m in self.worlds[k].driver.generator.modules if isinstance(m, Staged)]

    def set_stage(self, index: int) -> int:
        """Move every world's staged modules to ``index``; return the stage (-1: none)."""
        stages = [m.set_stage(index) for k in range(len(self.worlds)) for m in self._staged(k)]
        return stages[0] if stages else -1

    def get_stage(self) -> int:
        """The current curriculum stage (-1 without a staged module)."""
        mods = self._staged(0)
        return mods[0].stage if mods else -1

    def _slots(self, indices: Any) -> list[int]:
        return list(self._get_indices(indices))

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """The adapter's attribute, once per requested slot."""
        return [getattr(self, attr_name) for _ in self._slots(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        """Set an attribute of the adapter (shared by every slot)."""
        setattr(self, attr_name, value)

    def env_method(
        self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
    ) -> list[Any]:
        """Call an adapter method (``set_stage``, ``get_stage``) once; one result per slot."""
        result = getattr(self, method_name)(*method_args, **method_kwargs)
        return [result for _ in self._slots(indices)]

    def env_is_wrapped(self, wrapper_class: Any, indices: Any = None) -> list[bool]:
        """No slot is wrapped."""
        return [False for _ in self._slots(indices)]
