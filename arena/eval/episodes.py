"""One benchmark episode: the navigation stack drives robot 0 through the task; its figures.

:func:`run_episode` is what ``arena run`` (:func:`arena.experiment.run_experiment`) and
``arena bench`` (:mod:`arena.eval.runner`) simulate per episode: an
:class:`~arena.episode.runner.EpisodeRunner` with the
:class:`~arena.episode.navigation.NavigationController`, the one
:class:`~arena.eval.recorder.Recorder`, and hooks counting contacts, pacing, reporting progress
and keeping video frames. :func:`episode_metrics` turns its record into every registered metric.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from arena.config.names import run_name
from arena.config.schema import ExperimentConfig
from arena.core.rng import derive_rng
from arena.core.types import Outcome, Pose2D
from arena.crowd.driver import build_driver
from arena.episode.navigation import NavigationController, build_stack
from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.eval.counterfactual import align, replay_crowd
from arena.eval.io import save_record
from arena.eval.metrics import METRICS, compute_metrics
from arena.eval.metrics.arena_set import path_length_value
from arena.eval.record import EpisodeMeta, EpisodeRecord
from arena.eval.recorder import Recorder, with_perception
from arena.perception.stage import PERCEPTION, Perceived
from arena.scene.episode import Episode
from arena.scene.state import SimState
from arena.sim.backend import SimulatorBackend
from arena.tasks.generator import TaskRuntime


@dataclass
class EpisodeResult:
    """Figures of one finished episode (robot 0)."""

    index: int
    seed: int
    map: str
    robot: str
    stage: str
    outcome: str
    time: float
    steps: int
    path_length: float
    collisions: int
    start: list[float]
    goal: list[float]
    final_goal_distance: float
    wall_time: float
    error: str = ""
    goals_reached: int = 0
    teleports: int = 0
    control_ms_mean: float = 0.0
    control_ms_p95: float = 0.0
    control_ms_max: float = 0.0
    files: dict[str, str] = field(default_factory=dict)
    #: Every registered metric of the episode (:func:`episode_metrics`), set by
    #: :func:`run_experiment`; in summary.csv, not in episode.json.
    metrics: dict[str, float] = field(default_factory=dict, compare=False)
    #: The full step-by-step record (not part of :meth:`summary`, episode.json or summary.csv;
    #: on disk it is ``files["record"]``, ``episode.parquet``).
    record: EpisodeRecord | None = field(default=None, repr=False, compare=False)

    def summary(self) -> dict[str, Any]:
        """The figures as plain data, as in episode.json (all fields but record, metrics)."""
        return {
            f.name: getattr(self, f.name) for f in fields(self)
            if f.name not in ("record", "metrics")
        }


def failed_result(cfg: ExperimentConfig, episode: Episode, error: str,
                  wall_time: float = 0.0) -> EpisodeResult:
    """The result of an episode that failed before it could be simulated (outcome ``error``).

    Figures are NaN (time, path length, goal distance) or zero (steps, collisions); no record.
    """
    spawn = episode.robots[0]
    return EpisodeResult(
        index=episode.index, seed=episode.seed, map=episode.map_name, robot=spawn.model.name,
        stage=episode.label, outcome=Outcome.ERROR.value, time=math.nan, steps=0,
        path_length=math.nan, collisions=0, start=spawn.start.as_array().tolist(),
        goal=spawn.goal.as_array().tolist(), final_goal_distance=math.nan, wall_time=wall_time,
        error=error,
    )


def run_episode(
    cfg: ExperimentConfig,
    episode: Episode,
    backend: SimulatorBackend,
    out_dir: Path | None,
    *,
    video: bool = False,
    runtime: TaskRuntime | None = None,
    realtime: bool = False,
    on_step: Callable[[float, float], None] | None = None,
    hooks: Sequence[EpisodeHooks] = (),
) -> EpisodeResult:
    """Simulate one episode with the configured navigation stack and write its files.

    ``runtime`` decides when goals are reached and what comes next (the generator's
    :meth:`~arena.tasks.generator.TaskGenerator.runtime`); by default each robot is done when it
    reaches its goal. Every step its update is applied: teleports move the robot (backend
    ``teleport``, the stack plans afresh), new goals make the stack replan, and a forced reset
    ends the episode as ``aborted``. ``realtime`` paces the loop to ``dt`` of wall time per
    step (interactive runs). ``on_step(time, time_limit)`` (both s) is called after each
    simulated step (progress displays). ``hooks`` run after the episode's own (the live view's
    :class:`~arena.live.hook.LiveHook`): they see the navigation controller's goal and plan.

    The stack's goal tolerances follow the episode: position within ``0.9 · goal_radius`` (or
    the navigation config's, if smaller) and, when the task checks the heading
    (``goal_tolerance_angle``), the heading too; robots that can turn on the spot then align
    their heading at the goal. Car-like (Ackermann) robots cannot, so a heading tolerance is
    met by them only when the approach ends with it.

    When the stack reports ``STUCK`` (oscillation detected and every recovery behaviour of
    ``navigation.recovery_behaviors`` tried, see :mod:`arena.nav.recovery`), the episode ends
    at once as ``stuck``.
    """
    if runtime is None:
        runtime = TaskRuntime.single_goal(episode)
    t0 = time.perf_counter()
    spawn = episode.robots[0]
    robot = spawn.model
    seed, idx = cfg.seed, episode.index
    dt = cfg.sim.dt
    nav = NavigationController(
        build_stack(cfg.navigation, robot, episode), runtime, robot, cfg.navigation.scan_sensor,
        PERCEPTION.build(cfg.navigation.perception, robot, path="navigation.perception"),
    )
    recorder = Recorder()
    contacts = _ContactCounter()
    frames = _Frames(nav) if video else None
    # recorder and frames first: they keep the first state even when planning fails at once;
    # the contact counter after the controller: it sees the tick's teleports
    own: list[EpisodeHooks] = [recorder, *([frames] if frames else []), nav, contacts]
    if realtime:
        own.append(_Pacer())
    if on_step is not None:
        own.append(_Progress(on_step))
    runner = EpisodeRunner(backend, dt, [*own, *hooks], nav)
    crowd = build_driver(cfg.crowd, cfg.pedestrians)
    runner.reset(episode, crowd, seed)
    outcome = runner.run()
    state = runner.state
    assert state is not None
    goal = nav.goal or spawn.goal
    record = recorder.finish(
        EpisodeMeta(
            episode=idx,
            seed=episode.seed,
            stage=episode.label,
            map_name=episode.map_name,
            robot=robot.name,
            robot_radius=float(robot.radius),
            start=spawn.start.as_array(),
            goal=goal.as_array(),
            goal_radius=float(episode.goal_radius),
            goal_tolerance_angle=episode.goal_tolerance_angle,
            time_limit=float(episode.time_limit),
            dt=float(dt),
            outcome=outcome.value,
            config=cfg.model_dump(mode="json"),
        )
    )
    record = with_perception(record, nav.perceived)
    if cfg.evaluation.counterfactual and len(episode.agents):
        # The same crowd without the robot, from the stream the backend gave the pedestrians.
        track = replay_crowd(
            cfg.crowd, cfg.pedestrians, episode, state.step, dt,
            derive_rng(seed, "episode", idx, "sim"),
        )
        record = dataclasses.replace(
            record, ped_cf_position=align(record.ped_row, record.ped_id, track)
        )
    final = record.pose[-1]
    result = EpisodeResult(
        index=idx,
        seed=episode.seed,
        map=episode.map_name,
        robot=robot.name,
        stage=episode.label,
        outcome=outcome.value,
        time=round(state.time, 6),
        steps=state.step,
        path_length=path_length_value(record),
        collisions=contacts.count,
        start=spawn.start.as_array().tolist(),
        goal=goal.as_array().tolist(),
        final_goal_distance=float(math.hypot(goal.x - final[0], goal.y - final[1])),
        wall_time=0.0,
        error=runner.error,
        goals_reached=runtime.goals_reached[0],
        teleports=runtime.teleports[0],
        record=record,
    )
    if nav.control_s:
        ms = 1e3 * np.array(nav.control_s)
        result.control_ms_mean = float(ms.mean())
        result.control_ms_p95 = float(np.percentile(ms, 95))
        result.control_ms_max = float(ms.max())
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        result.files.update(recorder.write_csv(out_dir))
        result.files["record"] = str(save_record(record, out_dir / "episode.parquet"))
        if frames is not None and frames.states:
            result.files.update(
                _write_video(cfg, backend, frames.states, frames.views, out_dir, outcome, episode,
                             nav.perceived)
            )
        result.wall_time = time.perf_counter() - t0
        (out_dir / "episode.json").write_text(json.dumps(result.summary(), indent=2))
    result.wall_time = time.perf_counter() - t0
    return result


class _ContactCounter(EpisodeHooks):
    """Counts robot 0's contact events (a contact lasting several steps counts once)."""

    def __init__(self) -> None:
        self.count, self.touching = 0, False

    def initialize_episode(self, runner: EpisodeRunner) -> None:
        self.count, self.touching = 0, False

    def before_step(self, runner: EpisodeRunner) -> None:
        if 0 in runner.teleported:  # a contact where the robot was put is no new event
            assert runner.state is not None
            self.touching = bool(runner.state.collisions.any[0])

    def after_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        hit = bool(runner.state.collisions.any[0])
        self.count += hit and not self.touching
        self.touching = hit


class _Pacer(EpisodeHooks):
    """Paces the episode to ``dt`` of wall time per step (interactive runs)."""

    def initialize_episode(self, runner: EpisodeRunner) -> None:
        self.wall_start = time.perf_counter()

    def before_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        ahead = self.wall_start + runner.state.time + runner.dt - time.perf_counter()
        if ahead > 0:
            time.sleep(ahead)


class _Progress(EpisodeHooks):
    """Calls ``on_step(time s, time_limit s)`` after each step (progress displays)."""

    def __init__(self, on_step: Callable[[float, float], None]) -> None:
        self.on_step = on_step

    def after_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        assert runner.episode is not None
        self.on_step(runner.state.time, runner.episode.time_limit)


class _Frames(EpisodeHooks):
    """Keeps every state and the plan and goal it was driven by, for the video."""

    def __init__(self, nav: NavigationController) -> None:
        self.nav = nav
        self.states: list[SimState] = []
        self.views: list[tuple[NDArray[np.float64], Pose2D]] = []

    def _view(self) -> tuple[NDArray[np.float64], Pose2D]:
        assert self.nav.goal is not None
        return self.nav.stack.path, self.nav.goal

    def initialize_episode(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        self.states, self.views = [runner.state], []

    def before_step(self, runner: EpisodeRunner) -> None:
        if runner.ticks == 0 and not self.views:  # the first plan (none if planning failed)
            self.views.append(self._view())

    def after_step(self, runner: EpisodeRunner) -> None:
        assert runner.state is not None
        self.states.append(runner.state)
        self.views.append(self._view())


def _write_video(
    cfg, backend, states, views, out_dir: Path, outcome: Outcome, episode: Episode,
    perceived: Sequence[tuple[float, Perceived]] = (),
) -> dict[str, str]:
    """The episode's video and its last frame; ``views[k]`` is state ``k``'s (plan, goal).

    ``perceived`` (``(time, Perceived)`` per control tick) draws the detections and tracks the
    stack planned on over the state of the same time.
    """
    # Imported here: rendering is optional and the only user of matplotlib.
    from arena.render import FrameRenderer, Overlay, VideoWriter, legend_items, save_png

    at_time = {round(t, 9): p for t, p in perceived}
    last = len(states) - 1
    drawn = [k for k in range(len(states)) if k % cfg.output.frame_every == 0 or k == last]
    overlays = []
    for k in drawn:
        # no plan yet where planning failed at the start: the goal alone
        path, goal = views[k] if k < len(views) else (None, episode.robots[0].goal)
        text = f"t = {states[k].time:5.1f} s   step {states[k].step}"
        seen = at_time.get(round(states[k].time, 9))
        overlays.append(Overlay(
            paths=[path], goals=goal.as_array()[None, :],
            text=text + (f"   {outcome.value}" if k == last else ""),
            detections=None if seen is None else seen.detections,
            tracks=None if seen is None else (seen.tracks.ids, seen.tracks.positions),
        ))
    robot_specs = [spawn.model.laser for spawn in episode.robots]
    renderer = FrameRenderer(
        backend.world,
        lidar_specs=robot_specs,
        width_px=cfg.output.width_px,
        title=" · ".join(
            t for t in (run_name(cfg), episode.label, states[0].robots.models[0], cfg.crowd["type"])
            if t
        ),
        # a key to exactly what the video shows (its social states, a collision if one happens)
        legend=legend_items(
            [states[k] for k in drawn], overlays,
            lidar=any(spec is not None for spec in robot_specs), trails=True,
        ),
    )
    video_path = out_dir / f"video.{cfg.output.video_format}"
    fps = 1.0 / cfg.sim.dt / cfg.output.frame_every
    frame = None
    with VideoWriter(video_path, fps=fps) as writer:
        for k, ov in zip(drawn, overlays, strict=True):
            frame = renderer.render(states[k], ov)
            writer.append(frame)
    files = {"video": str(video_path)}
    if frame is not None:
        png = out_dir / "final.png"
        save_png(frame, png)
        files["final_frame"] = str(png)
    camera = cfg.output.camera_3d(str(cfg.sim.backend.get("type", "native2d")))
    if camera is not None:
        from arena.render.video3d import write_video_3d  # the optional 3-D extra

        path_3d = out_dir / f"video_3d.{cfg.output.video_format}"
        w, h = cfg.output.video_3d_size
        frame_3d = write_video_3d(
            episode, [states[k] for k in drawn], [ov.text for ov in overlays], str(path_3d),
            camera=camera, width=w, height=h, fps=fps,
            params=getattr(getattr(backend, "params", None), "world", None),  # mujoco's world
        )
        files["video_3d"] = str(path_3d)
        save_png(frame_3d, out_dir / "final_3d.png")
        files["final_frame_3d"] = str(out_dir / "final_3d.png")
    return files


def episode_metrics(record: EpisodeRecord | None) -> tuple[dict[str, float], str]:
    """Every registered metric of one episode (what ``arena bench`` stores per episode).

    Returns:
        ``{metric: value}`` (NaN where undefined; all NaN without a record or when a metric
        raises, so that a faulty metric plugin costs its figures, not the run) and ``""``, or
        that error as ``"metrics: <Type>: message"``.
    """
    if record is not None:
        try:
            return compute_metrics(record), ""
        except Exception as e:
            nan = {n: math.nan for n in METRICS.names()}
            return nan, f"metrics: {type(e).__name__}: {e}"
    return {n: math.nan for n in METRICS.names()}, ""
