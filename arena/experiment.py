"""Run an experiment: sample episodes, simulate them with the navigation stack, write results.

This is what ``arena run`` calls. One config + seed gives the same episodes, trajectories and
outcomes on every machine: every random draw comes from a generator derived from
``(seed, "episode", index, <component>)``.

Output layout (``output.dir``)::

    config.yaml             the resolved config
    summary.csv             one row per episode
    episode_000/
        trajectory.csv      robot state per step
        agents.csv          pedestrian state per step
        episode.parquet     the EpisodeRecord (arena.eval.io.load_record)
        episode.json        start, goal, outcome, figures
        video.mp4           top-down video (first ``output.video_episodes`` episodes)
        final.png           the last frame
"""

from __future__ import annotations

import csv
import functools
import json
import math
import time
from collections.abc import Callable, Sequence
from datetime import datetime
from pathlib import Path
from typing import Any

import yaml

import arena.plugins  # noqa: F401  (fills the registries)
from arena.config.names import UNNAMED, run_name
from arena.config.schema import ExperimentConfig
from arena.core.files import make_dir
from arena.episode.runner import EpisodeHooks, describe_exception
from arena.eval.episodes import EpisodeResult, episode_metrics, failed_result, run_episode
from arena.robots.model import RobotModel
from arena.robots.presets import load_robot
from arena.scene.episode import Episode
from arena.sim.backend import BACKENDS
from arena.tasks.generator import TaskGenerator

# The experiment API: run_experiment and make_episode here; one episode is arena.eval.episodes,
# run names arena.config.names.
__all__ = [
    "UNNAMED",
    "EpisodeResult",
    "default_output_dir",
    "describe_exception",
    "episode_metrics",
    "failed_result",
    "make_episode",
    "run_episode",
    "run_experiment",
    "run_name",
]


def make_episode(
    cfg: ExperimentConfig,
    index: int,
    robot: RobotModel | None = None,
    *,
    generator: TaskGenerator | None = None,
) -> Episode:
    """Episode ``index`` of the experiment, drawn deterministically from ``cfg.seed``.

    Pass ``generator`` to reuse one across episodes (maps are then built once).
    """
    generator = generator or TaskGenerator.from_config(
        cfg, [robot] if robot is not None else None
    )
    return generator.episode(index)


def default_output_dir(cfg: ExperimentConfig) -> Path:
    """``runs/<run name>_<YYYYmmdd-HHMMSS>`` (see :func:`run_name`)."""
    return Path("runs") / f"{run_name(cfg)}_{datetime.now().strftime('%Y%m%d-%H%M%S')}"


def run_experiment(
    cfg: ExperimentConfig,
    out_dir: Path | None = None,
    *,
    on_episode: Callable[[EpisodeResult], None] | None = None,
    modules: Sequence[Any] = (),
    realtime: bool = False,
    on_step: Callable[[int, float, float], None] | None = None,
    hooks: Sequence[EpisodeHooks] = (),
    on_start: Callable[[Path], None] | None = None,
    resume: bool = False,
) -> tuple[Path, list[EpisodeResult]]:
    """Run every episode of ``cfg`` and write the outputs under ``out_dir``.

    Args:
        cfg: the experiment.
        out_dir: output folder (default: ``output.dir`` or ``runs/<name>_<time>``).
        on_episode: called with each finished episode's result.
        modules: task module instances added after the config's (the CLI's interactive
            module, which it feeds from stdin).
        realtime: pace the simulation to wall-clock time (interactive runs).
        on_step: ``on_step(episode, time, time_limit)`` after each simulated step (s).
        hooks: extra episode hooks of every episode (the live view).
        on_start: called with the output folder once it exists, before the first episode.
        resume: keep the episodes ``out_dir`` already holds (their ``episode.json`` and
            record) and run only the others. Every episode is drawn and seeded by its index
            and the task modules hear every outcome in order, so the summary is the one an
            uninterrupted run writes (but for wall-clock figures).

    ``summary.csv`` has one row per episode: its figures, then every registered metric
    (:func:`episode_metrics`, the values ``arena bench`` stores).
    """
    robot = load_robot(cfg.robot)
    backend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
    generator = TaskGenerator.from_config(cfg, [robot])
    generator.modules.extend(modules)
    n_episodes = generator.num_episodes or cfg.episodes
    # Draw the first episode before writing anything: a bad map or task fails with no output.
    first = generator.episode(0)
    out = make_dir(Path(out_dir or cfg.output.dir or default_output_dir(cfg)),
                   what="output folder (output.dir, -o)")
    (out / "config.yaml").write_text(yaml.safe_dump(cfg.model_dump(mode="json"), sort_keys=False))
    if on_start is not None:
        on_start(out)
    results: list[EpisodeResult] = []
    for i in range(n_episodes):
        episode = first if i == 0 else generator.episode(i)  # drawn even when kept: same draws
        video = cfg.output.video and i < cfg.output.video_episodes
        t0 = time.perf_counter()
        kept = _finished(out / f"episode_{i:03d}") if resume else None
        try:
            res = kept or run_episode(
                cfg,
                episode,
                backend,
                out / f"episode_{i:03d}",
                video=video,
                runtime=generator.runtime(episode),
                realtime=realtime,
                on_step=None if on_step is None else functools.partial(on_step, i),
                hooks=hooks,
            )
        except Exception as e:  # raised outside the step loop (a planner's constructor ...)
            res = failed_result(cfg, episode, describe_exception(e), time.perf_counter() - t0)
        res.metrics, problem = episode_metrics(res.record)
        if problem:
            res.error = f"{res.error}; {problem}" if res.error else problem
        generator.feedback(i, res.outcome)
        results.append(res)
        # after every episode: a run stopped later keeps the rows of the finished ones
        _write_summary(out / "summary.csv", results)
        if on_episode:
            on_episode(res)
    if not results:
        _write_summary(out / "summary.csv", results)
    return out, results


def _finished(folder: Path) -> EpisodeResult | None:
    """The result an earlier run left in episode ``folder`` (``None``: run it again).

    ``episode.json`` is written last, so its presence means the episode finished; its record
    gives the metrics (which the file does not hold). A file that does not read back is run again.
    """
    from arena.eval.io import load_record

    try:
        result = EpisodeResult(**json.loads((folder / "episode.json").read_text()))
        record = folder / "episode.parquet"
        result.record = load_record(record) if record.is_file() else None
    except Exception:  # unreadable JSON or parquet, a field missing: whatever it is, run it again
        return None
    return result


def _write_summary(path: Path, results: list[EpisodeResult]) -> None:
    cols = [
        "index",
        "seed",
        "map",
        "robot",
        "stage",
        "outcome",
        "time",
        "steps",
        "path_length",
        "collisions",
        "goals_reached",
        "teleports",
        "final_goal_distance",
        "control_ms_mean",
        "control_ms_p95",
        "wall_time",
        "error",
    ]
    # then every metric (path_length and collisions: the episode's own figures, as in bench)
    metrics = list(dict.fromkeys(m for r in results for m in r.metrics if m not in cols))
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols + metrics)
        for r in results:
            d = r.summary()
            w.writerow([f"{d[c]:.4f}" if isinstance(d[c], float) else d[c] for c in cols]
                       + [f"{r.metrics.get(m, math.nan):.6g}" for m in metrics])
