"""Intermediate planners: refine the global path and tune the local planner near people.

Importing this package registers the built-in planners in :data:`INTERMEDIATE_PLANNERS`;
third-party planners arrive through the ``arena.intermediate_planners`` entry-point group.
"""

from arena.nav.intermediate.base import (
    INTERMEDIATE_PLANNERS,
    IntermediateInput,
    IntermediateOutput,
    IntermediatePlanner,
    Pedestrians,
    danger_level,
)
from arena.nav.intermediate.planners import (
    AggressivePlanner,
    BypassPlanner,
    MetaPlanner,
    PolitePlanner,
    ShortsightedPlanner,
    SidewaysPlanner,
)

__all__ = [
    "INTERMEDIATE_PLANNERS",
    "AggressivePlanner",
    "BypassPlanner",
    "IntermediateInput",
    "IntermediateOutput",
    "IntermediatePlanner",
    "MetaPlanner",
    "Pedestrians",
    "PolitePlanner",
    "ShortsightedPlanner",
    "SidewaysPlanner",
    "danger_level",
]
