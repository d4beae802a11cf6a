"""``arena run --live`` and ``--foxglove``: watch (and steer) a CLI run while it runs.

:func:`live_session` sets up what the options ask for and returns the episode hooks and task
modules the run needs; closing it stops the servers. ``--live`` serves the run's live channel
(:class:`~arena.live.server.LiveServer`, its address in the run folder's ``live.json``) and
the web app (:mod:`arena.web`) on 127.0.0.1, whose live page shows it; ``--foxglove`` serves a
Foxglove WebSocket. Both pace the run to real time (the live page changes the pace) and take
goals and teleports (the live page's clicks), as ``--interactive`` does.
"""

from __future__ import annotations

import contextlib
import webbrowser
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arena.cli_common import console, err_console

#: Default ports: the web app, Foxglove's own default.
WEB_PORT = 8080
FOXGLOVE_PORT = 8765


@dataclass
class LiveSession:
    """What a watched run adds: its hooks, its interactive module, a callback for its folder."""

    hooks: list[Any] = field(default_factory=list)
    modules: list[Any] = field(default_factory=list)
    on_start: Callable[[Path], None] | None = None
    url: str | None = None


@contextlib.contextmanager
def live_session(
    *, live: bool, foxglove: bool, web_port: int = WEB_PORT, foxglove_port: int = FOXGLOVE_PORT,
    open_browser: bool = True, web: bool = True,
) -> Iterator[LiveSession]:
    """Set up ``--live`` and/or ``--foxglove``; stop everything on exit.

    ``web=False`` serves the live channel without starting a web app (a web app already shows
    the run store: the runs it starts use this).
    """
    session = LiveSession()
    if not (live or foxglove):
        yield session
        return
    from arena.live import LiveControl, LiveHook, LiveServer
    from arena.tasks.modules.interactive import InteractiveModule

    ui = InteractiveModule(
        on_error=lambda msg: err_console.print(f"error: {msg}", highlight=False))
    control = LiveControl(speed=1.0, interactive=ui)
    session.modules.append(ui)
    sinks: list[Any] = []
    with contextlib.ExitStack() as stack:
        stack.callback(control.close)
        if foxglove:
            from arena.export.foxglove import FoxgloveSink, foxglove_module

            fg = foxglove_module()
            context = fg.Context()
            server = fg.start_server(name="arena", host="127.0.0.1", port=foxglove_port,
                                     context=context)
            stack.callback(server.stop)
            sink = FoxgloveSink(context, rate=20.0, start_ns=None)
            stack.callback(sink.close)
            sinks.append(sink)
            console.print(f"foxglove:    ws://127.0.0.1:{server.port} (open it in Foxglove: "
                          "Open connection → Foxglove WebSocket)", highlight=False)
        if live:
            from arena.web.server import require_web, serve_subprocess

            if web:
                require_web()  # before the run starts, not when its folder exists

            channel = LiveServer(control=control)
            stack.callback(channel.close)
            sinks.append(channel)

            def started(out: Path) -> None:
                info = channel.write_info(out)
                stack.callback(lambda: info.unlink(missing_ok=True))
                if not web:
                    console.print(f"live channel: {info}", highlight=False, soft_wrap=True)
                    return
                app = serve_subprocess(out.parent, port=web_port)
                stack.callback(app.stop)
                session.url = f"{app.url}/live/{out.name}"
                console.print(f"live view:   {session.url}", highlight=False, soft_wrap=True)
                if open_browser:
                    webbrowser.open(session.url)

            session.on_start = started
        session.hooks.append(LiveHook(sinks, control))
        yield session
