"""``arena web``: the app (FastAPI with NiceGUI pages) on a run store, and how it is served.

Why NiceGUI: its pages are written in Python next to the API they call, it runs on FastAPI
(whose OpenAPI schema documents the API for scripts), and it needs no JavaScript build. The one
view that must be fast, the live and replay canvas, is a small hand-written script
(``static/arena_view.js``) that talks to the API's WebSocket directly.

Security: the app binds 127.0.0.1 unless told otherwise, and any other host needs a token
(``--token`` or a generated one, printed once): a request must carry it as ``?token=`` (which
sets a cookie for the pages that follow), as that cookie or as ``Authorization: Bearer``.
Files are served only from the run store (:class:`~arena.web.store.RunStore`).
"""

from __future__ import annotations

import contextlib
import hmac
import os
import secrets
import socket
import subprocess
import sys
import time
from dataclasses import dataclass
from http.cookies import SimpleCookie
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

from arena.core.errors import ConfigError

#: Where the app's script and styles are.
STATIC = Path(__file__).resolve().parent / "static"
#: The cookie that carries the token after a ``?token=`` link.
TOKEN_COOKIE = "arena_token"
#: Hosts that need no token.
LOOPBACK = ("127.0.0.1", "localhost", "::1")


class TokenGate:
    """ASGI middleware: requests (HTTP and WebSocket) must carry the token (see the module doc)."""

    def __init__(self, app: Any, token: str) -> None:
        self.app, self.token = app, token

    def _carried(self, scope: dict[str, Any]) -> tuple[bool, bool]:
        """``(allowed, from_query)``."""
        query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
        if any(hmac.compare_digest(t, self.token) for t in query.get("token", [])):
            return True, True
        headers = {k.decode("latin-1").lower(): v.decode("latin-1")
                   for k, v in scope.get("headers", [])}
        auth = headers.get("authorization", "")
        if auth.startswith("Bearer ") and hmac.compare_digest(auth[7:], self.token):
            return True, False
        cookie = SimpleCookie()
        with contextlib.suppress(Exception):
            cookie.load(headers.get("cookie", ""))
        morsel = cookie.get(TOKEN_COOKIE)
        return morsel is not None and hmac.compare_digest(morsel.value, self.token), False

    async def __call__(self, scope: dict[str, Any], receive: Any, send: Any) -> None:
        """Pass an allowed request on (setting the cookie after ``?token=``); refuse others."""
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        allowed, from_query = self._carried(scope)
        if not allowed:
            if scope["type"] == "websocket":
                await send({"type": "websocket.close", "code": 4401})
                return
            await send({"type": "http.response.start", "status": 401,
                        "headers": [(b"content-type", b"text/plain; charset=utf-8")]})
            await send({"type": "http.response.body",
                        "body": b"this Arena web app needs its token: open the link with "
                                b"?token=... that arena web printed\n"})
            return
        if not from_query or scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def send_with_cookie(message: dict[str, Any]) -> None:
            if message["type"] == "http.response.start":
                headers = list(message.get("headers", []))
                headers.append((b"set-cookie", f"{TOKEN_COOKIE}={self.token}; HttpOnly; "
                                               "SameSite=Strict; Path=/".encode()))
                message = {**message, "headers": headers}
            await send(message)

        await self.app(scope, receive, send_with_cookie)


def require_web() -> None:
    """Raise a one-line :class:`ConfigError` naming the extra when the web packages are missing."""
    try:
        import fastapi  # noqa: F401
        import nicegui  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError:
        raise ConfigError("the web app needs the web extra: pip install 'arena[web]'") from None


def create_app(root: str | Path, *, token: str | None = None, pages: bool = True) -> Any:
    """The app on the run store ``root``.

    Args:
        root: the folder whose run folders the app shows (``runs/``).
        token: required from every request when set (see the module doc).
        pages: mount the NiceGUI pages (``False``: the API alone, for tests and scripts).
    """
    from fastapi import FastAPI
    from fastapi.staticfiles import StaticFiles

    from arena import __version__
    from arena.web.api import api_router
    from arena.web.api_editor import editor_router
    from arena.web.api_jobs import jobs_router
    from arena.web.jobs import JobManager
    from arena.web.store import RunStore

    store = RunStore(root)
    app = FastAPI(title="Arena", version=__version__,
                  description="Runs, results, replays and live views of Arena simulations.")
    app.state.store = store
    app.include_router(api_router(store))
    app.include_router(editor_router(store))
    manager = JobManager(store.root)
    app.state.jobs = manager
    app.include_router(jobs_router(manager))
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    if pages:
        from nicegui import ui

        from arena.web import editor  # noqa: F401  (registers the /editor page)
        from arena.web import pages as page_module

        page_module.STORE = store
        from arena.web import jobs_page  # registers the /jobs page

        jobs_page.MANAGER = manager
        ui.run_with(app, title="Arena", show_welcome_message=False, reconnect_timeout=10.0,
                    storage_secret=token or secrets.token_urlsafe(16))
    if token:
        app.add_middleware(TokenGate, token=token)
    return app


def check_host(host: str, token: str | None) -> str | None:
    """The token to use on ``host``: none needed on loopback, else the given or a new one."""
    if host in LOOPBACK:
        return token
    return token or secrets.token_urlsafe(24)


def serve(root: str | Path, *, host: str = "127.0.0.1", port: int = 8080,
          token: str | None = None, announce: Any = print) -> None:
    """Serve the app until interrupted (what ``arena web`` does)."""
    require_web()
    import uvicorn

    token = check_host(host, token)
    if not Path(root).is_dir():
        raise ConfigError(f"{root}: no such folder (the run store)", path="--root")
    app = create_app(root, token=token)
    shown = "127.0.0.1" if host in ("0.0.0.0", "::") else host
    announce(f"Arena web app: http://{shown}:{port}/" + (f"?token={token}" if token else ""))
    uvicorn.run(app, host=host, port=port, log_level="warning")


def free_port(start: int, host: str = "127.0.0.1", tries: int = 50) -> int:
    """The first port from ``start`` nobody listens on."""
    for port in range(start, start + tries):
        with socket.socket() as s:
            if s.connect_ex((host, port)) != 0:
                return port
    raise ConfigError(f"no free port in {start}..{start + tries - 1}", path="--port")


@dataclass
class WebProcess:
    """An ``arena web`` server process (started by ``arena run --live`` and the tests)."""

    process: subprocess.Popen[bytes]
    url: str
    log: Any = None
    """The open log file the process writes to (closed by :meth:`stop`), or ``None``."""

    def stop(self, timeout: float = 10.0) -> None:
        """Stop the server (terminate, then kill after ``timeout`` s)."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout)
        if self.log is not None:
            self.log.close()


def serve_subprocess(root: str | Path, *, port: int = 8080, timeout: float = 60.0,
                     log: str | Path | None = None) -> WebProcess:
    """Start ``arena web`` on 127.0.0.1 and wait until it answers (at most ``timeout`` s).

    It takes the first free port from ``port``.

    Raises:
        ConfigError: the server did not answer in time (its log says why).
    """
    require_web()
    port = free_port(port)
    out = open(log, "wb") if log is not None else subprocess.DEVNULL  # noqa: SIM115 (stop closes it)
    cmd = [sys.executable, "-m", "arena.cli", "web", "--root", str(root), "--port", str(port)]
    proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT,
                            env={**os.environ, "PYTHONUNBUFFERED": "1"})
    web = WebProcess(proc, f"http://127.0.0.1:{port}", out if log is not None else None)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            web.stop()
            raise ConfigError(f"arena web stopped at once (exit {proc.returncode})"
                              + (f"; see {log}" if log else ""))
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return web
        time.sleep(0.1)
    web.stop()
    raise ConfigError(f"arena web did not answer on port {port} within {timeout:g} s")
