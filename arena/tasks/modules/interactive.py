"""``modules.interactive``: teleport robots, set goals and force resets while episodes run.

Arena's ``rviz_ui`` module (specs §2.8) turns RViz clicks into a teleport (``/initialpose``), a
new goal (``/goalpose``) or a forced reset (``/clicked_point``). Here the same three commands come
from any thread (the CLI's stdin reader, a web UI) through a thread-safe queue::

    ui = InteractiveModule()
    ui.set_goal(0, Pose2D(4.0, 2.0, 0.0))      # robot 0 → (4, 2); guided robots append it
    ui.teleport(0, Pose2D(1.0, 1.0, 0.0))
    ui.reset()                                  # end the running episode

or from a deterministic ``script`` of timed commands (``t`` in s of simulated episode time)::

    modules: [{type: interactive, script: [{t: 5.0, goal: [4, 2, 0]},
                                           {t: 9.0, teleport: [1, 1, 0], robot: 0},
                                           {t: 20, reset: true}]}]

The :class:`~arena.tasks.generator.TaskRuntime` polls :meth:`InteractiveModule.poll` every step
and applies the commands (see :class:`~arena.tasks.generator.TaskUpdate`). Positions are checked
when a command is given (once the first episode is known) and again when it is applied: inside
the map, not in a wall, and with room for the robot's body.
"""

from __future__ import annotations

import math
import queue
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.core.errors import ArenaError, ConfigError
from arena.core.types import Pose2D
from arena.scene.episode import Episode
from arena.tasks.base import ModuleBase, ResetContext, register_mode
from arena.tasks.world import WorldSampler

CommandKind = Literal["teleport", "goal", "reset"]


class CommandError(ArenaError):
    """An interactive command that cannot be applied (bad robot index or position)."""


@dataclass(frozen=True)
class TaskCommand:
    """One interactive command.

    Attributes:
        kind: ``teleport``, ``goal`` or ``reset``.
        robot: the robot index (ignored by ``reset``).
        pose: target pose (m, rad) of ``teleport`` and ``goal``; ``None`` for ``reset``.
    """

    kind: CommandKind
    robot: int = 0
    pose: Pose2D | None = None


class ScriptEntry(BaseModel):
    """One timed command of ``modules.interactive.script``: exactly one of goal/teleport/reset."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    t: float = Field(ge=0, description="s of simulated episode time at which it applies")
    robot: int = Field(0, ge=0, description="robot index")
    goal: tuple[float, float] | tuple[float, float, float] | None = Field(
        None, description="[x m, y m] or [x, y, theta rad]: set a goal"
    )
    teleport: tuple[float, float] | tuple[float, float, float] | None = Field(
        None, description="[x m, y m] or [x, y, theta rad]: move the robot there"
    )
    reset: bool = Field(False, description="end the episode")

    @model_validator(mode="after")
    def _one(self) -> ScriptEntry:
        given = [k for k in ("goal", "teleport") if getattr(self, k) is not None]
        given += ["reset"] if self.reset else []
        if len(given) != 1:
            raise ValueError(
                f"a script entry needs exactly one of goal, teleport, reset: true (got "
                f"{', '.join(given) or 'none'})"
            )
        return self

    def command(self) -> TaskCommand:
        """The entry as a :class:`TaskCommand`."""
        if self.reset:
            return TaskCommand("reset", self.robot)
        kind: CommandKind = "goal" if self.goal is not None else "teleport"
        xy = self.goal if self.goal is not None else self.teleport
        assert xy is not None
        return TaskCommand(kind, self.robot, Pose2D.from_array(list(xy)))


@register_mode("modules", "interactive", tags=("ui",))
class InteractiveModule(ModuleBase):
    """Thread-safe teleport / set-goal / reset commands and timed scripted commands."""

    class Params(BaseModel):
        """Parameters of ``modules.interactive``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        script: list[ScriptEntry] = Field(
            default_factory=list,
            description="timed commands [{t: s, goal|teleport: [x, y, th], robot: i} | "
            "{t: s, reset: true}], replayed in every episode",
        )
        clearance: float = Field(
            0.1, ge=0,
            description="m beyond the robot radius a goal or teleport target keeps from walls",
        )

    def __init__(
        self, params: Params | None = None, *, on_error: Callable[[str], None] | None = None
    ) -> None:
        self.params = params or self.Params()
        self.on_error = on_error
        """Called with the message of each command dropped when applied."""
        self.ready = threading.Event()
        """Set once an episode is bound: commands are then validated against its map."""
        self._queue: queue.SimpleQueue[TaskCommand] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._script = sorted(self.params.script, key=lambda e: e.t)
        self._next = 0
        self._world: WorldSampler | None = None
        self._radii: list[float] = []
        self._map_name = ""
        self.errors: list[str] = []
        """Commands dropped when applied (their position no longer valid), as messages."""

    # -- commands (any thread) -----------------------------------------------------------------
    def teleport(self, robot: int, pose: Pose2D) -> None:
        """Queue moving ``robot`` to ``pose`` (m, rad).

        Raises:
            CommandError: bad robot index or position (once an episode is known).
        """
        self._put(TaskCommand("teleport", int(robot), pose))

    def set_goal(self, robot: int, pose: Pose2D) -> None:
        """Queue a new goal for ``robot`` (guided robots append it to their waypoint list).

        Raises:
            CommandError: bad robot index or position (once an episode is known).
        """
        self._put(TaskCommand("goal", int(robot), pose))

    def reset(self) -> None:
        """Queue a forced reset: the running episode ends."""
        self._queue.put(TaskCommand("reset"))

    def _put(self, cmd: TaskCommand) -> None:
        with self._lock:
            self.validate(cmd)
        self._queue.put(cmd)

    # -- validation ----------------------------------------------------------------------------
    def validate(self, cmd: TaskCommand) -> None:
        """Check a command against the current episode's map (no-op before the first episode).

        Raises:
            CommandError: unknown robot, non-finite pose, off the map, in a wall, or too close
                to one for the robot's body (radius + ``clearance``).
        """
        if cmd.kind == "reset":
            return
        if cmd.pose is None:
            raise CommandError(f"a {cmd.kind} command needs a pose")
        p = cmd.pose
        if not all(math.isfinite(v) for v in (p.x, p.y, p.theta)):
            raise CommandError(f"{cmd.kind}: the pose must be finite, got {p}")
        world = self._world
        if world is None:
            if cmd.robot < 0:
                raise CommandError(f"{cmd.kind}: robot index must be >= 0, got {cmd.robot}")
            return
        n = len(self._radii)
        if not 0 <= cmd.robot < n:
            raise CommandError(f"{cmd.kind}: no robot {cmd.robot} (the episode has {n})")
        grid = world.grid
        cell = grid.world_to_cell(p.xy)
        where = f"{cmd.kind} ({p.x:g}, {p.y:g})"
        if not bool(grid.in_bounds(cell)):
            (x0, y0), (w, h) = grid.origin, grid.size_m
            raise CommandError(
                f"{where} lies outside the map {self._map_name!r} "
                f"(x {x0:g}..{x0 + w:g}, y {y0:g}..{y0 + h:g} m)"
            )
        if not bool(grid.free[int(cell[0]), int(cell[1])]):
            raise CommandError(f"{where} lies in a wall of map {self._map_name!r}")
        need = self._radii[cmd.robot] + self.params.clearance
        d = float(world.wall_distance(p.xy[None])[0])
        if d < need:
            raise CommandError(
                f"{where} is {d:.2f} m from a wall; robot {cmd.robot} needs {need:.2f} m"
            )

    # -- hooks ---------------------------------------------------------------------------------
    def after_reset(self, ctx: ResetContext, episode: Episode) -> Episode:
        """Learn the episode's map and robots; check the script's positions against them."""
        self.bind(episode)
        for k, entry in enumerate(self._script):
            try:
                self.validate(entry.command())
            except CommandError as e:
                raise ConfigError(str(e), path=f"task.modules.interactive.script[{k}]") from None
        return episode

    def bind(self, episode: Episode) -> None:
        """Start an episode: validation uses its map; the script starts over at ``t = 0``."""
        world = WorldSampler(episode.grid)
        with self._lock:
            self._world = world
            self._radii = [r.model.radius for r in episode.robots]
            self._map_name = episode.map_name
            self._next = 0
        self.ready.set()

    def poll(self, time: float) -> list[TaskCommand]:
        """Commands due at ``time`` (s): scripted ones with ``t <= time``, then queued ones.

        Commands whose position is invalid for the running episode are dropped and their
        message appended to :attr:`errors`.
        """
        due: list[TaskCommand] = []
        while self._next < len(self._script) and self._script[self._next].t <= time + 1e-9:
            due.append(self._script[self._next].command())
            self._next += 1
        while True:
            try:
                due.append(self._queue.get_nowait())
            except queue.Empty:
                break
        out = []
        for cmd in due:
            try:
                with self._lock:
                    self.validate(cmd)
            except CommandError as e:
                self.errors.append(str(e))
                if self.on_error is not None:
                    self.on_error(str(e))
                continue
            out.append(cmd)
        return out

    def pending(self) -> bool:
        """Whether queued (not scripted) commands wait to be polled."""
        return not self._queue.empty()


def parse_command(line: str) -> TaskCommand | None:
    """Parse one text command: ``goal X Y [TH]``, ``teleport X Y [TH]``, ``reset``, ``quit``.

    An optional ``robot=I`` word picks the robot (default 0). Returns ``None`` for ``quit``.

    Raises:
        CommandError: unknown command or bad numbers (the message says what is expected).
    """
    words = line.split()
    usage = "expected: goal X Y [TH] | teleport X Y [TH] | reset | quit  (optional robot=I)"
    if not words:
        raise CommandError(f"empty command; {usage}")
    robot = 0
    rest = []
    for w in words[1:]:
        if w.startswith("robot="):
            try:
                robot = int(w.split("=", 1)[1])
            except ValueError:
                raise CommandError(f"bad robot index in {w!r}; {usage}") from None
        else:
            rest.append(w)
    kind = words[0].lower()
    if kind in ("quit", "exit", "q"):
        return None
    if kind == "reset":
        if rest:
            raise CommandError(f"reset takes no arguments; {usage}")
        return TaskCommand("reset")
    if kind not in ("goal", "teleport"):
        raise CommandError(f"unknown command {words[0]!r}; {usage}")
    try:
        values = [float(v) for v in rest]
    except ValueError:
        raise CommandError(f"{kind} needs numbers, got {' '.join(rest)!r}; {usage}") from None
    if len(values) not in (2, 3) or not all(np.isfinite(values)):
        raise CommandError(f"{kind} needs X Y [TH] (finite numbers); {usage}")
    return TaskCommand("goal" if kind == "goal" else "teleport", robot, Pose2D(*values))
