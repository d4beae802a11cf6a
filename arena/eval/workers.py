"""Worker processes for the benchmark runner: one job at a time each; a fault costs one job.

Why not :class:`concurrent.futures.ProcessPoolExecutor`: when one of its workers dies
(``os._exit``, a segfault, the OOM killer) the whole pool breaks, every pending future fails
with ``BrokenProcessPool`` and nothing says which job killed it; and it cannot stop a job that
never returns. Here each worker holds one job at a time over its own pipe, so the parent knows
which job a dead or overdue worker ran: that job ends as an error result ("worker died (exit
code -11: SIGSEGV)", "wall-clock limit 600 s exceeded"), the worker is replaced and the other
jobs go on.

Workers are fresh interpreters (``spawn``: no state inherited from the parent, same behaviour on
every OS). Each one runs ``initializer(*initargs)`` and reports ready before it gets a job, so
its start-up (imports, compiled kernels) does not count against a job's wall-clock limit.
Workers ignore Ctrl-C (the terminal sends it to the whole process group; the parent stops the
run and kills them) and exit with the parent however it ends: on Linux the kernel kills them
when the parent dies (``PR_SET_PDEATHSIG``), and everywhere a watchdog thread polls the parent's
pid (the fallback elsewhere, and a second line on Linux).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from typing import Any

from arena.core.errors import ArenaError

#: Seconds a worker may take to start (imports, compiled kernels) before the run stops: a
#: worker that cannot start is a broken installation or plugin, not a faulty episode.
STARTUP_TIMEOUT = 300.0
#: Seconds between two looks at the parent's pid in a worker's watchdog thread.
WATCHDOG_PERIOD = 0.5
#: Seconds a worker gets to exit after it was asked to (end of run) before it is killed.
EXIT_GRACE = 10.0

_READY = "ready"
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def exit_description(code: int | None) -> str:
    """``"exit code 3"``, ``"exit code -11: SIGSEGV"``: a negative code is the killing signal."""
    if code is None:
        return "exit code unknown"
    if code < 0:
        with contextlib.suppress(ValueError):
            name = signal.Signals(-code).name
            # SIGKILL is what the kernel's OOM killer sends
            return f"exit code {code}: {name}" + (
                " (out of memory?)" if name == "SIGKILL" else "")
    return f"exit code {code}"


def _exit_with_parent(parent_pid: int, *, pdeathsig: bool = True) -> None:
    """Make this process end when its parent ``parent_pid`` ends (see the module docstring).

    ``pdeathsig=False`` leaves the watchdog alone, as on systems without ``prctl`` (tests).
    """
    if pdeathsig and sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):  # no libc prctl: the watchdog still works
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)

    def watch() -> None:
        while True:
            if os.getppid() != parent_pid:  # re-parented: the parent is gone
                os._exit(1)
            time.sleep(WATCHDOG_PERIOD)

    if os.getppid() != parent_pid:  # it died before prctl took effect
        os._exit(1)
    threading.Thread(target=watch, name="arena-parent-watchdog", daemon=True).start()


def _worker_main(conn: Connection, parent_pid: int, fn: Callable[[Any], Any],
                 initializer: Callable[..., None] | None, initargs: tuple[Any, ...]) -> None:
    """A worker's life: start, report ready, then run jobs until told to stop (``None``)."""
    _exit_with_parent(parent_pid)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if initializer is not None:
        initializer(*initargs)
    conn.send(_READY)
    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):  # the parent closed the pipe: nothing more to do
            return
        if job is None:
            return
        try:
            reply: tuple[str, Any] = ("ok", fn(job))
        except Exception as e:  # fn should not raise; if it does, the job fails, not the worker
            first = (str(e).strip().splitlines() or [""])[0]
            reply = ("raised", f"{type(e).__name__}: {first}".rstrip(": "))
        conn.send(reply)


@dataclass
class _Worker:
    process: Any
    conn: Connection
    started: float
    ready: bool = False
    job: Any = None
    deadline: float = field(default=float("inf"))

    @property
    def busy(self) -> bool:
        return self.job is not None



THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
"""Thread counts of the numeric libraries, set to 1 in each worker unless the user set them."""


@contextlib.contextmanager
def _one_thread_each() -> Iterator[None]:
    """Start workers with one BLAS and numba thread each (where the user set none).

    A worker is one core: with several threads each, the workers' matrix products spin against
    each other on the same cores (the RGB-D detector ran 10 times slower per frame that way).
    The variables are set in this process only while a worker starts (a spawned worker copies
    the environment), then restored.
    """
    saved = {v: os.environ.get(v) for v in THREAD_VARS}
    for v in THREAD_VARS:
        os.environ.setdefault(v, "1")
    try:
        yield
    finally:
        for v, value in saved.items():
            if value is None:
                os.environ.pop(v, None)
            else:
                os.environ[v] = value

def run_jobs(
    jobs: Iterable[Any],
    fn: Callable[[Any], Any],
    on_result: Callable[[Any], None],
    error_result: Callable[[Any, str], Any],
    *,
    workers: int,
    timeout: float | None = None,
    initializer: Callable[..., None] | None = None,
    initargs: tuple[Any, ...] = (),
) -> None:
    """Run ``fn(job)`` for every job in up to ``workers`` worker processes.

    Args:
        jobs: picklable jobs, started in this order.
        fn: the job function, picklable by reference (a module-level function); it should
            return a result for every job rather than raise.
        on_result: called in this process with each job's result as it arrives (or with
            ``error_result(job, message)`` for a job that failed outside ``fn``).
        error_result: builds the result of a job whose worker died, ran past ``timeout`` or
            whose ``fn`` raised, from the job and a one-line message.
        workers: number of worker processes (>= 1).
        timeout: wall-clock limit of one job (s), or ``None`` for none; a job past it has its
            worker killed.
        initializer: run in each worker before its first job (imports, plugins).
        initargs: ``initializer``'s arguments.

    Raises:
        ArenaError: a worker died or hung while starting (before any job reached it).
        Exception: whatever ``on_result`` raises; every worker is killed first.
    """
    import multiprocessing as mp

    if workers < 1:
        raise ArenaError(f"workers must be >= 1, got {workers}")
    ctx = mp.get_context("spawn")
    queue = deque(jobs)
    pool: list[_Worker] = []

    def start() -> _Worker:
        ours, theirs = ctx.Pipe()
        process = ctx.Process(
            target=_worker_main, args=(theirs, os.getpid(), fn, initializer, initargs),
            name="arena-bench-worker",
        )
        with _one_thread_each():
            process.start()
        theirs.close()
        return _Worker(process, ours, time.monotonic())

    def retire(w: _Worker) -> None:
        """Kill ``w`` (if still alive), reap it and drop it from the pool."""
        if w.process.is_alive():
            w.process.kill()
        w.process.join(EXIT_GRACE)
        w.conn.close()
        pool.remove(w)

    def fail(w: _Worker, message: str) -> None:
        job, w.job = w.job, None
        retire(w)
        on_result(error_result(job, message))

    def dispatch(w: _Worker) -> None:
        """Give an idle, ready worker the next job."""
        while w.ready and not w.busy and queue:
            job = queue.popleft()
            try:
                w.conn.send(job)
            except OSError:  # it died while idle: the job goes to another worker
                queue.appendleft(job)
                return
            except Exception as e:  # the job does not pickle
                on_result(error_result(job, f"job not sent: {type(e).__name__}: {e}"))
                continue
            w.job = job
            w.deadline = time.monotonic() + timeout if timeout is not None else float("inf")

    clean = False
    try:
        while queue or any(w.busy for w in pool):
            want = min(workers, sum(w.busy for w in pool) + len(queue))
            while len(pool) < want:
                pool.append(start())
            for w in pool:
                dispatch(w)
            now = time.monotonic()
            limits = [w.deadline if w.ready else w.started + STARTUP_TIMEOUT
                      for w in pool if w.busy or not w.ready]
            wait_s = max(0.0, min(limits) - now) if limits else None
            ready = set(wait([x for w in pool for x in (w.conn, w.process.sentinel)],
                             None if wait_s == float("inf") else wait_s))
            for w in list(pool):
                if w.conn in ready or (w.process.sentinel in ready and w.conn.poll()):
                    try:
                        msg = w.conn.recv()
                    except (EOFError, OSError):  # died (the pipe closed with it)
                        msg = None
                    except Exception as e:  # alive, but its result did not unpickle here
                        job, w.job = w.job, None
                        on_result(error_result(job, f"result not received: "
                                                    f"{type(e).__name__}: {e}"))
                        continue
                    if msg == _READY:
                        w.ready = True
                        continue
                    if msg is not None:
                        job, w.job = w.job, None
                        dispatch(w)  # its next job runs while this result is committed
                        tag, value = msg
                        on_result(value if tag == "ok" else error_result(job, value))
                        continue
                if w.process.sentinel in ready or not w.process.is_alive():
                    w.process.join(EXIT_GRACE)
                    code = exit_description(w.process.exitcode)
                    if not w.ready:
                        retire(w)
                        raise ArenaError(
                            f"a benchmark worker process died while starting ({code}); a "
                            f"script starting workers needs an `if __name__ == \"__main__\":` "
                            f"guard; --workers 0 (workers=0) runs in this process and shows why")
                    if w.busy:
                        fail(w, f"worker died ({code})")
                    else:
                        retire(w)
            now = time.monotonic()
            for w in list(pool):
                if w.busy and now >= w.deadline:
                    fail(w, f"wall-clock limit {timeout:g} s exceeded")
                elif not w.ready and now >= w.started + STARTUP_TIMEOUT:
                    retire(w)
                    raise ArenaError(f"a benchmark worker process did not start within "
                                     f"{STARTUP_TIMEOUT:g} s")
        clean = True
    finally:
        for w in pool:
            if clean and not w.busy:
                with contextlib.suppress(OSError):
                    w.conn.send(None)  # let it exit on its own
            else:  # Ctrl-C or a failed commit: stop at once, the running jobs are lost anyway
                w.process.kill()
        for w in list(pool):
            w.process.join(EXIT_GRACE)
            retire(w)


__all__ = ["STARTUP_TIMEOUT", "exit_description", "run_jobs"]
