"""Counterfactual metrics: how far the robot displaced people.

They compare each recorded pedestrian row with the same person at the same step in the
episode replayed without the robot (``EpisodeRecord.ped_cf_position``, made by
:mod:`arena.eval.counterfactual`). All are NaN for records without a replay (recorded with
``evaluation.counterfactual: false``) or without pedestrians.
"""

from __future__ import annotations

import math

import numpy as np

from arena.eval.metrics.base import FloatArray, MetricParams, metric
from arena.eval.record import EpisodeRecord


def cf_displacement(record: EpisodeRecord) -> FloatArray | None:
    """``(K',)`` m, ``‖p − p_cf‖`` over the pedestrian rows the replay has; ``None`` if unknown."""
    cf = record.ped_cf_position
    if cf is None or not cf.shape[0]:
        return None
    d = np.hypot(*(record.ped_position - cf).T)
    d = d[np.isfinite(d)]
    return d if d.size else None


@metric(
    "cf_displacement_mean", unit="m",
    description="mean distance between people and where they would be without the robot",
)
def cf_displacement_mean(record: EpisodeRecord, params: MetricParams) -> float:
    """Mean distance between people and where they would be without the robot.

    m, mean over pedestrian rows (people × steps) of ``‖p_i(t) − p_i^cf(t)‖``, where ``p^cf`` is
    the same person at the same step in the crowd replayed without the robot (same seed).
    """
    d = cf_displacement(record)
    return math.nan if d is None else float(np.mean(d))


@metric(
    "cf_displacement_max", unit="m",
    description="largest distance of a person from where they would be without the robot",
)
def cf_displacement_max(record: EpisodeRecord, params: MetricParams) -> float:
    """Largest distance of a person from where they would be without the robot.

    m, ``max_{i,t} ‖p_i(t) − p_i^cf(t)‖`` over pedestrian rows.
    """
    d = cf_displacement(record)
    return math.nan if d is None else float(np.max(d))


@metric(
    "cf_people_displaced", unit="1",
    description="share of people the robot displaced by more than 0.2 m at some time",
)
def cf_people_displaced(record: EpisodeRecord, params: MetricParams) -> float:
    """Share of people the robot displaced by more than 0.2 m at some time.

    Dimensionless, the fraction of pedestrian ids with ``‖p_i(t) − p_i^cf(t)‖ >
    cf_displacement_threshold`` (0.2 m) at some step, among the ids the replay has.
    """
    cf = record.ped_cf_position
    if cf is None or not cf.shape[0]:
        return math.nan
    d = np.hypot(*(record.ped_position - cf).T)
    known = np.isfinite(d)
    if not known.any():
        return math.nan
    ids = np.unique(record.ped_id[known])
    moved = np.unique(record.ped_id[known & (d > params.cf_displacement_threshold)])
    return float(moved.size / ids.size)
