"""Local planners: observation (pose, twist, path, scan) → body-frame velocity command.

:data:`LOCAL_PLANNERS` declares the built-in planners by name and imports a planner's module when
a config first names it; third-party planners arrive through the ``arena.local_planners``
entry-point group. Import a planner class from its module (``arena.nav.local_planners.dwa``).
"""

from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    LocalPlanner,
    infer_kinematics,
    limit_command,
    stopping_speed,
)

__all__ = [
    "KINEMATICS",
    "LOCAL_PLANNERS",
    "LocalObservation",
    "LocalPlanner",
    "infer_kinematics",
    "limit_command",
    "stopping_speed",
]
