"""Episodes drawn ahead in a helper process, for the batched env.

Drawing an episode (placing obstacles and pedestrians, sampling start and goal, checking lines
of sight) is single-threaded Python: 3-4 ms on a packaged office map with 20 people. The
batched env steps its ``N`` worlds with numba threads on every core, but its own Python between
two kernel launches (rewards, observations, episode ends) runs on one core while the others
wait, and it drew restarting worlds' episodes there too: with 16 worlds, a fifth of the
training process's time. :class:`EpisodePrefetcher` moves the drawing to one helper process that
keeps each world's next episode ready; it runs on the cores the kernels leave idle.

The helper runs under ``SCHED_IDLE`` (Linux; elsewhere at a lower nice level): the scheduler
gives it a core only when no other thread wants it, so the kernels' threads, which wait for each
other at the end of every launch, are never held up by it. Measured on 2 shared cores
(``benchmarks/env_throughput.py``'s setup, 16 worlds, rounds of both envs interleaved in one
process): 19,115 env steps/s median without the helper against 22,603 with it (and 12,539
against 17,086 in a slower hour). In one comparison of all three, 11,735 without the helper
rose to 14,255 with it at nice 10 and to 15,174 under ``SCHED_IDLE``. The helper needs a few
seconds to start (imports, compiled kernels); until its first episodes arrive the env draws
them itself.

Results do not change: an episode is a pure function of ``(config, robot, seed, stage,
index)`` (every draw comes from ``derive_rng(seed, "episode", index, …)``), and the helper
builds its :class:`~arena.tasks.generator.TaskGenerator` exactly as the env does, so the
episode of index ``i`` is the one the env would have drawn itself (tested bit for bit).

Transport: episodes are pickled through a pipe to a fresh interpreter (POSIX only). Maps
(``OccupancyGrid``, ≈ 1.7 MB with its distance map) travel once per map: the helper sends a
new map in its own message under a token, and later episodes refer to the token (pickle's
``persistent_id``), so a fixed map is shared by all episodes, as the engine's banks expect
(they keep one copy of a map's static geometry per map object).
The robot model travels the same way, once, at start. The helper computes each new map's
distance transform before sending it, off the main process.
"""

from __future__ import annotations

import contextlib
import io
import os
import pickle
import select
import subprocess
import sys
import time
import warnings
from collections import OrderedDict, deque
from collections.abc import Callable, Iterable
from multiprocessing.connection import Connection
from typing import Any

from arena.maps.grid import OccupancyGrid
from arena.robots.model import RobotModel
from arena.scene.episode import Episode

#: Builds the task generator placing ``robot`` for ``(seed, stage)`` (stage ``None``: no
#: curriculum stage set).
GeneratorFactory = Callable[[RobotModel, int, "int | None"], Any]

#: Maps the helper remembers having sent; older ones are dropped on both sides. Dynamic maps
#: make a new map per episode and each costs megabytes; a map sent again after its drop is an
#: equal copy, which changes no result.
MAX_MAPS = 16

#: Niceness added to the helper process where ``SCHED_IDLE`` is not available (see :func:`main`).
NICE = 19

_ROBOT = "robot"


class _Pickler(pickle.Pickler):
    """Pickles maps already sent, and the robot model, as references (tokens)."""

    def __init__(self, file: io.BytesIO, sent: dict[int, tuple[int, OccupancyGrid]],
                 robot: RobotModel) -> None:
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.sent = sent
        self.robot = robot

    def persistent_id(self, obj: Any) -> Any:
        if obj is self.robot:
            return _ROBOT
        if isinstance(obj, OccupancyGrid):
            entry = self.sent.get(id(obj))
            if entry is not None and entry[1] is obj:
                return entry[0]
        return None


class _Unpickler(pickle.Unpickler):
    def __init__(self, file: io.BytesIO, grids: dict[int, OccupancyGrid],
                 robot: RobotModel) -> None:
        super().__init__(file)
        self.grids = grids
        self.robot = robot

    def persistent_load(self, pid: Any) -> Any:
        if pid == _ROBOT:
            return self.robot
        return self.grids[int(pid)]


class EpisodePrefetcher:
    """Draws episodes by index in a helper process, ahead of their use.

    Args:
        factory: builds the task generator for ``(robot, seed, stage)``; it must be picklable (a
            module-level function or a ``functools.partial`` of one): the helper process calls
            it.
        robot: the robot model the generator places (sent once, shared by every episode).
        seed: the episode seed.
        stage: the curriculum stage (``None``: leave the generator's own).

    Use :meth:`request` for indices needed soon and :meth:`take` when one is needed now (it
    returns ``None`` for one not drawn yet: draw it yourself);
    :meth:`restart` after a seed or stage change (episodes drawn before it are discarded);
    :meth:`close` (or garbage collection) ends the helper. If the helper dies (killed, out of
    memory), a ``RuntimeWarning`` says so once and :meth:`take` returns ``None`` from then on:
    the caller draws every episode itself, which changes no result.
    """

    def __init__(self, factory: GeneratorFactory, robot: RobotModel, seed: int,
                 stage: int | None = None) -> None:
        self.robot = robot
        from_parent, to_child = os.pipe()
        from_child, to_parent = os.pipe()
        # A fresh interpreter (``python -m arena.learn.prefetch``), not multiprocessing: ``fork``
        # would copy a parent that runs numba threads, and ``spawn``/``forkserver`` re-import
        # the user's main script, which breaks scripts without an ``if __name__`` guard.
        self._proc = subprocess.Popen(
            [sys.executable, "-m", "arena.learn.prefetch", str(from_parent), str(to_parent)],
            pass_fds=(from_parent, to_parent), stdin=subprocess.DEVNULL,
        )
        os.close(from_parent)
        os.close(to_parent)
        self._out = Connection(to_child, readable=False)
        self._in = Connection(from_child, writable=False)
        # One poll object for the life of the pipe: ``Connection.poll`` builds a selector per
        # call, which cost ~20 µs on every env step.
        self._poller = select.poll()
        self._poller.register(from_child, select.POLLIN)
        self._closed = False
        self._lost = False  # the helper went away: every episode is drawn by the caller
        self._send(("start", factory, robot, int(seed), stage))
        self._epoch = 0
        self._grids: dict[int, OccupancyGrid] = {}
        self._ready: dict[int, Episode] = {}
        self._pending: set[int] = set()
        self._failed: set[int] = set()

    # -- requests ------------------------------------------------------------------------------
    def restart(self, seed: int, stage: int | None) -> None:
        """Draw from ``(seed, stage)`` from now on, dropping episodes drawn or asked for before."""
        self._epoch += 1
        self._ready.clear()
        self._pending.clear()
        self._failed.clear()
        self._send(("generator", self._epoch, int(seed), stage))

    def request(self, indices: Iterable[int]) -> None:
        """Ask for episodes ``indices`` (those not ready or asked for already), in this order."""
        if self._lost:
            return
        new = [int(i) for i in indices
               if i not in self._ready and i not in self._pending and i not in self._failed]
        if new:
            self._pending.update(new)
            self._send(("draw", self._epoch, new))

    def take(self, index: int) -> Episode | None:
        """Episode ``index`` if the helper has drawn it, else ``None`` (never waits).

        On ``None`` the caller draws the episode itself; the helper is told to skip it if it has
        not started it yet. Waiting would be slower: the helper draws in request order, and the
        episode needed now may sit behind others not needed yet. A failed draw also gives
        ``None``, so the caller's own draw raises the error with a useful traceback.
        """
        index = int(index)
        self.pump()
        ep = self._ready.pop(index, None)
        if ep is None:
            self._failed.discard(index)
            if index in self._pending:
                self._pending.discard(index)
                self._send(("cancel", self._epoch, index))
        return ep

    def ready(self, index: int) -> bool:
        """Whether episode ``index`` has arrived (a :meth:`take` would return it)."""
        self.pump()
        return int(index) in self._ready

    def pump(self) -> None:
        """Receive whatever the helper has sent, without waiting (keeps its pipe flowing)."""
        while not self._lost and self._poller.poll(0):
            self._receive()

    @property
    def lost(self) -> bool:
        """Whether the helper went away (killed, crashed): :meth:`take` then gives ``None``."""
        return self._lost

    def wait(self, timeout: float = 120.0) -> bool:
        """Wait until every requested episode has arrived (or failed); ``False`` on timeout.

        Not needed for correctness (:meth:`take` never waits); benchmarks call it so that the
        helper's start-up does not count as drawing time.
        """
        deadline = time.monotonic() + timeout
        while True:
            self.pump()
            if not self._pending:
                return True
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            self._poller.poll(min(left, 0.05) * 1000.0)

    def close(self) -> None:
        """Stop the helper process."""
        if self._closed:
            return
        self._closed = True
        with contextlib.suppress(OSError):
            self._out.send_bytes(pickle.dumps(("close",)))
        self._out.close()
        self._in.close()
        # The helper holds nothing worth a graceful end (pipes only), and under SCHED_IDLE on
        # busy cores it may take long to read the message: a short wait, then kill.
        try:
            self._proc.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()

    def __del__(self) -> None:  # the helper also ends on its own when the pipe closes
        with contextlib.suppress(Exception):  # interpreter shutdown: nothing to report to
            self.close()

    # -- transport -----------------------------------------------------------------------------
    def _send(self, msg: tuple[Any, ...]) -> None:
        if self._closed:
            raise RuntimeError("EpisodePrefetcher used after close()")
        if self._lost:
            return
        try:
            self._out.send_bytes(pickle.dumps(msg, protocol=pickle.HIGHEST_PROTOCOL))
        except OSError:  # BrokenPipeError: the helper is gone
            self._lose()

    def _receive(self) -> None:
        try:
            data = self._in.recv_bytes()
        except (EOFError, OSError):
            self._lose()
            return
        msg = _Unpickler(io.BytesIO(data), self._grids, self.robot).load()
        kind = msg[0]
        if kind == "grid":
            self._grids[msg[1]] = msg[2]
        elif kind == "drop":
            self._grids.pop(msg[1], None)
        elif msg[1] == self._epoch and msg[2] in self._pending:  # not cancelled meanwhile
            index = msg[2]
            self._pending.discard(index)
            if kind == "episode":
                self._ready[index] = msg[3]
            else:
                self._failed.add(index)

    def _lose(self) -> None:
        """The helper went away: warn once and leave all drawing to the caller from now on.

        An optimisation must not end a long training run: episodes drawn here are the same.
        """
        if self._lost:
            return
        self._lost = True  # episodes already received stay valid and are still handed out
        self._pending.clear()
        self._failed.clear()
        warnings.warn(
            f"the episode prefetch process ended (exit code {self._proc.poll()}); episodes "
            "are drawn in this process from now on (the same episodes, more slowly)",
            RuntimeWarning,
            stacklevel=3,
        )


def _serve(inbox: Connection, outbox: Connection) -> None:
    """The helper process: draw requested episodes in order, newest generator only."""
    _, factory, robot, seed, stage = pickle.loads(inbox.recv_bytes())
    gen = factory(robot, seed, stage)
    epoch = 0
    tasks: deque[tuple[int, int]] = deque()  # (epoch, index) in request order
    cancelled: set[tuple[int, int]] = set()
    sent: OrderedDict[int, tuple[int, OccupancyGrid]] = OrderedDict()
    next_token = 0

    def send(msg: tuple[Any, ...]) -> None:
        buf = io.BytesIO()
        _Pickler(buf, sent, robot).dump(msg)
        outbox.send_bytes(buf.getbuffer())

    while True:
        # Read every waiting message first, so a new generator cancels stale draws at once.
        while not tasks or inbox.poll():
            try:
                msg = pickle.loads(inbox.recv_bytes())
            except EOFError:  # the parent went away
                return
            if msg[0] == "close":
                return
            if msg[0] == "generator":
                epoch, seed, stage = msg[1], msg[2], msg[3]
                gen = factory(robot, seed, stage)
                tasks.clear()
                cancelled.clear()
            elif msg[0] == "cancel":
                cancelled.add((msg[1], msg[2]))
            elif msg[1] == epoch:  # "draw"
                tasks.extend((epoch, i) for i in msg[2])
        task = tasks.popleft()
        if task[0] != epoch or task in cancelled:
            cancelled.discard(task)
            continue
        index = task[1]
        try:
            ep = gen.episode(index)
        except Exception:  # the parent draws it again and raises there
            send(("error", epoch, index))
            continue
        g = ep.grid
        entry = sent.get(id(g))
        if entry is None or entry[1] is not g:
            g.distance  # noqa: B018 - compute the distance map here, off the main process
            send(("grid", next_token, g))
            sent[id(g)] = (next_token, g)
            next_token += 1
            while len(sent) > MAX_MAPS:
                send(("drop", sent.popitem(last=False)[1][0]))
        else:
            sent.move_to_end(id(g))
        send(("episode", epoch, index, ep))


def main(argv: list[str] | None = None) -> None:
    """Entry point of the helper process: ``python -m arena.learn.prefetch IN_FD OUT_FD``."""
    args = sys.argv[1:] if argv is None else argv
    # Below the parent's priority: the helper should use the cores the simulation leaves idle
    # (while the parent runs its Python between kernel launches), not take them from it. A
    # merely niced helper still gets its fair share and delays the kernel threads it preempts.
    try:
        os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
    except (AttributeError, OSError):  # not Linux, or not permitted
        with contextlib.suppress(OSError):  # not permitted: run at the parent's priority
            os.nice(NICE)
    inbox = Connection(int(args[0]), writable=False)
    outbox = Connection(int(args[1]), readable=False)
    try:
        _serve(inbox, outbox)
    except BrokenPipeError:  # the parent closed its end while we were sending
        pass
    finally:
        inbox.close()
        outbox.close()


if __name__ == "__main__":
    main()
