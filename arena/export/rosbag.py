"""``arena export rosbag2 RUN`` and ``arena export rosbag RUN``: recorded episodes as ROS bags.

Like ``arena export mcap`` (:mod:`arena.export.mcap`), each recorded episode is simulated again
(:func:`~arena.eval.replay.resimulate`), this time with a :class:`~arena.ros.bag.RosbagSink`:
the bag holds the topics of :mod:`arena.ros.topics` (``/tf``, ``/tf_static``, ``/map``,
``/odom``, ``/scan``, people, ``/plan``, ``/cmd_vel`` ...) at every simulation step, and the
new trajectory is checked against the recorded one (``matches_record``).

One bag per episode; record and header times are the simulated time (the bag starts at the Unix
epoch, ``t = 0`` s of the episode). A ROS 2 bag's ``metadata.yaml`` keeps which episode it is in
its ``custom_data`` (``arena.episode``, ``arena.seed``, ``arena.outcome`` ...); a ROS 1 bag has no
place for it. Needs the ``rosbags`` package (``pip install 'arena[rosbag]'``).
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from arena.core.errors import ConfigError
from arena.eval.io import load_record
from arena.eval.replay import resimulate
from arena.export.mcap import find_records
from arena.live.hook import LiveHook
from arena.ros.bag import BagWriter, Flavour, RosbagSink, rosbags_module


@dataclass(frozen=True)
class BagFile:
    """One written episode.

    Its bag (a file, or a ROS 2 bag folder), source record, step count, message count and
    reproducibility check.
    """

    path: Path
    record: Path
    steps: int
    messages: int
    matches_record: bool


def _target(dest: Path, rel: Path, flavour: Flavour) -> Path:
    """``episode_000/episode.bag`` (ROS 1) or the folder ``episode_000/episode`` (ROS 2)."""
    target = dest / (rel.with_suffix(".bag") if flavour == "ros1" else rel.with_suffix(""))
    if flavour == "ros1":
        target.unlink(missing_ok=True)
    elif target.exists():
        # only ever remove a bag this exporter wrote: its metadata and its one MCAP file
        names = {p.name for p in target.iterdir()} if target.is_dir() else set()
        if names != {"metadata.yaml", f"{target.name}.mcap"}:
            raise ConfigError(f"{target} exists and is not a ROS 2 bag; not overwriting it",
                              path="--out")
        shutil.rmtree(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    return target


def export_rosbag(
    run: str | Path,
    out: str | Path | None = None,
    *,
    flavour: Flavour = "ros2",
    only: str | None = None,
    clock: bool = False,
    on_file: Callable[[BagFile], None] | None = None,
) -> list[BagFile]:
    """Write each recorded episode of ``run`` as a ROS bag.

    Args:
        run: the run folder (``arena run`` or ``arena bench``).
        out: destination folder (default ``<run>/rosbag2`` or ``<run>/rosbag``); bags mirror the
            records' paths (``episode_000/episode.bag``, or the ROS 2 bag folder
            ``episode_000/episode/`` holding ``episode.mcap`` and ``metadata.yaml``).
        flavour: ``"ros2"`` (MCAP storage) or ``"ros1"`` (bag format 2.0).
        only: a glob on the records' paths relative to ``run``; ``None``: all.
        clock: also write ``/clock`` every step.
        on_file: called with each bag once written.

    Raises:
        ConfigError: no such run, no record, ``only`` matches none, or rosbags is missing.
    """
    rosbags_module()
    src = Path(run)
    dest = Path(out) if out is not None else src / ("rosbag2" if flavour == "ros2" else "rosbag")
    records = find_records(src, only)
    written = []
    for path in records:
        rel = path.relative_to(src)
        target = _target(dest, rel, flavour)
        record = load_record(path)
        meta = record.meta
        info = {"record": str(rel), "stage": meta.stage, "episode": str(meta.episode),
                "seed": str(meta.seed), "outcome": meta.outcome, "map": meta.map_name,
                "robot": meta.robot}
        bag = BagWriter(target, flavour, {f"arena.{k}": v for k, v in info.items()})
        sink = RosbagSink(bag, clock=clock)
        try:
            res, same = resimulate(record, None, hooks=[LiveHook([sink])])
        except BaseException:
            bag.abort()  # no half-written bag left behind
            if target.is_dir():
                shutil.rmtree(target)
            target.unlink(missing_ok=True)
            raise
        if flavour == "ros2":  # known only now; custom_data is written on close
            bag.custom_data("arena.matches_record", str(same).lower())
        bag.close()
        item = BagFile(target, path, res.steps, bag.messages, same)
        written.append(item)
        if on_file is not None:
            on_file(item)
    return written
