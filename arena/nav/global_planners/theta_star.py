"""Theta*: any-angle search on the occupancy grid (numba), Nash et al. (AAAI 2007).

Theta* is A* over the 8-connected grid of cell centres in which a node may take as parent any
node it sees, not only a grid neighbour: when a node ``u`` relaxes its neighbour ``v`` and
``parent(u)`` has line of sight to ``v``, ``v`` is attached to ``parent(u)`` at cost
``g(parent(u)) + |parent(u) v|``; otherwise to ``u`` at ``g(u) + |u v|``. Paths therefore bend only
at obstacle corners and follow true straight lines elsewhere.

Line of sight is the Amanatides–Woo cell traversal of :mod:`arena.nav.global_planners.astar`:
every touched cell must be free, and a segment through an exact cell corner needs both side cells
free, so paths never squeeze between diagonally touching obstacles. Grid steps follow the same
no-corner-cutting rule as A*. The start and goal nodes sit at the exact start and goal positions
(every other node at its cell centre), so every returned segment is line-of-sight free.

Because the parent through line of sight is never costlier than the grid step (triangle
inequality) and the Euclidean heuristic is consistent, the returned path is never longer than the
shortest 8-connected grid path between the same points.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from arena.core.errors import NoPathFound
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.global_planners.astar import _line_cost, _pop_min, _sift_up
from arena.nav.global_planners.base import GLOBAL_PLANNERS, endpoint_cells

_SQRT2 = math.sqrt(2.0)
_DR = np.array([1, -1, 0, 0, 1, 1, -1, -1], dtype=np.int64)
_DC = np.array([0, 0, 1, -1, 1, -1, 1, -1], dtype=np.int64)


@njit(cache=True)
def _node_xy(
    node: int, w_cols: int, start: int, goal: int, sx: float, sy: float, gx: float, gy: float
) -> tuple[float, float]:
    if node == start:
        return sx, sy
    if node == goal:
        return gx, gy
    r = node // w_cols
    return node - r * w_cols + 0.5, r + 0.5


@njit(cache=True)
def _theta_star_cells(
    blocked: NDArray[Any],
    start_r: int,
    start_c: int,
    goal_r: int,
    goal_c: int,
    sx: float,
    sy: float,
    gx: float,
    gy: float,
) -> tuple[NDArray[Any], float]:
    """Theta* in cell units (x along columns); return ``((k, 2) [x, y] points, cost cells)``.

    ``k = 0`` when the goal is unreachable.
    """
    h_rows, w_cols = blocked.shape
    n = h_rows * w_cols
    g = np.full(n, np.inf)
    parent = np.full(n, -1, dtype=np.int32)
    pos = np.full(n, -1, dtype=np.int32)
    heap = np.empty(n, dtype=np.int32)
    hf = np.empty(n)
    hg = np.empty(n)
    no_penalty = np.zeros((1, 1))
    start = start_r * w_cols + start_c
    goal = goal_r * w_cols + goal_c
    g[start] = 0.0
    parent[start] = start
    heap[0] = start
    hf[0] = math.hypot(gx - sx, gy - sy)
    hg[0] = 0.0
    pos[start] = 0
    size = 1
    found = False
    while size > 0:
        u = heap[0]
        size = _pop_min(heap, hf, hg, pos, size)
        if u == goal:
            found = True
            break
        ur = u // w_cols
        uc = u - ur * w_cols
        ux, uy = _node_xy(u, w_cols, start, goal, sx, sy, gx, gy)
        pu = parent[u]
        px, py = _node_xy(pu, w_cols, start, goal, sx, sy, gx, gy)
        for k in range(8):
            vr = ur + _DR[k]
            vc = uc + _DC[k]
            if vr < 0 or vr >= h_rows or vc < 0 or vc >= w_cols or blocked[vr, vc]:
                continue
            if k >= 4 and (blocked[ur, vc] or blocked[vr, uc]):
                continue
            v = vr * w_cols + vc
            pv = pos[v]
            if pv == -2:
                continue
            vx, vy = _node_xy(v, w_cols, start, goal, sx, sy, gx, gy)
            if pu != u and np.isfinite(_line_cost(blocked, no_penalty, False, px, py, vx, vy)):
                cand = g[pu] + math.hypot(vx - px, vy - py)
                par = pu
            else:
                cand = g[u] + math.hypot(vx - ux, vy - uy)
                par = u
            if cand < g[v]:
                g[v] = cand
                parent[v] = par
                if pv == -1:
                    pv = size
                    heap[pv] = v
                    pos[v] = pv
                    size += 1
                hf[pv] = cand + math.hypot(gx - vx, gy - vy)
                hg[pv] = cand
                _sift_up(heap, hf, hg, pos, pv)
    if not found:
        return np.empty((0, 2)), np.inf
    k = 1
    v = goal
    while v != start:
        v = parent[v]
        k += 1
    pts = np.empty((k, 2))
    v = goal
    for i in range(k - 1, -1, -1):
        x, y = _node_xy(v, w_cols, start, goal, sx, sy, gx, gy)
        pts[i, 0] = x
        pts[i, 1] = y
        v = parent[v]
    return pts, g[goal]


@GLOBAL_PLANNERS.register("theta_star", tags=("grid", "any_angle"))
class ThetaStarPlanner:
    """Theta* any-angle planner (numba): straight segments with line of sight on the grid.

    Plans on the already-inflated grid it is given; no parameters. See the module docstring.

    Args:
        params: validated :class:`ThetaStarPlanner.Params` (currently empty).
    """

    class Params(BaseModel):
        """Parameters of :class:`ThetaStarPlanner` (none yet)."""

        model_config = ConfigDict(frozen=True, extra="forbid")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params if params is not None else self.Params()

    def plan(self, grid: OccupancyGrid, start: Pose2D, goal: Pose2D) -> NDArray[np.float64]:
        """Plan from ``start`` to ``goal`` on the inflated ``grid``.

        Returns:
            ``(k, 2)`` world waypoints (m), ``k ≥ 2``, from the start to the goal position,
            consecutive waypoints in line of sight.

        Raises:
            StartOccupied: start off the map or in an occupied cell.
            GoalOccupied: goal off the map or in an occupied cell.
            NoPathFound: no free 8-connected route links the two cells.
        """
        (sr, sc), (gr, gc) = endpoint_cells(grid, start, goal)
        origin = np.asarray(grid.origin)
        s = (start.xy - origin) / grid.resolution
        t = (goal.xy - origin) / grid.resolution
        if (sr, sc) == (gr, gc):
            pts = np.stack([s, t])
        else:
            pts, _cost = _theta_star_cells(
                grid.occupied, sr, sc, gr, gc, float(s[0]), float(s[1]), float(t[0]), float(t[1])
            )
            if len(pts) == 0:
                raise NoPathFound(
                    f"no path from ({start.x:.3f}, {start.y:.3f}) m to "
                    f"({goal.x:.3f}, {goal.y:.3f}) m: the goal is not connected to the start "
                    f"through free cells of the inflated map"
                )
        out: NDArray[np.float64] = pts * grid.resolution + origin
        return out
