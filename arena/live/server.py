"""A run's live channel: its scenes and frames on a loopback TCP port, one JSON object per line.

The simulation process serves; the web app (``arena web``) and scripts connect
(:class:`LiveClient`). The protocol, every message one line of JSON:

1. the client sends ``{"token": "..."}`` (the token is in the run's ``live.json``, readable only
   by whoever may read the run folder);
2. the server sends the control status, the current scene and the latest frame, then every
   scene, frame and status as they come (:func:`~arena.live.frame.scene_json`,
   :func:`~arena.live.frame.frame_json`, :meth:`~arena.live.control.LiveControl.status`);
3. the client may send commands (:meth:`~arena.live.control.LiveControl.apply`); a refused one
   comes back as ``{"type": "error", "message": "..."}``.

A slow viewer never slows the run: each client keeps only the newest frame (scenes, last
frames, statuses and errors are all delivered, in order). Frames are built at most ``rate``
times per second of wall time, and only while someone watches.
"""

from __future__ import annotations

import contextlib
import hmac
import json
import os
import secrets
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from arena.live.control import LiveControl
from arena.live.frame import LiveFrame, LiveScene, frame_json, scene_json
from arena.tasks.modules.interactive import CommandError

#: The file in a run folder that tells viewers where its live channel is.
LIVE_FILE = "live.json"
#: Longest line a client may send (bytes); longer ones close the connection.
MAX_LINE = 65536


def encode(message: dict[str, Any]) -> bytes:
    """One protocol line."""
    return json.dumps(message, separators=(",", ":"), allow_nan=False).encode() + b"\n"


class _Client:
    """One connected viewer: its socket, the queue of messages it must get, its newest frame."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.must: deque[bytes] = deque()
        self.latest: bytes | None = None
        self.ready = threading.Event()
        self.authorized = False
        self.closed = False

    def send(self, line: bytes, *, reliable: bool) -> None:
        if reliable:
            self.must.append(line)
        else:
            self.latest = line
        self.ready.set()

    def next(self) -> bytes | None:
        if self.must:
            return self.must.popleft()
        line, self.latest = self.latest, None
        return line


class LiveServer:
    """Serves one run's live channel (see the module doc).

    Args:
        host: interface to listen on (loopback by default; the web app is what faces users).
        port: TCP port, ``0`` for any free one (see :attr:`address`).
        token: what clients must send first (default: a fresh random one).
        rate: most frames per second of wall time.
        control: the run's pause/speed/goal control (``None``: commands are refused).
        clock: wall clock (s), replaceable in tests.
    """

    def __init__(
        self,
        *,
        host: str = "127.0.0.1",
        port: int = 0,
        token: str | None = None,
        rate: float = 30.0,
        control: LiveControl | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.token = token or secrets.token_urlsafe(16)
        self.rate = float(rate)
        self.control = control
        self._clock = clock
        self._lock = threading.Lock()
        self._clients: list[_Client] = []
        self._scene: bytes | None = None
        self._frame: bytes | None = None
        self._last_frame = -float("inf")
        self._sock = socket.create_server((host, port))
        self._closed = False
        self.frames_sent = 0
        """Frames handed to clients (for benchmarks and tests)."""
        self.title = ""
        """What the next scene is (a benchmark's contestant, stage and episode); in its JSON."""
        if control is not None:
            control.listeners.append(self._status)
        threading.Thread(target=self._accept, name="arena-live-accept", daemon=True).start()

    @property
    def address(self) -> tuple[str, int]:
        """``(host, port)`` it listens on."""
        host, port = self._sock.getsockname()[:2]
        return str(host), int(port)

    @property
    def clients(self) -> int:
        """Connected, authorized viewers."""
        with self._lock:
            return sum(c.authorized and not c.closed for c in self._clients)

    def info(self) -> dict[str, Any]:
        """What ``live.json`` holds: host, port, token, pid."""
        host, port = self.address
        return {"host": host, "port": port, "token": self.token, "pid": os.getpid()}

    def write_info(self, folder: str | Path, name: str = LIVE_FILE) -> Path:
        """Write :meth:`info` as ``name`` into ``folder`` (owner-readable only); its path."""
        path = Path(folder) / name
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{name}.{os.getpid()}.tmp")
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "w") as f:
            json.dump(self.info(), f)
        os.replace(tmp, path)
        return path

    # -- the sink (simulation thread) -------------------------------------------------------------
    def wants_frame(self, time: float) -> bool:
        """A viewer is connected and the last frame is ``1 / rate`` s of wall time old."""
        return self.clients > 0 and self._clock() - self._last_frame >= 1.0 / self.rate

    def scene(self, scene: LiveScene) -> None:
        """Send a new episode's scene to every viewer (their stale frames dropped)."""
        line = encode({**scene_json(scene), "title": self.title} if self.title
                      else scene_json(scene))
        with self._lock:
            self._scene, self._frame = line, None
            for c in self._clients:
                c.latest = None  # a frame of the previous episode is stale
                if c.authorized:
                    c.send(line, reliable=True)

    def frame(self, frame: LiveFrame, *, last: bool = False) -> None:
        """Make ``frame`` every viewer's newest (a ``last`` frame is always delivered)."""
        self._last_frame = self._clock()
        line = encode(frame_json(frame))
        with self._lock:
            self._frame = line
            for c in self._clients:
                if c.authorized:
                    if last:
                        c.latest = None  # an older frame must not arrive after the last one
                    c.send(line, reliable=last)
                    self.frames_sent += 1

    def _status(self, status: dict[str, Any]) -> None:
        self._broadcast(encode(status))

    def _broadcast(self, line: bytes) -> None:
        with self._lock:
            for c in self._clients:
                if c.authorized:
                    c.send(line, reliable=True)

    def close(self) -> None:
        """Stop listening and disconnect every viewer."""
        self._closed = True
        with contextlib.suppress(OSError):
            self._sock.close()
        with self._lock:
            clients = list(self._clients)
        for c in clients:
            self._drop(c)
        if self.control is not None and self._status in self.control.listeners:
            self.control.listeners.remove(self._status)

    def __enter__(self) -> LiveServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- connections ------------------------------------------------------------------------------
    def _accept(self) -> None:
        while not self._closed:
            try:
                sock, _ = self._sock.accept()
            except OSError:
                return
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            client = _Client(sock)
            with self._lock:
                self._clients.append(client)
            threading.Thread(target=self._read, args=(client,), daemon=True).start()
            threading.Thread(target=self._write, args=(client,), daemon=True).start()

    def _drop(self, client: _Client) -> None:
        client.closed = True
        client.ready.set()
        with contextlib.suppress(OSError):
            client.sock.shutdown(socket.SHUT_RDWR)
        with contextlib.suppress(OSError):
            client.sock.close()
        with self._lock:
            if client in self._clients:
                self._clients.remove(client)

    def _read(self, client: _Client) -> None:
        stream = client.sock.makefile("rb")
        try:
            for raw in iter(lambda: stream.readline(MAX_LINE + 1), b""):
                if len(raw) > MAX_LINE:
                    break
                try:
                    message = json.loads(raw)
                    if not isinstance(message, dict):
                        raise ValueError("a message must be a JSON object")
                except ValueError as e:
                    client.send(encode({"type": "error", "message": f"bad message: {e}"}),
                                reliable=True)
                    continue
                if not client.authorized:
                    if not hmac.compare_digest(str(message.get("token", "")), self.token):
                        break
                    self._welcome(client)
                    continue
                self._command(client, message)
        except OSError:
            pass
        finally:
            self._drop(client)

    def _welcome(self, client: _Client) -> None:
        with self._lock:
            client.authorized = True
            status = (self.control.status() if self.control is not None
                      else {"type": "status", "paused": False, "speed": 0.0,
                            "interactive": False})
            client.send(encode(status), reliable=True)
            if self._scene is not None:
                client.send(self._scene, reliable=True)
            if self._frame is not None:
                client.send(self._frame, reliable=False)

    def _command(self, client: _Client, message: dict[str, Any]) -> None:
        try:
            if self.control is None:
                raise CommandError("this run takes no commands")
            self.control.apply(message)
        except CommandError as e:
            client.send(encode({"type": "error", "message": str(e)}), reliable=True)

    def _write(self, client: _Client) -> None:
        while not client.closed:
            client.ready.wait(1.0)
            with self._lock:
                client.ready.clear()
                lines = []
                while (line := client.next()) is not None:
                    lines.append(line)
            try:
                for line in lines:
                    client.sock.sendall(line)
            except OSError:
                self._drop(client)
                return


class LiveClient:
    """A script's connection to a run's live channel (blocking; every wait bounded).

    Args:
        host, port, token: from the run's ``live.json`` (:meth:`from_run`).
        timeout: s, longest wait for the connection and for each message.
    """

    def __init__(self, host: str, port: int, token: str, *, timeout: float = 10.0) -> None:
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.settimeout(timeout)
        self._stream = self.sock.makefile("rb")
        self.send({"token": token})

    @classmethod
    def from_run(cls, run_dir: str | Path, *, timeout: float = 10.0) -> LiveClient:
        """Connect to the run in ``run_dir`` (its ``live.json``)."""
        return cls.from_info(Path(run_dir) / LIVE_FILE, timeout=timeout)

    @classmethod
    def from_info(cls, path: str | Path, *, timeout: float = 10.0) -> LiveClient:
        """Connect to the channel a ``live.json``-like file at ``path`` announces."""
        info = json.loads(Path(path).read_text())
        return cls(str(info["host"]), int(info["port"]), str(info["token"]), timeout=timeout)

    def send(self, message: dict[str, Any]) -> None:
        """Send one message (a command)."""
        self.sock.sendall(encode(message))

    def receive(self) -> dict[str, Any]:
        """The next message.

        Raises:
            TimeoutError: none came within the timeout.
            ConnectionError: the server closed the channel.
        """
        line = self._stream.readline()
        if not line:
            raise ConnectionError("the live channel was closed")
        message = json.loads(line)
        assert isinstance(message, dict)
        return message

    def messages(self) -> Iterator[dict[str, Any]]:
        """Messages until the channel closes."""
        while True:
            try:
                yield self.receive()
            except ConnectionError:
                return

    def close(self) -> None:
        """Close the connection."""
        with contextlib.suppress(OSError):
            self.sock.close()

    def __enter__(self) -> LiveClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
