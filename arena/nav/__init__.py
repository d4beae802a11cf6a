"""Navigation: global planners, local planners and the stack that runs them for one robot.

Importing :mod:`arena.nav` registers the built-in planners; :class:`NavigationStack` is the
pipeline a task drives every control tick.
"""

from arena.nav.global_planners import GLOBAL_PLANNERS, AStarPlanner, GlobalPlanner
from arena.nav.local_planners import (
    KINEMATICS,
    LOCAL_PLANNERS,
    LocalObservation,
    LocalPlanner,
    PurePursuitPlanner,
)
from arena.nav.stack import NavigationConfig, NavigationStack, NavStatus

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
]
