"""The web app's runs manager: ``arena run`` and ``arena bench`` as detached jobs in the run store.

A job is a run folder ``<root>/<name>`` with ``job.json`` and ``job.log``
(:mod:`arena.web.job_file`). :meth:`JobManager.start` checks a request
(:mod:`arena.web.job_requests`), claims the folder and starts ``python -m
arena.web.job_runner <folder>`` in a new session (its own process group), which runs
``python -m arena.cli run|bench ... -o <folder>`` and writes the exit status when it ends. Jobs
therefore go on when the browser closes and when the web server stops, and their outcome
survives a restart: the manager keeps no state of its own but the handles of the wrappers it
started (to reap them); everything it reports is read from the folders.

A job's state, from ``job.json``:

* ``running``: its wrapper lives (checked in ``/proc/<pid>/cmdline`` to be *this* job's wrapper,
  so a reused pid is not mistaken for it; ``os.kill(pid, 0)`` where there is no ``/proc``);
* ``done``: exit status 0;
* ``cancelled``: someone cancelled it (SIGTERM to its process group, SIGKILL after a bound);
* ``failed``: another exit status (the reason: the log's last line), or ``crashed``: the wrapper
  is gone without writing a status (killed, or the machine rebooted).

A cancelled or failed job resumes in its folder: a benchmark with ``arena bench --resume``
(committed episodes are kept), a run with ``arena run --resume`` (finished episodes are kept;
episodes are seeded by index, so the summary equals an uninterrupted run's).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
from dataclasses import asdict, dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

from arena.core.errors import ArenaError
from arena.web.job_file import (
    JOB_FILE,
    LOG_FILE,
    JobRecord,
    create_job,
    log_tail,
    read_job,
    update_job,
)
from arena.web.job_requests import BenchRequest, JobError, RunRequest, command, parse_request
from arena.web.job_runner import MODULE
from arena.web.store import RUN_NAME, NotFound, RunStore, pid_alive

#: States a job can be in.
STATES = ("running", "done", "failed", "cancelled")
#: A job without a wrapper pid yet counts as starting (running) this long (s).
STARTING_S = 30.0


class JobConflict(ArenaError):
    """An action the job's state does not allow (cancel a finished job ...); one line."""

    http_status = 409


@dataclass(frozen=True)
class JobStatus:
    """What the jobs list shows of one job.

    Attributes:
        name: the run folder's name.
        kind: ``"run"`` or ``"bench"``.
        title: config and robot, or suite × contest.
        state: one of :data:`STATES`.
        reason: why it failed or was cancelled ("" otherwise).
        done: episodes finished so far.
        planned: episodes it will have when done (0: unknown).
        started: s since the epoch, when the current attempt started.
        finished: s since the epoch, when it ended (``None``: running, or unknown).
        returncode: the command's exit status (``None``: running, or unknown).
        attempts: 1 + the number of resumes.
        live: it serves a live channel now (its live view can be opened).
        argv: the current attempt's command.
    """

    name: str
    kind: str
    title: str
    state: str
    reason: str
    done: int
    planned: int
    started: float
    finished: float | None
    returncode: int | None
    attempts: int
    live: bool
    argv: list[str]

    def as_json(self) -> dict[str, Any]:
        """The fields as a dict (the API's answer)."""
        return asdict(self)


class JobManager:
    """Start, list, cancel and resume the jobs of the run store ``root`` (see the module doc).

    Args:
        root: the run store's folder (created if missing).
        python: the interpreter that runs the wrapper and ``arena`` (default: this one).
        kill_after: s between a cancel's SIGTERM and its SIGKILL, if the job still runs.
    """

    def __init__(self, root: str | Path, *, python: str = sys.executable,
                 kill_after: float = 15.0) -> None:
        self.root = Path(root).resolve()
        self.python = python
        self.kill_after = kill_after
        self.store = RunStore(self.root)
        self._children: dict[str, subprocess.Popen[bytes]] = {}
        self._lock = threading.Lock()

    # -- starting ---------------------------------------------------------------------------------
    def start(self, request: RunRequest | BenchRequest | dict[str, Any]) -> JobStatus:
        """Check ``request`` and start its job; its status.

        Raises:
            JobError: bad input (unknown names, a taken or bad run name): nothing was started.
        """
        req = request if isinstance(request, RunRequest | BenchRequest) else parse_request(
            request)
        cmd = command(req, self.root)
        with self._lock:
            folder = self._claim(req.name, req.kind)
            return self.launch(folder.name, req.kind, cmd.args, title=cmd.title,
                               planned=cmd.planned, request=req.model_dump(mode="json"))

    def launch(self, name: str, kind: str, args: list[str], *, title: str = "",
               planned: int = 0, request: dict[str, Any] | None = None) -> JobStatus:
        """Start ``arena <args> -o <root>/<name>`` as job ``name`` in its (existing) folder.

        No check of ``args``: :meth:`start` is the front door; this is for callers that built
        a command themselves (and the tests).
        """
        folder = self.root / name
        argv = [self.python, "-m", "arena.cli", *args, "-o", str(folder)]
        create_job(folder, JobRecord(kind=kind, title=title, argv=argv, planned=planned,
                                     started=time.time(), request=dict(request or {})))
        self._spawn(name, folder)
        return self.status(name)

    def _claim(self, name: str | None, kind: str) -> Path:
        """Create the new run folder ``name`` (or ``<kind>_<date-time>``); it must not exist."""
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise JobError(f"the run store {self.root}: cannot create it ({e.strerror})") from None
        if name is not None:
            if not RUN_NAME.match(name):
                raise JobError(f"name: {name!r} is no plain folder name (letters, digits, "
                               "'.', '_', '-'; starting with a letter or digit)")
            try:
                (self.root / name).mkdir()
            except FileExistsError:
                raise JobError(f"name: a run {name!r} already exists; pick another name"
                               ) from None
            return self.root / name
        stamp = datetime.now().strftime("%y%m%d-%H%M%S")
        for i in range(1, 100):
            candidate = self.root / (f"{kind}_{stamp}" + (f"_{i}" if i > 1 else ""))
            with contextlib.suppress(FileExistsError):
                candidate.mkdir()
                return candidate
        raise JobError(f"no free run name {kind}_{stamp}_N in {self.root}")

    def _spawn(self, name: str, folder: Path) -> None:
        """Start the wrapper detached, its output appended to the job's log."""
        env = {**os.environ, "PYTHONUNBUFFERED": "1", "COLUMNS": "120"}
        with open(folder / LOG_FILE, "ab") as log:
            proc = subprocess.Popen(
                [self.python, "-m", MODULE, str(folder)], stdin=subprocess.DEVNULL,
                stdout=log, stderr=subprocess.STDOUT, cwd=self.root, env=env,
                start_new_session=True)
        self._children[name] = proc
        update_job(folder, pid=proc.pid)

    # -- reading ----------------------------------------------------------------------------------
    def folder(self, name: str) -> Path:
        """The folder of job ``name``.

        Raises:
            NotFound: no plain folder name, or no job of that name.
        """
        if not RUN_NAME.match(name or ""):
            raise NotFound(f"no job named {name!r}")
        path = (self.root / name).resolve()
        if path.parent != self.root or not (path / JOB_FILE).is_file():
            raise NotFound(f"no job named {name!r}")
        return path

    def jobs(self) -> list[JobStatus]:
        """Every job of the store, newest first."""
        self._reap()
        if not self.root.is_dir():
            return []
        found = [p.name for p in self.root.iterdir()
                 if RUN_NAME.match(p.name) and (p / JOB_FILE).is_file()]
        return sorted((self.status(n) for n in found), key=lambda j: -j.started)

    def status(self, name: str) -> JobStatus:
        """Job ``name``'s status, read from its folder now.

        Raises:
            NotFound: no such job.
        """
        folder = self.folder(name)
        self._reap()
        try:
            record = read_job(folder)
        except ValueError as e:
            return JobStatus(name, "run", "", "failed", str(e), 0, 0, 0.0, None, None, 0,
                             False, [])
        state, reason = self._state(folder, record)
        pattern = "episodes/*/*/*.json" if record.kind == "bench" else "episode_*/episode.json"
        done = sum(1 for _ in folder.glob(pattern))
        try:
            live = state == "running" and self.store.live(name) is not None
        except NotFound:
            live = False
        return JobStatus(name=name, kind=record.kind, title=record.title, state=state,
                         reason=reason, done=done, planned=record.planned,
                         started=record.started, finished=record.finished,
                         returncode=record.returncode, attempts=record.attempts, live=live,
                         argv=record.argv)

    def log(self, name: str, lines: int = 40) -> list[str]:
        """The last ``lines`` lines of job ``name``'s log."""
        return log_tail(self.folder(name), lines)

    def _state(self, folder: Path, record: JobRecord) -> tuple[str, str]:
        if record.returncode is None:
            if record.pid is None and time.time() - record.started < STARTING_S:
                return "running", ""
            if record.pid is not None and wrapper_alive(record.pid, folder):
                return "running", ""
            if record.cancelled:
                return "cancelled", "cancelled (stopped by force)"
            return "failed", ("crashed: its wrapper process ended without an exit status "
                              "(killed, or the machine restarted)")
        if record.returncode == 0:
            return "done", ""
        if record.cancelled:
            return "cancelled", "cancelled"
        last = next((line for line in reversed(log_tail(folder, 20)) if line.strip()), "")
        if record.returncode < 0:
            try:
                signame = signal.Signals(-record.returncode).name
            except ValueError:
                signame = f"signal {-record.returncode}"
            return "failed", f"killed by {signame}" + (f"; last output: {last}" if last else "")
        return "failed", last or f"exit status {record.returncode}"

    def _reap(self) -> None:
        """Collect the wrappers of this manager that ended (no zombies left behind)."""
        for name, proc in list(self._children.items()):
            if proc.poll() is not None:
                self._children.pop(name, None)

    # -- acting -----------------------------------------------------------------------------------
    def cancel(self, name: str) -> JobStatus:
        """Stop job ``name``: SIGTERM to its process group, SIGKILL after ``kill_after`` s.

        Raises:
            NotFound: no such job.
            JobConflict: it does not run.
        """
        with self._lock:
            folder = self.folder(name)
            job = self.status(name)
            record = read_job(folder)
            if job.state != "running":
                raise JobConflict(f"job {name!r} is {job.state}; only a running job can be "
                                  "cancelled")
            if record.pid is None:
                raise JobConflict(f"job {name!r} is starting; cancel it in a moment")
            update_job(folder, cancelled=True)
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(record.pid, signal.SIGTERM)
        threading.Thread(target=self._kill_later, args=(record.pid,), daemon=True,
                         name=f"arena-cancel-{name}").start()
        return self.status(name)

    def _kill_later(self, pgid: int) -> None:
        """SIGKILL the process group ``pgid`` if any of it still runs after ``kill_after`` s.

        A process group's id is not reused while one of its processes lives (or waits to be
        reaped), so a group found alive in the loop is still the job's.
        """
        deadline = time.monotonic() + self.kill_after
        while time.monotonic() < deadline:
            self._reap()
            if not group_alive(pgid):
                return
            time.sleep(0.2)
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(pgid, signal.SIGKILL)

    def resume(self, name: str) -> JobStatus:
        """Start a cancelled or failed job again in its folder, keeping what it finished.

        Raises:
            NotFound: no such job.
            JobConflict: it runs or is done, or processes of its last attempt still run.
        """
        with self._lock:
            folder = self.folder(name)
            job = self.status(name)
            if job.state not in ("cancelled", "failed"):
                raise JobConflict(f"job {name!r} is {job.state}; only a cancelled or failed "
                                  "job can be resumed")
            record = read_job(folder)
            if record.pid is not None and group_alive(record.pid):
                raise JobConflict(f"job {name!r}: processes of its last attempt still run "
                                  f"(process group {record.pid}); stop them first")
            args = self._resume_args(folder, record)
            argv = [self.python, "-m", "arena.cli", *args]
            update_job(folder, argv=argv, started=time.time(), pid=None, returncode=None,
                       finished=None, cancelled=False, attempts=record.attempts + 1)
            with open(folder / LOG_FILE, "a") as log:
                log.write(f"\n--- resumed {datetime.now():%Y-%m-%d %H:%M:%S} "
                          f"(attempt {record.attempts + 1}) ---\n")
            self._spawn(name, folder)
        return self.status(name)

    @staticmethod
    def _resume_args(folder: Path, record: JobRecord) -> list[str]:
        """The command that continues the job in ``folder``."""
        try:
            req = parse_request(record.request)
        except JobError:
            raise JobConflict(f"job {folder.name!r} was not started by the web app; resume it "
                              "with arena bench --resume or arena run --resume") from None
        if isinstance(req, BenchRequest):
            if not (folder / "run.json").is_file():  # stopped before its manifest: start over
                return [*record.argv[3:]]
            return ["bench", req.suite, "--resume", str(folder), "--workers", str(req.workers),
                    "--no-progress", *(["--live", "--no-web"] if req.live else [])]
        if not (folder / "config.yaml").is_file():  # stopped before its config: start over
            return [*record.argv[3:]]
        return ["run", "--resume", str(folder), *(["--live", "--no-web"] if req.live else [])]


def wrapper_alive(pid: int, folder: Path) -> bool:
    """Whether ``pid`` is the wrapper of the job in ``folder`` (not a process that reused it)."""
    if not Path("/proc/self/cmdline").is_file():  # no /proc (macOS): the pid's existence
        return pid_alive(pid)
    try:
        parts = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return False
    return MODULE.encode() in parts and str(folder).encode() in parts


def group_alive(pgid: int) -> bool:
    """Whether a process of group ``pgid`` runs (zombies, which wait to be reaped, do not)."""
    if not Path("/proc/self/stat").is_file():  # no /proc: any member, zombies too
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            # pid (comm) state ppid pgrp ...: comm may hold spaces and parentheses
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if len(fields) > 2 and fields[2] == str(pgid) and fields[0] != "Z":
            return True
    return False
