"""Videos of benchmark episodes, re-simulated from their records.

A benchmark run stores records, not videos (rendering every episode would cost more than
simulating it). Since an episode is a pure function of its config and seed, the episode can be
simulated again from the config stored in its record, this time with the video on; the new
trajectory is checked against the recorded one, so a video always shows what was measured.

:func:`pick_episodes` chooses the episodes worth watching (where the contestants differ most),
:func:`render_episode_video` renders one contestant's episode, :func:`episode_videos` does both
for a run.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from arena.eval import plots
from arena.eval.io import load_record
from arena.eval.record import EpisodeRecord

if TYPE_CHECKING:
    from arena.episode.runner import EpisodeHooks
    from arena.eval.episodes import EpisodeResult


@dataclass(frozen=True)
class EpisodeVideo:
    """A rendered episode.

    Attributes:
        path: the MP4 file.
        caption: "contestant · stage · episode k · outcome".
        matches_record: the re-simulated trajectory equals the recorded one (it should, always:
            ``False`` means the run is not reproducible and the video may differ).
        path_3d: the 3-D video (``output.video_3d``; runs on the mujoco backend), if any.
    """

    path: Path
    caption: str
    matches_record: bool
    path_3d: Path | None = None


def pick_episodes(table: Any, count: int = 1) -> list[tuple[str, int]]:
    """The ``count`` (stage, episode) pairs where the contestants differ most.

    Ranked by: episodes with people first (a finite ``min_distance_to_person``), then most
    collision events summed over contestants, then fewest successes, then most distinct
    outcomes, then table order (so the choice is deterministic).
    """
    cols = plots.as_columns(table)
    stage = cols["stage"].astype(str) if "stage" in cols else np.full(len(cols["episode"]), "")
    keys: dict[tuple[str, int], list[float]] = {}
    outcomes: dict[tuple[str, int], set[str]] = {}
    for i in range(len(stage)):
        key = (str(stage[i]), int(cols["episode"][i]))
        k = keys.setdefault(key, [0.0, 0.0, float(len(keys)), 0.0])
        k[0] += float(np.nan_to_num(float(cols["collisions"][i])))
        k[1] += float(str(cols["outcome"][i]) == "success")
        if "min_distance_to_person" in cols:
            k[3] = max(k[3], float(np.isfinite(float(cols["min_distance_to_person"][i]))))
        outcomes.setdefault(key, set()).add(str(cols["outcome"][i]))
    ranked = sorted(keys, key=lambda key: (-keys[key][3], -keys[key][0], keys[key][1],
                                           -len(outcomes[key]), keys[key][2]))
    return ranked[: max(0, count)]


def resimulate(
    record: EpisodeRecord, out_dir: Path | None = None, *, video: bool = False,
    hooks: Sequence[EpisodeHooks] = (), config: dict[str, Any] | None = None,
) -> tuple[EpisodeResult, bool]:
    """Simulate a recorded episode again from the config in its record.

    Args:
        record: the recorded episode (its meta holds the resolved config, seed and index).
        out_dir: where the new episode writes its files (``None``: nowhere).
        video: render its video (into ``out_dir``).
        hooks: extra episode hooks (a Foxglove sink's :class:`~arena.live.hook.LiveHook`).
        config: the config to use instead of the record's (the record's with changed output
            options); the counterfactual replay is always off.

    Returns:
        The new result and whether its trajectory equals the recorded one (it should, always:
        ``False`` means the run is not reproducible).
    """
    import arena.plugins  # noqa: F401  (fills the registries in a fresh worker)
    from arena.config.schema import ExperimentConfig
    from arena.eval.episodes import run_episode
    from arena.robots.presets import load_robot
    from arena.sim.backend import BACKENDS
    from arena.tasks.generator import TaskGenerator

    data = dict(config if config is not None else record.meta.config)
    data["evaluation"] = {**data.get("evaluation", {}), "counterfactual": False}
    cfg = ExperimentConfig.model_validate(data)
    gen = TaskGenerator.from_config(cfg, [load_robot(cfg.robot)])
    episode = gen.episode(record.meta.episode)
    backend = BACKENDS.build(cfg.sim.backend, path="sim.backend")
    res = run_episode(cfg, episode, backend, out_dir, video=video,
                      runtime=gen.runtime(episode), hooks=hooks)
    again = res.record
    same = (again is not None and again.pose.shape == record.pose.shape
            and bool(np.array_equal(again.pose, record.pose)))
    return res, same


def render_episode_video(
    record_path: str | Path, out_dir: str | Path, *, caption: str | None = None,
    width_px: int | None = None, frame_every: int = 2,
) -> EpisodeVideo:
    """Simulate a recorded episode again with the video on.

    Args:
        record_path: the episode's ``.parquet`` record (its meta holds the resolved config).
        out_dir: folder for ``video.mp4`` (and ``final.png``).
        caption: the video's caption (default: stage or map, episode and outcome).
        width_px: frame width (pixels); ``None``: the recorded config's ``output.width_px``
            (800 unless the run set it), readable in the report.
        frame_every: render every N-th step (N = 2 halves the file at 10 Hz simulation).

    Returns:
        The video and whether the new trajectory equals the recorded one.
    """
    record = load_record(record_path)
    data = dict(record.meta.config)
    size = {} if width_px is None else {"width_px": width_px}
    data["output"] = {**data.get("output", {}), **size,
                      "frame_every": frame_every, "video_format": "mp4"}
    res, same = resimulate(record, Path(out_dir), video=True, config=data)
    if caption is None:
        caption = (f"{record.meta.stage or record.meta.map_name} · "
                   f"episode {record.meta.episode} · {record.meta.outcome}")
    video_3d = res.files.get("video_3d")
    return EpisodeVideo(Path(res.files["video"]), caption, same,
                        Path(video_3d) if video_3d else None)


def episode_videos(
    run_dir: str | Path, table: Any, dest: str | Path, *, count: int = 1, workers: int = 1,
    width_px: int | None = None,
) -> list[EpisodeVideo]:
    """Videos of the :func:`pick_episodes` episodes for every contestant.

    Args:
        run_dir: the run folder (records resolved relative to it).
        table: its results table.
        dest: folder for the videos (``<contestant>/<stage>_<episode>/video.mp4``).
        count: number of episodes (each rendered for every contestant).
        workers: processes rendering at once.
        width_px: frame width (pixels); ``None``: each record's ``output.width_px``.

    Returns:
        The videos, episodes in rank order and contestants in table order.
    """
    cols = plots.as_columns(table)
    run, out = Path(run_dir), Path(dest)
    stage = cols["stage"].astype(str) if "stage" in cols else np.full(len(cols["episode"]), "")
    jobs = []
    for st, ep in pick_episodes(table, count):
        for i in np.flatnonzero((stage == st) & (cols["episode"].astype(int) == ep)):
            rec = cols["record"][i] if "record" in cols else None
            if rec is None or str(rec) in ("", "None") or not (run / str(rec)).is_file():
                continue  # an error episode without a record
            who = str(cols["contestant"][i])
            caption = f"{who} · {st} · episode {ep} · {cols['outcome'][i]}"
            jobs.append((str(run / str(rec)), str(out / who / f"{st}_{ep:03d}"), caption))
    if workers <= 1 or len(jobs) <= 1:
        return [render_episode_video(r, f, caption=c, width_px=width_px) for r, f, c in jobs]
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn")) as pool:
        futures = [pool.submit(render_episode_video, r, f, caption=c, width_px=width_px)
                   for r, f, c in jobs]
        return [f.result() for f in futures]
