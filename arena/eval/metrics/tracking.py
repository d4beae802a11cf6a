"""Tracking metrics of a run on perceived people: CLEAR MOT and IDF1 against the ground truth.

When the navigation stack planned on detected people (``navigation.perception`` of ``lidar``,
``rgbd`` or ``fused``), the record holds the tracks it planned on and which people its sensors
showed (:class:`~arena.eval.record.PerceptionRecord`). Each control tick is one frame of
:class:`~arena.perception.mot.MotAccumulator`: the ground truth is the people the sensors
showed, the hypotheses the confirmed tracks. A track nearest to a person the sensors did not
show (hidden behind someone, out of the field of view, within ``tracking_threshold``) is left
out: keeping a hidden person's track is the tracker's job, neither right nor wrong here. All
four metrics are NaN for a run on the ground truth.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from arena.eval.metrics.base import MetricParams, metric
from arena.eval.record import EpisodeRecord
from arena.perception.mot import MotAccumulator, MotScores


@lru_cache(maxsize=8)  # the four metrics of one record share one pass
def mot_scores(record: EpisodeRecord, threshold: float) -> MotScores | None:
    """The record's tracking scores (``None`` without perception)."""
    p = record.perception
    if p is None:
        return None
    acc = MotAccumulator(threshold)
    starts = np.searchsorted(record.ped_row, np.arange(record.steps + 1))
    t_starts = np.searchsorted(p.trk_row, np.arange(record.steps + 1))
    for row in np.flatnonzero(p.perceived):
        a, b = starts[row], starts[row + 1]
        ids, pos, seen = record.ped_id[a:b], record.ped_position[a:b], p.seen[a:b]
        ta, tb = t_starts[row], t_starts[row + 1]
        hid, hpos = p.trk_id[ta:tb], p.trk_position[ta:tb]
        if len(hid) and len(pos) and not seen.all():
            d = np.hypot(*(hpos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
            j = np.argmin(d, axis=1)
            keep = ~((d[np.arange(len(hid)), j] <= threshold) & ~seen[j])
            hid, hpos = hid[keep], hpos[keep]
        acc.add_frame(ids[seen], pos[seen], hid, hpos)
    return acc.scores()


def _score(record: EpisodeRecord, params: MetricParams, name: str) -> float:
    s = mot_scores(record, params.tracking_threshold)
    return math.nan if s is None else float(getattr(s, name))


@metric("tracking_mota", unit="1", description="multiple object tracking accuracy of the "
        "perceived people: 1 - (misses + false tracks + id switches) / people seen (NaN on "
        "ground truth)")
def tracking_mota(record: EpisodeRecord, params: MetricParams) -> float:
    """CLEAR MOT accuracy (see the module docstring; may be negative)."""
    return _score(record, params, "mota")


@metric("tracking_motp", unit="m", description="mean distance of the perceived people's "
        "matched tracks to the people (NaN on ground truth)")
def tracking_motp(record: EpisodeRecord, params: MetricParams) -> float:
    """CLEAR MOT precision (lower is better)."""
    return _score(record, params, "motp")


@metric("tracking_idf1", unit="1", description="identity F1 score of the perceived people's "
        "tracks (NaN on ground truth)")
def tracking_idf1(record: EpisodeRecord, params: MetricParams) -> float:
    """IDF1 in [0, 1]."""
    return _score(record, params, "idf1")


@metric("tracking_id_switches", unit="1", description="times a perceived person's track id "
        "changed (NaN on ground truth)")
def tracking_id_switches(record: EpisodeRecord, params: MetricParams) -> float:
    """IDSW over the episode."""
    return _score(record, params, "id_switches")
