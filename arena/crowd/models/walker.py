"""The simplest crowd model: walk straight to the destination, ignore everyone.

The baseline every social model is compared with: the desired velocity points at the
destination at the preferred speed (slowing on the last stretch), reached within a maximum
acceleration. No pedestrian, wall or robot term.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.state import CrowdState
from arena.scene.state import StaticWorld


@CROWD_MODELS.register("waypoint_walker", tags=("baseline",))
class WaypointWalker:
    """Pedestrians walk straight to their destinations at their preferred speed, no avoidance."""

    output: ClassVar[Literal["acceleration", "velocity"]] = "acceleration"

    class Params(BaseModel):
        """Parameters of :class:`WaypointWalker`."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        max_acceleration: float = Field(1.5, gt=0, description="m/s², limit on velocity change")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()

    def neighbor_cutoff(self) -> float:
        """No interactions: no neighbours needed."""
        return 0.0

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Nothing to prepare."""

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """Acceleration toward the desired velocity, limited to ``max_acceleration``."""
        s = frame.state
        acc = np.zeros((s.positions.shape[0], 2))  # here: cheaper than boxing a returned array
        _walk(
            s.positions,
            s.velocities,
            frame.destinations,
            s.vmax * s.vmax_factor,
            frame.active,
            self.params.max_acceleration,
            frame.dt,
            acc,
        )
        return ModelOutput(accelerations=acc, forces={"desired": acc})


@njit(cache=True)
def _walk(pos, vel, dest, vmax, active, max_acc, dt, acc):
    """Desired velocity toward the destination, reached within ``max_acc``, into ``acc``.

    The speed drops on the last stretch so the agent stops on its destination; inactive agents
    keep the zero ``acc`` ``(n, 2)`` m/s² the caller gives.
    """
    n = pos.shape[0]
    for i in range(n):
        if not active[i]:
            continue
        dx, dy = dest[i, 0] - pos[i, 0], dest[i, 1] - pos[i, 1]
        dist = math.sqrt(dx * dx + dy * dy)
        speed = min(vmax[i], dist / max(dt, 1e-9))
        ux, uy = (dx / dist * speed, dy / dist * speed) if dist > 1e-9 else (0.0, 0.0)
        ax, ay = (ux - vel[i, 0]) / dt, (uy - vel[i, 1]) / dt
        norm = math.sqrt(ax * ax + ay * ay)
        k = min(1.0, max_acc / max(norm, 1e-12))
        acc[i, 0], acc[i, 1] = ax * k, ay * k
