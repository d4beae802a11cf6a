"""The runs manager's page ``/jobs`` (NiceGUI): start a run or a benchmark, watch, cancel, resume.

The page calls the same :class:`~arena.web.jobs.JobManager` as the API (``/api/jobs``), and its
selects offer the API's lists (:func:`arena.web.job_requests.choices`). The job list is read
from the run folders once a second and redrawn when something changed, so it shows jobs started
elsewhere (the API, another browser, before a server restart) too.

Stable element ids for scripts and tests: ``jobs-kind``, ``jobs-name``, ``jobs-episodes`` ...,
``jobs-start``, ``jobs-error``, ``jobs-list``; per job ``jobs-row-<name>``,
``jobs-state-<name>``, ``jobs-progress-<name>``, ``jobs-results-<name>``, ``jobs-live-<name>``,
``jobs-cancel-<name>``, ``jobs-resume-<name>``.
"""

from __future__ import annotations

import html
from datetime import datetime
from typing import Any
from urllib.parse import quote

from nicegui import run, ui

from arena.core.errors import ArenaError
from arena.web.editor_store import EditorWorkspace
from arena.web.job_requests import choices
from arena.web.jobs import JobManager, JobStatus
from arena.web.pages import _header  # the app's one header, with its navigation links

#: The manager the page shows (set by :func:`arena.web.server.create_app`).
MANAGER: JobManager | None = None

#: Badge colours (Quasar palette) per state.
STATE_COLOURS = {"running": "primary", "done": "positive", "failed": "negative",
                 "cancelled": "grey-7"}
#: Seconds between two looks at the run folders.
REFRESH_S = 1.0


def _manager() -> JobManager:
    assert MANAGER is not None, "create_app sets the manager"
    return MANAGER


def _with_id(element: Any, name: str) -> Any:
    """``element`` with the DOM id ``name`` (a text field's goes on its ``<input>``)."""
    if isinstance(element, ui.input | ui.number):
        return element.props(f'for="{name}"')  # Quasar gives the native input this id
    return element.props(f'id="{name}"')


class _StartForm:
    """The form: a run's or a benchmark's fields, and the start button."""

    def __init__(self, on_started: Any) -> None:
        self.on_started = on_started
        lists = choices()
        names = {k: [d["name"] for d in v] for k, v in lists.items()}
        with ui.card().classes("w-full max-w-xl"):
            ui.label("Start").classes("text-lg font-bold")
            self.kind = _with_id(ui.toggle({"run": "run", "bench": "benchmark"}, value="run"),
                                 "jobs-kind")
            self.name = _with_id(ui.input("name", placeholder="automatic (kind_date-time)"),
                                 "jobs-name").classes("w-full")
            with ui.column().classes("w-full gap-1").bind_visibility_from(
                    self.kind, "value", value="run"):
                with ui.row().classes("w-full no-wrap"):
                    self.config = _with_id(ui.input(
                        "config", placeholder="the demo", autocomplete=names["configs"]),
                        "jobs-config").classes("w-1/2").tooltip(
                        "a packaged config or the path of an experiment YAML on the server")
                    self.robot = _with_id(ui.select(
                        {"": "the config's", **{n: n for n in names["robots"]}}, value="",
                        label="robot"), "jobs-robot").classes("w-1/2")
                saved = EditorWorkspace(_manager().root).scenarios()
                self.saved = _with_id(ui.select(
                    {"": "none", **{n: n for n in saved}}, value="",
                    label="scenario from the editor (brings its map)"),
                    "jobs-saved-scenario").classes("w-full")
                with ui.row().classes("w-full no-wrap").bind_visibility_from(
                        self.saved, "value", value=""):
                    self.map = _with_id(ui.input(
                        "map", placeholder="the config's", autocomplete=names["worlds"]),
                        "jobs-map").classes("w-1/2").tooltip(
                        "a packaged world, a world folder or a map.yaml on the server")
                    self.scenario = _with_id(ui.input(
                        "scenario", placeholder="none (e.g. default, corridor/default)"),
                        "jobs-scenario").classes("w-1/2")
                with ui.row().classes("w-full no-wrap items-center"):
                    self.episodes = _with_id(ui.number("episodes", value=2, min=1, step=1,
                                                       format="%d"), "jobs-episodes")
                    self.run_seed = _with_id(ui.number("seed", value=0, min=0, step=1,
                                                       format="%d"), "jobs-run-seed")
                    self.video = _with_id(ui.checkbox("videos"), "jobs-video")
                    self.live = _with_id(ui.checkbox("live view"), "jobs-live").tooltip(
                        "serve a live channel; the run then goes at real time")
            with ui.column().classes("w-full gap-1").bind_visibility_from(
                    self.kind, "value", value="bench"):
                with ui.row().classes("w-full no-wrap"):
                    self.suite = _with_id(ui.select(
                        {s["name"]: f"{s['name']} ({s['episodes']} episodes)"
                         for s in lists["suites"]}, value="quick", label="suite"),
                        "jobs-suite").classes("w-1/2")
                    self.contest = _with_id(ui.select(
                        {c["name"]: f"{c['name']} ({len(c['contestants'])} contestants)"
                         for c in lists["contests"]}, value="basic", label="contest"),
                        "jobs-contest").classes("w-1/2")
                with ui.row().classes("w-full no-wrap"):
                    self.workers = _with_id(ui.number("workers", value=1, min=1, step=1,
                                                      format="%d"), "jobs-workers")
                    self.scale = _with_id(ui.number("scale", value=1.0, min=0.01, step=0.1),
                                          "jobs-scale").tooltip("factor on every stage's "
                                                                "episodes")
                    self.bench_seed = _with_id(ui.number("seed", value=0, min=0, step=1,
                                                         format="%d"), "jobs-bench-seed")
                    self.bench_live = _with_id(ui.checkbox("live view"), "jobs-bench-live"
                                               ).tooltip("watch the workers' episodes (the "
                                                         "benchmark's results do not change)")
            with ui.row().classes("items-center"):
                self.button = _with_id(ui.button("start", icon="play_arrow",
                                                 on_click=self.start), "jobs-start")
                self.error = _with_id(ui.label(""), "jobs-error").classes(
                    "text-red-700 text-sm")

    def request(self) -> dict[str, Any]:
        """The form's values as a job request (empty fields left out: their defaults)."""
        def whole(value: Any) -> int | None:
            return None if value is None or value == "" else int(value)

        req: dict[str, Any] = {"kind": self.kind.value}
        if self.name.value.strip():
            req["name"] = self.name.value.strip()
        if self.kind.value == "run":
            place = ((("saved_scenario", self.saved.value),) if self.saved.value else
                     (("map", self.map.value), ("scenario", self.scenario.value)))
            for key, value in (("config", self.config.value), ("robot", self.robot.value),
                               *place):
                if value and str(value).strip():
                    req[key] = str(value).strip()
            req.update(episodes=whole(self.episodes.value), seed=whole(self.run_seed.value),
                       video=bool(self.video.value), live=bool(self.live.value))
        else:
            req.update(suite=self.suite.value, contest=self.contest.value,
                       workers=whole(self.workers.value), seed=whole(self.bench_seed.value),
                       scale=float(self.scale.value) if self.scale.value else None,
                       live=bool(self.bench_live.value))
        return {k: v for k, v in req.items() if v is not None}

    async def start(self) -> None:
        """Check and start the job; a refusal shows as one line under the button."""
        self.button.disable()
        try:
            status = await run.io_bound(_manager().start, self.request())
        except (ArenaError, OSError) as e:
            self.error.set_text(str(e))
            return
        finally:
            self.button.enable()
        self.error.set_text("")
        self.name.set_value("")
        ui.notify(f"started {status.name if status else 'the job'}", type="positive")
        self.on_started()


def _job_row(job: JobStatus, refresh: Any) -> None:
    """One job: name and links, state, progress, when, buttons; its log folded."""
    name = quote(job.name)

    async def act(action: str) -> None:
        call = _manager().cancel if action == "cancel" else _manager().resume
        try:
            await run.io_bound(call, job.name)
        except ArenaError as e:
            ui.notify(str(e), type="negative")
        refresh()

    with _with_id(ui.card(), f"jobs-row-{job.name}").classes("w-full gap-1 py-2"):
        with ui.row().classes("w-full items-center no-wrap gap-3"):
            _with_id(ui.link(job.name, f"/runs/{name}"), f"jobs-results-{job.name}").classes(
                "font-bold")
            ui.label(f"{job.kind} · {job.title}").classes("text-slate-600 text-sm")
            if job.live:
                _with_id(ui.link("live view", f"/live/{name}"), f"jobs-live-{job.name}")
            ui.space()
            _with_id(ui.badge(job.state, color=STATE_COLOURS.get(job.state, "grey")),
                     f"jobs-state-{job.name}").props(f'data-state="{job.state}"')
            if job.state == "running":
                _with_id(ui.button("cancel", icon="stop", color="negative",
                                   on_click=lambda: act("cancel")),
                         f"jobs-cancel-{job.name}").props("flat dense")
            elif job.state in ("cancelled", "failed"):
                _with_id(ui.button("resume", icon="replay", on_click=lambda: act("resume")),
                         f"jobs-resume-{job.name}").props("flat dense")
        with ui.row().classes("w-full items-center no-wrap gap-3"):
            fraction = min(1.0, job.done / job.planned) if job.planned else 0.0
            _with_id(ui.linear_progress(value=fraction, show_value=False, size="10px",
                                        color=STATE_COLOURS.get(job.state, "grey")),
                     f"jobs-progress-{job.name}").classes("grow")
            ui.label(f"{job.done} / {job.planned or '?'} episodes").classes(
                "text-sm whitespace-nowrap")
            started = datetime.fromtimestamp(job.started).strftime("%Y-%m-%d %H:%M:%S")
            took = (f" · {job.finished - job.started:.0f} s" if job.finished else "")
            ui.label(f"started {started}{took}" + (f" · attempt {job.attempts}"
                                                   if job.attempts > 1 else "")).classes(
                "text-sm text-slate-500 whitespace-nowrap")
        if job.reason:
            ui.label(job.reason).classes("text-sm text-red-700 break-all")
        with ui.expansion("log").classes("w-full text-sm").props("dense"):
            ui.html("<pre style='font-size:12px;margin:0;white-space:pre-wrap'>"
                    + html.escape("\n".join(_manager().log(job.name, 30))) + "</pre>",
                    sanitize=False)


@ui.page("/jobs")
def jobs() -> None:
    """Start runs and benchmarks; every job with its state, progress and actions."""
    _header("jobs")
    seen: list[Any] = [None]

    @ui.refreshable
    def job_list() -> None:
        listed = _manager().jobs()
        seen[0] = [(j.name, j.state, j.done, j.live, j.attempts) for j in listed]
        with _with_id(ui.column(), "jobs-list").classes("w-full gap-2"):
            if not listed:
                ui.label("No jobs yet: start a run or a benchmark.").classes("text-slate-500")
            for job in listed:
                _job_row(job, job_list.refresh)

    def tick() -> None:
        now = [(j.name, j.state, j.done, j.live, j.attempts) for j in _manager().jobs()]
        if now != seen[0]:
            job_list.refresh()

    with ui.row().classes("w-full items-start no-wrap gap-6 p-2"):
        _StartForm(on_started=job_list.refresh)
        with ui.column().classes("grow gap-2"):
            ui.label("Jobs").classes("text-lg font-bold")
            job_list()
    ui.timer(REFRESH_S, tick)
