"""Local planners: observation (pose, twist, path, scan) → body-frame velocity command.

Importing this package registers the built-in planners in :data:`LOCAL_PLANNERS`; third-party
planners arrive through the ``arena.local_planners`` entry-point group.
"""

from arena.nav.local_planners import cohan as _cohan  # noqa: F401  (registers)
from arena.nav.local_planners import crowdnav as _crowdnav  # noqa: F401  (crowdnav, sarl)
from arena.nav.local_planners import dwa as _dwa  # noqa: F401  (registers)
from arena.nav.local_planners import learned as _learned  # noqa: F401  (registers rosnav_rl)
from arena.nav.local_planners import mpc as _mpc  # noqa: F401  (registers)
from arena.nav.local_planners import orca_planner as _orca_planner  # noqa: F401  (registers)
from arena.nav.local_planners import pure_pursuit as _pure_pursuit  # noqa: F401  (registers)
from arena.nav.local_planners import rlca as _rlca  # noqa: F401  (registers rlca)
from arena.nav.local_planners import social_force as _social_force  # noqa: F401  (registers)
from arena.nav.local_planners import teb as _teb  # noqa: F401  (registers)
from arena.nav.local_planners.base import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    LocalPlanner,
    infer_kinematics,
    limit_command,
    stopping_speed,
)
from arena.nav.local_planners.cohan import CohanPlanner
from arena.nav.local_planners.dwa import DWAPlanner
from arena.nav.local_planners.mpc import MPCPlanner
from arena.nav.local_planners.orca_planner import OrcaPlanner
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner
from arena.nav.local_planners.social_force import SocialForcePlanner
from arena.nav.local_planners.teb import TEBPlanner

__all__ = [
    "KINEMATICS",
    "LOCAL_PLANNERS",
    "CohanPlanner",
    "DWAPlanner",
    "LocalObservation",
    "LocalPlanner",
    "MPCPlanner",
    "OrcaPlanner",
    "PurePursuitPlanner",
    "SocialForcePlanner",
    "TEBPlanner",
    "infer_kinematics",
    "limit_command",
    "stopping_speed",
]
