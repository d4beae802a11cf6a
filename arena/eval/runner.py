"""Run a benchmark: every contestant on every episode of every stage of a suite.

A job is one ``(contestant, stage, episode)``. Its episode is drawn by the stage's
:class:`~arena.tasks.generator.TaskGenerator`, a pure function of (config, seed, index), so a job
gives the same result in any process and in any order. Workers only compute; the parent process
commits each finished job to the run's :mod:`results store <arena.eval.store>`, one file pair per
job, so the results do not depend on the number of workers, and a killed run resumes where it
stopped (``resume=True`` skips the committed jobs).

Metrics named like a figure of :class:`~arena.eval.episodes.EpisodeResult` (``path_length``,
``collisions``) are stored once, as the figure (``collisions`` an int; ``path_length`` without
teleport jumps, as the metric, which finds them by the record's ``teleport`` events).

An episode whose planner raises, returns NaN or otherwise fails ends as ``error`` with the
message in ``error``; the run goes on. Each episode runs in a worker process
(:mod:`arena.eval.workers`), so an episode whose worker dies (a segfault, ``os._exit``, the OOM
killer) or that runs past the wall-clock limit ``episode_timeout`` ends as ``error`` too
("worker died (exit code -11: SIGSEGV)", "wall-clock limit 600 s exceeded") and costs nothing
else: the worker is replaced, the rows already committed stay, the run goes on.
"""

from __future__ import annotations

import contextlib
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError, ConfigError
from arena.eval import live_bench
from arena.eval.record import EpisodeRecord
from arena.eval.store import (
    MANIFEST,
    check_manifest,
    commit_episode,
    completed,
    load_results,
    load_rows,
    write_manifest,
)
from arena.tasks.suite import ContestFile, Suite, contestant_config, load_contest, load_suite

#: ``progress`` callback: ``(done, total, row)`` after each committed job.
ProgressFn = Callable[[int, int, dict[str, Any]], None]
#: Default wall-clock limit of one episode (s): far above what a planner needs for the packaged
#: suites' longest episodes, short enough that a hung planner costs minutes, not the night.
DEFAULT_EPISODE_TIMEOUT = 600.0


@dataclass(frozen=True)
class Job:
    """One episode to run: plain data, picklable for any worker process.

    Attributes:
        contestant: contestant name.
        local_planner: local planner name.
        inter_planner: intermediate planner name.
        stage: stage name.
        episode: episode index local to the stage.
        config: the stage's experiment config for this contestant (``model_dump(mode="json")``).
    """

    contestant: str
    local_planner: str
    inter_planner: str
    stage: str
    episode: int
    config: dict[str, Any]

    @property
    def key(self) -> tuple[str, str, int]:
        """``(contestant, stage, episode)``, as in :func:`arena.eval.store.completed`."""
        return (self.contestant, self.stage, self.episode)


def plan_jobs(suite: Suite, contest: ContestFile, base_cfg: ExperimentConfig,
              *, contest_source: str | None = None) -> list[Job]:
    """Every job of a run: contestants × stages × episodes, in that order.

    Raises:
        ConfigError: an unknown planner (naming the contest file and contestant) or a bad stage.
    """
    from arena.nav.intermediate.base import INTERMEDIATE_PLANNERS

    jobs = []
    stages = suite.stage_experiments(base_cfg)
    for ci, c in enumerate(contest.contestants):
        try:
            INTERMEDIATE_PLANNERS.entry(c.inter_planner)
        except ArenaError as e:
            raise ArenaError(
                f"{contest_source or 'contest'}: contestants[{ci}].inter_planner: {e}"
            ) from None
        for st, stage_cfg in stages:
            cfg = contestant_config(stage_cfg, c, source=contest_source, index=ci)
            data = cfg.model_dump(mode="json")
            data["name"] = stage_cfg.name
            data["navigation"]["intermediate_planner"] = {"type": c.inter_planner}
            cfg = ExperimentConfig.model_validate(data)
            dumped = cfg.model_dump(mode="json")
            for k in range(stage_cfg.episodes):
                jobs.append(Job(c.name, c.local_planner, c.inter_planner, st.name, k, dumped))
    return jobs


@lru_cache(maxsize=8)
def _generator(config_json: str) -> Any:
    import json

    from arena.robots.presets import load_robot
    from arena.tasks.generator import TaskGenerator

    cfg = ExperimentConfig.model_validate(json.loads(config_json))
    return cfg, TaskGenerator.from_config(cfg, [load_robot(cfg.robot)])


def _nan_metrics() -> dict[str, float]:
    from arena.eval.episodes import episode_metrics

    return episode_metrics(None)[0]


def _base_row(job: Job) -> dict[str, Any]:
    """A job's results row before it ran: its ids, outcome ``error``, no figures."""
    return {
        "contestant": job.contestant,
        "local_planner": job.local_planner,
        "inter_planner": job.inter_planner,
        "stage": job.stage,
        "episode": job.episode,
        "seed": None,
        "map": "",
        "robot": str(job.config.get("robot", "")),
        "outcome": "error",
        "time": math.nan,
        "path_length": math.nan,
        "collisions": 0,
        "wall_time": 0.0,
        "error": "",
    }


def _error_result(job: Job, error: str) -> tuple[dict[str, Any], EpisodeRecord | None]:
    """The result of a job that failed outside :func:`run_job` (e.g. its worker died)."""
    row = _base_row(job)
    row["error"] = error
    for name, value in _nan_metrics().items():
        row.setdefault(name, value)
    return row, None


def run_job(job: Job) -> tuple[dict[str, Any], EpisodeRecord | None]:
    """Run one job; return its results row (ids, outcome, metrics, figures) and its record.

    Never raises for a failing episode: any exception becomes outcome ``error`` with
    ``"<ExceptionType>: message"`` in ``error`` (and NaN metrics when no record was made).
    """
    import json

    import arena.plugins  # noqa: F401  (fills the registries in a fresh worker)
    from arena.episode.runner import describe_exception
    from arena.eval.episodes import episode_metrics, run_episode
    from arena.sim.backend import BACKENDS

    t0 = time.perf_counter()
    row = _base_row(job)
    record = None
    metrics = _nan_metrics()
    try:
        cfg, gen = _generator(json.dumps(job.config, sort_keys=True))
        episode = gen.episode(job.episode)
        row.update(seed=int(episode.seed), map=episode.map_name,
                   robot=episode.robots[0].model.name)
        backend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
        watched = live_bench.hooks(f"{job.contestant} · {job.stage} · episode {job.episode}")
        res = run_episode(cfg, episode, backend, None, runtime=gen.runtime(episode),
                          hooks=watched)
        row.update(outcome=res.outcome, time=float(res.time), path_length=res.path_length,
                   collisions=int(res.collisions), error=res.error)
        record = res.record
        metrics, problem = episode_metrics(record)  # a metric bug must not lose the episode
        if problem:
            row["error"] = f"{row['error']}; {problem}" if row["error"] else problem
    except Exception as e:
        row["outcome"] = "error"
        row["error"] = describe_exception(e)
    for name, value in metrics.items():  # path_length, collisions: run_episode's figures win
        row.setdefault(name, value)
    row["wall_time"] = time.perf_counter() - t0
    return row, record


def _warm_up(live_run: str | None = None) -> None:
    """A fresh worker's imports (registries, simulator, metrics), before its first job.

    With ``live_run`` (a run folder) the worker also serves its episodes live
    (:mod:`arena.eval.live_bench`).
    """
    if live_run is not None:  # first: a viewer may connect while the imports run
        live_bench.start(live_run)
    import arena.eval.episodes
    import arena.eval.metrics
    import arena.plugins  # noqa: F401


def check_scale(suite: Suite, source: str) -> None:
    """Warn once per stage that ``scale_episodes`` drops; raise when no episode is left.

    Raises:
        ConfigError: every stage scaled to 0 episodes (naming the suite and the smallest scale
            that keeps one).
    """
    scale = suite.scale_episodes
    counts = suite.episode_counts
    if sum(counts) == 0:
        planned = [st.episodes for st in suite.stages if st.episodes > 0]
        hint = f"; a scale >= {1 / max(planned):.3g} keeps one" if planned else ""
        raise ConfigError(f"scale {scale:g} leaves no episode in any stage{hint}",
                          source=source)
    for st, n in zip(suite.stages, counts, strict=True):
        if n == 0 and st.episodes > 0:
            warnings.warn(f"{source}: scale {scale:g} drops stage {st.name!r} "
                          f"({st.episodes} episode(s) x {scale:g} < 1)", UserWarning,
                          stacklevel=3)


def run_benchmark(
    suite: str | Path | Suite,
    contest: str | Path | ContestFile,
    run_dir: str | Path,
    *,
    base_cfg: ExperimentConfig | None = None,
    workers: int = 1,
    resume: bool = False,
    scale: float = 1.0,
    progress: bool | ProgressFn | None = None,
    backend: str = "process",
    ray_address: str | None = None,
    episode_timeout: float | None = DEFAULT_EPISODE_TIMEOUT,
    worlds: str | Path | None = None,
    live: bool = False,
) -> Path:
    """Run (or resume) a benchmark into ``run_dir``; return the run folder.

    Args:
        suite: packaged suite name, suite file or a loaded :class:`Suite` (then ``scale`` is
            the suite's own ``scale_episodes``).
        contest: packaged contest name, contest file or a loaded :class:`ContestFile`.
        run_dir: the run folder (created); results land as in :mod:`arena.eval.store`.
        base_cfg: the experiment every stage derives from (its ``seed`` is the run seed, its
            ``sim.backend`` the simulator of every episode: its type is kept in the manifest).
        workers: worker processes running the episodes; ``0`` runs them in this process
            (for debugging: no fault isolation, no wall-clock limit, but plugins registered at
            run time in this process are seen). With ``backend="ray"``, the number of tasks
            run at once (and the CPUs of the local Ray it starts).
        resume: continue the run in ``run_dir``: skip its committed episodes. The suite,
            contest, seed and scale must be the run's.
        scale: factor on every stage's episode count.
        progress: ``True`` shows a rich progress bar with ETA; a callable gets
            ``(done, total, row)`` after every committed episode.
        backend: ``"process"`` (``concurrent.futures``) or ``"ray"`` (needs ``ray``). The
            backend is not part of the run's settings: a run resumes with either.
        ray_address: with ``backend="ray"``: ``None`` starts a local Ray (shut down at the end)
            unless one is already initialized; ``"auto"`` or an address connects to a cluster.
        episode_timeout: wall-clock limit of one episode (s), ``None`` for none: an episode
            past it has its worker (ray: its task) killed and ends as ``error``. Like
            ``workers`` and ``backend`` it is not part of the run's settings.
        worlds: the folder of worlds in Arena's layout that the suite's world names are looked
            up in first (:mod:`arena.tasks.suite`); ``None``: the suite's ``worlds`` key, if
            any. Part of the run's settings (the manifest keeps the folder used).
        live: every worker serves the episode it runs for watching
            (:mod:`arena.eval.live_bench`; process backend only). Not part of the run's
            settings: it changes no result.

    Warns:
        UserWarning: once per stage that ``scale`` drops to 0 episodes.

    Raises:
        ArenaError: a bad suite/contest, a scale that leaves no episode, ``run_dir`` holding a
            run without ``resume`` (or being a file), a resume with different settings or a
            corrupt manifest, or ``backend="ray"`` without ray installed.
    """
    base_cfg = base_cfg or ExperimentConfig()
    if workers < (1 if backend == "ray" else 0):
        raise ArenaError(f"workers must be >= {1 if backend == 'ray' else 0}, got {workers}")
    if episode_timeout is not None and not (
        math.isfinite(episode_timeout) and episode_timeout > 0
    ):
        raise ArenaError(f"episode_timeout must be a finite number of seconds > 0 (or None for "
                         f"no limit), got {episode_timeout}")
    if not (math.isfinite(scale) and scale > 0):
        raise ArenaError(f"scale must be a finite number > 0, got {scale}")
    import arena.plugins  # noqa: F401  (fills the registries: map sources, planners, ...)

    if backend not in ("process", "ray"):
        raise ArenaError(f"unknown backend {backend!r}; expected 'process' or 'ray'")
    if live and backend == "ray":
        raise ArenaError("live viewing works with the process backend; drop --live or use "
                         "--backend process")
    if backend == "ray":
        try:
            import ray  # noqa: F401
        except ImportError:
            raise ArenaError(
                "backend 'ray' needs the ray package (pip install ray); "
                "or use the default backend 'process'"
            ) from None
    if isinstance(suite, Suite):
        suite_obj, scale = suite, suite.scale_episodes
    else:
        suite_obj = load_suite(suite, scale_episodes=scale, worlds=worlds)
    if isinstance(contest, ContestFile):
        contest_obj, contest_src = contest, "<contest>"
    else:
        contest_obj, contest_src = load_contest(contest)
    run = Path(run_dir)
    suite_src = str(Path(suite_obj.source).resolve())
    if contest_src != "<contest>":
        contest_src = str(Path(contest_src).resolve())
    settings: dict[str, Any] = {
        "suite": suite_src, "contest": contest_src, "seed": int(base_cfg.seed),
        "scale": float(scale),
        "worlds": None if suite_obj.worlds is None else str(suite_obj.worlds),
        "simulator": str(base_cfg.sim.backend.get("type", "native2d")),
    }
    check_scale(suite_obj, suite_src)
    jobs = plan_jobs(suite_obj, contest_obj, base_cfg, contest_source=contest_src)
    if resume:
        check_manifest(run, settings)
        load_rows(run)  # a corrupt row file: one line now, not after the run
    else:
        if (run / MANIFEST).exists():
            raise ArenaError(f"{run / MANIFEST}: {run} already holds a run; resume it instead")
        if run.exists() and not run.is_dir():
            raise ArenaError(f"{run}: is a file; the run folder must be a folder (new or empty)")
        try:
            run.mkdir(parents=True, exist_ok=True)
            write_manifest(run, suite=suite_src, contest=contest_src, seed=int(base_cfg.seed),
                           scale=float(scale), worlds=settings["worlds"],
                           simulator=settings["simulator"])
        except OSError as e:
            raise ArenaError(f"{run}: cannot create the run folder ({e.strerror or e})") from None
    done = completed(run)
    todo = [j for j in jobs if j.key not in done]
    total = len(jobs)
    _execute(run, todo, total, total - len(todo), workers, progress, backend, ray_address,
             episode_timeout, live)
    return run


def _execute(
    run: Path, todo: Sequence[Job], total: int, start: int, workers: int,
    progress: bool | ProgressFn | None, backend: str, ray_address: str | None = None,
    episode_timeout: float | None = None, live: bool = False,
) -> None:
    bar: Any = None
    task: Any = None
    if progress is True:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        bar = Progress(
            TextColumn("[bold]bench[/]"), BarColumn(), MofNCompleteColumn(),
            TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
            TextColumn("{task.description}"),
        )
        bar.start()
        task = bar.add_task("", total=total, completed=start)
    count = start

    def commit(result: tuple[dict[str, Any], EpisodeRecord | None]) -> None:
        nonlocal count
        row, record = result
        try:
            commit_episode(run, row, record)
        except OSError as e:  # disk full, folder removed: the run cannot go on
            raise ArenaError(f"{run}: cannot write the results of {row['contestant']}/"
                             f"{row['stage']}/{row['episode']} ({e.strerror or e})") from None
        count += 1
        if bar is not None:
            bar.update(task, advance=1,
                       description=f"{row['contestant']}/{row['stage']}/{row['episode']}: "
                                   f"{row['outcome']}")
        elif callable(progress):
            progress(count, total, row)

    try:
        if backend == "ray":
            _execute_ray(todo, workers, commit, address=ray_address, timeout=episode_timeout)
        elif workers == 0:
            if live:
                live_bench.start(run)
            for job in todo:
                commit(run_job(job))
        elif todo:
            from arena.eval.workers import run_jobs

            run_jobs(todo, run_job, commit, _error_result, workers=workers,
                     timeout=episode_timeout, initializer=_warm_up,
                     initargs=(str(run) if live else None,))
    finally:
        if workers == 0 and live:
            live_bench.stop()
        if bar is not None:
            bar.stop()


def _ray_run_job(config: dict[str, Any], contestant: str, local_planner: str,
                 inter_planner: str, stage: str, episode: int,
                 ) -> tuple[dict[str, Any], EpisodeRecord | None]:
    """:func:`run_job` as a ray task: the config comes as one shared object-store ref."""
    return run_job(Job(contestant, local_planner, inter_planner, stage, episode, config))


def _ray_error(e: BaseException) -> str:
    """``"<ExceptionType>: message"`` of a failed ray task (the task's own exception if any).

    A task whose worker process died reads ``"worker died (WorkerCrashedError: ...)"``, as
    with the process backend.
    """
    cause = getattr(e, "cause", None)
    err = cause if isinstance(cause, BaseException) else e
    lines = str(err).strip().splitlines()
    text = f"{type(err).__name__}: {lines[0] if lines else ''}".rstrip(": ")
    from ray.exceptions import WorkerCrashedError

    return f"worker died ({text})" if isinstance(err, WorkerCrashedError) else text


def _ray_init(ray: Any, workers: int, address: str | None) -> str | None:
    """Start (``address=None``) or connect to Ray, quietly; return the temp dir we made."""
    import logging
    import os
    import tempfile

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    kwargs: dict[str, Any] = {
        "include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR,
    }
    from arena.plugins import PLUGINS_ENV

    if os.environ.get(PLUGINS_ENV):  # ray workers import the same --plugin files (arena.plugins)
        kwargs["runtime_env"] = {"env_vars": {PLUGINS_ENV: os.environ[PLUGINS_ENV]}}
    if address is not None:
        ray.init(address=address, **kwargs)
        return None
    # A short private folder: ray's unix sockets live there (path limit ~107 chars), and a
    # CI's TMPDIR may be long or shared; RAY_TMPDIR picks another parent.
    parent = os.environ.get("RAY_TMPDIR") or ("/tmp" if os.path.isdir("/tmp") else None)
    temp_dir = tempfile.mkdtemp(prefix="arena_ray_", dir=parent)
    try:
        ray.init(num_cpus=workers, _temp_dir=temp_dir, **kwargs)
    except BaseException:
        import shutil

        shutil.rmtree(temp_dir, ignore_errors=True)
        raise
    return temp_dir


def _execute_ray(todo: Sequence[Job], workers: int, commit: Callable[[Any], None],
                 *, address: str | None = None, timeout: float | None = None) -> None:
    """Run the jobs as ray tasks (at most ``workers`` at once); commit in the caller.

    Starts a local Ray (``address=None``) or connects to ``address`` unless Ray is already
    initialized, and shuts it down afterwards only if it did. A task that fails outside
    :func:`run_job` (its worker died, its arguments did not arrive) becomes an ``error`` row;
    so does a task still running ``timeout`` seconds after it was submitted (its worker is
    killed: ``ray.cancel(force=True)``). On a busy cluster a task may wait for a CPU, and that
    wait counts against its limit.
    """
    import ray

    started = not ray.is_initialized()
    temp_dir = _ray_init(ray, workers, address) if started else None
    try:
        remote = ray.remote(num_cpus=1, max_retries=0)(_ray_run_job)
        configs: dict[int, Any] = {}  # one object-store copy per distinct config
        queue = list(todo)
        queue.reverse()
        pending: dict[Any, tuple[Job, float]] = {}  # ref -> (job, deadline)
        try:
            while queue or pending:
                while queue and len(pending) < workers:
                    job = queue.pop()
                    if id(job.config) not in configs:
                        configs[id(job.config)] = ray.put(job.config)
                    ref = remote.remote(configs[id(job.config)], job.contestant,
                                        job.local_planner, job.inter_planner, job.stage,
                                        job.episode)
                    limit = time.monotonic() + timeout if timeout is not None else math.inf
                    pending[ref] = (job, limit)
                first = min(limit for _, limit in pending.values())
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=(
                    None if first == math.inf else max(0.0, first - time.monotonic())))
                for ref in ready:
                    job, _ = pending.pop(ref)
                    try:
                        result = ray.get(ref)
                    except Exception as e:  # the task failed outside run_job
                        result = _error_result(job, _ray_error(e))
                    commit(result)
                now = time.monotonic()
                for ref, (job, limit) in list(pending.items()):
                    if now >= limit:  # kill its worker: a hung task never yields to a cancel
                        with contextlib.suppress(Exception):
                            ray.cancel(ref, force=True)
                        del pending[ref]
                        commit(_error_result(job, f"wall-clock limit {timeout:g} s exceeded"))
        except BaseException:  # Ctrl-C or a failed commit: drop the running tasks, stop now
            for ref in pending:  # (not force=True: that kills the workers, maybe a cluster's)
                with contextlib.suppress(Exception):
                    ray.cancel(ref)
            raise
    finally:
        if started:
            ray.shutdown()
            if temp_dir is not None:
                import shutil

                shutil.rmtree(temp_dir, ignore_errors=True)


__all__ = ["Job", "load_results", "plan_jobs", "run_benchmark", "run_job"]
