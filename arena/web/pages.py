"""The web app's pages (NiceGUI): the run list, a run's results, the live view and the replay.

Pages read the store through the same :class:`~arena.web.store.RunStore` as the API; the live
and replay canvases are ``static/arena_view.js``, fed by the API (``/api/runs/{run}/live`` and
``/api/runs/{run}/replay``). Everything a page shows from a run's files is HTML-escaped.
"""

from __future__ import annotations

import html
import json
from datetime import datetime
from typing import Any
from urllib.parse import quote

from nicegui import ui

from arena.web.results_page import results_page
from arena.web.store import NotFound, RunStore

#: The store the pages show (set by :func:`arena.web.server.create_app`).
STORE: RunStore | None = None

#: Speeds the live view offers (multiples of real time; 0: as fast as it goes).
SPEEDS = {"¼×": 0.25, "½×": 0.5, "1×": 1.0, "2×": 2.0, "4×": 4.0, "8×": 8.0, "max": 0.0}
SCRIPT = '<script src="/static/arena_view.js"></script>'
CANVAS = ('<canvas id="arena-canvas" style="width:100%;height:72vh;display:block;'
          'border-radius:6px"></canvas>')


def _store() -> RunStore:
    assert STORE is not None, "create_app sets the store"
    return STORE


def _header(title: str) -> None:
    ui.page_title(f"{title} · Arena")
    with ui.header().classes("items-center bg-slate-800"):
        ui.link("Arena", "/").classes("text-white text-lg font-bold no-underline")
        ui.label(title).classes("text-slate-200")
        ui.space()
        ui.link("jobs", "/jobs").classes("text-slate-300")
        ui.link("editor", "/editor").classes("text-slate-300")
        ui.link("API", "/docs").classes("text-slate-300")


@ui.page("/")
def index() -> None:
    """Every run of the store, newest first, with links to its results and live view."""
    _header("runs")
    runs = _store().runs()
    if not runs:
        ui.label(f"No runs in {_store().root} yet: start one with arena run or arena bench.")
        return
    rows = []
    for r in runs:
        name = quote(r.name)
        live = f' · <a href="/live/{name}">live</a>' if r.live else ""
        when = datetime.fromtimestamp(r.modified).strftime("%Y-%m-%d %H:%M")
        rows.append(f'<tr><td><a href="/runs/{name}">{html.escape(r.name)}</a>{live}</td>'
                    f"<td>{r.kind}</td><td>{html.escape(r.title)}</td><td>{r.episodes}</td>"
                    f"<td>{when}</td></tr>")
    ui.html('<table class="arena-table"><tr><th>run</th><th>kind</th><th>what</th>'
            "<th>episodes</th><th>modified</th></tr>" + "".join(rows) + "</table>",
            sanitize=False)
    _table_style()


def _table_style() -> None:
    ui.add_css(".arena-table{border-collapse:collapse;font-size:14px}"
               ".arena-table td,.arena-table th{padding:4px 10px;border-bottom:1px solid #ddd;"
               "text-align:left}.arena-table .iv{color:#666;font-size:0.9em}"
               ".arena-table tr.o-collision td,.arena-table tr.o-timeout td,"
               ".arena-table tr.o-error td{background:#fff4f0}")


@ui.page("/runs/{run}")
def results(run: str) -> None:
    """A run's results: tables, charts and its episodes with a replay link each."""
    _header(run)
    _table_style()
    results_page(_store(), run)


@ui.page("/live/{run}")
def live(run: str, channel: str = "") -> None:
    """The live view: canvas, pause/step/speed, and goal or teleport by clicking.

    A benchmark's workers each have a channel (``?channel=worker_<pid>``, links above the
    canvas); they are for watching only, so the controls answer with an error there.
    """
    _header(f"{run} · live")
    try:
        bench = _store().info(run).kind == "bench"
    except NotFound as e:
        ui.label(str(e)).classes("text-red-700")
        return
    ui.add_head_html(SCRIPT)
    ui.html('<div id="arena-channels" style="font-size:14px"></div>', sanitize=False)
    if bench:
        ui.label("A benchmark is watched only: its episodes are not paused or steered, so its "
                 "results do not depend on a viewer.").classes("text-slate-600")
    with ui.row().classes("items-center gap-2").set_visibility(not bench):
        # the buttons talk to the run's WebSocket from the browser (no round trip here)
        for name, message in (("pause", {"cmd": "pause"}), ("resume", {"cmd": "resume"}),
                              ("step", {"cmd": "step"})):
            ui.button(name).props(f"id=arena-{name}").on("click", js_handler=_send_js(message))
        ui.toggle(list(SPEEDS), value="1×",
                  on_change=lambda e: _send({"cmd": "speed", "value": SPEEDS[e.value]}))
        ui.label("click:")
        ui.toggle({"": "look", "goal": "set goal", "teleport": "move robot"}, value="",
                  on_change=lambda e: ui.run_javascript(
                      f"window.arenaView.tool = {json.dumps(e.value or None)}"))
    ui.html('<div id="arena-status" style="font-family:monospace;font-size:13px">connecting'
            "…</div>" + CANVAS, sanitize=False).classes("w-full")
    ui.add_body_html(f"<script>arenaStartLive({js_literal(run)}, {js_literal(channel)});</script>")


def js_literal(value: Any) -> str:
    """``value`` as a JavaScript literal safe inside a ``<script>`` element."""
    return json.dumps(value).replace("<", "\\u003c").replace(">", "\\u003e")


def _send_js(message: dict[str, Any]) -> str:
    return f"() => window.arenaLive && window.arenaLive.send({json.dumps(message)})"


def _send(message: dict[str, Any]) -> None:
    ui.run_javascript(f"window.arenaLive && window.arenaLive.send({json.dumps(message)})")


@ui.page("/replay/{run}")
def replay(run: str, record: str = "") -> None:
    """One recorded episode, simulated again, on the canvas with a time slider."""
    _header(f"{run} · replay")
    try:
        _store().file(run, record)
    except NotFound as e:
        ui.label(str(e)).classes("text-red-700")
        return
    ui.add_head_html(SCRIPT)
    with ui.row().classes("items-center gap-2"):
        ui.button("play").props("id=arena-play").on(
            "click", js_handler="() => window.arenaReplay && window.arenaReplay.play()")
        ui.button("pause").on(
            "click", js_handler="() => window.arenaReplay && window.arenaReplay.pause()")
        ui.label(record).classes("text-slate-500")
    ui.html('<div style="display:flex;gap:12px;align-items:center">'
            '<input id="arena-slider" type="range" min="0" max="0" value="0" '
            'style="flex:1"><span id="arena-time" style="font-family:monospace">loading…'
            "</span></div>" + CANVAS, sanitize=False).classes("w-full")
    ui.add_body_html(f"<script>arenaStartReplay({js_literal(run)}, {js_literal(record)});</script>")
