"""The training environments: SB3 vector envs of :class:`~arena.learn.env.SocialNavEnv`.

Dummy, subprocess, batched or multi-robot; the curriculum stage settable by the trainer.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError
from arena.robots.model import RobotModel


# -- environments -------------------------------------------------------------------------------
def staged_spec(cfg: ExperimentConfig) -> dict[str, Any] | None:
    """The ``staged`` entry of ``task.modules``, if any."""
    for m in cfg.task.modules:
        if isinstance(m, dict) and m.get("type") == "staged":
            return m
    return None


def _stage_env_class() -> type:
    import gymnasium as gym

    from arena.tasks.modules.staged import Staged

    class StagedEnv(gym.Wrapper):  # type: ignore[misc,unused-ignore]
        """Lets the trainer set the curriculum stage of a wrapped :class:`SocialNavEnv`."""

        def __init__(self, env: Any) -> None:
            super().__init__(env)
            self._stage: int | None = None

        def _modules(self) -> list[Staged]:
            driver: Any = self.env.unwrapped.driver
            return [m for m in driver.generator.modules
                    if isinstance(m, Staged)]

        def set_stage(self, index: int) -> int:
            """Move every staged module to ``index`` (clamped); return the stage."""
            self._stage = int(index)
            stages = [m.set_stage(index) for m in self._modules()]
            return stages[0] if stages else -1

        def get_stage(self) -> int:
            """The current stage (-1 without a staged module)."""
            mods = self._modules()
            return mods[0].stage if mods else -1

        def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> Any:
            if seed is not None and self._stage is not None:
                # a seeded reset rebuilds the task generator (back at its start stage)
                self.env.reset(seed=seed)
                self.set_stage(self._stage)
                opts = {"episode": 0, **(options or {})}
                obs, info = self.env.reset(options=opts)
            else:
                obs, info = self.env.reset(seed=seed, options=options)
            return obs, info

        def step(self, action: Any) -> Any:
            obs, reward, terminated, truncated, info = self.env.step(action)
            return obs, reward, terminated, truncated, info

    return StagedEnv


def make_env_fn(cfg: ExperimentConfig, robot: RobotModel | None = None) -> Callable[[], Any]:
    """A thunk building ``Monitor(StagedEnv(SocialNavEnv(cfg, robot)))``."""

    def thunk() -> Any:
        from stable_baselines3.common.monitor import Monitor

        from arena.learn.env import SocialNavEnv

        return Monitor(_stage_env_class()(SocialNavEnv(cfg, robot=robot)))

    return thunk


def make_vec_env(
    cfg: ExperimentConfig,
    n_envs: int,
    kind: str = "dummy",
    robot: RobotModel | None = None,
    seed: int | None = None,
    robots_per_world: Sequence[int] | None = None,
    respawn: bool = False,
    prefetch: int = 0,
) -> Any:
    """``n_envs`` environments in SB3's ``DummyVecEnv`` or ``SubprocVecEnv``.

    Env ``k`` restarts at episode 0 of ``seed + k`` at its next reset when ``seed`` is given.

    ``kind="batched"``: one :class:`~arena.learn.sb3_vec.SB3VecEnv` over a
    :class:`~arena.learn.batched.BatchedSocialNavEnv` of ``n_envs`` worlds (seeded with
    ``seed`` at its next reset when given; ``prefetch`` episodes per world drawn ahead in a
    helper process). ``kind="multi_robot"``: a
    :class:`~arena.learn.multi_vec.MultiRobotVecEnv` with ``robots_per_world`` (summing to
    ``n_envs``; default: one world of ``n_envs`` robots) and ``respawn``.
    """
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    if kind == "multi_robot":
        from arena.learn.multi_vec import MultiRobotVecEnv

        rpw = list(robots_per_world) if robots_per_world is not None else [n_envs]
        if sum(rpw) != n_envs:
            raise ConfigError(f"robots_per_world {rpw} does not sum to n_envs {n_envs}",
                              path="learning.train.robots_per_world")
        mvenv = MultiRobotVecEnv(cfg, rpw, robot=robot, respawn=respawn)
        if seed is not None:
            mvenv.seed(int(seed))
        return mvenv

    if kind == "batched":
        from arena.learn.sb3_vec import SB3VecEnv

        venv = SB3VecEnv(cfg, num_envs=n_envs, robot=robot, prefetch=prefetch)
        if seed is not None:
            venv.seed(int(seed))
        return venv

    fns = [make_env_fn(cfg, robot) for _ in range(n_envs)]
    vec = SubprocVecEnv(fns) if kind == "subproc" and n_envs > 1 else DummyVecEnv(fns)
    if seed is not None:
        # env k restarts at episode 0 of seed + k at its next reset (without this every env
        # would play the config seed's episodes: n copies of the same world)
        vec.seed(int(seed))
    return vec
