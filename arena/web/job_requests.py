"""What the web app may start: the request models of a run and a benchmark, checked into commands.

A request is checked here, in the web server's process, before anything starts: names of
robots, worlds, scenarios, suites, contests and configs are looked up with the same functions
the CLI uses, so a typo is a one-line :class:`JobError` (the API's 422), not a job that fails a
second later. What passes becomes a :class:`JobCommand`: the ``arena`` arguments (``run`` or
``bench``), a title and the number of episodes planned (the job's progress bar).

The choices the start form offers (:func:`choices`) come from the same places.
"""

from __future__ import annotations

import functools
import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError

from arena.core.errors import ArenaError, from_validation_error


class JobError(ArenaError):
    """A request the web app will not start (bad or unknown input); one line."""


class RunRequest(BaseModel):
    """Start ``arena run``: the packaged demo or a config file, with the CLI's usual options."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: Literal["run"] = "run"
    name: str | None = Field(None, description="run folder name (default: run_<date-time>)")
    config: str | None = Field(
        None, description="experiment YAML file or packaged config name (default: the demo)")
    robot: str | None = Field(None, description="robot preset name or YAML file")
    episodes: int | None = Field(None, ge=1, le=100_000, description="number of episodes")
    seed: int | None = Field(None, ge=0, description="master seed")
    map: str | None = Field(None, description="packaged world name, world folder or map.yaml")
    scenario: str | None = Field(
        None, description="Arena scenario JSON file, or NAME in the map's world, or WORLD/NAME")
    saved_scenario: str | None = Field(
        None, description="a scenario saved by the editor (its name); it brings its map")
    video: bool = Field(False, description="write videos (slow)")
    live: bool = Field(False, description="serve a live channel (the run goes at real time)")


class BenchRequest(BaseModel):
    """Start ``arena bench``: every contestant of a contest on every episode of a suite."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    kind: Literal["bench"] = "bench"
    name: str | None = Field(None, description="run folder name (default: bench_<date-time>)")
    suite: str = Field("quick", description="packaged suite name or suite YAML file")
    contest: str = Field("basic", description="packaged contest name or contest YAML file")
    workers: int = Field(1, ge=1, le=256, description="worker processes")
    scale: float = Field(1.0, gt=0, le=1000, description="factor on every stage's episodes")
    seed: int = Field(0, ge=0, description="run seed")
    live: bool = Field(False, description="serve each worker's episode for watching (changes "
                                          "no result)")


JobRequest = Annotated[RunRequest | BenchRequest, Field(discriminator="kind")]
_REQUEST: TypeAdapter[RunRequest | BenchRequest] = TypeAdapter(JobRequest)


def parse_request(data: Any) -> RunRequest | BenchRequest:
    """The request in ``data`` (a JSON object).

    Raises:
        JobError: not an object, an unknown kind or key, a value out of range (one line).
    """
    if not isinstance(data, dict):
        raise JobError(f"a job request is a JSON object, got {type(data).__name__}")
    try:
        return _REQUEST.validate_python(data)
    except ValidationError as e:
        raise JobError(str(from_validation_error(e))) from None


def request_schema() -> dict[str, Any]:
    """The request's JSON schema without references (for the OpenAPI document)."""
    return {"oneOf": [RunRequest.model_json_schema(), BenchRequest.model_json_schema()]}


@dataclass(frozen=True)
class JobCommand:
    """A checked request as a command.

    Attributes:
        args: ``arena`` arguments without the output folder (``["run", ...]``).
        title: what the run list shows.
        planned: episodes the command will run.
    """

    args: list[str]
    title: str
    planned: int


def _checked(call: Any, *args: Any, what: str) -> Any:
    """``call(*args)``, its ArenaError as a JobError naming the request field ``what``."""
    try:
        return call(*args)
    except ArenaError as e:
        raise JobError(f"{what}: {e}") from None


def run_command(req: RunRequest, root: Path | None = None) -> JobCommand:
    """The ``arena run`` arguments of ``req``, checked.

    Args:
        req: the request.
        root: the run store, whose editor workspace holds ``req.saved_scenario``.

    Raises:
        JobError: an unknown config, robot, world, scenario or saved scenario, or a config that
            does not load.
    """
    if req.saved_scenario is not None:
        req = _with_saved_scenario(req, root)
    from arena.config import load_config
    from arena.config.loader import PRESETS_DIR
    from arena.maps.sources import resolve_scenario, resolve_world
    from arena.robots.presets import load_robot

    args = ["run"]
    items: list[str] = []
    config: Path | None = None
    if req.config:
        file, preset = Path(req.config).expanduser(), PRESETS_DIR / f"{req.config}.yaml"
        if file.is_file():
            config = file.resolve()
        elif "/" not in req.config and preset.is_file():
            config = preset
        else:
            known = ", ".join(sorted(p.stem for p in PRESETS_DIR.glob("*.yaml")))
            raise JobError(f"config: no file {req.config!r} and no packaged config of that "
                           f"name (packaged: {known})")
        args.append(str(config))
    if req.robot:
        _checked(load_robot, req.robot, what="robot")
        args += ["--robot", req.robot]
        items.append(f"robot={req.robot}")
    if req.episodes is not None:
        args += ["-n", str(req.episodes)]
        items.append(f"episodes={req.episodes}")
    if req.seed is not None:
        args += ["--seed", str(req.seed)]
        items.append(f"seed={req.seed}")
    world: str | None = None
    if req.map:
        path = Path(req.map).expanduser()
        if path.suffix in (".yaml", ".yml"):
            if not path.is_file():
                raise JobError(f"map: no file {req.map!r}")
            args += ["--map", str(path.resolve())]
        else:
            _checked(resolve_world, req.map, what="map")
            world = str(path.resolve()) if path.is_dir() else req.map
            args += ["--map", world]
    cfg = _checked(load_config, config, items, what="config")
    if req.scenario:
        if world is None and cfg.map.get("type") == "world":
            world = str(cfg.map.get("name"))
        file = _checked(resolve_scenario, req.scenario, world, what="scenario")
        args += ["--scenario", str(file)]
    args.append("--video" if req.video else "--no-video")
    if req.live:
        args += ["--live", "--no-web"]  # the web app that started it shows it
    title = f"{Path(req.config).stem if req.config else 'demo'} · {req.robot or cfg.robot}"
    return JobCommand(args, title, int(cfg.episodes))


def bench_command(req: BenchRequest) -> JobCommand:
    """The ``arena bench`` arguments of ``req``, checked (its plan is drawn to count it).

    Raises:
        JobError: an unknown suite or contest, a contestant's unknown planner, or a scale that
            leaves no episode.
    """
    from arena.config.schema import ExperimentConfig
    from arena.eval.runner import check_scale, plan_jobs
    from arena.tasks.suite import load_contest, load_suite

    if not math.isfinite(req.scale):  # the model refuses it too; a caller may build one by hand
        raise JobError(f"scale: expected a finite number > 0, got {req.scale}")
    suite = _checked(lambda: load_suite(req.suite, scale_episodes=req.scale), what="suite")
    contest, contest_src = _checked(load_contest, req.contest, what="contest")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a stage the scale drops: the job's log says so
        _checked(check_scale, suite, suite.source, what="scale")
    jobs = _checked(lambda: plan_jobs(suite, contest, ExperimentConfig(seed=req.seed),
                                      contest_source=contest_src), what="contest")
    args = ["bench", req.suite, "--contest", req.contest, "--workers", str(req.workers),
            "--scale", repr(req.scale), "--seed", str(req.seed), "--no-progress",
            *(["--live", "--no-web"] if req.live else [])]
    title = f"{Path(req.suite).stem} × {Path(req.contest).stem}"
    return JobCommand(args, title, len(jobs))


def _with_saved_scenario(req: RunRequest, root: Path | None) -> RunRequest:
    """``req`` with the editor's saved scenario as ``scenario`` (its file) and ``map``."""
    from arena.web.editor_store import EditorWorkspace, MapRef
    from arena.web.store import NotFound

    if req.map or req.scenario:
        raise JobError("saved_scenario brings its own map and scenario: drop map and scenario")
    if root is None:
        raise JobError("saved_scenario: no run store to find it in")
    workspace = EditorWorkspace(root)
    try:
        path = workspace.scenario_path(str(req.saved_scenario))
    except ArenaError as e:
        raise JobError(f"saved_scenario: {e}") from None
    if not path.is_file():
        raise JobError(f"saved_scenario: no scenario {req.saved_scenario!r} in "
                       f"{workspace.scenarios_dir} (saved: "
                       f"{', '.join(workspace.scenarios()) or 'none'})")
    try:
        label = json.loads(path.read_text()).get("map") or ""
    except (OSError, ValueError, AttributeError):
        raise JobError(f"saved_scenario: {path} is no scenario JSON object") from None
    ref = MapRef.from_label(str(label))
    try:
        map_yaml = workspace.map_yaml(ref)
    except NotFound as e:
        raise JobError(f"saved_scenario: its map {label!r}: {e}") from None
    where = ref.name if ref.kind == "world" else str(map_yaml.parent)
    return req.model_copy(update={"map": where, "scenario": str(path),
                                  "saved_scenario": None})


def command(req: RunRequest | BenchRequest, root: Path | None = None) -> JobCommand:
    """The checked command of either kind of request (``root``: the run store)."""
    return run_command(req, root) if isinstance(req, RunRequest) else bench_command(req)


@functools.lru_cache(maxsize=1)
def choices() -> dict[str, list[dict[str, Any]]]:
    """What the start form offers: packaged suites, contests, robots, worlds and configs.

    Read once (package data); the caller must not change the answer.
    """
    from arena.config.loader import PRESETS_DIR
    from arena.maps.sources import packaged_worlds
    from arena.robots.presets import robot_names
    from arena.tasks.datafiles import packaged
    from arena.tasks.suite import load_contest, load_suite

    suites = []
    for name in packaged("suites"):
        suite = load_suite(name)
        suites.append({"name": name, "stages": [s.name for s in suite.stages],
                       "episodes": int(sum(suite.episode_counts))})
    contests = []
    for name in packaged("contests"):
        contest, _ = load_contest(name)
        contests.append({"name": name, "contestants": [c.name for c in contest.contestants]})
    return {
        "suites": suites,
        "contests": contests,
        "robots": [{"name": n} for n in robot_names()],
        "worlds": [{"name": n} for n in packaged_worlds()],
        "configs": [{"name": p.stem} for p in sorted(PRESETS_DIR.glob("*.yaml"))],
    }
