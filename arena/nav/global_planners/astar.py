"""A* on the occupancy grid, compiled with numba.

The search runs over the 4- or 8-connected grid of cell centres with an indexed binary heap
(decrease-key, so memory stays ``O(cells)`` rather than ``O(edges)``). Diagonal moves may not cut
corners: a diagonal step needs both orthogonal neighbours free, so the path never squeezes between
two cells that touch only at a corner.

Edge cost (m) of a step of length ``ℓ`` between cells ``u`` and ``v``::

    ℓ · (1 + clearance_weight · (p(u) + p(v)) / 2),    p(c) = exp(-distance(c) / clearance_scale)

where ``distance`` is the inflated grid's distance map, i.e. the distance to the inflated
boundary. The penalty is charged per metre travelled (not per cell) so the cost does not depend on
the map resolution, and it is symmetric so a path and its reverse cost the same. The heuristic is
the octile (8-connected) or Manhattan (4-connected) distance times ``heuristic_weight``; as every
edge costs at least its length it is consistent, so ``heuristic_weight = 1`` returns a path of the
same cost as Dijkstra's.

Optional smoothing removes waypoints by line-of-sight shortcutting: from each kept waypoint the
path jumps to the farthest following waypoint reachable by a straight segment whose every touched
cell (Amanatides–Woo traversal, both cells at an exact corner crossing) is free *and* whose cost
under the same per-metre clearance cost is no higher than the section it replaces. Plain
line-of-sight smoothing would pull every corner tight against the inflated walls and undo the
clearance cost; this way smoothing never makes the path costlier, and with the clearance cost off
it is ordinary any-free-chord shortcutting.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import NoPathFound
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.global_planners.base import GLOBAL_PLANNERS, endpoint_cells

_SQRT2 = math.sqrt(2.0)
# Neighbour offsets: the first four are orthogonal, the last four diagonal.
_DR = np.array([1, -1, 0, 0, 1, 1, -1, -1], dtype=np.int64)
_DC = np.array([0, 0, 1, -1, 1, -1, 1, -1], dtype=np.int64)


# -- indexed binary heap --------------------------------------------------------------------------
# The keys (f, g) live in arrays parallel to the heap, not indexed by node: sifting then reads
# neighbouring memory instead of jumping across million-cell arrays (about 2x faster on big maps).
@njit(cache=True)
def _sift_up(heap: NDArray, hf: NDArray, hg: NDArray, pos: NDArray, i: int) -> None:
    # Hole-based: carry the moving entry in registers, shift parents down into the hole.
    node, f, g = heap[i], hf[i], hg[i]
    while i > 0:
        parent = (i - 1) >> 1
        pf = hf[parent]
        # Ties on f go to the larger g (nearer the goal): far fewer expansions on open maps.
        if not (f < pf or (f == pf and g > hg[parent])):
            break
        heap[i], hf[i], hg[i] = heap[parent], pf, hg[parent]
        pos[heap[i]] = i
        i = parent
    heap[i], hf[i], hg[i] = node, f, g
    pos[node] = i


@njit(cache=True)
def _pop_min(heap: NDArray, hf: NDArray, hg: NDArray, pos: NDArray, size: int) -> int:
    """Remove the heap's root (the caller read it first), mark it closed; return the new size."""
    u = heap[0]
    size -= 1
    if size > 0:
        heap[0] = heap[size]
        hf[0] = hf[size]
        hg[0] = hg[size]
        pos[heap[0]] = 0
        _sift_down(heap, hf, hg, pos, 0, size)
    pos[u] = -2
    return size


@njit(cache=True)
def _sift_down(heap: NDArray, hf: NDArray, hg: NDArray, pos: NDArray, i: int, n: int) -> None:
    node, f, g = heap[i], hf[i], hg[i]
    while True:
        child = 2 * i + 1
        if child >= n:
            break
        right = child + 1
        if right < n and (
            hf[right] < hf[child] or (hf[right] == hf[child] and hg[right] > hg[child])
        ):
            child = right
        cf = hf[child]
        if not (cf < f or (cf == f and hg[child] > g)):
            break
        heap[i], hf[i], hg[i] = heap[child], cf, hg[child]
        pos[heap[i]] = i
        i = child
    heap[i], hf[i], hg[i] = node, f, g
    pos[node] = i


# -- search ---------------------------------------------------------------------------------------
@njit(cache=True)
def _heuristic(r: int, c: int, goal_r: int, goal_c: int, diagonal: bool, scale: float) -> float:
    dr = abs(r - goal_r)
    dc = abs(c - goal_c)
    if diagonal:
        lo = min(dr, dc)
        return scale * ((max(dr, dc) - lo) + _SQRT2 * lo)  # octile distance
    return scale * (dr + dc)


@njit(cache=True)
def _astar_cells(
    blocked: NDArray,
    penalty: NDArray,
    start_r: int,
    start_c: int,
    goal_r: int,
    goal_c: int,
    diagonal: bool,
    heuristic_weight: float,
    use_clearance: bool,
    resolution: float,
) -> tuple[NDArray, float]:
    """Search the grid; return ``((k, 2) [row, col] cells start→goal, cost m)``, k = 0 if none."""
    h_rows, w_cols = blocked.shape
    n = h_rows * w_cols
    g = np.full(n, np.inf)
    parent = np.full(n, -1, dtype=np.int32)
    pos = np.full(n, -1, dtype=np.int32)  # index in the heap; -1 never pushed, -2 closed
    heap = np.empty(n, dtype=np.int32)
    hf = np.empty(n)
    hg = np.empty(n)
    n_moves = 8 if diagonal else 4

    start = start_r * w_cols + start_c
    goal = goal_r * w_cols + goal_c
    g[start] = 0.0
    h_scale = heuristic_weight * resolution
    heap[0] = start
    hf[0] = _heuristic(start_r, start_c, goal_r, goal_c, diagonal, h_scale)
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
        gu = g[u]
        pen_u = penalty[ur, uc] if use_clearance else 0.0
        for k in range(n_moves):
            vr = ur + _DR[k]
            vc = uc + _DC[k]
            if vr < 0 or vr >= h_rows or vc < 0 or vc >= w_cols or blocked[vr, vc]:
                continue
            step = resolution
            if k >= 4:
                # No corner cutting: both orthogonal cells of the diagonal step must be free.
                if blocked[ur, vc] or blocked[vr, uc]:
                    continue
                step = _SQRT2 * resolution
            v = vr * w_cols + vc
            pv = pos[v]
            if pv == -2:
                continue
            cost = step
            if use_clearance:
                cost = step * (1.0 + 0.5 * (pen_u + penalty[vr, vc]))
            gv = gu + cost
            if gv < g[v]:
                g[v] = gv
                parent[v] = u
                if pv == -1:
                    pv = size
                    heap[pv] = v
                    pos[v] = pv
                    size += 1
                hf[pv] = gv + _heuristic(vr, vc, goal_r, goal_c, diagonal, h_scale)
                hg[pv] = gv
                _sift_up(heap, hf, hg, pos, pv)

    if not found:
        return np.empty((0, 2), dtype=np.int64), np.inf
    k = 1
    v = goal
    while v != start:
        v = parent[v]
        k += 1
    cells = np.empty((k, 2), dtype=np.int64)
    v = np.int64(goal)
    for i in range(k - 1, -1, -1):
        cells[i, 0] = v // w_cols
        cells[i, 1] = v - (v // w_cols) * w_cols
        v = parent[v]
    return cells, g[goal]


# -- line of sight --------------------------------------------------------------------------------
@njit(cache=True)
def _cell_blocked(blocked: NDArray, r: int, c: int) -> bool:
    h_rows, w_cols = blocked.shape
    return r < 0 or r >= h_rows or c < 0 or c >= w_cols or blocked[r, c]


@njit(cache=True)
def _line_cost(
    blocked: NDArray, penalty: NDArray, use_clearance: bool,
    x0: float, y0: float, x1: float, y1: float,
) -> float:
    """Cost of the segment ``(x0, y0)→(x1, y1)`` in cell units (x along columns); inf if blocked.

    The cost is the length inside each touched cell times ``1 + penalty`` of that cell — the same
    per-metre cost the search charges. Every touched cell must be free; an exact corner crossing
    touches both side cells, so both must be free (conservative).
    """
    c = math.floor(x0)
    r = math.floor(y0)
    c_end = math.floor(x1)
    r_end = math.floor(y1)
    if _cell_blocked(blocked, r, c):
        return np.inf
    dx = x1 - x0
    dy = y1 - y0
    length = math.sqrt(dx * dx + dy * dy)
    step_c = 1 if dx > 0 else -1
    step_r = 1 if dy > 0 else -1
    t_delta_x = abs(1.0 / dx) if dx != 0.0 else np.inf
    t_delta_y = abs(1.0 / dy) if dy != 0.0 else np.inf
    if dx > 0:
        t_max_x = (c + 1 - x0) / dx
    elif dx < 0:
        t_max_x = (x0 - c) / -dx
    else:
        t_max_x = np.inf
    if dy > 0:
        t_max_y = (r + 1 - y0) / dy
    elif dy < 0:
        t_max_y = (y0 - r) / -dy
    else:
        t_max_y = np.inf
    cost = 0.0
    t_prev = 0.0
    # Bounded by the number of cell boundaries crossed; the guard stops float drift looping.
    n_steps = abs(c_end - c) + abs(r_end - r)
    for _ in range(n_steps + 2):
        t_next = min(t_max_x, t_max_y)
        if (r == r_end and c == c_end) or t_next > 1.0:
            t_next = 1.0
        weight = 1.0 + penalty[r, c] if use_clearance else 1.0
        cost += (t_next - t_prev) * length * weight
        if t_next >= 1.0:
            return cost
        t_prev = t_next
        if abs(t_max_x - t_max_y) < 1e-9:
            # Through a corner: the segment grazes both side cells; demand both free.
            if _cell_blocked(blocked, r, c + step_c) or _cell_blocked(blocked, r + step_r, c):
                return np.inf
            c += step_c
            r += step_r
            t_max_x += t_delta_x
            t_max_y += t_delta_y
        elif t_max_x < t_max_y:
            c += step_c
            t_max_x += t_delta_x
        else:
            r += step_r
            t_max_y += t_delta_y
        if _cell_blocked(blocked, r, c):
            return np.inf
    return cost


@njit(cache=True)
def _shortcut(blocked: NDArray, penalty: NDArray, use_clearance: bool, pts: NDArray) -> NDArray:
    """Greedy cost-aware shortcutting of ``(k, 2)`` points (cell units); returns kept indices.

    From each kept point the path jumps to the farthest following point whose straight segment
    is free and costs no more than the path section it replaces (with the clearance cost off,
    any free segment qualifies: a chord is never longer than the arc).
    """
    k = pts.shape[0]
    prefix = np.zeros(k)
    for i in range(1, k):
        prefix[i] = prefix[i - 1] + _line_cost(
            blocked, penalty, use_clearance, pts[i - 1, 0], pts[i - 1, 1], pts[i, 0], pts[i, 1]
        )
    keep = np.empty(k, dtype=np.int64)
    n_keep = 1
    keep[0] = 0
    i = 0
    while i < k - 1:
        best = i + 1  # neighbouring path cells are always mutually visible (no corner cutting)
        for j in range(i + 2, k):
            direct = _line_cost(
                blocked, penalty, use_clearance, pts[i, 0], pts[i, 1], pts[j, 0], pts[j, 1]
            )
            if direct <= (prefix[j] - prefix[i]) * (1.0 + 1e-9) + 1e-12:
                best = j
            else:
                break
        keep[n_keep] = best
        n_keep += 1
        i = best
    return keep[:n_keep].copy()


def segment_is_free(grid: OccupancyGrid, a: ArrayLike, b: ArrayLike) -> bool:
    """Whether the straight world segment ``a→b`` (each ``(2,)``, m) touches only free cells.

    Off-map cells count as blocked; a segment through an exact cell corner must have both side
    cells free.
    """
    pa = (np.asarray(a, dtype=np.float64) - grid.origin) / grid.resolution
    pb = (np.asarray(b, dtype=np.float64) - grid.origin) / grid.resolution
    cost = _line_cost(
        grid.occupied, np.zeros((1, 1)), False, float(pa[0]), float(pa[1]), float(pb[0]),
        float(pb[1]),
    )
    return bool(np.isfinite(cost))


# -- the planner ----------------------------------------------------------------------------------


def grid_search(
    grid: OccupancyGrid,
    start: Pose2D,
    goal: Pose2D,
    *,
    diagonal: bool = True,
    heuristic_weight: float = 1.0,
    clearance_weight: float = 1.0,
    clearance_scale: float = 0.3,
    smooth: bool = True,
) -> NDArray[np.float64]:
    """A* (``heuristic_weight ≥ 1``) or Dijkstra (``0``) on an inflated grid, then smoothing.

    Shared by :class:`AStarPlanner` and the Dijkstra planner; see their ``Params`` for the
    arguments and ``plan`` for the returned path and the typed failures.
    """
    (sr, sc), (gr, gc) = endpoint_cells(grid, start, goal)
    blocked = grid.occupied
    use_clearance = clearance_weight > 0
    # The distance map costs an EDT; only pay for it when the clearance cost is on. One
    # vectorised exp per cell is cheaper than one per edge relaxation inside the search.
    if use_clearance:
        penalty = clearance_weight * np.exp(-grid.distance / clearance_scale)
    else:
        penalty = np.zeros((1, 1))
    cells, _cost = _astar_cells(
        blocked, penalty, sr, sc, gr, gc, diagonal, heuristic_weight, use_clearance,
        grid.resolution,
    )
    if len(cells) == 0:
        raise NoPathFound(
            f"no path from ({start.x:.3f}, {start.y:.3f}) m to ({goal.x:.3f}, {goal.y:.3f}) m: "
            f"the goal is not connected to the start through free cells of the inflated map"
        )
    # Continuous cell coordinates [x, y] (x along columns): exact endpoints, centres between.
    # Start and goal in one cell still give two points.
    pts = np.empty((max(len(cells), 2), 2))
    pts[1:-1, 0] = cells[1:-1, 1] + 0.5
    pts[1:-1, 1] = cells[1:-1, 0] + 0.5
    origin = np.asarray(grid.origin)
    pts[0] = (start.xy - origin) / grid.resolution
    pts[-1] = (goal.xy - origin) / grid.resolution
    if smooth and len(pts) > 2:
        pts = pts[_shortcut(blocked, penalty, use_clearance, pts)]
    return pts * grid.resolution + np.asarray(grid.origin)


@GLOBAL_PLANNERS.register("astar", tags=("default", "grid"))
class AStarPlanner:
    """A* over the occupancy grid (numba), with a clearance cost and line-of-sight smoothing.

    Plans on the already-inflated grid it is given; see the module docstring for the edge cost
    and the smoothing rule. A 1000 × 1000 grid plans in well under a second.

    Args:
        params: validated :class:`AStarPlanner.Params`.
    """

    class Params(BaseModel):
        """Parameters of :class:`AStarPlanner`."""

        model_config = ConfigDict(frozen=True, extra="forbid")

        diagonal: bool = Field(True, description="8-connected search (else 4-connected)")
        heuristic_weight: float = Field(
            1.0, ge=1.0, description="weighted A*: > 1 expands fewer cells, path ≤ w × optimal"
        )
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

        Args:
            grid: the map, already inflated by the robot radius.
            start: start pose (m); heading ignored.
            goal: goal pose (m); heading ignored.

        Returns:
            ``(k, 2)`` world waypoints (m), ``k ≥ 2``, from the start position to the goal position.

        Raises:
            StartOccupied: start off the map or in an occupied cell.
            GoalOccupied: goal off the map or in an occupied cell.
            NoPathFound: no free 4/8-connected route links the two cells.
        """
        p = self.params
        return grid_search(
            grid, start, goal, diagonal=p.diagonal, heuristic_weight=p.heuristic_weight,
            clearance_weight=p.clearance_weight, clearance_scale=p.clearance_scale,
            smooth=p.smooth,
        )
