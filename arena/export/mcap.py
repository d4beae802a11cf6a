"""``arena export mcap RUN``: recorded episodes as MCAP files that Foxglove opens.

A record keeps poses, people and contacts, not the lidar scans or plans. Since an episode is a
pure function of its config and seed, each recorded episode is simulated again
(:func:`~arena.eval.replay.resimulate`) with a :class:`~arena.export.foxglove.FoxgloveSink` on
an MCAP writer: the file holds every topic of a live Foxglove view, at every simulation step,
and the new trajectory is checked against the recorded one (``matches_record``).

Each file has one episode; its timeline starts at the Unix epoch (``t = 0`` s of the episode),
and its metadata record ``arena`` says which episode it is (contestant, stage, episode, seed,
outcome, map, robot, matches_record).
"""

from __future__ import annotations

import fnmatch
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from arena.core.errors import ConfigError
from arena.eval.io import load_record
from arena.eval.replay import resimulate
from arena.export.foxglove import FoxgloveSink, foxglove_module
from arena.live.hook import LiveHook


@dataclass(frozen=True)
class McapFile:
    """One written episode: its file, source record, step count and reproducibility check."""

    path: Path
    record: Path
    steps: int
    messages: int
    matches_record: bool


def find_records(run: Path, only: str | None = None) -> list[Path]:
    """The episode records of a run folder (``arena bench`` or ``arena run``), sorted.

    ``only``: a glob on the records' paths relative to ``run``; ``None``: all of them.

    Raises:
        ConfigError: ``run`` is no folder, holds no record, or ``only`` matches none.
    """
    if not run.is_dir():
        raise ConfigError(f"{run}: no such run folder", path="RUN")
    records = sorted([*run.glob("episodes/*/*/*.parquet"), *run.glob("episode_*/episode.parquet")])
    records = [p for p in records if not p.name.startswith(".")]
    if not records:
        raise ConfigError(
            f"{run}: holds no episode records (*.parquet) to export; is it an arena run or "
            "arena bench folder?", path="RUN")
    if only is not None:
        records = [r for r in records if fnmatch.fnmatch(str(r.relative_to(run)), only)]
        if not records:
            raise ConfigError(f"no record of {run} matches {only!r}", path="--only")
    return records


def export_mcap(
    run: str | Path,
    out: str | Path | None = None,
    *,
    only: str | None = None,
    on_file: Callable[[McapFile], None] | None = None,
) -> list[McapFile]:
    """Write each recorded episode of ``run`` as MCAP.

    Args:
        run: the run folder.
        out: destination folder (default ``<run>/mcap``); files mirror the records' paths
            (``episodes/<contestant>/<stage>/<k>.mcap`` for a benchmark,
            ``episode_000/episode.mcap`` for ``arena run``).
        only: a glob on the records' paths relative to ``run`` (``"*/dwa/*"``); ``None``: all.
        on_file: called with each file once written.

    Raises:
        ConfigError: no such run, no record, or ``only`` matches none.
    """
    fg = foxglove_module()
    src = Path(run)
    dest = Path(out) if out is not None else src / "mcap"
    records = find_records(src, only)
    written = []
    for path in records:
        rel = path.relative_to(src)
        target = dest / rel.with_suffix(".mcap")
        target.parent.mkdir(parents=True, exist_ok=True)
        record = load_record(path)
        context = fg.Context()
        writer = fg.open_mcap(target, allow_overwrite=True, context=context)
        sink = FoxgloveSink(context, start_ns=0)
        try:
            res, same = resimulate(record, None, hooks=[LiveHook([sink])])
            meta = record.meta
            writer.write_metadata("arena", {
                "record": str(rel), "contestant": rel.parts[1] if rel.parts[0] == "episodes"
                and len(rel.parts) > 3 else "", "stage": meta.stage,
                "episode": str(meta.episode), "seed": str(meta.seed), "outcome": meta.outcome,
                "map": meta.map_name, "robot": meta.robot, "matches_record": str(same).lower(),
            })
        finally:
            writer.close()
            sink.close()
        item = McapFile(target, path, res.steps, sink.messages, same)
        written.append(item)
        if on_file is not None:
            on_file(item)
    return written
