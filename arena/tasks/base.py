"""Task modes: the plugin API of the task generator (Arena specs §2.1).

A task is one **robot** mode + one **obstacle** mode + any number of **modules**, all
registered in :data:`TASK_MODES` under ``<role>.<name>`` (``robots.random``,
``obstacles.parametrized``, ``modules.staged``). The :class:`~arena.tasks.generator.TaskGenerator`
resets an episode in Arena's order::

    modules.before_reset(ctx)          # may change counts, map, robots, modes, seed, limits
    map  = ctx.map_spec built for ctx.map_key (cached)
    robots    = robot_mode.reset(ctx)        # start and goal per robot
    obstacles = obstacle_mode.reset(ctx)     # static obstacles and pedestrians
    modules.after_reset(ctx, episode)  # may edit the finished episode

Every random draw comes from ``ctx.rng(<component>)``, a generator derived from the episode's
seed, so an episode is a pure function of (config, seed, index).

During an episode the robot mode decides what happens when a robot reaches its goal
(:meth:`RobotMode.next_goal`: a new goal, or ``None`` when the robot is done), which is how
``explore``, ``guided`` and ``zones`` keep robots busy.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

import numpy as np

from arena.core.errors import ConfigError, UnknownNameError
from arena.core.registry import Registry
from arena.core.rng import derive_rng
from arena.core.types import Pose2D
from arena.maps.sources import MapResult
from arena.robots.model import RobotModel
from arena.scene.episode import AgentSpawn, Episode, RobotSpawn
from arena.scene.state import Obstacle
from arena.tasks.world import WorldSampler

Role = Literal["robots", "obstacles", "modules"]
ROLES: tuple[Role, ...] = ("robots", "obstacles", "modules")


@dataclass
class ObstacleCounts:
    """Count overrides a module (``staged``) imposes on the obstacle mode; ``None`` = keep."""

    static: int | None = None
    interactive: int | None = None
    dynamic: int | None = None


@dataclass
class ResetContext:
    """Everything one episode reset reads and writes.

    Modules edit it in ``before_reset``; the generator then builds the map, and the robot and
    obstacle modes sample into ``world``.

    Attributes:
        index: episode number within the run (or within the benchmark stage).
        seed: the seed the episode's generators derive from.
        map_spec: the ``map`` block to build (``{type: ..., ...}``).
        map_key: which instance of ``map_spec`` to build; episodes with equal keys share one
            map (``dynamic_map`` sets it to ``index // episodes_per_map``).
        robots: the robot models of the episode.
        robot_mode, obstacle_mode: the modes that will sample the episode.
        counts: obstacle count overrides (``staged``).
        forbidden: keep-out zones (:class:`~arena.tasks.config.ForbiddenZone`) put into the
            world's forbidden layer before anything is sampled; starts with the config's
            ``task.forbidden_zones``, emptied by ``clear_forbidden_zones``.
        timeout: s of simulated time before the episode ends.
        goal_radius: m; goal_tolerance_angle: rad or ``None`` (heading not checked).
        spawns: the robots' starts and goals, once the robot mode has placed them.
        map_result, world: set by the generator once the map is built.
        label: a name for reports (the benchmark stage).
    """

    index: int
    seed: int
    map_spec: dict[str, Any]
    map_key: int
    robots: list[RobotModel]
    robot_mode: RobotMode
    obstacle_mode: ObstacleMode
    timeout: float
    goal_radius: float
    goal_tolerance_angle: float | None
    counts: ObstacleCounts = field(default_factory=ObstacleCounts)
    forbidden: list[Any] = field(default_factory=list)
    label: str = ""
    spawns: list[RobotSpawn] = field(default_factory=list)
    map_result: MapResult | None = None
    world: WorldSampler | None = None

    def rng(self, *component: str | int) -> np.random.Generator:
        """The generator for one component of this episode (``ctx.rng("robots")``)."""
        return derive_rng(self.seed, "episode", self.index, *component)

    @property
    def map(self) -> MapResult:
        """The episode's map (after the generator built it)."""
        if self.map_result is None:
            raise RuntimeError("the map is built after modules.before_reset")
        return self.map_result

    @property
    def sampler(self) -> WorldSampler:
        """The position sampler over the episode's map (after the generator built it)."""
        if self.world is None:
            raise RuntimeError("the world sampler exists after modules.before_reset")
        return self.world


class RobotMode(Protocol):
    """Places robots: start and goal per robot, and what happens on arrival."""

    def reset(self, ctx: ResetContext) -> list[RobotSpawn]:
        """Start and goal for every model in ``ctx.robots``."""
        ...

    def next_goal(
        self, ctx: ResetContext, robot: int, pose: Pose2D, rng: np.random.Generator
    ) -> Pose2D | None:
        """The next goal after ``robot`` reached its goal at ``pose``; ``None`` = done."""
        ...


class ObstacleMode(Protocol):
    """Places static obstacles and pedestrians."""

    def reset(self, ctx: ResetContext) -> tuple[list[Obstacle], AgentSpawn]:
        """Obstacles added to the map's own, and the pedestrians."""
        ...


class TaskModule(Protocol):
    """Hooks around each reset (curricula, map changes, benchmark stages, UI)."""

    def before_reset(self, ctx: ResetContext) -> None:
        """Edit the context before anything is sampled."""
        ...

    def after_reset(self, ctx: ResetContext, episode: Episode) -> Episode:
        """Return the (possibly edited) finished episode."""
        ...

    def on_episode_end(self, index: int, outcome: str) -> None:
        """Feedback once an episode has been simulated (``outcome``: an Outcome value)."""
        ...


class ModuleBase:
    """No-op hooks; modules override the ones they need."""

    def before_reset(self, ctx: ResetContext) -> None:
        """Nothing to change."""

    def after_reset(self, ctx: ResetContext, episode: Episode) -> Episode:
        """The episode unchanged."""
        return episode

    def on_episode_end(self, index: int, outcome: str) -> None:
        """Ignore feedback."""


class SingleGoal:
    """``next_goal`` for modes whose robots are done on arrival (random, scenario)."""

    def next_goal(
        self, ctx: ResetContext, robot: int, pose: Pose2D, rng: np.random.Generator
    ) -> Pose2D | None:
        """``None``: the robot is done."""
        return None


_BUILTIN_MODES = {
    "robots": ("explore", "guided", "random", "scenario", "zones"),
    "obstacles": ("parametrized", "random", "scenario", "zones"),
    "modules": ("benchmark", "clear_forbidden_zones", "dynamic_map", "interactive", "staged"),
}
_PACKAGES = {"robots": "robot_modes", "obstacles": "obstacle_modes", "modules": "modules"}

TASK_MODES: Registry[Any] = Registry(
    "task mode",
    entry_points="arena.task_modes",
    # <role>.<name> -> arena.tasks.<role package>.<name>, imported when the mode is first named
    builtins={
        f"{role}.{name}": f"arena.tasks.{_PACKAGES[role]}.{name}"
        for role, names in _BUILTIN_MODES.items()
        for name in names
    },
)
"""Every task mode, named ``<role>.<name>`` and tagged with its role."""


def register_mode(
    role: Role, name: str, *, tags: tuple[str, ...] = ()
) -> Callable[[Any], Any]:
    """Class decorator: register a task mode under ``<role>.<name>`` with the role as a tag."""
    return TASK_MODES.register(f"{role}.{name}", tags=(role, *tags))


def mode_names(role: Role) -> list[str]:
    """Short names of the modes of one role (``["explore", "guided", "random", ...]``)."""
    prefix = f"{role}."
    return [n.removeprefix(prefix) for n in TASK_MODES.names() if n.startswith(prefix)]


def _qualified(
    role: Role, spec: Mapping[str, Any] | str, *, source: str | None, path: str | None
) -> dict[str, Any]:
    if isinstance(spec, str):
        spec = {"type": spec}
    if not isinstance(spec, Mapping):
        raise ConfigError(
            f"expected a mapping {{type: <{role} mode>, ...}}, got {spec!r}",
            source=source,
            path=path,
        )
    if "type" not in spec:
        raise ConfigError(
            f"missing 'type' (one of: {', '.join(mode_names(role))})", source=source, path=path
        )
    name = spec["type"]
    if f"{role}.{name}" not in TASK_MODES:
        known = mode_names(role)
        close = difflib.get_close_matches(str(name), known, n=1, cutoff=0.5)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise UnknownNameError(
            f"unknown {role} task mode {name!r}; {hint}known: {', '.join(known)}",
            source=source,
            path=".".join(p for p in (path, "type") if p),
        )
    return {**spec, "type": f"{role}.{name}"}


def validate_mode(
    role: Role, spec: Mapping[str, Any] | str, *, source: str | None = None, path: str | None = None
) -> None:
    """Check one mode block against its role's registry (errors name ``source`` and ``path``)."""
    TASK_MODES.validate(_qualified(role, spec, source=source, path=path), source=source, path=path)


def build_mode(
    role: Role, spec: Mapping[str, Any] | str, *, source: str | None = None, path: str | None = None
) -> Any:
    """Build the ``role`` mode a config block names (``{type: random, ...}``)."""
    return TASK_MODES.build(_qualified(role, spec, source=source, path=path), source=source,
                            path=path)
