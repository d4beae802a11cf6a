"""Small value types shared by every module: poses, twists and episode outcomes.

Arrays of many poses are plain ``(n, 3)`` float arrays ``[x, y, theta]`` (struct-of-arrays code
never builds one object per agent); these classes are for single values at API boundaries.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True, slots=True)
class Pose2D:
    """A planar pose: position in metres, heading ``theta`` in radians (world frame)."""

    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    @classmethod
    def from_array(cls, a: NDArray[np.floating] | list[float] | tuple[float, ...]) -> Pose2D:
        """Build from ``[x, y]`` or ``[x, y, theta]``."""
        values = [float(v) for v in a]
        if len(values) not in (2, 3):
            raise ValueError(f"a pose needs 2 or 3 values [x, y, theta], got {len(values)}")
        return cls(*values)

    def as_array(self) -> NDArray[np.float64]:
        """``[x, y, theta]`` as a float array of shape (3,)."""
        return np.array([self.x, self.y, self.theta], dtype=np.float64)

    @property
    def xy(self) -> NDArray[np.float64]:
        """Position as a (2,) array."""
        return np.array([self.x, self.y], dtype=np.float64)

    def distance_to(self, other: Pose2D) -> float:
        """Euclidean distance between the two positions (m)."""
        return math.hypot(other.x - self.x, other.y - self.y)

    def compose(self, other: Pose2D) -> Pose2D:
        """``self ⊕ other``: ``other`` is expressed in this pose's frame."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose2D(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            wrap_angle_scalar(self.theta + other.theta),
        )


@dataclass(frozen=True, slots=True)
class Twist:
    """A body-frame velocity: ``vx`` forward and ``vy`` left in m/s, ``omega`` in rad/s (CCW)."""

    vx: float = 0.0
    vy: float = 0.0
    omega: float = 0.0

    @classmethod
    def from_array(cls, a: NDArray[np.floating] | list[float] | tuple[float, ...]) -> Twist:
        """Build from ``[vx, vy, omega]``."""
        vx, vy, omega = (float(v) for v in a)
        return cls(vx, vy, omega)

    def as_array(self) -> NDArray[np.float64]:
        """``[vx, vy, omega]`` as a float array of shape (3,)."""
        return np.array([self.vx, self.vy, self.omega], dtype=np.float64)


class Outcome(enum.StrEnum):
    """How an episode ended. Values are stable strings stored in results files."""

    SUCCESS = "success"
    """The robot reached its goal within the tolerances."""
    COLLISION = "collision"
    """The episode was ended by a collision (when the task ends episodes on collision)."""
    TIMEOUT = "timeout"
    """The time limit ran out before the goal was reached."""
    STUCK = "stuck"
    """The robot made no progress for too long."""
    PLANNER_FAILURE = "planner_failure"
    """The navigation stack reported that no path exists."""
    ERROR = "error"
    """A planner or the simulator raised, or produced non-finite values."""
    ABORTED = "aborted"
    """The episode was ended early by a forced reset (interactive control)."""


def wrap_angle_scalar(a: float) -> float:
    """Wrap one angle to ``[-pi, pi)``."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi
