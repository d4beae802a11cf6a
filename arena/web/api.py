"""The web app's REST and WebSocket API (FastAPI; its OpenAPI schema at ``/docs``).

=====================================  =========================================================
``GET  /api/health``                   ``{"ok": true, "version": ...}``
``GET  /api/runs``                     every run of the store (:class:`~arena.web.store.RunInfo`)
``GET  /api/runs/{run}``               one run: its info, results rows, records and live
                                       channels (``live``; a bench's ``worker_<pid>``)
``GET  /api/runs/{run}/summary``       the results page's data (:mod:`arena.web.results`):
                                       headline table, other metrics, outcomes, radar
``GET  /api/runs/{run}/files/{path}``  a file of the run (videos, reports, records)
``GET  /api/runs/{run}/replay``        ``?record=PATH``: the episode's scene and every frame,
                                       simulated again from its record
``WS   /api/runs/{run}/live``          the run's live channel (:mod:`arena.live.server`;
                                       ``?channel=``: a bench worker's): scenes, frames and
                                       statuses down, commands up
=====================================  =========================================================

Errors are JSON ``{"detail": "one line"}`` with status 404 (no such run or file) or 422 (bad
input); the server never answers with a traceback.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
from collections.abc import Callable
from functools import lru_cache
from typing import Any, TypeVar

from fastapi import APIRouter, HTTPException, Query, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse

from arena import __version__
from arena.core.errors import ArenaError
from arena.live.frame import LiveFrame, LiveScene, frame_json, scene_json
from arena.live.server import MAX_LINE, encode
from arena.web.results import run_view
from arena.web.store import NotFound, RunStore

T = TypeVar("T")

#: Longest command a browser may send on the live socket (characters).
MAX_COMMAND = 4096


def _clean(value: Any) -> Any:
    """``value`` with non-finite floats as ``None`` (JSON has no NaN)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    return value


class _Frames:
    """A live sink that keeps every frame as JSON (the replay)."""

    def __init__(self) -> None:
        self.scene_data: dict[str, Any] | None = None
        self.frames: list[dict[str, Any]] = []

    def wants_frame(self, time: float) -> bool:
        return True

    def scene(self, scene: LiveScene) -> None:
        self.scene_data = scene_json(scene)

    def frame(self, frame: LiveFrame, *, last: bool = False) -> None:
        if last and self.frames and self.frames[-1]["step"] == frame.step:
            self.frames[-1] = frame_json(frame)  # the same step, now with its outcome
        else:
            self.frames.append(frame_json(frame))


@lru_cache(maxsize=8)
def _replay(path: str, mtime: float) -> dict[str, Any]:
    """Scene and frames of the record at ``path`` (cached per file version)."""
    from arena.eval.io import load_record
    from arena.eval.replay import resimulate
    from arena.live.hook import LiveHook

    record = load_record(path)
    sink = _Frames()
    _, same = resimulate(record, None, hooks=[LiveHook([sink])])
    return {"scene": sink.scene_data, "frames": sink.frames, "matches_record": same,
            "outcome": record.meta.outcome}


def answered(call: Callable[..., T], *args: Any) -> T:
    """``call(*args)``, its refusals as one-line HTTP errors (every router of the app).

    :class:`NotFound` is 404; an :class:`ArenaError` is its ``http_status`` (a job's state
    conflict: 409) or 422; an :class:`OSError` (the store's disk full or gone) is 422.
    """
    try:
        return call(*args)
    except NotFound as e:
        raise HTTPException(404, str(e)) from None
    except ArenaError as e:
        raise HTTPException(getattr(e, "http_status", 422), str(e)) from None
    except OSError as e:
        raise HTTPException(422, f"the run store: {e.strerror or e}") from None


def api_router(store: RunStore) -> APIRouter:
    """The API on ``store`` (see the module doc)."""
    router = APIRouter(prefix="/api")
    found = answered

    @router.get("/health")
    def health() -> dict[str, Any]:
        return {"ok": True, "version": __version__}

    @router.get("/runs")
    def runs() -> list[dict[str, Any]]:
        return [r.as_json() for r in store.runs()]

    @router.get("/runs/{run}")
    def run(run: str) -> dict[str, Any]:
        info = found(store.info, run)
        return {"info": info.as_json(), "results": _clean(found(store.results, run)),
                "records": found(store.records, run), "channels": list(store.channels(run))}

    @router.get("/runs/{run}/summary")
    def summary(run: str) -> dict[str, Any]:
        """The results page's data: headline table, other metrics, outcomes, radar."""
        return found(run_view, store, run)

    @router.get("/runs/{run}/files/{path:path}")
    def file(run: str, path: str) -> FileResponse:
        return FileResponse(found(store.file, run, path))

    @router.get("/runs/{run}/replay")
    def replay(run: str, record: str = Query(..., description="record path in the run")
               ) -> dict[str, Any]:
        if not record.endswith(".parquet"):
            raise HTTPException(404, f"no record {record!r} in run {run!r}")
        path = found(store.file, run, record)
        return found(_replay, str(path), path.stat().st_mtime)

    @router.websocket("/runs/{run}/live")
    async def live(ws: WebSocket, run: str, channel: str | None = None) -> None:
        try:
            info = store.live(run, channel)
        except NotFound:
            info = None
        await ws.accept()
        if info is None:
            what = f"run {run!r}" + (f" has no live channel {channel!r}" if channel else
                                     " is not running")
            await ws.send_text(json.dumps({"type": "closed", "message": what}))
            await ws.close()
            return
        try:
            reader, writer = await asyncio.open_connection(
                info["host"], info["port"], limit=16 * MAX_LINE + 2**22)
        except OSError:
            await ws.send_text(json.dumps({"type": "closed", "message": "the run has ended"}))
            await ws.close()
            return
        writer.write(encode({"token": info["token"]}))

        async def down() -> None:
            while line := await reader.readline():
                await ws.send_text(line.decode())

        async def up() -> None:
            while True:
                text = await ws.receive_text()
                try:
                    message = json.loads(text) if len(text) <= MAX_COMMAND else None
                except ValueError:
                    message = None
                if not isinstance(message, dict) or "cmd" not in message:
                    await ws.send_text(json.dumps({"type": "error", "message":
                                                   "a command is a JSON object with 'cmd'"}))
                    continue
                writer.write(encode(message))
                await writer.drain()

        tasks = [asyncio.ensure_future(down()), asyncio.ensure_future(up())]
        try:
            await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
        finally:
            for t in tasks:
                t.cancel()
            writer.close()
            with contextlib.suppress(Exception):
                await ws.send_text(json.dumps({"type": "closed", "message": "the run has ended"}))
                await ws.close()
        with contextlib.suppress(WebSocketDisconnect, ConnectionError, asyncio.CancelledError):
            await asyncio.gather(*tasks, return_exceptions=True)

    return router
