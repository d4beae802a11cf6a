"""``ackermann``: a car-like robot as a kinematic bicycle about the rear axle (e.g. F1TENTH)."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike
from pydantic import BaseModel, ConfigDict, Field, model_validator

from arena.robots.kinematics.base import (
    KINEMATICS,
    KinematicState,
    check_step_inputs,
    integrate_twist,
    rate_limit,
)
from arena.robots.limits import VelocityLimits

_V_EPS = 1e-9  # m/s: below this a commanded speed counts as "stopped"
_W_EPS = 1e-9  # rad/s: below this a commanded yaw rate counts as "no turn"


@KINEMATICS.register("ackermann", tags=("wheeled", "non_holonomic", "car_like"))
class AckermannKinematics:
    """Kinematic bicycle with steering-angle and steering-rate limits; reference point = rear axle.

    Description:
        The command ``[v, vy, omega]`` is read as a speed and a path curvature ``omega / v``
        (``vy`` is ignored: a car cannot slide sideways). The speed is clipped to
        ``[vx_min, vx_max]`` and changes by at most ``acc_x·dt``. The curvature becomes a
        steering target ``delta* = atan(wheelbase · omega / v)``, clipped to
        ``±max_steering_angle``; the wheels turn toward it by at most ``max_steering_rate·dt``
        from ``state.steering``. The executed yaw rate is ``omega = v · tan(delta) / wheelbase``
        and the rear axle moves along the exact arc of radius ``wheelbase / tan(delta)``; at full
        lock that is the minimum turning radius ``wheelbase / tan(max_steering_angle)``.

        At a commanded speed of (almost) zero the curvature is undefined. Then a non-zero yaw
        rate steers to full lock toward it (the limit of ``atan(L·omega/v)`` as ``v → 0⁺``, so
        the car takes the tightest arc once it moves), and a zero yaw rate holds the current
        steering angle (a stop command leaves the wheels where they are).

    Arguments:
        params: :class:`AckermannKinematics.Params`; ``acc_x`` and ``max_steering_rate``
            default to ``inf`` (no limit).
    """

    name: ClassVar[str] = "ackermann"

    class Params(BaseModel):
        """Geometry, steering and speed limits of a car-like robot."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        wheelbase: float = Field(gt=0, description="m, distance between front and rear axles")
        max_steering_angle: float = Field(
            gt=0, lt=math.pi / 2, description="rad, front-wheel steering limit (symmetric)"
        )
        max_steering_rate: float = Field(
            math.inf, gt=0, description="rad/s, how fast the steering angle can change"
        )
        vx_min: float = Field(le=0, description="m/s, most negative (reverse) speed")
        vx_max: float = Field(gt=0, description="m/s, forward speed limit")
        acc_x: float = Field(math.inf, gt=0, description="m/s², longitudinal acceleration limit")

        @model_validator(mode="after")
        def _finite_speeds(self) -> AckermannKinematics.Params:
            if not (math.isfinite(self.vx_min) and math.isfinite(self.vx_max)):
                raise ValueError("vx_min and vx_max must be finite")
            return self

    def __init__(self, params: Params) -> None:
        self.params = params
        self._tan_max = math.tan(params.max_steering_angle)

    @property
    def holonomic(self) -> bool:
        """Always ``False``."""
        return False

    @property
    def min_turning_radius(self) -> float:
        """Radius of the rear axle's circle at full lock (m): ``wheelbase / tan(max_steering)``."""
        return self.params.wheelbase / self._tan_max

    def limits(self) -> VelocityLimits:
        """Box summary for planners.

        ``omega_max`` is the yaw rate at full lock and top speed; ``acc_omega`` bounds
        ``d/dt (v·tan(delta)/L) = (a·tan delta + v·delta'/cos² delta) / L`` over the limits.
        """
        p = self.params
        v_abs = max(abs(p.vx_min), p.vx_max)
        omega_max = v_abs * self._tan_max / p.wheelbase
        sec2 = 1.0 + self._tan_max**2
        acc_omega = (p.acc_x * self._tan_max + v_abs * p.max_steering_rate * sec2) / p.wheelbase
        return VelocityLimits(
            vx_min=p.vx_min, vx_max=p.vx_max, vy_min=0.0, vy_max=0.0, omega_max=omega_max,
            acc_x=p.acc_x, acc_y=0.0, acc_omega=acc_omega,
            min_turning_radius=self.min_turning_radius,
        )

    def steering_target(self, commands: np.ndarray, current: np.ndarray) -> np.ndarray:
        """Steering angle ``(n,)`` (rad, before limits) that realises the commanded curvature.

        Args:
            commands: ``(n, 3)`` commands ``[v, vy, omega]``.
            current: ``(n,)`` current steering angles, kept where the command carries no
                curvature (``v ≈ 0`` and ``omega ≈ 0``).
        """
        v, w = commands[:, 0], commands[:, 2]
        sign = np.where(v < 0.0, -1.0, 1.0)  # reversing flips the curvature's sign
        # atan2 keeps v -> 0 finite: atan(L·w/v) tends to ±pi/2 (full lock after clipping)
        target = np.arctan2(self.params.wheelbase * w * sign, np.abs(v))
        undefined = (np.abs(v) < _V_EPS) & (np.abs(w) < _W_EPS)
        return np.where(undefined, current, target)

    def step(self, state: KinematicState, commands: ArrayLike, dt: float) -> KinematicState:
        """Advance ``n`` robots by ``dt`` (see :meth:`Kinematics.step`)."""
        cmd = check_step_inputs(state, commands, dt)
        p = self.params
        dmax = p.max_steering_angle
        # velocity limits win over the state: clip the previous speed and steering first
        v_prev = np.clip(state.twists[:, 0], p.vx_min, p.vx_max)
        d_prev = np.clip(state.steering, -dmax, dmax)
        v = rate_limit(v_prev, np.clip(cmd[:, 0], p.vx_min, p.vx_max), p.acc_x * dt)
        d_target = np.clip(self.steering_target(cmd, d_prev), -dmax, dmax)
        delta = np.clip(rate_limit(d_prev, d_target, p.max_steering_rate * dt), -dmax, dmax)
        twist = np.zeros((len(state), 3))
        twist[:, 0] = np.clip(v, p.vx_min, p.vx_max)
        twist[:, 2] = twist[:, 0] * np.tan(delta) / p.wheelbase
        poses = integrate_twist(state.poses, twist, dt)
        return KinematicState(poses, twist, delta)
