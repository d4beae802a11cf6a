"""Global planners: map + start + goal → a collision-free waypoint path.

Importing this package registers the built-in planners in :data:`GLOBAL_PLANNERS`; third-party
planners arrive through the ``arena.global_planners`` entry-point group.
"""

from arena.nav.global_planners import astar as _astar  # noqa: F401  (registers "astar")
from arena.nav.global_planners.astar import AStarPlanner, segment_is_free
from arena.nav.global_planners.base import (
    GLOBAL_PLANNERS,
    GlobalPlanner,
    endpoint_cells,
    path_length,
)

__all__ = [
    "GLOBAL_PLANNERS",
    "AStarPlanner",
    "GlobalPlanner",
    "endpoint_cells",
    "path_length",
    "segment_is_free",
]
