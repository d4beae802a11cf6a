"""The one episode loop: reset a backend, then tick it with hooks until the episode ends.

:class:`EpisodeRunner` is the tick loop of every path that simulates an episode:
``arena run`` and ``arena bench`` (:func:`arena.eval.episodes.run_episode`), the value-policy
trainer (:mod:`arena.learn.value.train`) and the learning environments'
:class:`~arena.learn.driver.EpisodeDriver`. What differs between them lives in
:class:`EpisodeHooks` (in the manner of dm_control's ``Task``), called in a fixed order::

    reset(episode):  backend.reset  -> initialize_episode (each hook)
    tick():          before_step (each hook) -> time limit -> controller.command
                     -> advance: backend.step x substeps -> after_step (each hook)
    the end:         episode_end (each hook), once

A hook or the controller ends the episode with :meth:`EpisodeRunner.end`. Any exception raised
by a hook, the controller or the backend ends it too: a :class:`~arena.core.errors.PlanningError`
as ``planner_failure``, anything else as ``error`` (a faulty plugin costs its episode, not the
run); the exception is kept in :attr:`EpisodeRunner.exception`.

The runner can be run to the end (:meth:`EpisodeRunner.run`) or ticked from outside
(:meth:`EpisodeRunner.tick`); an environment whose commands come from an agent drives
:meth:`EpisodeRunner.advance` itself.
"""

from __future__ import annotations

import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ArenaError, PlanningError
from arena.core.rng import derive_rng
from arena.core.types import Outcome, Pose2D
from arena.scene.episode import Episode
from arena.scene.state import SimState

if TYPE_CHECKING:
    from arena.sim.backend import PedestrianDriver, SimulatorBackend

FloatArray = NDArray[np.float64]


def describe_exception(e: BaseException) -> str:
    """One line for a failed episode: ``"<Type>: message"`` (its first line).

    Anything but an :class:`ArenaError` (a plugin's bug) gets ``" (at file.py:line)"``, where it
    was raised.
    """
    lines = str(e).strip().splitlines()
    text = f"{type(e).__name__}: {lines[0] if lines else ''}".rstrip(": ")
    if not isinstance(e, ArenaError):
        tb = traceback.extract_tb(e.__traceback__)
        if tb:
            text += f" (at {Path(tb[-1].filename).name}:{tb[-1].lineno})"
    return text


class EpisodeHooks:
    """What one part of an episode does at each point of the loop (no-ops by default).

    Every hook receives the runner: its :attr:`~EpisodeRunner.state`, :attr:`~EpisodeRunner.
    episode`, :attr:`~EpisodeRunner.backend`, and :meth:`~EpisodeRunner.end` /
    :meth:`~EpisodeRunner.event` to end the episode or note an event.
    """

    def initialize_episode(self, runner: EpisodeRunner) -> None:
        """After the backend reset: ``runner.state`` is the first snapshot."""

    def before_step(self, runner: EpisodeRunner) -> None:
        """At the start of a tick, before the time limit is checked and the command computed."""

    def after_step(self, runner: EpisodeRunner) -> None:
        """After each simulation step (``runner.state`` is the new snapshot)."""

    def episode_end(self, runner: EpisodeRunner) -> None:
        """Once, when the episode has ended (``runner.outcome`` is set)."""


class Controller(Protocol):
    """Where a tick's command comes from (the navigation stack, for benchmark episodes)."""

    def command(self, runner: EpisodeRunner) -> FloatArray:
        """``(r, 3)`` ``[vx m/s, vy m/s, ω rad/s]`` per robot for the next step.

        May end the episode instead (:meth:`EpisodeRunner.end`); the command is then ignored.
        """
        ...


class EpisodeRunner:
    """Steps one episode on a backend through its hooks.

    Args:
        backend: the simulator (reset once per episode by :meth:`reset`).
        dt: s, simulation step.
        hooks: called in this order at each point of the loop.
        controller: the command of each :meth:`tick` (``None``: only :meth:`advance` steps).
        substeps: simulation steps per tick, all with the tick's command.

    Attributes:
        state: the current snapshot.
        episode: the running episode.
        crowd: the pedestrian driver it was reset with (``None``: the backend's default).
        outcome: ``None`` while the episode runs, then how it ended.
        error: one line on the exception that ended it ("" if none).
        exception: that exception, or ``None``.
        events: ``(time s, kind, detail)`` noted by hooks (:meth:`event`), the outcome last.
        ticks: ticks advanced since the reset.
        teleported: robots moved by :meth:`teleport` since this tick began.
    """

    def __init__(
        self,
        backend: SimulatorBackend,
        dt: float,
        hooks: Sequence[EpisodeHooks] = (),
        controller: Controller | None = None,
        *,
        substeps: int = 1,
    ) -> None:
        self.backend = backend
        self.dt = float(dt)
        self.hooks = list(hooks)
        self.controller = controller
        self.substeps = int(substeps)
        self.episode: Episode | None = None
        self.state: SimState | None = None
        self.crowd: PedestrianDriver | None = None
        self.outcome: Outcome | None = None
        self.error = ""
        self.exception: BaseException | None = None
        self.events: list[tuple[float, str, str]] = []
        self.ticks = 0
        self.teleported: list[int] = []
        self._ended = False

    # -- episodes -------------------------------------------------------------------------------
    def reset(
        self, episode: Episode, crowd: PedestrianDriver | None, seed: int
    ) -> SimState:
        """Start ``episode``: reset the backend, then every hook's ``initialize_episode``.

        The backend draws from ``derive_rng(seed, "episode", episode.index, "sim")``, so an
        episode of ``arena run``, ``arena bench`` and the learning env with the same seed and
        index are the same. A hook raising here ends the episode at once (see the module doc).
        """
        self.episode, self.crowd = episode, crowd
        self.state = self.backend.reset(
            episode, crowd, derive_rng(seed, "episode", episode.index, "sim")
        )
        self.outcome, self.error, self.exception = None, "", None
        self.events = []
        self.ticks = 0
        self.teleported = []
        self._ended = False
        try:
            for hook in self.hooks:
                hook.initialize_episode(self)
        except Exception as e:
            self._fail(e)
        self._close()
        return self.state

    @property
    def running(self) -> bool:
        """The episode has not ended."""
        return self.outcome is None

    def end(self, outcome: Outcome, error: str = "") -> None:
        """End the episode as ``outcome`` (a hook or the controller calls this)."""
        if self.outcome is None:
            self.outcome, self.error = outcome, error

    def event(self, kind: str, detail: str = "") -> None:
        """Note an event at the current time (e.g. ``goal_reached``, ``teleport``)."""
        assert self.state is not None
        self.events.append((float(self.state.time), kind, detail))

    def teleport(self, i: int, pose: Pose2D) -> SimState:
        """Move robot ``i`` to ``pose`` (:meth:`SimulatorBackend.teleport`); the new state."""
        self.state = self.backend.teleport(i, pose)
        self.teleported.append(i)
        return self.state

    def at_time_limit(self) -> bool:
        """The episode's time limit is reached."""
        assert self.state is not None
        assert self.episode is not None
        return bool(self.state.time >= self.episode.time_limit - 1e-9)

    # -- stepping -------------------------------------------------------------------------------
    def advance(self, command: FloatArray) -> SimState:
        """Step the backend ``substeps`` times with ``command`` ``(r, 3)``; the new state.

        Each step is followed by every hook's ``after_step``; the call counts one tick.
        """
        hooks = self.hooks
        for _ in range(self.substeps):
            self.state = self.backend.step(command, self.dt)
            for hook in hooks:
                hook.after_step(self)
        self.ticks += 1
        assert self.state is not None
        return self.state

    def tick(self) -> bool:
        """One tick: hooks, time limit, the controller's command, :meth:`advance`.

        Returns:
            Whether the episode still runs afterwards.
        """
        if self.outcome is not None:
            return False
        assert self.controller is not None, "tick() needs a controller"
        self.teleported = []
        try:
            for hook in self.hooks:
                hook.before_step(self)
                if self.outcome is not None:
                    break
            if self.outcome is None and self.at_time_limit():
                self.end(Outcome.TIMEOUT)
            if self.outcome is None:
                cmd = self.controller.command(self)
                if self.outcome is None:
                    self.advance(cmd)
        except Exception as e:  # a faulty plugin (any exception) costs this episode, not the run
            self._fail(e)
        self._close()
        return self.outcome is None

    def run(self) -> Outcome:
        """Tick until the episode ends; its outcome."""
        while self.tick():
            pass
        assert self.outcome is not None
        return self.outcome

    # -- internals ------------------------------------------------------------------------------
    def _fail(self, e: BaseException) -> None:
        self.exception = e
        if isinstance(e, PlanningError):
            self.end(Outcome.PLANNER_FAILURE, f"{type(e).__name__}: {e}")
        else:
            self.end(Outcome.ERROR, describe_exception(e))

    def _close(self) -> None:
        """Once the episode has ended: the outcome event, then every ``episode_end``."""
        if self.outcome is None or self._ended:
            return
        self._ended = True
        self.event("outcome", self.outcome.value)
        for hook in self.hooks:
            hook.episode_end(self)

