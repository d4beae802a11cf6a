"""Parameters of the ``mujoco`` simulator backend (light: validating a config imports no MuJoCo)."""

from __future__ import annotations

from pydantic import Field

from arena.sim.engine.params import EngineParams
from arena.sim.mujoco.scene import WorldParams


class MujocoParams(EngineParams):
    """The YAML ``sim.backend`` block of ``mujoco``: the engine's parameters plus the 3-D world's.

    ``pedestrians_block_lidar`` and ``lidar`` keep their meaning; ``pedestrian_body`` and the
    leg parameters do not apply (a lidar sees the 3-D figures, :mod:`arena.sim.mujoco.figures`).
    """

    world: WorldParams = Field(
        default_factory=WorldParams, description="how the 2-D scene becomes a 3-D world"
    )
    lidar_height: float | None = Field(
        None, gt=0, le=5,
        description=(
            "m above the floor of every 2-D lidar's scan plane; None: 0.9 x the height of the "
            "robot carrying it (just under its top, so robots of one model see each other's sides)"
        ),
    )
    max_substep: float = Field(
        0.05, gt=0, le=1,
        description=(
            "m, the farthest a robot's footprint moves between two contact tests within a step "
            "(longer moves are tested at evenly spaced intermediate poses: no tunnelling "
            "through walls thicker than this)"
        ),
    )
