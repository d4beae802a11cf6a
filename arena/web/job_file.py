"""A job's files in its run folder: ``job.json`` (what was started, how it ended), ``job.log``.

Two processes write ``job.json``: the web app's :class:`~arena.web.jobs.JobManager` (start,
pid, cancel, resume) and the job's wrapper :mod:`arena.web.job_runner` (exit status). Each
change is a read-modify-write under an exclusive ``flock`` on ``.job.lock``, so neither loses
the other's fields, and the file itself is replaced atomically (:func:`os.replace`), so a reader
never sees half of it. This module imports nothing heavy: the wrapper starts in milliseconds.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import tempfile
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

JOB_FILE = "job.json"
LOG_FILE = "job.log"
LOCK_FILE = ".job.lock"


@dataclass
class JobRecord:
    """The contents of ``job.json``.

    Attributes:
        kind: ``"run"`` (``arena run``) or ``"bench"`` (``arena bench``).
        title: what the run list shows (config or suite × contest).
        argv: the command the wrapper runs (the current attempt's; a resume replaces it).
        planned: episodes the job will have when done (0: unknown).
        started: s since the epoch, when the current attempt started.
        pid: the wrapper's process id (it leads the job's process group); ``None`` until known.
        returncode: the command's exit status once it ended (negative: killed by that signal);
            ``None`` while it runs or when the wrapper itself died.
        finished: s since the epoch, when the command ended (``None``: not yet, or unknown).
        cancelled: someone asked this attempt to stop.
        attempts: how many times the job was started (1 + resumes).
        request: see below.
    """

    kind: str
    title: str
    argv: list[str]
    planned: int = 0
    started: float = 0.0
    pid: int | None = None
    returncode: int | None = None
    finished: float | None = None
    cancelled: bool = False
    attempts: int = 1
    request: dict[str, Any] = field(default_factory=dict)
    """The start request as JSON, from which a resume builds its command (opaque here)."""

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> JobRecord:
        """The record in ``data`` (unknown keys are dropped, so older files still load).

        Raises:
            ValueError: a missing or mistyped field.
        """
        known = {f.name for f in fields(cls)}
        record = cls(**{k: v for k, v in data.items() if k in known})
        if record.kind not in ("run", "bench") or not isinstance(record.argv, list):
            raise ValueError("kind must be run or bench and argv a list")
        if record.pid is not None and not isinstance(record.pid, int):
            raise ValueError("pid must be an integer")
        if record.returncode is not None and not isinstance(record.returncode, int):
            raise ValueError("returncode must be an integer")
        return record


def read_job(folder: Path) -> JobRecord:
    """The job of run folder ``folder``.

    Raises:
        ValueError: no job file, or one that is unreadable or malformed (the message says which).
    """
    path = folder / JOB_FILE
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: unreadable job file ({e})") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path}: not a JSON object")
    try:
        return JobRecord.from_json(data)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{path}: malformed job file ({e})") from None


def _write(folder: Path, record: JobRecord) -> None:
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{JOB_FILE}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(asdict(record), f, indent=1)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, folder / JOB_FILE)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def _locked(folder: Path) -> Iterator[None]:
    with open(folder / LOCK_FILE, "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def create_job(folder: Path, record: JobRecord) -> None:
    """Write a new job file into ``folder`` (which exists)."""
    with _locked(folder):
        _write(folder, record)


def update_job(folder: Path, **changes: Any) -> JobRecord:
    """Change some fields of ``folder``'s job file under the lock; the updated record.

    Raises:
        ValueError: no or a malformed job file.
    """
    with _locked(folder):
        record = read_job(folder)
        for key, value in changes.items():
            if not hasattr(record, key):
                raise ValueError(f"no job field {key!r}")
            setattr(record, key, value)
        _write(folder, record)
        return record


def log_tail(folder: Path, lines: int = 40, max_bytes: int = 32_768) -> list[str]:
    """The last ``lines`` lines of the job's log (at most its last ``max_bytes`` bytes read)."""
    path = folder / LOG_FILE
    try:
        with path.open("rb") as f:
            f.seek(0, os.SEEK_END)
            size = f.tell()
            f.seek(max(0, size - max_bytes))
            data = f.read()
    except OSError:
        return []
    text = data.decode("utf-8", errors="replace").replace("\r", "\n")
    return [line.rstrip() for line in text.splitlines()][-lines:]
