"""``diff_drive``: a differential-drive (unicycle) base such as the TurtleBot3 or the Jackal."""

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
)
from arena.robots.limits import VelocityLimits


@KINEMATICS.register("diff_drive", tags=("wheeled", "non_holonomic"))
class DiffDriveKinematics:
    """Differential drive: forward speed and yaw rate, no side slip.

    Description:
        The command ``[vx, vy, omega]`` is clipped to ``vx ∈ [vx_min, vx_max]`` and
        ``|omega| ≤ omega_max``; ``vy`` is forced to 0. Forward speed and yaw rate then change by
        at most ``acc_x·dt`` and ``acc_omega·dt`` from the last executed twist, and the pose moves
        along the exact arc of radius ``vx/omega``.

    Arguments:
        params: :class:`DiffDriveKinematics.Params`. The acceleration limits default to ``inf``:
            the command is executed at once, as Arena's flatland ``DiffDrive`` plugin does.
    """

    name: ClassVar[str] = "diff_drive"

    class Params(BaseModel):
        """Velocity and acceleration limits of a differential-drive base."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        vx_min: float = Field(le=0, description="m/s, most negative forward speed (0: no reverse)")
        vx_max: float = Field(gt=0, description="m/s, forward speed limit")
        omega_max: float = Field(gt=0, description="rad/s, yaw-rate limit (symmetric)")
        acc_x: float = Field(math.inf, gt=0, description="m/s², forward acceleration limit")
        acc_omega: float = Field(math.inf, gt=0, description="rad/s², yaw acceleration limit")

        @model_validator(mode="after")
        def _finite_speeds(self) -> DiffDriveKinematics.Params:
            if not (math.isfinite(self.vx_min) and math.isfinite(self.vx_max)):
                raise ValueError("vx_min and vx_max must be finite")
            if not math.isfinite(self.omega_max):
                raise ValueError("omega_max must be finite")
            return self

    def __init__(self, params: Params) -> None:
        self.params = params
        self._lower = np.array([params.vx_min, 0.0, -params.omega_max])
        self._upper = np.array([params.vx_max, 0.0, params.omega_max])
        self._acc = np.array([params.acc_x, np.inf, params.acc_omega])
        self._box = (self._lower, self._upper, self._acc)

    @property
    def holonomic(self) -> bool:
        """Always ``False``: a differential drive cannot move sideways."""
        return False

    @property
    def box_limits(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(lower, upper, acc)`` ``(3,)`` each over ``[vx, vy, omega]`` (m/s, m/s, rad/s; /s).

        :meth:`step` is exactly :func:`~arena.robots.kinematics.base.box_step` with these
        arrays, so a simulator may call :func:`~arena.robots.kinematics.base.box_step_rows`
        instead (not to be modified).
        """
        return self._box

    def limits(self) -> VelocityLimits:
        """Box limits for planners (``vy`` and its acceleration are 0)."""
        p = self.params
        return VelocityLimits(
            vx_min=p.vx_min, vx_max=p.vx_max, vy_min=0.0, vy_max=0.0, omega_max=p.omega_max,
            acc_x=p.acc_x, acc_y=0.0, acc_omega=p.acc_omega,
        )

    def step(self, state: KinematicState, commands: ArrayLike, dt: float) -> KinematicState:
        """Advance ``n`` robots by ``dt`` (see :meth:`Kinematics.step`)."""
        cmd = check_step_inputs(state, commands, dt)
        # Clip the command (forcing vy = 0), clip the previous twist (a hand-made state outside
        # the limits is brought back at once: velocity limits win), rate-limit, integrate.
        poses, twist = box_step(state.poses, state.twists, cmd, self._lower, self._upper,
                                self._acc, dt)
        return KinematicState(poses, twist, np.zeros(len(state)))
