"""Reward terms on nearby pedestrians by type (Arena's ``ped_type_*`` units).

numpy only (:class:`~arena.learn.rewards.base.Term`): they read the per-pedestrian arrays.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from arena.learn.rewards.base import ELDER, REWARD_TERMS, FloatArray, RewardInput, Term, TermParams


def _nearest_of_kind(inp: RewardInput, kind: int) -> FloatArray:
    """``(N,)`` m to the nearest pedestrian of ``kind`` (inf when there is none)."""
    d = np.where(inp.ped_mask & (inp.ped_kind == kind), inp.ped_distance, np.inf)
    return d.min(axis=1) if d.shape[1] else np.full(inp.n, np.inf)


@REWARD_TERMS.register("ped_type_safety_distance")
class PedTypeSafetyDistanceTerm(Term):
    """``+reward`` when the nearest pedestrian of ``type`` is closer than ``distance``."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        type: int = Field(ELDER, description="pedestrian type code (1 elder)")
        reward: float = -0.25
        distance: float = Field(1.25, gt=0, description="m")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        near = _nearest_of_kind(inp, self.params.type) < self.params.distance
        return near * self.params.reward, None


@REWARD_TERMS.register("ped_type_collision")
class PedTypeCollisionTerm(Term):
    """``+reward`` when a pedestrian of ``type`` is within robot radius + bumper zone."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        type: int = Field(ELDER, description="pedestrian type code (1 elder)")
        reward: float = -10.0
        bumper_zone: float = Field(0.05, ge=0, description="m")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        hit = _nearest_of_kind(inp, self.params.type) <= inp.robot_radius + self.params.bumper_zone
        return hit * self.params.reward, None


@REWARD_TERMS.register("ped_type_vel_constraint")
class PedTypeVelConstraintTerm(Term):
    """``−penalty_factor · v`` while a pedestrian of ``type`` is within ``active_distance``."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        type: int = Field(ELDER, description="pedestrian type code (1 elder)")
        penalty_factor: float = 0.05
        active_distance: float = Field(1.25, gt=0, description="m")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        p = self.params
        near = _nearest_of_kind(inp, p.type) < p.active_distance
        return np.where(near, -p.penalty_factor * inp.action[:, 0], 0.0), None
