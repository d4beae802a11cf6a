"""A viewer's hold on a running episode: pause, single steps, speed, goals and teleports.

:class:`LiveControl` is shared between the simulation thread (which calls :meth:`LiveControl.
wait` before every tick) and the viewers' threads (which call :meth:`LiveControl.apply` with
their messages). Goals and teleports go through the run's
:class:`~arena.tasks.modules.interactive.InteractiveModule`, Arena's guided and interactive
modes, so they are checked against the map exactly as ``arena run --interactive`` commands are.

Only the wall-clock pace changes with pause and speed; the simulated episode stays the same
(the same steps with the same commands), so a watched episode has the figures of an unwatched
one unless a viewer sets goals or moves the robot.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from arena.core.types import Pose2D
from arena.tasks.modules.interactive import CommandError, InteractiveModule

#: Fastest and slowest pace a viewer may set (multiples of real time); 0 = as fast as it goes.
MAX_SPEED = 64.0
MIN_SPEED = 1.0 / 16.0


class LiveControl:
    """Pause, steps, speed and the interactive commands of one run (thread-safe).

    Args:
        speed: initial pace, a multiple of real time (``0``: as fast as the computer goes).
        interactive: where goal and teleport commands go; ``None`` refuses them (benchmarks,
            whose figures must not depend on a viewer).
        clock, sleep: wall clock (s) and sleep, replaceable in tests.
    """

    def __init__(
        self,
        speed: float = 1.0,
        interactive: InteractiveModule | None = None,
        *,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.interactive = interactive
        self._clock, self._sleep = clock, sleep
        self._cond = threading.Condition()
        self._paused = False
        self._steps = 0
        self._closed = False
        self._speed = self._checked_speed(speed)
        self._anchor: tuple[float, float] | None = None  # (wall s, sim s) the pace counts from
        self._last_time = 0.0  # the last tick's sim time (s): a smaller one starts an episode
        self.listeners: list[Callable[[dict[str, Any]], None]] = []
        """Called with :meth:`status` after every change (the live server tells its viewers)."""

    # -- state ------------------------------------------------------------------------------------
    @property
    def paused(self) -> bool:
        """A viewer paused the run."""
        return self._paused

    @property
    def speed(self) -> float:
        """The pace, a multiple of real time (0: as fast as it goes)."""
        return self._speed

    def status(self) -> dict[str, Any]:
        """``{"type": "status", "paused", "speed", "interactive"}`` (JSON-ready)."""
        return {"type": "status", "paused": self._paused, "speed": self._speed,
                "interactive": self.interactive is not None}

    @staticmethod
    def _checked_speed(speed: float) -> float:
        s = float(speed)
        if not math.isfinite(s) or s < 0:
            raise CommandError(
                f"speed must be a number >= 0 (0: as fast as possible), got {speed!r}")
        return 0.0 if s == 0 else min(MAX_SPEED, max(MIN_SPEED, s))

    # -- the viewers' side ------------------------------------------------------------------------
    def pause(self) -> None:
        """Hold the run before its next tick."""
        with self._cond:
            self._paused, self._steps = True, 0
        self._changed()

    def resume(self) -> None:
        """Let the run go on at its pace."""
        with self._cond:
            self._paused, self._anchor = False, None
            self._cond.notify_all()
        self._changed()

    def step(self, count: int = 1) -> None:
        """While paused: let ``count`` more ticks run (pauses first when running)."""
        with self._cond:
            self._paused = True
            self._steps += max(1, int(count))
            self._cond.notify_all()
        self._changed()

    def set_speed(self, speed: float) -> None:
        """Set the pace (see :attr:`speed`; clipped to 1/16..64)."""
        value = self._checked_speed(speed)
        with self._cond:
            self._speed, self._anchor = value, None
            self._cond.notify_all()
        self._changed()

    def close(self) -> None:
        """Release the simulation for good (the run ends or the server stops)."""
        with self._cond:
            self._closed, self._paused = True, False
            self._cond.notify_all()

    def apply(self, message: Mapping[str, Any]) -> None:
        """Apply one viewer message.

        Messages: ``{"cmd": "pause" | "resume" | "reset"}``, ``{"cmd": "step", "count": n}``,
        ``{"cmd": "speed", "value": s}``, ``{"cmd": "goal" | "teleport", "x": m, "y": m,
        "theta": rad, "robot": i}`` (theta and robot optional).

        Raises:
            CommandError: an unknown command, a bad value, or a goal or teleport refused (no
                interactive module, or a position off the map or in a wall).
        """
        cmd = message.get("cmd")
        if cmd == "pause":
            self.pause()
        elif cmd == "resume":
            self.resume()
        elif cmd == "step":
            self.step(_int(message.get("count", 1), "count"))
        elif cmd == "speed":
            self.set_speed(_number(message.get("value"), "value"))
        elif cmd in ("goal", "teleport", "reset"):
            if self.interactive is None:
                raise CommandError(f"{cmd}: this run takes no goals or teleports (a benchmark)")
            if cmd == "reset":
                self.interactive.reset()
                return
            pose = Pose2D(_number(message.get("x"), "x"), _number(message.get("y"), "y"),
                          _number(message.get("theta", 0.0), "theta"))
            robot = _int(message.get("robot", 0), "robot")
            if cmd == "goal":
                self.interactive.set_goal(robot, pose)
            else:
                self.interactive.teleport(robot, pose)
        else:
            raise CommandError(
                f"unknown command {cmd!r} (expected pause, resume, step, speed, goal, teleport "
                "or reset)"
            )

    def _changed(self) -> None:
        status = self.status()
        for listener in list(self.listeners):
            listener(status)

    # -- the simulation's side --------------------------------------------------------------------
    def wait(self, sim_time: float) -> None:
        """Block until the tick at ``sim_time`` (s) may run.

        It may once the run is not paused (or a step is granted) and the pace allows it.
        """
        with self._cond:
            while self._paused and self._steps == 0 and not self._closed:
                self._cond.wait(0.25)
            if self._closed:
                return
            if self._paused:
                self._steps -= 1
                self._anchor = None
                return
            if self._speed == 0:
                return
            now = self._clock()
            if self._anchor is None or sim_time < self._last_time:
                self._anchor = (now, sim_time)  # the first tick, or a new episode's clock
            self._last_time = sim_time
            ahead = self._anchor[0] + (sim_time - self._anchor[1]) / self._speed - now
        if ahead > 0:
            self._sleep(ahead)


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise CommandError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def _int(value: Any, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise CommandError(f"{name} must be an integer, got {value!r}")
    return value
