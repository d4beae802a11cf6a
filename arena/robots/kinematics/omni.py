"""``omni``: a holonomic wheeled base (mecanum or omni wheels) such as the Ridgeback or Robotino."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.robots.kinematics.base import (
    KINEMATICS,
    FloatArray,
    KinematicState,
    box_step,
    check_step_inputs,
    integrate_twist,
    quadric_norm,
    quadric_step_fraction,
    rate_limit,
)
from arena.robots.limits import VelocityLimits


@KINEMATICS.register("omni", tags=("wheeled", "holonomic"))
class OmniKinematics:
    """Holonomic base: independent forward, lateral and yaw velocities.

    Description:
        The command is clipped to the box ``vx ∈ [vx_min, vx_max]``, ``vy ∈ [vy_min, vy_max]``,
        ``|omega| ≤ omega_max``; with ``speed_max`` set, the planar speed ``‖(vx, vy)‖`` is then
        capped by scaling ``(vx, vy)`` along its direction (the yaw rate is left alone). Each
        axis changes by at most ``acc·dt`` from the last executed twist; if that per-axis window
        leaves the speed disc, ``(vx, vy)`` stops where the segment from the last twist meets
        the disc, so both limits hold. The pose follows the exact motion of a constant body
        twist (translation while rotating: an arc whose chord turns with the heading).

    Arguments:
        params: :class:`OmniKinematics.Params`; acceleration limits default to ``inf``.
    """

    name: ClassVar[str] = "omni"

    class Params(BaseModel):
        """Velocity and acceleration limits of a holonomic base."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        vx_min: float = Field(le=0, description="m/s, most negative forward speed")
        vx_max: float = Field(gt=0, description="m/s, forward speed limit")
        vy_min: float = Field(le=0, description="m/s, lateral limit to the right (negative)")
        vy_max: float = Field(ge=0, description="m/s, lateral limit to the left")
        omega_max: float = Field(gt=0, description="rad/s, yaw-rate limit (symmetric)")
        speed_max: float | None = Field(
            None, gt=0, description="m/s, cap on the planar speed ‖(vx, vy)‖; None: box only"
        )
        acc_x: float = Field(math.inf, gt=0, description="m/s², forward acceleration limit")
        acc_y: float = Field(math.inf, gt=0, description="m/s², lateral acceleration limit")
        acc_omega: float = Field(math.inf, gt=0, description="rad/s², yaw acceleration limit")

        @model_validator(mode="after")
        def _finite_speeds(self) -> OmniKinematics.Params:
            vals = (self.vx_min, self.vx_max, self.vy_min, self.vy_max, self.omega_max)
            if not all(math.isfinite(v) for v in vals):
                raise ValueError("velocity limits must be finite")
            if self.speed_max is not None and not math.isfinite(self.speed_max):
                raise ValueError("speed_max must be finite (leave it out for no cap)")
            return self

    def __init__(self, params: Params) -> None:
        self.params = params
        self._lower = np.array([params.vx_min, params.vy_min, -params.omega_max])
        self._upper = np.array([params.vx_max, params.vy_max, params.omega_max])
        self._acc = np.array([params.acc_x, params.acc_y, params.acc_omega])
        # the speed disc as a quadric on [vx, vy, omega] (omega unconstrained by it)
        s = params.speed_max
        self._disc = None if s is None else np.array([1.0 / s**2, 1.0 / s**2, 0.0])
        self._box = None if s is not None else (self._lower, self._upper, self._acc)

    @property
    def holonomic(self) -> bool:
        """``True`` unless both lateral limits are 0."""
        return self.params.vy_max > 0 or self.params.vy_min < 0

    @property
    def box_limits(self) -> tuple[FloatArray, FloatArray, FloatArray] | None:
        """``(lower, upper, acc)`` ``(3,)`` each over ``[vx, vy, omega]`` without a speed disc.

        Then :meth:`step` is exactly :func:`~arena.robots.kinematics.base.box_step` with these
        arrays (not to be modified); ``None`` with ``speed_max`` (the disc needs more steps).
        """
        return self._box

    def limits(self) -> VelocityLimits:
        """Box limits for planners; ``speed_max`` tightens each axis limit it undercuts."""
        p = self.params
        cap = math.inf if p.speed_max is None else p.speed_max
        return VelocityLimits(
            vx_min=max(p.vx_min, -cap), vx_max=min(p.vx_max, cap),
            vy_min=max(p.vy_min, -cap), vy_max=min(p.vy_max, cap),
            omega_max=p.omega_max, acc_x=p.acc_x, acc_y=p.acc_y, acc_omega=p.acc_omega,
        )

    def step(self, state: KinematicState, commands: ArrayLike, dt: float) -> KinematicState:
        """Advance ``n`` robots by ``dt`` (see :meth:`Kinematics.step`)."""
        cmd = check_step_inputs(state, commands, dt)
        if self._disc is None:  # box limits only: the compiled fast path
            poses, twist = box_step(state.poses, state.twists, cmd, self._lower, self._upper,
                                    self._acc, dt)
            return KinematicState(poses, twist, np.zeros(len(state)))
        target = np.clip(cmd, self._lower, self._upper)
        prev = np.clip(state.twists, self._lower, self._upper)  # velocity limits win
        if self._disc is not None:
            # scaling (vx, vy) toward 0 keeps the box (it contains 0) and the direction of travel;
            # the yaw rate is independent of the wheels' planar speed budget
            target[:, :2] /= np.maximum(quadric_norm(target, self._disc), 1.0)[:, None]
            prev[:, :2] /= np.maximum(quadric_norm(prev, self._disc), 1.0)[:, None]
        twist = rate_limit(prev, target, self._acc * dt)
        # the per-axis window keeps the box but may leave the speed disc: stop on its rim
        if self._disc is not None:
            delta = twist[:, :2] - prev[:, :2]
            frac = quadric_step_fraction(prev[:, :2], delta, self._disc[:2])
            twist[:, :2] = prev[:, :2] + np.minimum(frac, 1.0)[:, None] * delta
        poses = integrate_twist(state.poses, twist, dt)
        return KinematicState(poses, twist, np.zeros(len(state)))
