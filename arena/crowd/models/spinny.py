"""Arena's ``spinny`` demo force model: pedsim's force, turned a little further every step.

Arena ships it as the smallest example of a crowd plugin that rewrites pedsim's force: each
step every agent's acceleration is rotated by an angle that grows by ``angle_per_step_deg``
(Arena: 3°) per step, so after ``k`` steps the rotation is ``k·3°``. The force keeps turning
relative to the goal direction, so pedestrians walk in circles instead of reaching their
waypoints. It is a demo and a plugin-API check (a model with per-episode state), not a model of
people.

Rotating is linear, so each named term in ``forces`` is rotated by the same angle and the terms
still sum to the acceleration. The step count restarts at :meth:`SpinnyModel.reset`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from arena.crowd.base import CROWD_MODELS, CrowdFrame, ModelOutput
from arena.crowd.models.pedsim.model import PedsimModel
from arena.crowd.models.pedsim.params import SpinnyParams
from arena.crowd.state import CrowdState
from arena.scene.state import StaticWorld

FloatArray = NDArray[np.float64]


@CROWD_MODELS.register("spinny", tags=("demo",))
class SpinnyModel(PedsimModel):
    """Arena's demo: pedsim's acceleration rotated by ``k·angle_per_step_deg`` at step ``k``."""

    Params = SpinnyParams

    def __init__(self, params: SpinnyParams | None = None) -> None:
        super().__init__(params or self.Params())
        self.params: SpinnyParams
        self._steps = 0

    def reset(self, state: CrowdState, world: StaticWorld, rng: np.random.Generator) -> None:
        """Prepare pedsim's state and restart the step count (no rotation accumulated)."""
        super().reset(state, world, rng)
        self._steps = 0

    def compute(self, frame: CrowdFrame) -> ModelOutput:
        """The pedsim force and terms rotated by ``k·angle_per_step_deg`` on call ``k`` (m/s²)."""
        acc, forces = self._pedsim(frame)
        self._steps += 1
        # Wrapped in degrees first so a long episode does not lose precision in the angle.
        angle = math.radians((self.params.angle_per_step_deg * self._steps) % 360.0)
        c, s = math.cos(angle), math.sin(angle)
        return ModelOutput(
            accelerations=_rotate(acc, c, s),
            forces={name: _rotate(f, c, s) for name, f in forces.items()},
        )

    @property
    def steps(self) -> int:
        """Calls to :meth:`compute` since the last :meth:`reset`."""
        return self._steps


def _rotate(v: FloatArray, c: float, s: float) -> FloatArray:
    """Rows of ``v`` ``(n, 2)`` turned counter-clockwise by the angle with cos ``c``, sin ``s``."""
    out = np.empty_like(v)
    out[:, 0] = c * v[:, 0] - s * v[:, 1]
    out[:, 1] = s * v[:, 0] + c * v[:, 1]
    return out
