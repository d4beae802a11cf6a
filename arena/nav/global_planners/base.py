"""The global-planner interface, its registry and helpers shared by grid planners.

A global planner turns a map, a start and a goal into a collision-free polyline of world
waypoints. It plans on the grid it is given: the caller (normally
:class:`arena.nav.stack.NavigationStack`) has already inflated that grid by the robot radius plus a
margin, so a planner treats the robot as a point and every occupied cell as forbidden.

Failures are typed, never ``None``: :class:`~arena.core.errors.StartOccupied`,
:class:`~arena.core.errors.GoalOccupied` (off-map counts as occupied) and
:class:`~arena.core.errors.NoPathFound`.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import GoalOccupied, StartOccupied
from arena.core.registry import Registry
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid


@runtime_checkable
class GlobalPlanner(Protocol):
    """Plans a path through free cells of an (already inflated) occupancy grid."""

    def plan(self, grid: OccupancyGrid, start: Pose2D, goal: Pose2D) -> NDArray[np.float64]:
        """Plan from ``start`` to ``goal``.

        Args:
            grid: the map, already inflated by the robot radius (occupied cells are forbidden).
            start: start pose (m, rad); only its position is used by grid planners.
            goal: goal pose (m, rad); only its position is used by grid planners.

        Returns:
            ``(k, 2)`` world waypoints (m), ``k ≥ 2``: the first is the start position, the last
            the goal position, consecutive points joined by collision-free straight segments.

        Raises:
            StartOccupied: the start lies in an occupied cell or off the map.
            GoalOccupied: the goal lies in an occupied cell or off the map.
            NoPathFound: start and goal are not connected through free cells.
        """
        ...


GLOBAL_PLANNERS: Registry[GlobalPlanner] = Registry(
    "global planner",
    entry_points="arena.global_planners",
    # name -> the module registering it, imported when first named: ArtPlanner's learned motion
    # cost lives above ``nav`` (arena.learn.planners), which ``nav`` never imports
    builtins={"artplanner": "arena.learn.planners.artplanner"},
)


def endpoint_cells(
    grid: OccupancyGrid, start: Pose2D, goal: Pose2D
) -> tuple[tuple[int, int], tuple[int, int]]:
    """Check that start and goal lie in free cells and return their ``(row, col)`` cells.

    Args:
        grid: the (inflated) map.
        start: start pose (m).
        goal: goal pose (m).

    Returns:
        ``((start_row, start_col), (goal_row, goal_col))``.

    Raises:
        StartOccupied: start off the map or in a blocking cell.
        GoalOccupied: goal off the map or in a blocking cell.
    """
    cells = []
    for pose, err, what in ((start, StartOccupied, "start"), (goal, GoalOccupied, "goal")):
        if not (np.isfinite(pose.x) and np.isfinite(pose.y)):
            raise err(f"the {what} position ({pose.x}, {pose.y}) is not finite")
        cell = grid.world_to_cell((pose.x, pose.y))
        r, c = int(cell[0]), int(cell[1])
        if not bool(grid.in_bounds(cell)):
            xmin, ymin, xmax, ymax = grid.bounds
            raise err(
                f"the {what} ({pose.x:.3f}, {pose.y:.3f}) m lies off the map "
                f"[{xmin:.2f}, {xmax:.2f}] x [{ymin:.2f}, {ymax:.2f}] m"
            )
        if grid.occupied[r, c]:
            raise err(
                f"the {what} ({pose.x:.3f}, {pose.y:.3f}) m lies in occupied cell "
                f"(row {r}, col {c}) of the inflated map"
            )
        cells.append((r, c))
    return cells[0], cells[1]
