"""``legged``: a walking robot (quadruped) driven by a body-velocity gait controller (e.g. Go1)."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.robots.kinematics.base import (
    KINEMATICS,
    KinematicState,
    check_step_inputs,
    integrate_twist,
    quadric_norm,
    quadric_step_fraction,
    rate_limit,
)
from arena.robots.limits import VelocityLimits

FloatArray = NDArray[np.float64]


@KINEMATICS.register("legged", tags=("legged", "holonomic"))
class LeggedKinematics:
    """Quadruped gait limits: forward, lateral and yaw speed share one budget.

    Description:
        A gait controller turns a body twist into foot placements; stride length and step
        frequency bound the sum of what each axis asks for, so a quadruped cannot trot at full
        forward speed while also side-stepping and turning at full rate. The feasible set is the
        ellipsoid ``(vx/vx_lim)² + (vy/vy_max)² + (omega/omega_max)² ≤ 1`` with
        ``vx_lim = vx_max`` forward and ``|vx_min|`` backward (two half-ellipsoids, still
        convex); each axis alone reaches its limit. ``max_speed`` optionally caps the planar
        speed ``‖(vx, vy)‖`` as well (a slower gait). A command outside is scaled toward zero
        along its own direction until it lies on the boundary, which keeps the commanded path
        curvature and the sideways-to-forward ratio. Each axis then changes by at most
        ``acc·dt`` (the dynamic window); where that window leaves the feasible set, the twist
        stops where the segment from the previous twist meets the boundary, so velocity and
        acceleration limits hold together. ``vy_max = 0`` gives a robot configured without
        side-stepping, ``vx_min = 0`` one that does not walk backward.

    Arguments:
        params: :class:`LeggedKinematics.Params`; acceleration limits default to ``inf``.
    """

    name: ClassVar[str] = "legged"

    class Params(BaseModel):
        """Gait velocity limits and acceleration limits of a legged robot."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        vx_min: float = Field(le=0, description="m/s, backward walking limit (0: no backward)")
        vx_max: float = Field(gt=0, description="m/s, forward walking limit")
        vy_max: float = Field(ge=0, description="m/s, side-stepping limit, symmetric (0: none)")
        omega_max: float = Field(gt=0, description="rad/s, turning-rate limit, symmetric")
        max_speed: float | None = Field(
            None, gt=0, description="m/s, planar speed cap ‖(vx, vy)‖ of the gait; None: none"
        )
        acc_x: float = Field(math.inf, gt=0, description="m/s², forward acceleration limit")
        acc_y: float = Field(math.inf, gt=0, description="m/s², lateral acceleration limit")
        acc_omega: float = Field(math.inf, gt=0, description="rad/s², yaw acceleration limit")

        @model_validator(mode="after")
        def _finite_speeds(self) -> LeggedKinematics.Params:
            if not all(
                math.isfinite(v) for v in (self.vx_min, self.vx_max, self.vy_max, self.omega_max)
            ):
                raise ValueError("velocity limits must be finite")
            if self.max_speed is not None and not math.isfinite(self.max_speed):
                raise ValueError("max_speed must be finite (leave it out for no cap)")
            return self

    def __init__(self, params: Params) -> None:
        self.params = params
        p = params
        w_y = 0.0 if p.vy_max == 0 else 1.0 / p.vy_max**2  # vy is forced to 0 then
        w_w = 1.0 / p.omega_max**2
        # backward weight unused when vx_min = 0 (vx is clipped at 0): avoid 1/0
        back = p.vx_max if p.vx_min == 0 else -p.vx_min
        self._w_fwd = np.array([1.0 / p.vx_max**2, w_y, w_w])
        self._w_back = np.array([1.0 / back**2, w_y, w_w])
        self._acc = np.array([p.acc_x, p.acc_y, p.acc_omega])
        s = p.max_speed
        self._disc = None if s is None else np.array([1.0 / s**2, 1.0 / s**2, 0.0])

    @property
    def holonomic(self) -> bool:
        """Whether side-stepping is allowed (``vy_max > 0``)."""
        return self.params.vy_max > 0

    def limits(self) -> VelocityLimits:
        """Box hull of the gait ellipsoid (each axis alone), tightened by ``max_speed``.

        Without side-stepping (``vy_max = 0``) the lateral limits and ``acc_y`` read 0, as for
        any non-holonomic robot.
        """
        p = self.params
        cap = math.inf if p.max_speed is None else p.max_speed
        vy = min(p.vy_max, cap)
        return VelocityLimits(
            vx_min=max(p.vx_min, -cap), vx_max=min(p.vx_max, cap), vy_min=-vy if vy else 0.0,
            vy_max=vy,
            omega_max=p.omega_max, acc_x=p.acc_x, acc_y=p.acc_y if vy else 0.0,
            acc_omega=p.acc_omega,
        )

    def _weights(self, vx: FloatArray) -> FloatArray:
        """``(n, 3)`` ellipsoid weights for twists whose forward speed is ``vx`` ``(n,)``."""
        return np.where((vx >= 0.0)[:, None], self._w_fwd, self._w_back)

    def project(self, twists: FloatArray) -> FloatArray:
        """Scale ``(n, 3)`` twists along their direction into the feasible set (new array)."""
        v = np.array(twists, dtype=np.float64)
        if self.params.vy_max == 0:
            v[:, 1] = 0.0  # a forbidden axis is removed, not scaled
        if self.params.vx_min == 0:
            v[:, 0] = np.maximum(v[:, 0], 0.0)
        scale = quadric_norm(v, self._weights(v[:, 0]))
        if self._disc is not None:
            scale = np.maximum(scale, quadric_norm(v, self._disc))
        return v / np.maximum(scale, 1.0)[:, None]

    def _ellipsoid_fraction(self, prev: FloatArray, delta: FloatArray) -> FloatArray:
        """Largest fraction of ``delta`` from ``prev`` (inside) that stays in the ellipsoid."""
        new_x = prev[:, 0] + delta[:, 0]
        w_first = self._weights(prev[:, 0])
        w_second = self._weights(new_x)
        crosses = prev[:, 0] * new_x < 0.0
        # no sign change of vx: one half-ellipsoid covers the whole segment
        same = quadric_step_fraction(prev, delta, self._weights(prev[:, 0] + new_x))
        # sign change at s0 (vx = 0): the root lies on the first piece iff g(s0) > 1
        with np.errstate(divide="ignore", invalid="ignore"):
            s0 = np.where(crosses, prev[:, 0] / (prev[:, 0] - new_x), 0.0)
        at_s0 = prev + s0[:, None] * delta
        first = quadric_step_fraction(prev, delta, w_first)
        # the second piece's quadratic, expanded from prev, equals g on [s0, 1]; its larger
        # root lies there because g(s0) <= 1 < g(1)
        second = quadric_step_fraction(prev, delta, w_second)
        on_first = quadric_norm(at_s0, w_first) > 1.0
        return np.where(crosses, np.where(on_first, first, second), same)

    def step(self, state: KinematicState, commands: ArrayLike, dt: float) -> KinematicState:
        """Advance ``n`` robots by ``dt`` (see :meth:`Kinematics.step`)."""
        cmd = check_step_inputs(state, commands, dt)
        target = self.project(cmd)
        prev = self.project(state.twists)  # velocity limits win over a hand-made state
        delta = rate_limit(prev, target, self._acc * dt) - prev
        frac = np.minimum(self._ellipsoid_fraction(prev, delta), 1.0)
        if self._disc is not None:
            frac = np.minimum(frac, quadric_step_fraction(prev, delta, self._disc))
        twist = prev + frac[:, None] * delta
        poses = integrate_twist(state.poses, twist, dt)
        return KinematicState(poses, twist, np.zeros(len(state)))
