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
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

import arena.plugins  # noqa: F401  (fills the registries)
from arena.config.schema import ExperimentConfig
from arena.core.errors import SamplingError
from arena.core.rng import derive_rng
from arena.core.types import Outcome
from arena.crowd.driver import build_driver
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.learn.actions import ActionDecoder
from arena.learn.config import substeps as substeps
from arena.learn.keywords import ConfigLike as ConfigLike
from arena.learn.keywords import resolve_config as resolve_config
from arena.learn.observations import Obs, ObservationBuilder, ObsInput
from arena.learn.rewards import (
    DoneReason,
    RewardFunction,
    RewardInput,
    RewardOutput,
    SingleRewardInput,
)
from arena.learn.subgoals import SubgoalTracker as SubgoalTracker
from arena.maps.raster import planning_grid
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.scene.state import SimState
from arena.sim.backend import BACKENDS, SimulatorBackend
from arena.tasks.generator import TaskGenerator
from arena.tasks.robot_modes.random import sample_start_goal, spawn_radius
from arena.tasks.world import WorldSampler

FloatArray = NDArray[np.float64]
# substeps, ConfigLike, resolve_config and SubgoalTracker are also imported from here (envs)

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


_SUCCESS = int(DoneReason.SUCCESS)
_COLLISION = int(DoneReason.COLLISION)
_OUT_SUCCESS = Outcome.SUCCESS.value
_OUT_COLLISION = Outcome.COLLISION.value
_OUT_TIMEOUT = Outcome.TIMEOUT.value


class _ContactDuringTick(EpisodeHooks):
    """``any``: ``(r,)`` bool, each robot touched something during the tick's substeps."""

    def __init__(self) -> None:
        self.any = np.zeros(0, dtype=bool)

    def after_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        self.any |= runner.state.collisions.any


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
        self._sensor = self.env_cfg.observation.sensor  # the lidar the observation reads
        self._sensor_is_primary = self.robot.primary_lidar == self._sensor
        self.decoder = ActionDecoder(self.env_cfg.action, self.robot)
        self.reward_fn = RewardFunction(self.env_cfg.reward)
        self.backend: SimulatorBackend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
        # the one episode loop, stepped from outside: each env step is one runner tick
        self._contact = _ContactDuringTick()
        self.runner = EpisodeRunner(
            self.backend, self.dt, [self._contact] if self.substeps > 1 else [],
            substeps=self.substeps,
        )
        self.seed = cfg.seed
        self.generator = self._generator(self.seed)
        self.next_index = 0
        self.episode: Episode | None = None
        self.state: SimState | None = None
        r = self.n_robots
        # steps since each robot's start (differ from ``steps`` only after a respawn)
        self.robot_steps = np.zeros(r, dtype=np.int64)
        self._episode_index = -1
        self._respawns = 0
        self.scans = np.zeros((r, self.env_cfg.observation.laser_stack, self.obs_builder.beams))
        self.last_action = np.zeros((r, 3))
        self.goals = np.zeros((r, 3))
        self.active = np.ones(r, dtype=bool)
        self.radius = float(self.robot.radius)
        self._consts: dict[str, Any] = {}
        # operands and result of _hypot: (1,) views made once (each view costs a numpy call)
        buf = np.zeros((3, 1))
        self._hypot_views = (buf[0], buf[1], buf[2])
        # (dx, dy, ρ) of the last _hypot: the goal distance before a step is the one after the
        # previous step unless robot or goal moved in between (reset, a caller moving the goal)
        self._hypot_memo = (math.nan, math.nan, math.nan)
        self._ped_mask_1 = np.ones((1, 0), dtype=bool)  # _peds' mask for one robot
        self.subgoal_cfg = self.env_cfg.observation.subgoal
        self.subgoals = SubgoalTracker(
            self.subgoal_cfg, self.radius + float(cfg.navigation.inflation_margin), r
        ) if self.subgoal_cfg.enabled else None

    def _generator(self, seed: int) -> TaskGenerator:
        cfg = self.cfg.model_copy(update={"seed": int(seed)})
        return TaskGenerator.from_config(cfg, [self.robot] * self.n_robots)

    @property
    def steps(self) -> int:
        """Env steps since the episode's reset (the runner's ticks)."""
        return self.runner.ticks

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
        crowd = build_driver(self.cfg.crowd, self.cfg.pedestrians)
        self.state = self.runner.reset(ep, crowd, self.seed)
        self.robot_steps = np.zeros(self.n_robots, dtype=np.int64)
        self._episode_index = idx
        self._respawns = 0
        self.goals = np.array([s.goal.as_array() for s in ep.robots])
        self.last_action[:] = 0.0
        self.active[:] = True
        # a new array, not written in place: after a step self.scans may be a view of a snapshot
        self.scans = np.repeat(
            np.stack(self._robot_scans())[:, None, :], self.scans.shape[1], axis=1
        )
        self._renderer: Any = None  # drawn lazily, once per episode (the world changes)
        # per-episode constants of the reward input (allocated once, never written to)
        r = self.n_robots
        self._consts = {
            "goal_jump": np.zeros(r),
            "goal_radius": np.full(r, ep.goal_radius),
            "robot_radius": np.full(r, self.radius),
            "safe_dist": np.full(r, self.radius + self.env_cfg.safety_distance),
            "dt": np.full(r, self.period),
            "max_steps": np.full(r, self.env_cfg.max_steps, dtype=np.int64),
            "no_range": np.full(r, np.inf),
            # the same as Python floats for the one-robot path
            "goal_radius_f": float(ep.goal_radius),
            "safe_dist_f": float(self.radius + self.env_cfg.safety_distance),
        }
        if self.subgoals is not None:
            self.subgoals.reset(planning_grid(ep), self.state.robots.poses, self.goals, 0.0)
        return self.obs_builder.build(self._obs_input())

    def _peds(self) -> tuple[FloatArray, FloatArray, Any, Any, Any]:
        assert self.state is not None
        a = self.state.agents
        r = self.n_robots
        m = len(a)
        if r == 1:  # views with a leading axis of one (cheaper than broadcast_to)
            if self._ped_mask_1.shape[1] != m:
                # all slots hold a person; read-only, so one array serves every step
                self._ped_mask_1 = np.ones((1, m), dtype=bool)
                self._ped_mask_1.flags.writeable = False
            return (
                a.positions[None], a.velocities[None], a.kinds[None], a.states[None],
                self._ped_mask_1,
            )
        return (
            np.broadcast_to(a.positions, (r, m, 2)),
            np.broadcast_to(a.velocities, (r, m, 2)),
            np.broadcast_to(a.kinds, (r, m)),
            np.broadcast_to(a.states, (r, m)),
            np.ones((r, m), dtype=bool),
        )

    def _obs_input(
        self, peds: tuple[FloatArray, FloatArray, Any, Any, Any] | None = None
    ) -> ObsInput:
        """The observation input of the current state (``peds``: :meth:`_peds` if known)."""
        assert self.state is not None
        pos, vel, kind, st, mask = self._peds() if peds is None else peds
        rs = self.state.robots
        goals = self.goals[:, :2] if self.subgoals is None else self.subgoals.current
        cam = self.env_cfg.observation.camera.sensor
        return ObsInput(
            poses=rs.poses, twists=rs.twists, goals=goals, scans=self.scans,
            last_action=self.last_action, ped_pos=pos, ped_vel=vel, ped_kind=kind,
            ped_state=st, ped_mask=mask,
            frames=() if cam is None else tuple(s[cam] for s in rs.sensors),
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
        cmd = self.decoder.decode(actions)  # a fresh array
        if not all(self.active.tolist()):  # a short list: cheaper than ndarray.all
            cmd[~self.active] = 0.0
        if self.n_robots == 1:
            return self._step_single(cmd)
        prev_heading = self.state.robots.poses[:, 2].copy()
        prev_dist = self.goal_distance()
        collision = self._advance(cmd)
        r = self.n_robots
        scans = self._push_scans()
        poses = self.state.robots.poses
        dist = self.goal_distance()
        goal_reached = dist < self.episode.goal_radius
        peds = self._peds()
        inp = self._reward_input(
            cmd, dist, prev_dist, goal_reached, scans, collision, poses, prev_heading, peds
        )
        out = self.reward_fn(inp)
        self.last_action = cmd
        return self._finish(out, goal_reached, collision, dist, peds, r)

    def _step_single(self, cmd: FloatArray) -> StepResult:
        """:meth:`step` for one robot: the reward input as Python scalars.

        :meth:`RewardFunction.single` on a :class:`SingleRewardInput` returns the bits of the
        batched call (same float64 operations) at a fraction of the cost of a dozen ``(1,)``
        arrays; the batched input is built only for terms without a scalar form.
        """
        assert self.state is not None
        assert self.episode is not None
        gx, gy, _ = self.goals.tolist()[0]  # read each step: callers may move the goal
        px, py, prev_heading = self.state.robots.poses.tolist()[0]
        prev_dist = self._hypot(gx - px, gy - py)
        if self.substeps == 1:
            self.state = self.runner.advance(cmd)
            # Collisions.any on scalars (the index arrays are >= -1): four item reads instead
            # of four ufunc calls
            hits = self.state.collisions
            collision = hits.wall.item() or (
                max(hits.obstacle.item(), hits.agent.item(), hits.robot.item()) >= 0
            )
            collision_a = np.array([collision])
        else:
            collision_a = self._advance(cmd)
            collision = collision_a.item()
        # _push_scans with one view instead of three: scan (beams,), stacked (1, 1, beams)
        scan = self._robot_scans()[0]
        stacked = scan[None, None]
        if self.scans.shape[1] == 1:
            self.scans = stacked
        else:
            self.scans = np.concatenate([self.scans[:, 1:], stacked], axis=1)
        poses = self.state.robots.poses
        px, py, heading = poses.tolist()[0]
        dist = self._hypot(gx - px, gy - py)
        reached = dist < self.episode.goal_radius
        dist_a = np.array([dist])
        reached_a = np.array([reached])
        peds = self._peds()
        c = self._consts

        def batched() -> RewardInput:
            return self._reward_input(
                cmd, dist_a, np.array([prev_dist]), reached_a, stacked[:, 0], collision_a, poses,
                np.array([prev_heading]), peds,
            )

        a0, a1, a2 = cmd.tolist()[0]
        p0, p1, p2 = self.last_action.tolist()[0]
        inp = SingleRewardInput(
            action=(a0, a1, a2),
            prev_action=(p0, p1, p2),
            goal_distance=dist,
            prev_goal_distance=prev_dist,
            goal_jump=0.0,
            goal_radius=c["goal_radius_f"],
            goal_reached=reached,
            # the reduction of ndarray.min without its Python wrapper
            min_range=np.minimum.reduce(scan).item() if scan.shape[0] else math.inf,
            robot_radius=self.radius,
            safe_dist=c["safe_dist_f"],
            collision=collision,
            heading=heading,
            prev_heading=prev_heading,
            dt=self.period,
            step=self.steps,
            max_steps=self.env_cfg.max_steps,
            batched=batched,
        )
        out = self.reward_fn.single(inp)
        self.last_action = cmd
        # _finish's rules for r = 1 on scalars
        reason = int(out.reason[0])
        hit = reason == _COLLISION
        term_reason = hit or reason == _SUCCESS
        done = bool(out.done[0])
        terminated = reached or collision or (done and term_reason)
        truncated = not terminated and (self._at_limit() or (done and not term_reason))
        if collision or hit:
            outcome: str | None = _OUT_COLLISION
        elif terminated:
            outcome = _OUT_SUCCESS
        elif truncated:
            outcome = _OUT_TIMEOUT
        else:
            outcome = None
        return self._result(
            out, reached_a, collision_a, np.array([terminated]), np.array([truncated]), dist_a,
            [outcome], peds,
        )

    def _hypot(self, dx: float, dy: float) -> float:
        """``np.hypot(dx, dy)`` of two floats via preallocated ``(1,)`` buffers.

        Not ``math.hypot``: it rounds differently from numpy's (libm) hypot in about 0.5 % of
        cases, and :meth:`goal_distance` (the batched path) uses numpy's. The buffers skip the
        scalar ufunc call's conversions (≈ 0.6 vs 1.4 µs). The operands of the last call
        return its result (hypot is a function of its operands): that spares the distance
        before a step, the one after the previous step.
        """
        mx, my, mr = self._hypot_memo
        if dx == mx and dy == my:  # ±0 compare equal; hypot ignores the signs
            return mr
        a, b, out = self._hypot_views
        a[0] = dx
        b[0] = dy
        np.hypot(a, b, out=out)
        r: float = out.item()
        self._hypot_memo = (dx, dy, r)
        return r

    def _advance(self, cmd: FloatArray) -> NDArray[np.bool_]:
        """Step the backend for one action period; ``(r,)`` bool, any contact during it."""
        if self.substeps == 1:
            self.state = self.runner.advance(cmd)
            collision = self.state.collisions.any  # a fresh array
        else:
            self._contact.any = np.zeros(self.n_robots, dtype=bool)
            self.state = self.runner.advance(cmd)
            collision = self._contact.any
        self.robot_steps += 1
        return collision

    def _robot_scans(self) -> tuple[FloatArray, ...]:
        """Per robot the ranges of the observed lidar (``observation.sensor``)."""
        assert self.state is not None
        robots = self.state.robots
        if self._sensor_is_primary:  # RobotStates.scans is that lidar's: no lookups
            return robots.scans
        return tuple(m[self._sensor] for m in robots.sensors)

    def _push_scans(self) -> FloatArray:
        """Append the new scans to the laser stack; return them ``(r, beams)``."""
        assert self.state is not None
        robot_scans = self._robot_scans()
        # The snapshot's scans are copies the backend never writes to; views of them serve
        # (reset replaces self.scans instead of writing into it).
        scans = robot_scans[0][None] if self.n_robots == 1 else np.stack(robot_scans)
        if self.scans.shape[1] == 1:
            self.scans = scans[:, None, :]
        else:
            self.scans = np.concatenate([self.scans[:, 1:], scans[:, None, :]], axis=1)
        return scans

    def _reward_input(
        self,
        cmd: FloatArray,
        dist: FloatArray,
        prev_dist: FloatArray,
        goal_reached: NDArray[np.bool_],
        scans: FloatArray,
        collision: NDArray[np.bool_],
        poses: FloatArray,
        prev_heading: FloatArray,
        peds: tuple[FloatArray, FloatArray, Any, Any, Any],
    ) -> RewardInput:
        """The batched reward input of the step just taken (``(r, …)`` arrays)."""
        c = self._consts
        pos, _, kind, _, mask = peds
        d = pos - poses[:, None, :2]
        ped_d = np.hypot(d[..., 0], d[..., 1])
        return RewardInput(
            action=cmd,
            prev_action=self.last_action,  # replaced after the reward, never written to
            goal_distance=dist,
            prev_goal_distance=prev_dist,
            goal_jump=c["goal_jump"],
            goal_radius=c["goal_radius"],
            goal_reached=goal_reached,
            min_range=scans.min(axis=1) if scans.shape[1] else c["no_range"],
            robot_radius=c["robot_radius"],
            safe_dist=c["safe_dist"],
            collision=collision,
            heading=poses[:, 2].copy(),
            prev_heading=prev_heading,
            dt=c["dt"],
            # one robot: robot_steps is not kept (the scalar path counts self.steps only)
            step=(self.robot_steps.copy() if self.n_robots > 1
                  else np.array([self.steps], dtype=np.int64)),
            max_steps=c["max_steps"],
            ped_distance=ped_d,
            ped_kind=kind if kind.dtype == np.int64 else kind.astype(np.int64),
            ped_mask=mask,
        )

    def _finish(
        self,
        out: RewardOutput,
        goal_reached: NDArray[np.bool_],
        collision: NDArray[np.bool_],
        dist: FloatArray,
        peds: tuple[FloatArray, FloatArray, Any, Any, Any],
        r: int,
    ) -> StepResult:
        """Episode-end flags and outcomes, then :meth:`_result`."""
        world_limit = self._at_time_limit()
        steps_l = self.robot_steps.tolist()
        # Per robot in Python (r is small): terminated on arrival, contact or a term ending the
        # episode with success/collision; truncated at the limits or when another term ends it.
        reached_l, collision_l = goal_reached.tolist(), collision.tolist()
        done_l, reason_l = out.done.tolist(), out.reason.tolist()
        term_l: list[bool] = []
        trunc_l: list[bool] = []
        outcomes: list[str | None] = []
        for i in range(r):
            hit = reason_l[i] == _COLLISION
            term_reason = hit or reason_l[i] == _SUCCESS
            terminated_i = reached_l[i] or collision_l[i] or (done_l[i] and term_reason)
            limit = world_limit or steps_l[i] >= self.env_cfg.max_steps
            truncated_i = not terminated_i and (limit or (done_l[i] and not term_reason))
            term_l.append(terminated_i)
            trunc_l.append(truncated_i)
            if collision_l[i] or hit:
                outcomes.append(_OUT_COLLISION)
            elif terminated_i:
                outcomes.append(_OUT_SUCCESS)
            elif truncated_i:
                outcomes.append(_OUT_TIMEOUT)
            else:
                outcomes.append(None)
        terminated = np.array(term_l, dtype=bool)
        truncated = np.array(trunc_l, dtype=bool)
        return self._result(
            out, goal_reached, collision, terminated, truncated, dist, outcomes, peds
        )

    def _at_limit(self) -> bool:
        """The episode's step or time limit is reached (truncation)."""
        return (self.steps >= self.env_cfg.max_steps) or self._at_time_limit()

    def _at_time_limit(self) -> bool:
        """The episode's time limit is reached (every robot is truncated): the runner's rule."""
        return self.runner.at_time_limit()

    # -- respawns (multi-robot training) -------------------------------------------------------
    def respawn(self, i: int, min_goal_distance: float, clearance: float) -> bool:
        """Give robot ``i`` a new random start and goal in the running world.

        For multi-robot training (Long et al. 2018): a robot that arrived or collided starts
        over while the others drive on. The start and goal are drawn like ``robots.random``
        draws them (body radius + clearance from walls and obstacles, the body radius being
        :func:`~arena.tasks.robot_modes.random.spawn_radius`; one connected region,
        ``min_goal_distance`` apart), also keeping that clearance from where the other robots
        stand and from the people; the robot is teleported there at rest, its laser stack
        filled with its fresh scan, its last action zeroed, its step count restarted and its
        path planned. The draws come from ``derive_rng(seed, "episode", index, "respawn", k)``
        (``k`` counts the episode's respawns), so a rollout stays reproducible.

        Returns:
            ``False`` when no start/goal pair was found (the robot is left as it was).
        """
        assert self.state is not None
        assert self.episode is not None
        if self.n_robots < 2:
            raise ValueError("respawn() is for multi-robot worlds; one robot starts a new episode")
        ep = self.episode
        world = WorldSampler(ep.grid, ep.obstacles)  # the map's wall distance is memoised
        poses = self.state.robots.poses
        body = spawn_radius(self.robot)  # a footprint may reach past `radius` (buddy)
        for j in range(self.n_robots):
            if j != i:
                world.forbid(poses[j, :2], body)
        agents = self.state.agents
        for xy, rad in zip(agents.positions, agents.radii, strict=True):
            world.forbid(xy, float(rad))
        rng = derive_rng(self.seed, "episode", self._episode_index, "respawn", self._respawns)
        self._respawns += 1
        try:
            start, goal = sample_start_goal(
                world, body + clearance, min_goal_distance, rng, what=f"robot {i} respawn"
            )
        except SamplingError:
            return False
        self.state = self.runner.teleport(i, start)
        self.goals = self.goals.copy()
        self.goals[i] = goal.as_array()
        self.last_action = self.last_action.copy()
        self.last_action[i] = 0.0
        self.scans = self.scans.copy()
        self.scans[i] = self._robot_scans()[i][None, :]
        self.robot_steps[i] = 0
        self.active[i] = True
        if self.subgoals is not None:
            self.subgoals.restart(i, self.state.robots.poses[i], self.goals[i], self.state.time)
        return True

    def observe(self) -> Obs:
        """The observation of every robot in the current state."""
        return self.obs_builder.build(self._obs_input())

    def _result(
        self,
        out: RewardOutput,
        goal_reached: NDArray[np.bool_],
        collision: NDArray[np.bool_],
        terminated: NDArray[np.bool_],
        truncated: NDArray[np.bool_],
        dist: FloatArray,
        outcomes: list[str | None],
        peds: tuple[FloatArray, FloatArray, Any, Any, Any],
    ) -> StepResult:
        """Move the subgoals and observe: the :class:`StepResult` of the step just taken."""
        assert self.state is not None
        if self.subgoals is not None:
            self.subgoals.update(self.state.robots.poses, self.goals, self.state.time)
        obs = self.obs_builder.build(self._obs_input(peds))
        return StepResult(obs, out, goal_reached, collision, terminated, truncated, dist, outcomes)

    # -- rendering --------------------------------------------------------------------------
    def render(self, width_px: int | None = None) -> NDArray[np.uint8]:
        """An RGB frame ``(H, W, 3)`` of the current state (goals drawn)."""
        from arena.render import FrameRenderer, Overlay

        assert self.state is not None
        if getattr(self, "_renderer", None) is None:
            self._renderer = FrameRenderer(
                self.backend.world,
                lidar_specs=[self.robot.laser] * self.n_robots,  # draws RobotStates.scans
                width_px=width_px or self.cfg.output.width_px,
                show_trails=False,
            )
        text = f"t = {self.state.time:5.1f} s   step {self.steps}"
        return self._renderer.render(self.state, Overlay(goals=self.goals, text=text))

    def info(self, i: int = 0, *, goal_distance: FloatArray | None = None) -> dict[str, Any]:
        """Status of robot ``i``: episode index, time (s), steps, goal distance (m).

        ``goal_distance``: the ``(r,)`` :meth:`goal_distance` of the current state when the
        caller has it (:attr:`StepResult.goal_distance` of the last step), to skip recomputing.
        """
        assert self.state is not None
        assert self.episode is not None
        dist = self.goal_distance() if goal_distance is None else goal_distance
        return {
            "episode_index": self.episode.index,
            "time": float(self.state.time),
            "steps": self.steps,
            "goal_distance": float(dist[i]),
            "goal_radius": float(self.episode.goal_radius),
        }


def action_period_fps(period: float) -> float:
    """Frames per second of a rendering at one frame per env step."""
    return 1.0 / period if period > 0 and math.isfinite(period) else 10.0
