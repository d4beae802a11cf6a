"""Parameters of the simulation engine (the YAML ``sim.backend`` block of ``native2d``)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field


class EngineParams(BaseModel):
    """Parameters of :class:`~arena.sim.engine.Engine` (and so of ``native2d``)."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    collision_response: Literal["stop", "record"] = Field(
        "stop", description="'stop': a colliding move is undone; 'record': only reported"
    )
    lidar: bool = Field(True, description="simulate the robots' laser scanners")
    pedestrians_block_lidar: bool = Field(True, description="pedestrians are seen by lidar")
    pedestrian_body: Literal["circle", "legs"] = Field(
        "circle", description="what lidar sees of a pedestrian: its body circle or two legs"
    )
    leg_radius: float = Field(0.07, gt=0, description="m, radius of one leg (legs body)")
    hip_half_width: float = Field(
        0.1, ge=0, description="m, leg centre offset from the body axis"
    )
    stride_amplitude: float = Field(
        0.25, ge=0, description="m, forward/backward swing of each leg at full walking speed"
    )
    stride_length: float = Field(1.4, gt=0, description="m walked per full gait cycle")
    parallel_min_worlds: int = Field(
        2, ge=1, description="kernels use numba's thread pool from this many worlds on"
    )
    parallel_chunksize: int = Field(
        1, ge=0, description=(
            "worlds a thread takes at a time in the parallel kernels (dynamic scheduling: a "
            "thread slowed by other load takes fewer); 0: numba's static split"
        ),
    )
