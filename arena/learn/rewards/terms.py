"""Reward terms on the task and the robot's motion (Arena's units, arena_specs §8.4).

One formula per term (:class:`~arena.learn.rewards.base.Term`); :class:`ScalarTerm` formulas
also run on one world's scalars. Sign convention: every reward/penalty parameter is the value
*added* to the reward (penalties are negative), as in Arena's configs.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from arena.learn.rewards.base import REWARD_TERMS, DoneReason, ScalarTerm, Term, TermParams


@REWARD_TERMS.register("goal_reached")
class GoalReachedTerm(ScalarTerm):
    """``+reward`` and done (success) when the goal is reached (the env: ρ < goal radius)."""

    reason = DoneReason.SUCCESS

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        reward: float = Field(15.0, description="added on arrival")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc (``bool · reward``: ``False · −x`` is ``−0.0`` in both forms)."""
        hit = inp.goal_reached
        return hit * self.params.reward, hit


@REWARD_TERMS.register("collision")
class CollisionTerm(ScalarTerm):
    """``+reward`` and done (collision) on contact (and, optionally, laser ≤ radius + bumper)."""

    reason = DoneReason.COLLISION

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-10.0, description="added on collision")
        bumper_zone: float = Field(0.05, ge=0, description="m, for from_laser")
        from_laser: bool = Field(False, description="also min laser ≤ robot radius + bumper")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        hit = inp.collision
        if self.params.from_laser:
            hit = ops.either(hit, inp.min_range <= inp.robot_radius + self.params.bumper_zone)
        return hit * self.params.reward, hit


@REWARD_TERMS.register("safe_distance")
class SafeDistanceTerm(ScalarTerm):
    """``+reward`` while the min laser range is within the safe distance."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-0.15, description="added per step of breach")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        return (inp.min_range <= inp.safe_dist) * self.params.reward, None


@REWARD_TERMS.register("no_movement")
class NoMovementTerm(ScalarTerm):
    """``+reward`` when the commanded forward speed is within ±0.1 m/s."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-0.01, description="added per idle step")
        tolerance: float = Field(0.1, ge=0, description="m/s")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        idle = ops.abs(ops.col(inp.action, 0)) <= self.params.tolerance
        return idle * self.params.reward, None


@REWARD_TERMS.register("approach_goal")
class ApproachGoalTerm(ScalarTerm):
    """``factor · Δ``, ``Δ = d_prev − d`` (pos factor if Δ > 0, else neg); skipped on goal jumps."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        pos_factor: float = Field(0.3, description="per m approached")
        neg_factor: float = Field(0.5, description="per m receded")
        goal_update_threshold: float = Field(2.5, gt=0, description="m; a larger jump skips")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        p = self.params
        delta = inp.prev_goal_distance - inp.goal_distance
        r = ops.where(delta > 0, p.pos_factor, p.neg_factor) * delta
        return ops.where(inp.goal_jump >= p.goal_update_threshold, 0.0, r), None


@REWARD_TERMS.register("distance_travelled")
class DistanceTravelledTerm(ScalarTerm):
    """``−(|v|·lin_scalar + |ω|·ang_scalar)·consumption_factor``."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        consumption_factor: float = Field(0.005, description="per (m/s)")
        lin_vel_scalar: float = 1.0
        ang_vel_scalar: float = 0.001

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        p = self.params
        a = inp.action
        v = ops.abs(ops.col(a, 0)) * p.lin_vel_scalar + ops.abs(ops.col(a, 2)) * p.ang_vel_scalar
        return -v * p.consumption_factor, None


@REWARD_TERMS.register("reverse_drive")
class ReverseDriveTerm(ScalarTerm):
    """``+reward`` when the commanded forward speed is negative and below ``threshold``."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-0.01, description="added per reversing step")
        threshold: float = Field(0.0, le=0, description="m/s (Arena code default 0)")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        v = ops.col(inp.action, 0)
        return ops.both(v < 0, v < self.params.threshold) * self.params.reward, None


@REWARD_TERMS.register("abrupt_velocity_change")
class AbruptVelocityChangeTerm(Term):
    """``−Σ_i factor_i · |a_i − a_prev,i|⁴ / 100`` over the components ``[vx, vy, ω]``.

    numpy only: its power may round unlike Python's ``**``.
    """

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        vel_factors: dict[str, float] = Field(
            default_factory=lambda: {"0": 0.3, "1": 0.07, "2": 0.07},
            description="action component index (str) -> factor",
        )

    def __init__(self, params: Params) -> None:
        super().__init__(params)
        self._idx = np.array([int(k) for k in params.vel_factors], dtype=np.int64)
        self._f = np.array(list(params.vel_factors.values()), dtype=np.float64)

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        d = np.abs(inp.action[:, self._idx] - inp.prev_action[:, self._idx])
        return -(d**4 / 100.0 * self._f).sum(axis=1), None


@REWARD_TERMS.register("two_factor_velocity_difference")
class TwoFactorVelocityDifferenceTerm(ScalarTerm):
    """``−(α·Δvx² + β·Δω²)``."""

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        alpha: float = 0.002
        beta: float = 0.005

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc (squares as products: exact in both forms)."""
        a, b = inp.action, inp.prev_action
        d0 = ops.col(a, 0) - ops.col(b, 0)
        d2 = ops.col(a, 2) - ops.col(b, 2)
        return -(self.params.alpha * (d0 * d0) + self.params.beta * (d2 * d2)), None


@REWARD_TERMS.register("angular_vel_constraint")
class AngularVelConstraintTerm(Term):
    """``−penalty_factor · ω_est`` when ``ω_est = |Δψ| / dt`` exceeds ``threshold``.

    numpy only: its float remainder may round unlike Python's ``%``.
    """

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        penalty_factor: float = 0.05
        threshold: float | None = Field(None, ge=0, description="rad/s; null: never")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        p = self.params
        if p.threshold is None:
            return np.zeros(inp.n), None
        dpsi = (inp.heading - inp.prev_heading + np.pi) % (2 * np.pi) - np.pi
        w = np.abs(dpsi) / inp.dt
        return np.where(w > p.threshold, -p.penalty_factor * w, 0.0), None


@REWARD_TERMS.register("rotation_penalty")
class RotationPenaltyTerm(ScalarTerm):
    """``−factor · |ω|`` when the commanded yaw rate ``|ω|`` exceeds ``threshold`` (Long et al.).

    Long et al. 2018 (eq. 5, ``r_w``) penalise large rotational *commands*, not the measured
    heading change of :class:`AngularVelConstraintTerm`: a robot pinned against a wall still
    pays for asking to spin, and the term needs no estimate from poses.
    """

    class Params(TermParams):
        """Parameters, with Long et al.'s values."""

        factor: float = Field(0.1, ge=0, description="per rad/s of commanded |ω|")
        threshold: float = Field(0.7, ge=0, description="rad/s; smaller |ω| is free")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        w = ops.abs(ops.col(inp.action, 2))
        return ops.where(w > self.params.threshold, -self.params.factor * w, 0.0), None


@REWARD_TERMS.register("max_steps_exceeded")
class MaxStepsExceededTerm(ScalarTerm):
    """``+reward`` and done (step limit) when the step count reaches ``max_steps``."""

    reason = DoneReason.STEP_LIMIT

    class Params(TermParams):
        """Parameters, with Arena's defaults."""

        reward: float = Field(-10.0, description="added at the step limit")

    def formula(self, inp: Any, ops: Any) -> tuple[Any, Any]:
        """See the class doc."""
        hit = inp.step >= inp.max_steps
        return hit * self.params.reward, hit
