"""Live channels of a benchmark's workers (``arena bench --live``).

Each worker process serves the episode it is running on its own loopback
:class:`~arena.live.server.LiveServer` and announces it in the run folder as
``live/worker_<pid>.json`` (the same fields as ``live.json``: host, port, token, pid). The web
app lists a run's channels from these files and shows any one of them; a file whose process
has died is ignored, and a worker removes its file when it exits.

A benchmark's channels are for watching only: they take no pause, pace, goal or teleport
(a :class:`LiveServer` without control refuses commands), so a benchmark's figures never
depend on a viewer, and an episode is never held past its wall-clock limit. Frames are sent
only while someone watches (:class:`~arena.live.hook.LiveHook`); watched or not, every
trajectory is the same (tested).
"""

from __future__ import annotations

import atexit
import contextlib
import os
from pathlib import Path
from typing import Any

#: The run folder's subfolder of channel files.
LIVE_DIR = "live"

_server: Any = None
_file: Path | None = None


def channel_name(pid: int) -> str:
    """The channel file's stem of worker process ``pid``."""
    return f"worker_{pid}"


def start(run_dir: str | Path) -> None:
    """Serve this process's episodes and announce the channel in ``run_dir/live/`` (once)."""
    global _server, _file
    if _server is not None:
        return
    from arena.live.server import LiveServer

    _server = LiveServer(control=None)
    _file = _server.write_info(Path(run_dir) / LIVE_DIR, f"{channel_name(os.getpid())}.json")
    atexit.register(stop)


def stop() -> None:
    """Close this process's channel and remove its file (at exit; idempotent)."""
    global _server, _file
    if _file is not None:
        with contextlib.suppress(OSError):
            _file.unlink()
    if _server is not None:
        _server.close()
    _server, _file = None, None


def hooks(title: str) -> list[Any]:
    """The episode hooks that feed this process's channel (none when it has none)."""
    if _server is None:
        return []
    from arena.live.hook import LiveHook

    _server.title = title
    return [LiveHook([_server])]
