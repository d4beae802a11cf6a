"""Velocity and acceleration limits of a robot, as planners see them.

Kinematics models enforce their own (richer) constraints; this flat summary is what a local
planner needs to sample or clip commands. Body-frame, SI units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class VelocityLimits:
    """Box limits on the body twist ``[vx, vy, omega]`` and on its rate of change.

    Attributes:
        vx_min: most negative forward speed (m/s, ≤ 0; 0 for robots that cannot reverse).
        vx_max: forward speed limit (m/s).
        vy_min: lateral limit to the right (m/s, 0 for non-holonomic robots).
        vy_max: lateral limit to the left (m/s).
        omega_max: yaw-rate limit, symmetric (rad/s).
        acc_x: forward acceleration limit (m/s²).
        acc_y: lateral acceleration limit (m/s²).
        acc_omega: yaw acceleration limit (rad/s²).
        min_turning_radius: smallest turning radius (m); 0 for robots that turn on the spot.
    """

    vx_min: float
    vx_max: float
    vy_min: float
    vy_max: float
    omega_max: float
    acc_x: float
    acc_y: float
    acc_omega: float
    min_turning_radius: float = 0.0

    @property
    def holonomic(self) -> bool:
        """Whether the robot can move sideways."""
        return self.vy_max > 0 or self.vy_min < 0

    @property
    def lower(self) -> NDArray[np.float64]:
        """``[vx_min, vy_min, -omega_max]``."""
        return np.array([self.vx_min, self.vy_min, -self.omega_max])

    @property
    def upper(self) -> NDArray[np.float64]:
        """``[vx_max, vy_max, omega_max]``."""
        return np.array([self.vx_max, self.vy_max, self.omega_max])

    @property
    def acceleration(self) -> NDArray[np.float64]:
        """``[acc_x, acc_y, acc_omega]``."""
        return np.array([self.acc_x, self.acc_y, self.acc_omega])

    def clip(self, twist: NDArray[np.float64]) -> NDArray[np.float64]:
        """Clip ``(..., 3)`` twists into the velocity box (acceleration is not applied)."""
        return np.clip(twist, self.lower, self.upper)
