"""Navigation: global planners, local planners and the stack that runs them for one robot.

The local-planner registry names its built-ins and imports one when a config names it;
:class:`NavigationStack` is the pipeline a task drives every control tick.
"""

from arena.nav.build import stack_from_config
from arena.nav.config import NavigationConfig, NavStatus
from arena.nav.global_planners import GLOBAL_PLANNERS, AStarPlanner, GlobalPlanner
from arena.nav.local_planners import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    LocalPlanner,
)
from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner
from arena.nav.stack import NavigationStack

__all__ = [
    "GLOBAL_PLANNERS",
    "KINEMATICS",
    "LOCAL_PLANNERS",
    "AStarPlanner",
    "GlobalPlanner",
    "LocalObservation",
    "LocalPlanner",
    "NavStatus",
    "NavigationConfig",
    "NavigationStack",
    "PurePursuitPlanner",
    "stack_from_config",
]
