"""``N`` social-navigation worlds as one Gymnasium vector environment on one simulation engine.

:class:`BatchedSocialNavEnv` is the vectorised counterpart of
:class:`~arena.learn.env.SocialNavEnv`: the same observation and action spaces (built by
:class:`~arena.learn.observations.ObservationBuilder` and
:class:`~arena.learn.actions.ActionDecoder`), the same reward terms
(:class:`~arena.learn.rewards.RewardFunction`) and the same episode-end rules (terminated on goal
or collision, truncated after ``max_steps`` env steps or the episode's time limit), all from the
same :class:`~arena.config.schema.ExperimentConfig`. The worlds are stepped by one
:class:`~arena.sim.engine.Engine` with ``N`` worlds (one :meth:`Engine.step` per simulation
sub-step for all of them); the reward, end rules and observations run on arrays with a leading
world axis.

The simulation is ``native2d``'s own: the engine with one world is the ``native2d`` backend, the
pedestrians of each world are ``cfg.crowd`` with ``cfg.pedestrians`` (built as ``arena run``
builds them), contacts use the robot's real footprint, and the engine parameters are those of
``cfg.sim.backend``. World ``i`` therefore plays its episode exactly as
:class:`~arena.learn.env.SocialNavEnv` plays the same episode and seed: the same observations,
rewards and ends (``tests/learn/test_batched.py``), and a policy trains on the crowd it is
evaluated on.

Episodes: world ``i`` plays the task generator's episodes ``i, i + N, i + 2N, …`` of the current
seed (``cfg.seed``, or the last ``reset(seed=…)``), each with the simulator stream
``derive_rng(seed, "episode", index, "sim")`` as ``arena run`` uses. Results therefore depend on
``(config, seed, N)`` only, and a world's first episode does not depend on ``N`` at all.

Autoreset: gymnasium's ``NEXT_STEP`` mode (the default): the step that ends a world's episode
returns its last observation with ``terminated``/``truncated`` set; on the next ``step()`` that
world ignores its action, restarts, and returns the first observation of its next episode with
reward 0 and both flags false. ``SAME_STEP`` (``autoreset_mode=AutoresetMode.SAME_STEP``):
the ending step already returns the new episode's first observation, with the last one in
``info["final_obs"]`` (an object array) and its info in ``info["final_info"]`` (used by
:class:`SB3VecEnv`).

Info (arrays over worlds, each key ``k`` with its mask ``_k``, gymnasium's vector layout):
``episode`` index, ``time`` (s), ``steps``, ``goal_distance`` (m), ``goal_radius`` (m),
``outcome`` (``success``/``collision``/``timeout`` or ``None``), and after a step
``collision`` and ``reward_terms`` (``{term: (N,)}``).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError
from arena.core.rng import derive_rng
from arena.core.types import Outcome
from arena.crowd.driver import build_driver
from arena.learn.actions import ActionDecoder
from arena.learn.driver import (
    ConfigLike,
    SubgoalTracker,
    resolve_config,
    substeps,
)
from arena.learn.keywords import check_config_keywords
from arena.learn.observations import Obs, ObservationBuilder, ObsInput
from arena.learn.prefetch import EpisodePrefetcher
from arena.learn.rewards import DoneReason, RewardFunction, RewardInput, RewardOutput
from arena.maps.raster import planning_grid
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.sim.backend import BACKENDS
from arena.sim.engine import Engine, EngineParams
from arena.tasks.generator import TaskGenerator

F64 = NDArray[np.float64]
B1 = NDArray[np.bool_]

_SUCCESS = Outcome.SUCCESS.value
_COLLISION = Outcome.COLLISION.value
_TIMEOUT = Outcome.TIMEOUT.value
#: ``info["outcome"]`` by code (0 running, 1 timeout, 2 success, 3 collision): one fancy index
#: per step instead of filling an object array mask by mask.
_OUTCOMES: NDArray[np.object_] = np.array([None, _TIMEOUT, _SUCCESS, _COLLISION], dtype=object)
# Plain ints: comparing an array with an IntEnum member takes numpy's slow path (~5 µs).
_REASON_SUCCESS = int(DoneReason.SUCCESS)
_REASON_COLLISION = int(DoneReason.COLLISION)


class BatchedSocialNavEnv(VectorEnv[Any, Any, Any]):
    """``num_envs`` single-robot worlds in one :class:`Engine`; see the module docstring.

    Args:
        config: an :class:`ExperimentConfig`, a YAML path or ``None`` (the packaged default).
        overrides: ``key.path=value`` overrides (with a path or ``None`` only).
        num_envs: ``N``, the number of worlds.
        robot: a preset name or robot YAML path (the config key), or a robot model
            replacing ``cfg.robot``.
        sim_params: engine parameters; ``None``: those of ``cfg.sim.backend`` (``native2d``).
        autoreset_mode: ``NEXT_STEP`` (default) or ``SAME_STEP``.
        prefetch: episodes per world drawn ahead by a helper process
            (:class:`~arena.learn.prefetch.EpisodePrefetcher`); 0 (default) draws them in this
            process when a world restarts. The episodes, and so every result, are the same
            either way; prefetching overlaps the drawing with the simulation (one more process;
            :meth:`close` stops it).
        **config_keys: other top-level config keys (``map``, ``task``, ``seed``, …), applied
            as in :class:`~arena.learn.env.SocialNavEnv`.
    """

    metadata = {  # noqa: RUF012  (gymnasium declares it an instance attribute)
        "render_modes": [],
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        config: ConfigLike = None,
        overrides: Sequence[str] = (),
        *,
        num_envs: int = 1,
        robot: RobotModel | str | os.PathLike[str] | None = None,
        sim_params: EngineParams | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        prefetch: int = 0,
        **config_keys: Any,
    ) -> None:
        if num_envs < 1:
            raise ValueError(f"num_envs must be >= 1, got {num_envs}")
        mode = AutoresetMode(autoreset_mode)
        if mode == AutoresetMode.DISABLED:
            raise ValueError("autoreset_mode must be NEXT_STEP or SAME_STEP")
        self.autoreset_mode = mode
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        owner = type(self).__name__
        check_config_keywords(owner, config_keys)
        if robot is not None and not isinstance(robot, RobotModel):
            config_keys["robot"] = robot  # a preset name or a robot file: the config key
            robot = None
        self.cfg = resolve_config(config, overrides, config_keys, owner=owner)
        self.env_cfg = self.cfg.learning.env
        self.robot = robot if robot is not None else load_robot(self.cfg.robot)
        self.num_envs = n = int(num_envs)
        self.dt = float(self.cfg.sim.dt)
        self.substeps = substeps(self.env_cfg, self.dt)
        self.period = self.dt * self.substeps
        if self.env_cfg.observation.camera.sensor is not None:
            raise ConfigError(
                "learning.env.observation.camera: the batched env runs the native2d engine, "
                "which renders no camera; observe a camera with SocialNavEnv on "
                "sim.backend.type: mujoco"
            )
        self.obs_builder = ObservationBuilder(self.env_cfg.observation, self.robot)
        self.decoder = ActionDecoder(self.env_cfg.action, self.robot)
        self.reward_fn = RewardFunction(self.env_cfg.reward)
        self.single_observation_space = self.obs_builder.space
        self.single_action_space = self.decoder.space
        self.observation_space = batch_space(self.single_observation_space, n)
        self.action_space = batch_space(self.single_action_space, n)
        self.render_mode = None
        self.sim = Engine(n, sim_params if sim_params is not None else _engine_params(self.cfg))
        self.seed_value = int(self.cfg.seed)
        self.generator = self._generator(self.seed_value)
        self.radius = float(self.robot.radius)
        # per world bookkeeping
        stack = self.env_cfg.observation.laser_stack
        self._k = np.zeros(n, dtype=np.int64)  # episodes started by each world
        self._ep_index = np.zeros(n, dtype=np.int64)
        self._goals = np.zeros((n, 2))
        self._goal_radius = np.zeros(n)
        self._time_limit = np.zeros(n)
        self._steps = np.zeros(n, dtype=np.int64)
        self._scans = np.zeros((n, stack, self.obs_builder.beams))
        self._sensor = self.env_cfg.observation.sensor  # the lidar the observation reads
        self._scan_rows: list[int] = []  # per world its sensor row (rows move on resets)
        self._last_action = np.zeros((n, 3))
        self._autoreset = np.zeros(n, dtype=bool)
        self._outcome: NDArray[np.object_] = np.full(n, None, dtype=object)
        self._state: _Frame | None = None
        self._ones = np.ones(n, dtype=bool)
        self._arange = np.arange(n)
        self._safe = np.full(n, self.radius + self.env_cfg.safety_distance)
        self._rrad = np.full(n, self.radius)
        self._dt_arr = np.full(n, self.period)
        self._max_steps = np.full(n, self.env_cfg.max_steps, dtype=np.int64)
        self._zeros = np.zeros(n)
        # subgoals (learning.env.observation.subgoal): one tracker per world, as SocialNavEnv
        self._episodes: list[Episode | None] = [None] * n
        sub = self.env_cfg.observation.subgoal
        inscribed = self.radius + float(self.cfg.navigation.inflation_margin)
        self.trackers: list[SubgoalTracker] | None = (
            [SubgoalTracker(sub, inscribed, 1) for _ in range(n)] if sub.enabled else None
        )
        self._subgoals = np.zeros((n, 2))
        self._stage: int | None = None
        if prefetch < 0:
            raise ValueError(f"prefetch must be >= 0 episodes per world, got {prefetch}")
        if prefetch and os.name == "nt":
            warnings.warn(
                "episode prefetching needs a POSIX system (it passes pipes to a helper process); "
                "drawing episodes in this process instead", RuntimeWarning, stacklevel=2,
            )
            prefetch = 0
        self.prefetch = int(prefetch)
        self._prefetcher: EpisodePrefetcher | None = None
        if self.prefetch:
            self._prefetcher = EpisodePrefetcher(
                partial(make_generator, self.cfg), self.robot, self.seed_value, None
            )

    # -- episodes ----------------------------------------------------------------------------------
    def _generator(self, seed: int) -> TaskGenerator:
        return make_generator(self.cfg, self.robot, seed, getattr(self, "_stage", None))

    def set_stage(self, index: int) -> int:
        """Move every ``staged`` task module to ``index`` (clamped); return the stage."""
        self._stage = int(index)
        stages = [m.set_stage(index) for m in _staged_modules(self.generator)]
        if self._prefetcher is not None:
            self._prefetcher.restart(self.seed_value, self._stage)
            self._request_next(self._arange)
        return stages[0] if stages else -1

    def get_stage(self) -> int:
        """The current curriculum stage (-1 without a ``staged`` module)."""
        mods = _staged_modules(self.generator)
        return int(mods[0].stage) if mods else -1

    def _draw(self, worlds: Sequence[int]) -> tuple[list[Episode], list[np.random.Generator]]:
        """The next episode (and simulator stream) of each world in ``worlds``."""
        eps: list[Episode] = []
        rngs: list[np.random.Generator] = []
        pre = self._prefetcher
        for i in worlds:
            idx = i + int(self._k[i]) * self.num_envs
            self._k[i] += 1
            ep = pre.take(idx) if pre is not None else None
            # None: no helper, not drawn yet, the helper lost, or its draw failed: draw here
            # (the same episode; a failing draw raises its real error here)
            if ep is None:
                ep = self.generator.episode(idx)
            eps.append(ep)
            rngs.append(derive_rng(self.seed_value, "episode", idx, "sim"))
            self._ep_index[i] = idx
            self._episodes[i] = ep
            self._goals[i] = ep.robots[0].goal.as_array()[:2]
            self._goal_radius[i] = ep.goal_radius
            self._time_limit[i] = ep.time_limit
        if pre is not None:
            self._request_next(worlds)
        return eps, rngs

    def _reset_worlds(self, worlds: NDArray[np.int64]) -> _Frame:
        """Draw and start the next episode of each world in ``worlds``; the frame after it."""
        eps, rngs = self._draw(worlds.tolist())
        for ep in eps:
            if len(ep.robots) != 1:
                raise ConfigError(
                    f"task.robots: BatchedSocialNavEnv worlds hold one robot, the task placed "
                    f"{len(ep.robots)}"
                )
        drivers = [build_driver(self.cfg.crowd, self.cfg.pedestrians) for _ in eps]
        self.sim.reset_worlds(worlds, eps, drivers, rngs)
        self._scan_rows = self.sim.sensor_rows(self._sensor).tolist()
        return self._frame()

    def _frame(self) -> _Frame:
        """What the env reads of the engine now (one robot per world, its observed lidar)."""
        sim = self.sim
        peds = sim.padded_agents()
        return _Frame(
            time=np.array(sim.time), poses=sim.poses, twists=sim.twists,
            scans=np.stack([sim.scans[s] for s in self._scan_rows]),
            ped_positions=peds.positions, ped_velocities=peds.velocities,
            ped_kinds=peds.kinds, ped_states=peds.states, ped_mask=peds.mask,
        )

    def sensor_readings(self, name: str) -> F64:
        """``(N, ...)`` each world's robot's latest reading of its sensor ``name``.

        A lidar's is ``(N, beams)`` m. Raises ``KeyError`` when the robot has no such sensor.
        """
        rows = self.sim.sensor_rows(name).tolist()
        if not rows or min(rows) < 0:
            raise KeyError(f"the robot has no sensor {name!r} (its sensors: "
                           f"{', '.join(self.robot.sensors)})")
        return np.stack([self.sim.scans[s] for s in rows])

    def _request_next(self, worlds: Sequence[int] | NDArray[np.int64]) -> None:
        """Ask the prefetcher for the next ``prefetch`` episodes of each world in ``worlds``."""
        pre = self._prefetcher
        if pre is None:
            return
        n = self.num_envs
        pre.request(
            int(i) + (int(self._k[i]) + a) * n for a in range(self.prefetch) for i in worlds
        )

    def _restart(self, worlds: NDArray[np.int64], state: _Frame) -> None:
        """Bookkeeping of freshly reset worlds (state: the snapshot after their reset)."""
        self._steps[worlds] = 0
        self._last_action[worlds] = 0.0
        self._scans[worlds] = state.scans[worlds][:, None, :]
        self._outcome[worlds] = None
        self._autoreset[worlds] = False
        if self.trackers is not None:
            for i in np.asarray(worlds).tolist():
                ep = self._episodes[i]
                assert ep is not None
                tr = self.trackers[i]
                tr.reset(planning_grid(ep), state.poses[i : i + 1], self._goals[i : i + 1], 0.0)
                self._subgoals[i] = tr.current[0]

    def _update_subgoals(self, state: _Frame, skip: B1 | None = None) -> None:
        """Replan/move each world's subgoal after a step (worlds in ``skip`` restart anyway)."""
        if self.trackers is None:
            return
        for i, tr in enumerate(self.trackers):
            if skip is not None and skip[i]:
                continue
            tr.update(state.poses[i : i + 1], self._goals[i : i + 1], float(state.time[i]))
            self._subgoals[i] = tr.current[0]

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Start every world's next episode; ``seed`` restarts at episodes ``0..N-1`` of it.

        ``options={"reset_mask": (N,) bool}`` restarts only the masked worlds.
        """
        if isinstance(seed, list | tuple):
            if len(set(seed)) != 1:
                raise ValueError("BatchedSocialNavEnv takes one seed for all worlds")
            seed = int(seed[0])
        if seed is not None:
            self._np_random, _ = _seeding(int(seed))
            if int(seed) != self.seed_value:
                self.seed_value = int(seed)
                self.generator = self._generator(self.seed_value)
            self._k[:] = 0
            if self._prefetcher is not None:
                self._prefetcher.restart(self.seed_value, self._stage)
        mask = (options or {}).get("reset_mask")
        if mask is not None and self._state is not None and seed is None:
            worlds = np.flatnonzero(np.asarray(mask, dtype=bool))
            state = self._reset_worlds(worlds)
        else:
            worlds = self._arange
            state = self._reset_worlds(worlds)
        self._state = state
        self._restart(worlds, state)
        obs = self._observe(state)
        return obs, self._info(state)

    # -- stepping ----------------------------------------------------------------------------------
    def step(self, actions: Any) -> tuple[Any, F64, B1, B1, dict[str, Any]]:
        """Hold each world's action for one action period (autoreset as the mode says)."""
        if self._state is None:
            raise RuntimeError("call reset() before step()")
        if self._prefetcher is not None:
            self._prefetcher.pump()
        n = self.num_envs
        cmd = self.decoder.decode(actions)
        if cmd.shape[0] != n:
            raise ValueError(f"expected {n} actions, got {cmd.shape[0]}")
        restart = self._autoreset.copy()  # NEXT_STEP: finished last step, restart now
        cmd[restart] = 0.0
        prev = self._state
        prev_pose = prev.poses
        d = self._goals - prev_pose[:, :2]
        prev_dist = np.hypot(d[:, 0], d[:, 1])
        self.sim.step(cmd, self.dt)
        collision = self.sim.collided()  # a fresh array
        for _ in range(self.substeps - 1):
            self.sim.step(cmd, self.dt)
            collision = collision | self.sim.collided()
        state = self._frame()
        self._steps += 1
        scans = state.scans
        if self._scans.shape[1] > 1:
            self._scans[:, :-1] = self._scans[:, 1:]
        self._scans[:, -1] = scans
        d = self._goals - state.poses[:, :2]
        dist = np.hypot(d[:, 0], d[:, 1])
        goal_reached = dist < self._goal_radius
        pd = state.ped_positions - state.poses[:, None, :2]
        ped_d = np.hypot(pd[..., 0], pd[..., 1])
        inp = RewardInput(
            action=cmd,
            prev_action=self._last_action.copy(),
            goal_distance=dist,
            prev_goal_distance=prev_dist,
            goal_jump=self._zeros,
            goal_radius=self._goal_radius.copy(),
            goal_reached=goal_reached,
            min_range=scans.min(axis=1) if scans.shape[1] else np.full(n, np.inf),
            robot_radius=self._rrad,
            safe_dist=self._safe,
            collision=collision,
            heading=state.poses[:, 2].copy(),
            prev_heading=prev_pose[:, 2],
            dt=self._dt_arr,
            step=self._steps.copy(),
            max_steps=self._max_steps,
            ped_distance=ped_d,
            ped_kind=state.ped_kinds,
            ped_mask=state.ped_mask,
        )
        out = self.reward_fn(inp)
        self._last_action = cmd
        terminated, truncated, outcome = self._ends(out, goal_reached, collision, state)
        reward = out.total.copy()
        self._state = state
        self._outcome = outcome
        self._update_subgoals(state, restart)
        if self.autoreset_mode == AutoresetMode.NEXT_STEP:
            if restart.any():
                worlds = np.flatnonzero(restart)
                state = self._reset_worlds(worlds)
                self._state = state
                self._restart(worlds, state)
                reward[restart] = 0.0
                terminated[restart] = False
                truncated[restart] = False
            obs = self._observe(state)
            info = self._info(state, out, collision & ~restart)
            self._autoreset = terminated | truncated
            return obs, reward, terminated, truncated, info
        # SAME_STEP
        done = terminated | truncated
        final_obs = self._observe(state) if done.any() else None
        info = self._info(state, out, collision)
        if final_obs is not None:
            worlds = np.flatnonzero(done)
            fo = np.full(n, None, dtype=object)
            for i in worlds:
                fo[i] = self._single(final_obs, int(i))
            final_info = {
                k: v for k, v in info.items()
            }
            info["final_info"] = final_info
            info["_final_info"] = done.copy()
            info["final_obs"] = fo
            info["_final_obs"] = done.copy()
            state = self._reset_worlds(worlds)
            self._state = state
            self._restart(worlds, state)
            fresh = self._info(state)
            for k in ("episode_index", "time", "steps", "goal_distance", "goal_radius", "outcome"):
                info[k] = fresh[k]
        return self._observe(state), reward, terminated, truncated, info

    def _ends(
        self, out: RewardOutput, goal_reached: B1, collision: B1, state: _Frame
    ) -> tuple[B1, B1, NDArray[np.object_]]:
        """Termination, truncation and outcome per world (the rules of the single env)."""
        reason_collision = out.reason == _REASON_COLLISION
        term_reason = (out.reason == _REASON_SUCCESS) | reason_collision
        terminated = goal_reached | collision | (out.done & term_reason)
        limit = (self._steps >= self.env_cfg.max_steps) | (
            state.time >= self._time_limit - 1e-9
        )
        truncated = ~terminated & (limit | (out.done & ~term_reason))
        # later codes win, as the masks were applied in this order: timeout, success, collision
        code = truncated.astype(np.int64)
        code[terminated] = 2
        code[collision | reason_collision] = 3
        outcome: NDArray[np.object_] = _OUTCOMES[code]
        return terminated, truncated, outcome

    # -- observations and info ---------------------------------------------------------------------
    def _observe(self, state: _Frame) -> Any:
        n = self.num_envs
        m = state.ped_positions.shape[1]
        goals = self._goals if self.trackers is None else self._subgoals
        ocfg = self.env_cfg.observation
        if m == 0:
            ped_pos, ped_vel = np.zeros((n, 0, 2)), np.zeros((n, 0, 2))
            ped_kind, ped_state = np.zeros((n, 0), np.int64), np.zeros((n, 0), np.int64)
            ped_mask = np.zeros((n, 0), bool)
        else:
            ped_pos, ped_vel = state.ped_positions, state.ped_velocities
            ped_kind, ped_mask = state.ped_kinds, state.ped_mask
            # the builder reads ped_state only for the pedestrian/semantic parts
            ped_state = (
                np.maximum(state.ped_states, 0)
                if ocfg.pedestrians.enabled or ocfg.semantic.enabled
                else state.ped_states
            )
        inp = ObsInput(
            poses=state.poses, twists=state.twists, goals=goals, scans=self._scans,
            last_action=self._last_action, ped_pos=ped_pos, ped_vel=ped_vel, ped_kind=ped_kind,
            ped_state=ped_state, ped_mask=ped_mask,
        )
        obs: Obs = self.obs_builder.build(inp)
        if ocfg.flatten:
            return self.obs_builder.flatten(obs)
        return obs

    def _single(self, obs: Any, i: int) -> Any:
        if isinstance(obs, dict):
            return {k: v[i].copy() for k, v in obs.items()}
        return obs[i].copy()

    def _info(
        self, state: _Frame, out: RewardOutput | None = None, collision: B1 | None = None
    ) -> dict[str, Any]:
        d = self._goals - state.poses[:, :2]
        ones = self._ones
        info: dict[str, Any] = {
            "episode_index": self._ep_index.copy(), "_episode_index": ones.copy(),
            "time": state.time.copy(), "_time": ones.copy(),
            "steps": self._steps.copy(), "_steps": ones.copy(),
            "goal_distance": np.hypot(d[:, 0], d[:, 1]), "_goal_distance": ones.copy(),
            "goal_radius": self._goal_radius.copy(), "_goal_radius": ones.copy(),
            "outcome": self._outcome.copy(), "_outcome": ones.copy(),
        }
        if out is not None and collision is not None:
            terms: dict[str, Any] = {}
            for k, v in out.terms.items():
                terms[k] = v
                terms[f"_{k}"] = ones.copy()
            info["reward_terms"] = terms
            info["_reward_terms"] = ones.copy()
            info["collision"] = collision.copy()
            info["_collision"] = ones.copy()
        return info

    def wait_prefetch(self, timeout: float = 120.0) -> bool:
        """Block until the prefetch helper holds every episode asked of it; ``False`` on timeout.

        Never needed for correctness (a world whose next episode has not arrived draws it
        itself); benchmarks call it so that the helper's start-up (a few seconds of imports)
        is not timed. ``True`` at once without a helper.
        """
        return self._prefetcher.wait(timeout) if self._prefetcher is not None else True

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the prefetch process, if any."""
        if self._prefetcher is not None:
            self._prefetcher.close()
            self._prefetcher = None


@dataclass(frozen=True, eq=False)
class _Frame:
    """The engine's state as the env reads it; arrays the engine never writes into.

    ``time`` ``(N,)`` s; ``poses``/``twists`` ``(N, 3)``; ``scans`` ``(N, B)`` m (each
    world's ``observation.sensor`` lidar); ``ped_*`` ``(N, P, ...)`` padded, valid where
    ``ped_mask``.
    """

    time: F64
    poses: F64
    twists: F64
    scans: F64
    ped_positions: F64
    ped_velocities: F64
    ped_kinds: NDArray[np.int64]
    ped_states: NDArray[np.int64]
    ped_mask: B1


def _engine_params(cfg: ExperimentConfig) -> EngineParams:
    """The engine parameters of ``cfg.sim.backend`` (``native2d``'s), as ``arena run`` uses."""
    entry, params = BACKENDS.validate(cfg.sim.backend, path="sim.backend")
    if entry.name != "native2d" or not isinstance(params, EngineParams):
        raise ConfigError(
            f"BatchedSocialNavEnv runs the native2d engine, got {entry.name!r}",
            path="sim.backend.type",
        )
    return params


def make_generator(
    cfg: ExperimentConfig, robot: RobotModel, seed: int, stage: int | None
) -> TaskGenerator:
    """The task generator of ``cfg`` placing ``robot``, with ``seed`` and curriculum ``stage``.

    Module-level (picklable with ``functools.partial``) so the prefetch process builds the
    very generator the env builds.
    """
    gen: TaskGenerator = TaskGenerator.from_config(
        cfg.model_copy(update={"seed": int(seed)}), [robot]
    )
    if stage is not None:
        for m in _staged_modules(gen):
            m.set_stage(stage)
    return gen


def _staged_modules(gen: TaskGenerator) -> list[Any]:
    from arena.tasks.modules.staged import Staged

    return [m for m in gen.modules if isinstance(m, Staged)]


def _seeding(seed: int) -> tuple[np.random.Generator, int]:
    from gymnasium.utils import seeding

    return seeding.np_random(seed)
