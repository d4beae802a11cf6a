"""Global planners: map + start + goal → a collision-free waypoint path.

Importing this package registers the built-in planners in :data:`GLOBAL_PLANNERS`; third-party
planners arrive through the ``arena.global_planners`` entry-point group.
"""

from arena.nav.global_planners import astar as _astar  # noqa: F401  (registers "astar")
from arena.nav.global_planners import dijkstra as _dijkstra  # noqa: F401  (registers "dijkstra")
from arena.nav.global_planners import theta_star as _theta  # noqa: F401  (registers "theta_star")
from arena.nav.global_planners.astar import AStarPlanner, segment_is_free
from arena.nav.global_planners.base import (
    GLOBAL_PLANNERS,
    GlobalPlanner,
    endpoint_cells,
)
from arena.nav.global_planners.dijkstra import DijkstraPlanner, plan_on_costmap
from arena.nav.global_planners.theta_star import ThetaStarPlanner

__all__ = [
    "GLOBAL_PLANNERS",
    "AStarPlanner",
    "DijkstraPlanner",
    "GlobalPlanner",
    "ThetaStarPlanner",
    "endpoint_cells",
    "plan_on_costmap",
    "segment_is_free",
]
