"""Sensor specifications as validated data (shared by robot presets and the sensor code)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator


class LidarSpec(BaseModel):
    """A planar laser scanner, as in Arena's ``model_params.yaml`` ``laser`` block.

    Beam ``i`` points at ``angle_min + i · angle_increment`` in the sensor frame. A scan covering
    the full circle (``angle_max - angle_min`` ≥ 2π − 1e-3) spreads ``num_beams`` beams evenly
    without repeating the first beam; otherwise the first and last beams sit at ``angle_min`` and
    ``angle_max``. The ``Params`` of the ``lidar2d`` sensor type
    (:data:`arena.sensors.base.SENSORS`).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    type: Literal["lidar2d"] = Field(
        "lidar2d", description="sensor type (registry name); optional in Arena's laser block"
    )
    angle_min: float = Field(description="rad, first beam angle in the sensor frame")
    angle_max: float = Field(description="rad, last beam angle in the sensor frame")
    num_beams: int = Field(
        gt=0, le=10_000, description="number of beams (real 2-D scanners: up to a few thousand)"
    )
    range_max: float = Field(
        gt=0, le=1000.0, description="m, beams that hit nothing report this range (<= 1000)"
    )
    range_min: float = Field(0.0, ge=0, description="m, returns closer than this report range_min")
    update_rate: float = Field(10.0, gt=0, le=1000.0, description="Hz (<= 1000)")
    noise_std: float = Field(0.0, ge=0, description="m, std of additive Gaussian range noise")
    mount: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="sensor pose [x m, y m, yaw rad] in the robot base frame"
    )

    @model_validator(mode="after")
    def _check(self) -> LidarSpec:
        check_fan(self.angle_min, self.angle_max, self.range_min, self.range_max)
        return self

    @property
    def full_circle(self) -> bool:
        """Whether the beams cover 360° (no duplicate beam at the seam)."""
        return is_full_circle(self.angle_min, self.angle_max)

    @property
    def angle_increment(self) -> float:
        """Angle between neighbouring beams (rad)."""
        return fan_increment(self.angle_min, self.angle_max, self.num_beams)

    def angles(self) -> NDArray[np.float64]:
        """Beam angles in the sensor frame, shape ``(num_beams,)`` (rad)."""
        return self.angle_min + self.angle_increment * np.arange(self.num_beams, dtype=np.float64)


def check_fan(angle_min: float, angle_max: float, range_min: float, range_max: float) -> None:
    """Validate a fan of beams (rad) and its range limits (m); ``ValueError`` saying what."""
    if angle_max < angle_min:
        raise ValueError(f"angle_max ({angle_max}) must be >= angle_min ({angle_min})")
    if angle_max - angle_min > 2 * math.pi + 1e-3:
        raise ValueError("the scan spans more than a full circle")
    if range_min >= range_max:
        raise ValueError(f"range_min ({range_min}) must be < range_max ({range_max})")


def is_full_circle(angle_min: float, angle_max: float) -> bool:
    """Whether a fan from ``angle_min`` to ``angle_max`` (rad) covers 360°."""
    return angle_max - angle_min >= 2 * math.pi - 1e-3


def fan_increment(angle_min: float, angle_max: float, n: int) -> float:
    """Angle (rad) between neighbouring beams of ``n`` spread from ``angle_min`` to ``angle_max``.

    A full circle spreads them evenly without repeating the first beam; otherwise the first
    and last beams sit at ``angle_min`` and ``angle_max`` (one beam: at ``angle_min``).
    """
    if is_full_circle(angle_min, angle_max):
        return 2 * math.pi / n
    return (angle_max - angle_min) / max(n - 1, 1)


@dataclass(frozen=True, eq=False)
class LidarReading:
    """One lidar's latest scan with its geometry, as a local planner reads it.

    Attributes:
        ranges: ``(beams,)`` m.
        angles: ``(beams,)`` beam angles in the robot frame, mount yaw included (rad).
        origin: ``(2,)`` sensor position in the robot frame (m).
    """

    ranges: NDArray[np.float64]
    angles: NDArray[np.float64]
    origin: NDArray[np.float64]


def lidar_geometry(spec: LidarSpec) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(angles (beams,) rad, origin (2,) m)`` of ``spec``'s beams in the robot frame."""
    return spec.angles() + spec.mount[2], np.array(spec.mount[:2], dtype=np.float64)
