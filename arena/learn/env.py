"""``arena/SocialNav-v0``: one robot crossing a crowd, as a Gymnasium environment.

Description:
    A robot (``cfg.robot``) must reach a goal on the experiment's map among the experiment's
    pedestrians and obstacles, simulated by the native 2-D backend. Episodes come from the
    task generator exactly as in ``arena run`` (same seed and index → same episode).

Action Space:
    ``Discrete(k)`` (the robot's discrete actions or a custom ``n_linear × n_angular`` grid)
    or a ``Box`` of ``[v, ω]`` (``[vx, vy, ω]`` for holonomic robots) in m/s, rad/s; see
    :mod:`arena.learn.actions`. Each action is held for ``action_period`` seconds.

Observation Space:
    A ``Dict`` (or, with ``observation.flatten``, one float32 ``Box``) of ``lidar``, ``goal``,
    ``last_action``, ``pedestrians`` + ``pedestrians_mask`` and ``semantic``; see
    :mod:`arena.learn.observations`. With ``observation.subgoal.enabled`` (Arena's "spacial
    horizon", arena_specs §8.1) ``goal`` is ``[ρ, θ]`` of a subgoal: an A* path is planned at
    reset on the episode's planning grid (map + static obstacles, inflated by the robot radius
    + ``navigation.inflation_margin``), replanned every ``replan_period`` s (1.0) or when the
    robot strays more than ``max_deviation`` m (1.0) from it, and the subgoal is the path point
    ``horizon`` m (5.0) ahead of the robot's projection on it, or the goal when it is closer
    (:func:`~arena.learn.paths.subgoal_on_path`).

Rewards:
    The configured reward terms (:mod:`arena.learn.rewards`), Arena's ``default.yaml`` unless
    ``learning.env.reward`` says otherwise; ``info["reward_terms"]`` has each term's share.
    Distance-based terms (``approach_goal``, ``goal_reached``) always use the final goal, also
    when the observation refers to a subgoal.

Crowd:
    The experiment's ``crowd`` and ``pedestrians`` blocks, unchanged: by default the
    social-force ``pysocial`` model with Arena's social states (idle, talking, phone, …), the
    people the benchmark evaluates against, so that a policy trains on the crowd it is tested
    on and an RL episode equals the ``arena run`` episode of the same seed and index. The
    crowd is the largest part of a step's cost. Measured on one core (small_office, jackal
    with 720 beams, 20 people, 2026-11-21, CPU time per env step, resets excluded):
    pysocial + social states ≈ 3,500 steps/s (≈ 1,100 before the crowd, statechart and env
    kernels of 2026-11-21); pysocial without states ≈ 3,800; pedsim or orca + states
    ≈ 3,400–3,600; ``waypoint_walker`` without states ≈ 5,900. For throughput-bound
    experiments pass e.g.
    ``overrides=["crowd={type: waypoint_walker}", "pedestrians.social_states=false"]``
    (scripted walkers: no reaction to the robot), or train on
    :class:`~arena.learn.batched.BatchedSocialNavEnv`. An episode reset (task generation, crowd
    and simulator setup) costs ≈ 8–10 ms of CPU.

Starting State:
    The episode's start pose, at rest; people at their spawn positions.

Episode End:
    Terminated when the robot is within ``task.goal_radius`` of the goal (success; the heading
    is not checked, as in Arena's training) or touches anything (collision). Truncated after
    ``max_steps`` env steps or ``task.timeout`` seconds. ``info["outcome"]`` is ``success``,
    ``collision`` or ``timeout`` at the end, else ``None``.

Arguments:
    config: an :class:`~arena.config.schema.ExperimentConfig`, a YAML path or ``None`` (the
        packaged default); ``overrides`` (``key.path=value``) apply to a path.
    robot: a preset name or robot YAML path (the config key ``robot``), or a
        :class:`~arena.robots.model.RobotModel` replacing ``cfg.robot`` (e.g. fewer beams).
    render_mode: ``None`` or ``"rgb_array"``.
    **config_keys: any other top-level config key (``map``, ``task``, ``crowd``, ``seed``,
        ``learning``, …), applied after ``overrides`` as the override ``key=value`` would be;
        an unknown keyword is a one-line :class:`~arena.core.errors.ConfigError`.

Example::

    import gymnasium as gym
    import arena.learn  # registers the id
    env = gym.make("arena/SocialNav-v0", config="my.yaml", overrides=["learning.env.max_steps=300"])
    env = gym.make("arena/SocialNav-v0", robot="burger", map={"type": "empty", "width": 10},
                   overrides=["task.obstacles.dynamic=5"])
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, ClassVar, SupportsFloat

import gymnasium as gym

from arena.learn.driver import (
    ConfigLike,
    EpisodeDriver,
    action_period_fps,
    resolve_config,
)
from arena.learn.keywords import check_config_keywords
from arena.robots.model import RobotModel


class SocialNavEnv(gym.Env[Any, Any]):
    """One robot, one world; see the module docstring for the contract."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        config: ConfigLike = None,
        overrides: Sequence[str] = (),
        *,
        robot: RobotModel | str | Path | None = None,
        render_mode: str | None = None,
        **config_keys: Any,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be one of {self.metadata['render_modes']}")
        check_config_keywords(type(self).__name__, config_keys)
        if robot is not None and not isinstance(robot, RobotModel):
            config_keys["robot"] = robot  # a preset name or a robot file: the config key
            robot = None
        self.cfg = resolve_config(config, overrides, config_keys, owner=type(self).__name__)
        self.driver = EpisodeDriver(self.cfg, robot, n_robots=1)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": action_period_fps(self.driver.period)}
        self.observation_space = self.driver.obs_builder.space
        self.action_space = self.driver.decoder.space
        self._started = False

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Start the next episode; ``seed`` restarts at episode 0 of that seed.

        ``options={"episode": i}`` picks episode ``i`` of the current seed.
        """
        super().reset(seed=seed)
        index = (options or {}).get("episode")
        obs = self.driver.reset(seed=seed, index=index)
        self._started = True
        info = self.driver.info()
        info["outcome"] = None
        return self.driver.obs_builder.single(obs), info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        """Hold ``action`` for one action period."""
        if not self._started:
            raise RuntimeError("call reset() before step()")
        # ActionDecoder.decode reshapes one action to a batch of one itself
        res = self.driver.step(action)
        info = self.driver.info(goal_distance=res.goal_distance)
        info["outcome"] = res.outcomes[0]
        info["is_success"] = res.outcomes[0] == "success"  # SB3 logs rollout/success_rate
        # .item(): the Python float/bool of a (1,) array in one call
        info["reward_terms"] = {k: v.item() for k, v in res.reward.terms.items()}
        info["collision"] = res.collision.item()
        obs = self.driver.obs_builder.single(res.obs)
        return (
            obs, res.reward.total.item(), res.terminated.item(), res.truncated.item(), info
        )

    def render(self) -> Any:
        """An RGB frame ``(H, W, 3)`` uint8 in ``rgb_array`` mode, else ``None``."""
        if self.render_mode != "rgb_array" or not self._started:
            return None
        return self.driver.render()
