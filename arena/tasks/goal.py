"""When a robot has reached its goal (Arena specs §2.3)."""

from __future__ import annotations

import math

from arena.core.types import Pose2D


def heading_error(a: float, b: float) -> float:
    """Absolute difference of two headings (rad), in ``[0, π]``.

    Arena writes it ``π − | |θ_goal − θ| − π |``, which is the same for headings in ``[-π, π)``
    but not for unwrapped ones; this works for any pair.
    """
    d = (a - b) % (2.0 * math.pi)
    return min(d, 2.0 * math.pi - d)


def goal_reached(
    pose: Pose2D, goal: Pose2D, radius: float, angle_tolerance: float | None = None
) -> bool:
    """Whether ``pose`` is within ``radius`` (m) and ``angle_tolerance`` (rad) of ``goal``.

    ``angle_tolerance=None`` ignores the heading.
    """
    if math.hypot(goal.x - pose.x, goal.y - pose.y) >= radius:
        return False
    return angle_tolerance is None or heading_error(goal.theta, pose.theta) < angle_tolerance
