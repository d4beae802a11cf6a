"""Layered costmaps after ROS ``costmap_2d``: static, obstacle, inflation and pedestrian layers."""

from arena.nav.costmap.costmap import (
    CostmapParams,
    GlobalCostmap,
    LocalCostmap,
    pedestrians_from_semantic,
)
from arena.nav.costmap.layers import (
    FREE_SPACE,
    INSCRIBED,
    LETHAL,
    MAX_NON_OBSTACLE,
    NO_INFORMATION,
    Costmap,
    inflate,
    inflation_cost,
    social_costs,
    static_costs,
    static_window,
    update_obstacles,
)

__all__ = [
    "FREE_SPACE",
    "INSCRIBED",
    "LETHAL",
    "MAX_NON_OBSTACLE",
    "NO_INFORMATION",
    "Costmap",
    "CostmapParams",
    "GlobalCostmap",
    "LocalCostmap",
    "inflate",
    "inflation_cost",
    "pedestrians_from_semantic",
    "social_costs",
    "static_costs",
    "static_window",
    "update_obstacles",
]
