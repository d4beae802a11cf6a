"""Dijkstra's algorithm on the occupancy grid (numba): ``navfn``'s classic global planner.

It is the A* search of :mod:`arena.nav.global_planners.astar` with a zero heuristic, so it shares
that module's edge cost (length times the optional clearance penalty), the no-corner-cutting rule,
the indexed binary heap and the cost-aware line-of-sight smoothing. It expands every cell closer
than the goal, which makes it slower than A* but a useful independent optimum and the planner ROS
``navfn`` users know.

:func:`plan_on_costmap` runs the same search on a :class:`~arena.nav.costmap.Costmap` instead of an
occupancy grid, ``navfn``-style: cells of cost ``≥ lethal_threshold`` are forbidden and every
other cell ``c`` charges ``cost_weight · cost(c) / 252`` extra per metre.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import NoPathFound
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.costmap.layers import INSCRIBED, MAX_NON_OBSTACLE, NO_INFORMATION, Costmap
from arena.nav.global_planners.astar import _astar_cells, _shortcut, grid_search
from arena.nav.global_planners.base import GLOBAL_PLANNERS, endpoint_cells


@GLOBAL_PLANNERS.register("dijkstra", tags=("grid",))
class DijkstraPlanner:
    """Dijkstra over the occupancy grid (numba), with a clearance cost and smoothing.

    Args:
        params: validated :class:`DijkstraPlanner.Params`.
    """

    class Params(BaseModel):
        """Parameters of :class:`DijkstraPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        diagonal: bool = Field(True, description="8-connected search (else 4-connected)")
        clearance_weight: float = Field(
            1.0, ge=0.0,
            description="extra cost per metre next to obstacles (× exp(-d/scale)); 0 disables",
        )
        clearance_scale: float = Field(
            0.3, gt=0.0, description="m, decay length of the clearance cost"
        )
        smooth: bool = Field(True, description="line-of-sight shortcutting of the cell path")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def plan(self, grid: OccupancyGrid, start: Pose2D, goal: Pose2D) -> NDArray[np.float64]:
        """Plan from ``start`` to ``goal`` on the inflated ``grid``.

        Returns:
            ``(k, 2)`` world waypoints (m), ``k ≥ 2``, from the start to the goal position.

        Raises:
            StartOccupied: start off the map or in an occupied cell.
            GoalOccupied: goal off the map or in an occupied cell.
            NoPathFound: no free 4/8-connected route links the two cells.
        """
        p = self.params
        return grid_search(
            grid, start, goal, diagonal=p.diagonal, heuristic_weight=0.0,
            clearance_weight=p.clearance_weight, clearance_scale=p.clearance_scale,
            smooth=p.smooth,
        )


def plan_on_costmap(
    costmap: Costmap,
    start: Pose2D,
    goal: Pose2D,
    *,
    cost_weight: float = 3.0,
    lethal_threshold: int = INSCRIBED,
    unknown_is_occupied: bool = False,
    heuristic_weight: float = 0.0,
    diagonal: bool = True,
    smooth: bool = False,
) -> NDArray[np.float64]:
    """Cost-aware grid search on a costmap (Dijkstra, or A* with ``heuristic_weight ≥ 1``).

    Edge cost (m) of a step of length ``ℓ`` between cells ``u`` and ``v``:
    ``ℓ · (1 + (p(u) + p(v)) / 2)`` with ``p(c) = cost_weight · cost(c) / 252`` (unknown cells
    count as 252 when traversable). The octile heuristic stays consistent since every edge costs
    at least its length. Smoothing, if asked, only takes shortcuts that cost no more.

    Args:
        costmap: the costmap (e.g. :attr:`GlobalCostmap.master`).
        start: start pose (m).
        goal: goal pose (m).
        cost_weight: extra cost per metre at cost 252 (dimensionless); 0 plans shortest paths.
        lethal_threshold: cells of at least this cost are forbidden (253: the inscribed zone).
        unknown_is_occupied: whether unknown (255) cells are forbidden.
        heuristic_weight: 0 for Dijkstra, 1 for A* (same cost), > 1 weighted A*.
        diagonal: 8-connected search (else 4-connected).
        smooth: cost-aware line-of-sight shortcutting.

    Returns:
        ``(k, 2)`` world waypoints (m), ``k ≥ 2``.

    Raises:
        StartOccupied: start off the costmap or in a forbidden cell.
        GoalOccupied: goal off the costmap or in a forbidden cell.
        NoPathFound: start and goal are not connected.
        ValueError: a negative ``cost_weight`` or ``heuristic_weight`` in (0, 1).
    """
    if cost_weight < 0 or (0 < heuristic_weight < 1):
        raise ValueError(
            f"cost_weight must be >= 0 and heuristic_weight 0 or >= 1, got {cost_weight}, "
            f"{heuristic_weight}"
        )
    grid = costmap.to_occupancy(lethal_threshold, unknown_is_occupied=unknown_is_occupied)
    (sr, sc), (gr, gc) = endpoint_cells(grid, start, goal)
    costs = costmap.costs.astype(np.float64)
    costs[costmap.costs == NO_INFORMATION] = MAX_NON_OBSTACLE
    penalty = cost_weight * np.minimum(costs, MAX_NON_OBSTACLE) / MAX_NON_OBSTACLE
    blocked = grid.occupied
    use_cost = cost_weight > 0
    cells, _cost = _astar_cells(
        blocked, penalty, sr, sc, gr, gc, diagonal, heuristic_weight, use_cost, grid.resolution
    )
    if len(cells) == 0:
        raise NoPathFound(
            f"no path from ({start.x:.3f}, {start.y:.3f}) m to ({goal.x:.3f}, {goal.y:.3f}) m "
            f"through costmap cells below {lethal_threshold}"
        )
    pts = np.empty((max(len(cells), 2), 2))
    pts[1:-1, 0] = cells[1:-1, 1] + 0.5
    pts[1:-1, 1] = cells[1:-1, 0] + 0.5
    origin = np.asarray(grid.origin)
    pts[0] = (start.xy - origin) / grid.resolution
    pts[-1] = (goal.xy - origin) / grid.resolution
    if smooth and len(pts) > 2:
        pts = pts[_shortcut(blocked, penalty, use_cost, pts)]
    out: NDArray[np.float64] = pts * grid.resolution + origin
    return out
