"""Training samples: (rendered scan, target = the motion's end, first command).

Every sample is one open-space motion (:mod:`.motions`), the obstacles hallucinated around
it (:mod:`.hallucinate`) and the scan our lidar ray caster renders from the motion's start
in that grid (:class:`~arena.sensors.lidar2d.Lidar2D`, the jackal's 270° / 720-beam laser).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.learn.lflh.features import FeatureParams, policy_input
from arena.learn.lflh.hallucinate import HallucinationParams, hallucinate
from arena.learn.lflh.motions import MotionParams, sample_motion
from arena.sensors.lidar2d import Lidar2D
from arena.sensors.spec import LidarSpec

JACKAL_LASER = LidarSpec(angle_min=-2.35619, angle_max=2.35619, num_beams=720, range_max=30.0)
"""The scanner the samples are rendered with (the jackal preset's ``laser``)."""


class DataParams(BaseModel):
    """Everything that shapes the training set."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    motion: MotionParams = Field(default_factory=MotionParams)
    hallucination: HallucinationParams = Field(default_factory=HallucinationParams)
    features: FeatureParams = Field(default_factory=FeatureParams)
    laser: LidarSpec = Field(default=JACKAL_LASER, description="scanner rendered")


def make_sample(
    params: DataParams, rng: np.random.Generator, lidar: Lidar2D
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """One ``(input (sectors + 2,), label [v m/s, ω rad/s])`` pair."""
    motion = sample_motion(params.motion, rng)
    speed = float(np.mean(motion.commands[:, 0]))
    obstacles = hallucinate(motion.poses, speed, params.hallucination, rng)
    lidar.bind(obstacles.grid)
    ranges = lidar.scan(np.zeros(3))
    x = policy_input(ranges, motion.poses[-1, :2], params.features)
    return x, motion.commands[0].astype(np.float32)


def make_dataset(
    n: int, params: DataParams, seed: int
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """``(n, sectors + 2)`` inputs and ``(n, 2)`` labels, reproducible from ``seed``."""
    rng = np.random.default_rng(seed)
    lidar = Lidar2D(params.laser)
    xs = np.empty((n, params.features.size), dtype=np.float32)
    ys = np.empty((n, 2), dtype=np.float32)
    for i in range(n):
        xs[i], ys[i] = make_sample(params, rng, lidar)
    return xs, ys
