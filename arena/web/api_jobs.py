"""The runs manager's REST API: start, watch, cancel and resume jobs (:mod:`arena.web.jobs`).

=====================================  =========================================================
``GET  /api/jobs``                     every job (:class:`~arena.web.jobs.JobStatus`)
``POST /api/jobs``                     start one: a run or a benchmark request
                                       (:mod:`arena.web.job_requests`); 201 and its status
``GET  /api/jobs/{name}``              its status and the tail of its log (``?lines=``)
``POST /api/jobs/{name}/cancel``       stop it (SIGTERM, then SIGKILL)
``POST /api/jobs/{name}/resume``       start a cancelled or failed job again, keeping its
                                       finished episodes
``GET  /api/suites``                   the packaged suites (stages, episodes)
``GET  /api/contests``                 the packaged contests (contestants)
``GET  /api/robots``                   the robot presets
=====================================  =========================================================

Errors are JSON ``{"detail": "one line"}``: 404 (no such job), 409 (the job's state does not
allow it) or 422 (bad input: nothing was started).
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, HTTPException, Query, Request
from fastapi.concurrency import run_in_threadpool

from arena.web.api import answered
from arena.web.job_requests import choices, request_schema
from arena.web.jobs import JobManager


def jobs_router(manager: JobManager) -> APIRouter:
    """The jobs API on ``manager`` (see the module doc)."""
    router = APIRouter(prefix="/api")

    answer = answered

    @router.get("/jobs")
    def jobs() -> list[dict[str, Any]]:
        return [j.as_json() for j in manager.jobs()]

    # The body is read as JSON and checked by the request models here, so that bad input is
    # the one-line 422 of every other error (FastAPI's own check answers with a list).
    @router.post("/jobs", status_code=201, openapi_extra={"requestBody": {
        "required": True, "content": {"application/json": {"schema": request_schema()}}}})
    async def start(request: Request) -> dict[str, Any]:
        try:
            body = await request.json()
        except ValueError:
            raise HTTPException(422, "the body is no JSON: send a job request as a JSON object"
                                ) from None
        # checking the request draws a benchmark's plan (~0.1 s): off the event loop
        status = await run_in_threadpool(answer, manager.start, body)
        return status.as_json()

    @router.get("/jobs/{name}")
    def job(name: str, lines: int = Query(40, ge=0, le=1000)) -> dict[str, Any]:
        status = answer(manager.status, name)
        return {**status.as_json(), "log": answer(manager.log, name, lines)}

    @router.post("/jobs/{name}/cancel")
    def cancel(name: str) -> dict[str, Any]:
        return answer(manager.cancel, name).as_json()

    @router.post("/jobs/{name}/resume")
    def resume(name: str) -> dict[str, Any]:
        return answer(manager.resume, name).as_json()

    for kind in ("suites", "contests", "robots"):  # worlds: the editor's /api/worlds
        router.add_api_route(f"/{kind}", _lister(kind), methods=["GET"],
                             summary=f"The packaged {kind}")
    return router


def _lister(kind: str) -> Any:
    def listing() -> list[dict[str, Any]]:
        return choices()[kind]

    listing.__name__ = f"list_{kind}"
    return listing
