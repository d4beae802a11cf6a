"""The global-planning half of the navigation stack: planning grids, plans, scans and costmaps.

:class:`PathPlanning` is mixed into :class:`~arena.nav.stack.NavigationStack` (it reads the
stack's maps, planners and last scan, declared below): planning on the inflated map (or the
footprint's, in narrow passages, see the stack's module docstring) or on the global costmap,
starting from the nearest free cell when the robot stands in the inflated zone; folding scans
into the costmaps; checking whether the path ahead is blocked. :func:`subdivide` refines coarse
maps before they are inflated.

Blocked path (``replan_on_blocked``): the next ``blocked_lookahead`` m of path are checked every
tick, at most one blocked replan per :data:`BLOCKED_REPLAN_INTERVAL`: a laser return within
``robot_radius`` of the path, or an inscribed/lethal local-costmap cell on it, triggers a replan
with the current scan marked on the planning grid (inflated like the map; in the global
costmap: folded into its obstacle layer). Readings at ``scan_range_max`` count as no return.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from arena.core.errors import PlanningError, StartOccupied
from arena.core.types import Pose2D
from arena.maps.grid import OccupancyGrid
from arena.nav.config import GlobalCostmapConfig
from arena.nav.costmap import INSCRIBED, Costmap, GlobalCostmap, LocalCostmap, update_obstacles
from arena.nav.global_planners import GlobalPlanner, plan_on_costmap, segment_is_free
from arena.nav.intermediate import Pedestrians
from arena.nav.local_planners import LocalObservation
from arena.nav.recovery import mark_points, scan_to_world

BLOCKED_REPLAN_INTERVAL = 0.5
"""s, least time between two replans triggered by a blocked path."""

MAX_PLANNING_CELLS = 16_000_000
"""Most cells :func:`subdivide` makes (4000 × 4000; the search keeps ~10 arrays of that size)."""


def subdivide(grid: OccupancyGrid, max_resolution: float) -> OccupancyGrid:
    """``grid`` with each cell split into ``k × k`` equal cells of at most ``max_resolution`` m.

    The same walls at a finer raster (``grid`` itself when its cells are small enough): a
    distance map measures centre to centre, so on a 0.5 m map an inflation below 0.5 m marks
    no cell and a plan through the cells next to a wall keeps only 0.25 m from it, less than a
    jackal's radius (the robot drove into the wall and stalled). On cells of ``max_resolution``
    the inflation errs by at most half of it. The split stops short of
    :data:`MAX_PLANNING_CELLS` cells (a 1 km map of 0.5 m cells gets 0.25 m ones).
    """
    k = math.ceil(grid.resolution / max_resolution - 1e-9)
    k = min(k, max(int(math.sqrt(MAX_PLANNING_CELLS / grid.data.size)), 1))
    if k <= 1:
        return grid
    data = np.repeat(np.repeat(grid.data, k, axis=0), k, axis=1)
    return OccupancyGrid(data, grid.resolution / k, grid.origin, grid.unknown_is_occupied)


class PathPlanning:
    """Global planning, scans and costmaps of :class:`~arena.nav.stack.NavigationStack`."""

    # the stack's state this part reads and writes (set by NavigationStack)
    global_planner: GlobalPlanner
    grid: OccupancyGrid | None
    inflated: OccupancyGrid | None
    inflated_footprint: OccupancyGrid | None
    robot_radius: float
    footprint_radius: float | None
    inflation_margin: float
    goal: Pose2D
    footprint_plan: bool
    global_costmap: GlobalCostmap | None
    global_costmap_config: GlobalCostmapConfig | None
    local_costmap: LocalCostmap | None
    replan_on_blocked: bool
    blocked_lookahead: float
    scan_range_max: float
    _obs: LocalObservation
    _scan_world: NDArray[np.float64]
    _samples: NDArray[np.float64]
    _sample_s: NDArray[np.float64]
    _time: float
    _retry_after: float
    _last_blocked: float
    _wide_labels: NDArray[np.int32] | None
    _nearest_free: dict[int, NDArray[np.intp]]

    def _sense(
        self, obs: LocalObservation, q: NDArray[np.float64], pedestrians: Pedestrians | None
    ) -> None:
        """Fold this tick's scan into the costmaps and keep its returns (world frame)."""
        ranges = np.asarray(obs.scan_ranges, dtype=np.float64).reshape(-1)
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        self._obs = obs
        self._scan_world = scan_to_world(q, ranges, angles, obs.scan_origin, self.scan_range_max)
        lcm = self.local_costmap
        if lcm is not None:
            peds = pedestrians if pedestrians is not None and len(pedestrians) else None
            lcm.update(
                q,
                scan_ranges=ranges if ranges.size and ranges.shape == angles.shape else None,
                scan_angles=angles, scan_origin=obs.scan_origin, range_max=self.scan_range_max,
                ped_positions=None if peds is None else peds.positions,
                ped_velocities=None if peds is None else peds.velocities,
            )
        gcfg = self.global_costmap_config
        if gcfg is not None and gcfg.use_scan:
            self._fold_scan_into_global()

    def _fold_scan_into_global(self) -> None:
        """Mark and clear the last scan in the global obstacle layer (recomposed when planning)."""
        gcm, obs = self.global_costmap, getattr(self, "_obs", None)
        if gcm is None or obs is None:
            return
        ranges = np.asarray(obs.scan_ranges, dtype=np.float64).reshape(-1)
        angles = np.asarray(obs.scan_angles, dtype=np.float64).reshape(-1)
        if ranges.size == 0 or ranges.shape != angles.shape:
            return
        q = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        c, s = math.cos(q[2]), math.sin(q[2])
        so = np.asarray(obs.scan_origin, dtype=np.float64).reshape(2)
        sensor = q[:2] + np.array([c * so[0] - s * so[1], s * so[0] + c * so[1]])
        p = gcm.params
        update_obstacles(
            gcm.obstacles, sensor, angles + q[2], ranges, obstacle_range=p.obstacle_range,
            raytrace_range=p.raytrace_range, range_max=self.scan_range_max,
        )

    def _path_blocked(self, q: NDArray[np.float64]) -> bool:
        """Whether the next ``blocked_lookahead`` m of path are blocked (rate-limited).

        Blocked: a lethal or inscribed cell of the local costmap on the path, or a laser return
        within ``robot_radius`` of it.
        """
        if (
            not self.replan_on_blocked
            or self._time < self._retry_after
            or self._time - self._last_blocked < BLOCKED_REPLAN_INTERVAL
            or len(self._samples) == 0
        ):
            return False
        i0 = int(np.argmin(np.hypot(*(self._samples - q[:2]).T)))
        s0 = self._sample_s[i0]
        within = (self._sample_s >= s0) & (self._sample_s <= s0 + self.blocked_lookahead)
        ahead = self._samples[within]
        if self.local_costmap is not None:
            costs = self.local_costmap.master.cost_at(ahead, off_map=0)
            if bool(np.any((costs >= INSCRIBED) & (costs != 255))):
                return True
        pts = self._scan_world
        if len(pts) == 0 or len(ahead) == 0:
            return False
        d2 = np.sum((ahead[:, None, :] - pts[None, :, :]) ** 2, axis=-1)
        return bool(np.min(d2) < self.robot_radius**2)

    def _planning_grid(
        self, mark_scan: bool, *, footprint: bool = False
    ) -> tuple[OccupancyGrid, Costmap | None]:
        """The occupancy grid to plan on, and the global costmap's master when configured.

        Without a global costmap: the inflated map (by the footprint radius when ``footprint``),
        with the last scan's returns marked (inflated alike) when ``mark_scan``. With one: its
        lethal/inscribed cells, after folding the last scan into its obstacle layer when
        ``mark_scan`` (every tick already with ``use_scan``).
        """
        assert self.inflated is not None
        gcm, gcfg = self.global_costmap, self.global_costmap_config
        if gcm is not None and gcfg is not None:
            if mark_scan and not gcfg.use_scan:
                self._fold_scan_into_global()
            master = gcm.update()
            return master.to_occupancy(INSCRIBED), master
        grid, radius = self.inflated, self.robot_radius
        if footprint and self.inflated_footprint is not None and self.footprint_radius:
            grid, radius = self.inflated_footprint, self.footprint_radius
        if mark_scan and len(self._scan_world):
            return mark_points(grid, self._scan_world, radius + self.inflation_margin), None
        return grid, None

    def _plan_on(
        self, grid: OccupancyGrid, costmap: Costmap | None, start: Pose2D
    ) -> NDArray[np.float64]:
        gcfg = self.global_costmap_config
        if costmap is not None and gcfg is not None and gcfg.cost_weight > 0:
            return plan_on_costmap(
                costmap, start, self.goal, cost_weight=gcfg.cost_weight, heuristic_weight=1.0,
                smooth=True,
            )
        return self.global_planner.plan(grid, start, self.goal)

    def _plan_from(self, start: Pose2D, *, mark_scan: bool = False) -> NDArray[np.float64]:
        """Plan with the robot radius; where that fails, with the footprint's (narrow passages)."""
        narrow = self.inflated_footprint is not None and self.global_costmap is None
        if not (narrow and self._apart_for_the_circle(start)):
            try:
                path = self._plan_with(start, mark_scan, footprint=False)
            except PlanningError:
                if not narrow:
                    raise
            else:
                self.footprint_plan = False
                return path
        path = self._plan_with(start, mark_scan, footprint=True)
        self.footprint_plan = True
        return path

    def _apart_for_the_circle(self, start: Pose2D) -> bool:
        """Whether start and goal lie in different free regions of :attr:`inflated`.

        Then planning with the robot radius surely fails (a scan marked on the grid only blocks
        more), so a replan in a narrow passage need not search the whole region first. The
        8-connected regions are labelled once per map; a start in the inflated zone is not
        judged (its way out is found by the planning).
        """
        assert self.inflated is not None
        if self._wide_labels is None:
            self._wide_labels = ndimage.label(
                ~self.inflated.occupied, structure=np.ones((3, 3), dtype=bool)
            )[0]
        cells = self.inflated.world_to_cell(np.array([start.xy, self.goal.xy]))
        if not bool(np.all(self.inflated.in_bounds(cells))):
            return False
        a, b = self._wide_labels[cells[:, 0], cells[:, 1]]
        return bool(a > 0 and b > 0 and a != b)

    def _plan_with(
        self, start: Pose2D, mark_scan: bool, *, footprint: bool
    ) -> NDArray[np.float64]:
        assert self.inflated is not None
        assert self.grid is not None
        grid, costmap = self._planning_grid(mark_scan, footprint=footprint)
        try:
            return self._plan_on(grid, costmap, start)
        except StartOccupied:
            free = self._free_cell_near(grid, start)
            if free is None:
                raise
        via = Pose2D(float(free[0]), float(free[1]), start.theta)
        path = self._plan_on(grid, costmap, via)
        return np.vstack([start.xy[None, :], path])

    def _free_cell_near(
        self, grid: OccupancyGrid, start: Pose2D
    ) -> NDArray[np.float64] | None:
        """Centre (m) of ``grid``'s free cell nearest to ``start``, if safely reachable."""
        assert self.grid is not None
        cell = grid.world_to_cell(start.xy)
        blocked = grid.occupied
        if not bool(grid.in_bounds(cell)) or bool(blocked.all()):
            return None
        # The inflated maps (not those with a scan marked) keep their nearest-free-cell table.
        key = 0 if grid is self.inflated else 1 if grid is self.inflated_footprint else -1
        if key in self._nearest_free:
            idx = self._nearest_free[key]
        else:
            # One EDT with indices gives every cell's nearest free cell; computed on first need.
            _, idx = ndimage.distance_transform_edt(blocked, return_indices=True)
            if key >= 0:
                self._nearest_free[key] = idx
        r, c = int(cell[0]), int(cell[1])
        free_cell = idx[:, r, c]
        centre = grid.cell_to_world(free_cell)
        if not segment_is_free(self.grid, start.xy, centre):
            return None
        return centre
