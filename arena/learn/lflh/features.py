"""The policy's input: a min-pooled, clipped scan and the target direction in the robot frame.

Training (:mod:`arena.learn.lflh.dataset`) and the planner build the input with these same
functions, so the two cannot drift apart.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field


class FeatureParams(BaseModel):
    """How a scan and a target become the policy's input."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    sectors: int = Field(72, gt=0, description="scan sectors; each keeps its nearest return")
    clip_range: float = Field(3.0, gt=0, description="m, ranges beyond this read as this")

    @property
    def size(self) -> int:
        """Input width: the sectors and ``[cos, sin]`` of the target direction."""
        return self.sectors + 2


def scan_features(ranges: NDArray[np.float64], params: FeatureParams) -> NDArray[np.float32]:
    """``(sectors,)`` nearest range per sector / ``clip_range`` in ``[0, 1]``.

    ``ranges`` ``(beams,)`` (m; ``inf``/``nan`` = no return) must divide into ``sectors``
    equal groups: the minimum keeps a thin pole that a mean would blur away.
    """
    r = np.asarray(ranges, dtype=np.float64).reshape(-1)
    if r.size % params.sectors:
        raise ValueError(f"{r.size} beams do not split into {params.sectors} sectors")
    r = np.where(np.isfinite(r), r, params.clip_range)
    r = np.minimum(r, params.clip_range).reshape(params.sectors, -1).min(axis=1)
    return (r / params.clip_range).astype(np.float32)


def target_features(target_xy: NDArray[np.float64]) -> NDArray[np.float32]:
    """``(2,)`` unit direction ``[cos, sin]`` to the target ``(2,)`` (m, robot frame).

    Only the direction: a motion's length encodes its speed, which the scan should decide.
    """
    angle = math.atan2(float(target_xy[1]), float(target_xy[0]))
    return np.array([math.cos(angle), math.sin(angle)], dtype=np.float32)


def policy_input(
    ranges: NDArray[np.float64], target_xy: NDArray[np.float64], params: FeatureParams
) -> NDArray[np.float32]:
    """``(sectors + 2,)`` policy input from a scan and a target (robot frame)."""
    return np.concatenate([scan_features(ranges, params), target_features(target_xy)])
