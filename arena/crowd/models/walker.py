"""The simplest crowd model: walk straight to the destination, ignore everyone.

The baseline every social model is compared with: the desired velocity points at the
destination at the preferred speed (slowing on the last stretch), reached within a maximum
acceleration. No pedestrian, wall or robot term.
"""

from __future__ import annotations

from typing import ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.state import CrowdState
from arena.sim.state import StaticWorld


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
        delta = frame.destinations - s.positions
        dist = np.hypot(delta[:, 0], delta[:, 1])[:, None]
        speed = np.minimum((s.vmax * s.vmax_factor)[:, None], dist / max(frame.dt, 1e-9))
        desired = np.divide(delta, dist, out=np.zeros_like(delta), where=dist > 1e-9) * speed
        acc = (desired - s.velocities) / frame.dt
        norm = np.hypot(acc[:, 0], acc[:, 1])[:, None]
        acc *= np.minimum(1.0, self.params.max_acceleration / np.maximum(norm, 1e-12))
        acc[~frame.active] = 0.0
        return ModelOutput(accelerations=acc, forces={"desired": acc.copy()})
