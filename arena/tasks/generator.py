"""The task generator: robot mode + obstacle mode + modules → episodes (Arena specs §2.1).

    gen = TaskGenerator.from_config(cfg)
    ep = gen.episode(3)                  # a pure function of (cfg, seed, 3)
    runtime = gen.runtime(ep)            # per-step goal logic while the episode runs

Maps are built once per ``(map block, map key)`` and reused: without the ``dynamic_map``
module every episode of a run shares one map, as in Arena.
"""

from __future__ import annotations

import copy
import json
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

import arena.maps.generators  # noqa: F401  (registers the generators as map sources)
from arena.core.rng import derive_rng
from arena.core.types import Pose2D
from arena.maps.sources import MAP_SOURCES, MapResult, MapSource
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.tasks.base import ResetContext, build_mode
from arena.tasks.config import TaskConfig
from arena.tasks.goal import goal_reached
from arena.tasks.world import WorldSampler, wall_distance_map

if TYPE_CHECKING:
    from arena.config.schema import ExperimentConfig


class TaskGenerator:
    """Yields the episodes of a run deterministically from a seed.

    Args:
        config: the ``task`` block.
        map_spec: the ``map`` block (modules may replace it per episode).
        robots: the robot models (one per robot in the episode).
        seed: the run's master seed.
        source: the config file, for error messages.
    """

    MAP_CACHE = 4
    """Maps kept in memory (a benchmark alternates a few; a curriculum moves on)."""

    def __init__(
        self,
        config: TaskConfig,
        *,
        map_spec: dict[str, Any],
        robots: Sequence[RobotModel],
        seed: int,
        source: str | None = None,
    ) -> None:
        self.config = config
        self.map_spec = dict(map_spec)
        self.robots = list(robots)
        self.seed = int(seed)
        self.source = source
        self.robot_mode = build_mode("robots", config.robots, source=source, path="task.robots")
        self.obstacle_mode = build_mode(
            "obstacles", config.obstacles, source=source, path="task.obstacles"
        )
        self.modules = [
            build_mode("modules", m, source=source, path=f"task.modules[{i}]")
            for i, m in enumerate(config.modules)
        ]
        self._sources: dict[str, MapSource] = {}
        self._maps: OrderedDict[tuple[str, int, int], tuple[MapResult, np.ndarray]] = (
            OrderedDict()
        )
        self._contexts: OrderedDict[int, ResetContext] = OrderedDict()

    @classmethod
    def from_config(cls, cfg: ExperimentConfig, robots: Sequence[RobotModel] | None = None):
        """The generator of an experiment config (robots default to ``cfg.robot``)."""
        return cls(
            cfg.task,
            map_spec=cfg.map,
            robots=list(robots) if robots is not None else [load_robot(cfg.robot)],
            seed=cfg.seed,
        )

    # -- episodes ------------------------------------------------------------------------------
    @property
    def num_episodes(self) -> int | None:
        """Episodes a module prescribes (``benchmark``: the suite's total), else ``None``."""
        counts = [m.num_episodes for m in self.modules if getattr(m, "num_episodes", None)]
        return counts[-1] if counts else None

    def context(self, index: int) -> ResetContext:
        """A fresh reset context for episode ``index`` with the run's defaults."""
        c = self.config
        return ResetContext(
            index=index,
            seed=self.seed,
            map_spec=copy.deepcopy(self.map_spec),
            map_key=0,
            robots=list(self.robots),
            robot_mode=self.robot_mode,
            obstacle_mode=self.obstacle_mode,
            timeout=c.timeout,
            goal_radius=c.goal_radius,
            goal_tolerance_angle=c.goal_tolerance_angle,
            forbidden=list(c.forbidden_zones),
        )

    def episode(self, index: int) -> Episode:
        """Episode ``index``: modules, map, robots, obstacles, in Arena's reset order."""
        ctx = self.context(index)
        for m in self.modules:
            m.before_reset(ctx)
        ctx.map_result, wall = self._map(ctx)
        ctx.world = WorldSampler(
            ctx.map_result.grid, ctx.map_result.obstacles, wall_distance=wall
        )
        for zone in ctx.forbidden:
            if zone.polygon is not None:
                ctx.world.forbid_polygon(np.array(zone.polygon, dtype=np.float64))
            else:
                ctx.world.forbid(zone.center, zone.radius)
        spawns = ctx.robot_mode.reset(ctx)
        ctx.spawns = list(spawns)
        obstacles, agents = ctx.obstacle_mode.reset(ctx)
        ep = Episode(
            index=index,
            seed=ctx.seed,
            map_name=ctx.map_result.name,
            grid=ctx.map_result.grid,
            obstacles=tuple(ctx.map_result.obstacles) + tuple(obstacles),
            robots=tuple(spawns),
            agents=agents,
            time_limit=ctx.timeout,
            goal_radius=ctx.goal_radius,
            goal_tolerance_angle=ctx.goal_tolerance_angle,
            label=ctx.label,
        )
        for m in self.modules:
            ep = m.after_reset(ctx, ep)
        self._contexts[index] = ctx
        while len(self._contexts) > 8:
            self._contexts.popitem(last=False)
        return ep

    def episodes(self, n: int | None = None, start: int = 0) -> Iterator[Episode]:
        """Episodes ``start, start+1, ...``: ``n`` of them, or :attr:`num_episodes`."""
        count = n if n is not None else self.num_episodes
        if count is None:
            raise ValueError("give n: no module prescribes the number of episodes")
        for i in range(start, start + count):
            yield self.episode(i)

    def feedback(self, index: int, outcome: str) -> None:
        """Tell every module how episode ``index`` ended (curricula promote on it)."""
        for m in self.modules:
            m.on_episode_end(index, outcome)

    def runtime(self, episode: Episode) -> TaskRuntime:
        """The goal logic for a drawn episode while it runs."""
        ctx = self._contexts.get(episode.index)
        if ctx is None:  # drawn by another generator (a worker): redraw the same episode here
            self.episode(episode.index)
            ctx = self._contexts[episode.index]
        return TaskRuntime(ctx, episode, modules=self.modules)

    # -- maps ------------------------------------------------------------------------------
    def _map(self, ctx: ResetContext) -> tuple[MapResult, np.ndarray]:
        spec_key = json.dumps(ctx.map_spec, sort_keys=True, default=str)
        key = (spec_key, ctx.seed, ctx.map_key)
        if key in self._maps:
            self._maps.move_to_end(key)
            return self._maps[key]
        source = self._sources.get(spec_key)
        if source is None:
            source = MAP_SOURCES.build(ctx.map_spec, source=self.source, path="map")
            self._sources[spec_key] = source
        result = source.build(derive_rng(ctx.seed, "map", ctx.map_key))
        entry = (result, wall_distance_map(result.grid))
        self._maps[key] = entry
        while len(self._maps) > self.MAP_CACHE:
            self._maps.popitem(last=False)
        return entry


@dataclass
class TaskUpdate:
    """What changed for the robots at one step.

    Attributes:
        goals: robot index → its new goal (the stack must replan).
        teleports: robot index → the pose the robot was moved to.
        reached: indices of robots that reached a goal at this step.
        done: every robot is done (the episode ends as a success).
        reset: the episode must end now (interactive force reset).
    """

    goals: dict[int, Pose2D] = field(default_factory=dict)
    teleports: dict[int, Pose2D] = field(default_factory=dict)
    reached: list[int] = field(default_factory=list)
    done: bool = False
    reset: bool = False


class TaskRuntime:
    """Per-step goal logic of one running episode: arrivals, new goals, timeouts, commands.

    Optional robot-mode hooks it uses (besides :meth:`~arena.tasks.base.RobotMode.next_goal`):

    - ``goal_timeout`` (s or ``None``) and ``on_goal_timeout(ctx, robot, rng, avoid) ->
      (pose, goal)``: a robot that has not reached its goal within ``goal_timeout`` seconds is
      teleported to ``pose`` with the new ``goal`` (``robots.explore``).
    - ``add_goal(ctx, robot, goal) -> Pose2D | None``: a goal set by a user is handed to the mode
      (``robots.guided`` appends it to its waypoint list) instead of replacing the robot's goal;
      the answer, if any, is the robot's new goal.
    - ``on_teleport(ctx, robot, pose) -> Pose2D``: the robot's goal after a user teleport
      (``robots.guided`` clears its list and idles there); without it the goal is kept.

    A robot whose goal equals the pose it just reached (or whose goal is its start) is *idle*:
    it counts no arrivals and waits for a new goal; it is not done. Modules with a
    ``poll(time) -> list[TaskCommand]`` method (``modules.interactive``) feed commands.

    Args:
        ctx: the episode's reset context (``None`` for a hand-built episode: single goals).
        episode: the episode.
        modules: the generator's modules (the interactive module feeds commands here).
    """

    def __init__(
        self, ctx: ResetContext | None, episode: Episode, *, modules: Sequence[Any] = ()
    ) -> None:
        self.ctx = ctx
        self.episode = episode
        self.modules = list(modules)
        self.goals = [r.goal for r in episode.robots]
        self.done = [False] * len(episode.robots)
        self.idle = [r.goal == r.start for r in episode.robots]
        self.goals_reached = [0] * len(episode.robots)
        self.goal_since = [0.0] * len(episode.robots)
        self.teleports = [0] * len(episode.robots)
        self.rng = ctx.rng("runtime") if ctx is not None else derive_rng(episode.seed, "runtime")
        mode: Any = ctx.robot_mode if ctx is not None else None
        timeout = getattr(mode, "goal_timeout", None)
        self.goal_timeout: float | None = (
            float(timeout) if timeout is not None and hasattr(mode, "on_goal_timeout") else None
        )
        for m in self.modules:
            bind = getattr(m, "bind", None)
            if callable(bind):
                bind(episode)

    @classmethod
    def single_goal(cls, episode: Episode, *, modules: Sequence[Any] = ()) -> TaskRuntime:
        """For an episode built by hand: each robot is done when it reaches its goal."""
        return cls(None, episode, modules=modules)

    def update(
        self, time: float, poses: np.ndarray, agents: np.ndarray | None = None
    ) -> TaskUpdate:
        """Check arrivals and timeouts at ``time`` (s), then apply module commands.

        Args:
            time: simulated time (s).
            poses: ``(n_robots, 3)`` robot poses.
            agents: optional ``(k, 2)`` pedestrian positions (m); timeout teleports avoid them.
        """
        upd = TaskUpdate()
        ep = self.episode
        mode: Any = self.ctx.robot_mode if self.ctx is not None else None
        arr = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
        current = [Pose2D.from_array(a) for a in arr]
        for i, pose in enumerate(current):
            if self.done[i] or self.idle[i]:
                continue
            if goal_reached(pose, self.goals[i], ep.goal_radius, ep.goal_tolerance_angle):
                self.goals_reached[i] += 1
                upd.reached.append(i)
                nxt = (
                    None
                    if self.ctx is None
                    else self.ctx.robot_mode.next_goal(self.ctx, i, pose, self.rng)
                )
                if nxt is None:
                    self.done[i] = True
                elif nxt == self.goals[i]:
                    self.idle[i] = True
                    self.goal_since[i] = time
                else:
                    self._set_goal(upd, i, nxt, time)
            elif (
                self.goal_timeout is not None
                and self.ctx is not None
                and time - self.goal_since[i] >= self.goal_timeout - 1e-9
            ):
                others = [arr[j, :2] for j in range(len(arr)) if j != i]
                if agents is not None and len(agents):
                    others += list(np.asarray(agents, dtype=np.float64).reshape(-1, 2))
                avoid = np.array(others).reshape(-1, 2)
                start, goal = mode.on_goal_timeout(self.ctx, i, self.rng, avoid)
                upd.teleports[i] = start
                self.teleports[i] += 1
                self._set_goal(upd, i, goal, time)
        for m in self.modules:
            poll = getattr(m, "poll", None)
            if callable(poll):
                for cmd in poll(time):
                    self._apply(upd, cmd, time)
        upd.done = all(self.done)
        return upd

    def _set_goal(self, upd: TaskUpdate, i: int, goal: Pose2D, time: float) -> None:
        self.goals[i] = goal
        self.goal_since[i] = time
        self.done[i] = False
        self.idle[i] = False
        upd.goals[i] = goal

    def _apply(self, upd: TaskUpdate, cmd: Any, time: float) -> None:
        """Apply one interactive command (``TaskCommand``) to the running episode."""
        # the interactive mode is imported when a config names it (TASK_MODES), and only it
        # sends commands
        from arena.tasks.modules.interactive import CommandError

        if cmd.kind == "reset":
            upd.reset = True
            return
        i = int(cmd.robot)
        if not 0 <= i < len(self.goals):
            raise CommandError(f"{cmd.kind}: no robot {i} (the episode has {len(self.goals)})")
        mode: Any = self.ctx.robot_mode if self.ctx is not None else None
        if cmd.kind == "teleport":
            upd.teleports[i] = cmd.pose
            self.teleports[i] += 1
            on_teleport = getattr(mode, "on_teleport", None)
            if callable(on_teleport):
                goal = on_teleport(self.ctx, i, cmd.pose)
                self._set_goal(upd, i, goal, time)
                self.idle[i] = goal == cmd.pose
            else:
                self.goal_since[i] = time
            return
        add_goal = getattr(mode, "add_goal", None)
        if callable(add_goal):
            nxt = add_goal(self.ctx, i, cmd.pose)
            # Every idle robot of the mode wakes up to the new waypoint list.
            for j in range(len(self.goals)):
                if j == i and nxt is not None:
                    self._set_goal(upd, j, nxt, time)
                elif j != i and self.idle[j] and self.ctx is not None:
                    g = mode.next_goal(self.ctx, j, self.goals[j], self.rng)
                    if g is not None and g != self.goals[j]:
                        self._set_goal(upd, j, g, time)
        else:
            self._set_goal(upd, i, cmd.pose, time)
