"""Stable-Baselines3 ``VecEnv`` over a :class:`~arena.learn.batched.BatchedSocialNavEnv`.

Defined only when stable-baselines3 is importable (``HAVE_SB3``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode

from arena.core.types import Outcome
from arena.learn.batched import BatchedSocialNavEnv
from arena.learn.driver import ConfigLike
from arena.robots.model import RobotModel
from arena.sim.engine import EngineParams

_SUCCESS = Outcome.SUCCESS.value

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv as _SB3VecEnv

    HAVE_SB3 = True
except ImportError:  # pragma: no cover - optional dependency
    HAVE_SB3 = False


if HAVE_SB3:

    class SB3VecEnv(_SB3VecEnv):
        """Stable-Baselines3 ``VecEnv`` over a :class:`BatchedSocialNavEnv` (``SAME_STEP``).

        SB3 conventions: ``reset()`` returns observations only; ``step_wait()`` returns
        ``(obs, rewards, dones, infos)`` with a list of per-world info dicts; a finished world is
        reset in the same step, its last observation in ``infos[i]["terminal_observation"]``
        and ``infos[i]["TimeLimit.truncated"]`` set on truncation. ``seed(s)`` applies at the
        next ``reset()``.

        Args:
            config, overrides, num_envs, robot, sim_params, prefetch: as
                :class:`BatchedSocialNavEnv`.
        """

        def __init__(
            self,
            config: ConfigLike = None,
            overrides: Sequence[str] = (),
            *,
            num_envs: int = 1,
            robot: RobotModel | None = None,
            sim_params: EngineParams | None = None,
            prefetch: int = 0,
        ) -> None:
            self.env = BatchedSocialNavEnv(
                config, overrides, num_envs=num_envs, robot=robot, sim_params=sim_params,
                autoreset_mode=AutoresetMode.SAME_STEP, prefetch=prefetch,
            )
            super().__init__(
                num_envs, self.env.single_observation_space, self.env.single_action_space
            )
            self._actions: Any = None

        def reset(self) -> Any:
            """Restart every world (with the seed given to :meth:`seed`, if any)."""
            seed = self._seeds[0] if self._seeds else None
            obs, _ = self.env.reset(seed=seed)
            self._reset_seeds()
            self._reset_options()
            return obs

        def step_async(self, actions: np.ndarray) -> None:
            """Remember the actions of the next :meth:`step_wait`."""
            self._actions = actions

        def step_wait(self) -> Any:
            """One batched step; finished worlds restart at once (SB3 convention)."""
            obs, rew, term, trunc, info = self.env.step(self._actions)
            done = term | trunc
            n = self.num_envs
            infos: list[dict[str, Any]] = [{} for _ in range(n)]
            src = info.get("final_info", info)
            for i in range(n):
                d = infos[i]
                s = src if done[i] else info
                for k in ("episode_index", "time", "steps", "goal_distance", "outcome",
                          "collision"):
                    if k in s:
                        v = s[k][i]
                        d[k] = v.item() if isinstance(v, np.generic) else v
                d["is_success"] = d.get("outcome") == _SUCCESS
                if done[i]:
                    d["terminal_observation"] = info["final_obs"][i]
                    d["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
            return obs, rew.astype(np.float32), done, infos

        def close(self) -> None:
            """Close the batched env."""
            self.env.close()

        def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
            """The batched env's attribute, once per requested world."""
            return [getattr(self.env, attr_name) for _ in self._get_indices(indices)]

        def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
            """Set an attribute of the batched env (shared by every world)."""
            setattr(self.env, attr_name, value)

        def env_method(
            self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
        ) -> list[Any]:
            """Call a method of the batched env, once per requested world."""
            fn = getattr(self.env, method_name)
            return [fn(*method_args, **method_kwargs) for _ in self._get_indices(indices)]

        def env_is_wrapped(self, wrapper_class: Any, indices: Any = None) -> list[bool]:
            """No world is wrapped."""
            return [False for _ in self._get_indices(indices)]
