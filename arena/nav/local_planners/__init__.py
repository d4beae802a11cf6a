"""Local planners: observation (pose, twist, path, scan) → body-frame velocity command.

Importing this package registers the built-in planners in :data:`LOCAL_PLANNERS`; third-party
planners arrive through the ``arena.local_planners`` entry-point group.
"""

from arena.nav.local_planners import dwa as _dwa  # noqa: F401  (registers)
from arena.nav.local_planners import pure_pursuit as _pure_pursuit  # noqa: F401  (registers)
from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    LocalPlanner,
    infer_kinematics,
    limit_command,
    stopping_speed,
)
from arena.nav.local_planners.dwa import DWAPlanner
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner

__all__ = [
    "KINEMATICS",
    "LOCAL_PLANNERS",
    "DWAPlanner",
    "LocalObservation",
    "LocalPlanner",
    "PurePursuitPlanner",
    "infer_kinematics",
    "limit_command",
    "stopping_speed",
]
