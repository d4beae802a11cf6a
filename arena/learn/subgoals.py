"""Global paths and subgoals of the robots of one world (Arena's "spacial horizon").

Used by the learning environments (:class:`~arena.learn.driver.EpisodeDriver`, the batched
env) to give the policy a goal on the path ``horizon`` m ahead instead of the final goal.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from arena.core.errors import PlanningError, StartOccupied
from arena.core.types import Pose2D
from arena.learn.config import SubgoalObsConfig
from arena.learn.paths import project_on_path, subgoal_on_path
from arena.nav.global_planners.astar import AStarPlanner

FloatArray = NDArray[np.float64]


class SubgoalTracker:
    """Global paths and subgoals of ``r`` robots (Arena's "spacial horizon", arena_specs §8.1).

    At :meth:`reset` the planning grid is inflated by ``inscribed`` m (robot radius +
    ``navigation.inflation_margin``, as the navigation stack does) and an A* path planned per
    robot; :meth:`update` replans every ``replan_period`` s and whenever a robot is more than
    ``max_deviation`` m from its path, then moves each subgoal to
    :func:`~arena.learn.paths.subgoal_on_path`. A robot whose start lies in the
    inflated zone plans from the nearest free cell (its position prepended); when no path exists
    the straight segment to the goal stands in, so an episode never fails for want of a plan.
    """

    def __init__(self, cfg: SubgoalObsConfig, inscribed: float, n_robots: int) -> None:
        self.cfg = cfg
        self.inscribed = float(inscribed)
        self.planner = AStarPlanner()
        self.paths: list[FloatArray] = [np.zeros((1, 2))] * n_robots
        self.current = np.zeros((n_robots, 2))
        self.plan_time = np.zeros(n_robots)
        self.grid: Any = None
        self._nearest: Any = None

    def reset(self, grid: Any, poses: FloatArray, goals: FloatArray, time: float) -> None:
        """Inflate ``grid`` and plan from each pose to its goal."""
        self.grid = grid
        self.inflated = grid.inflate(self.inscribed)
        self._nearest = None
        for i in range(poses.shape[0]):
            self._replan(i, poses[i], goals[i], time)
        self._subgoals(poses, goals)

    def update(self, poses: FloatArray, goals: FloatArray, time: float) -> None:
        """Replan where due or strayed; move the subgoals."""
        for i in range(poses.shape[0]):
            due = time - self.plan_time[i] >= self.cfg.replan_period - 1e-9
            if due or project_on_path(self.paths[i], poses[i, :2])[1] > self.cfg.max_deviation:
                self._replan(i, poses[i], goals[i], time)
        self._subgoals(poses, goals)

    def restart(self, i: int, pose: FloatArray, goal: FloatArray, time: float) -> None:
        """Plan robot ``i`` afresh (a new start or goal) and place its subgoal."""
        self._replan(i, pose, goal, time)
        self.current[i] = subgoal_on_path(self.paths[i], pose[:2], self.cfg.horizon)

    def _subgoals(self, poses: FloatArray, goals: FloatArray) -> None:
        for i in range(poses.shape[0]):
            self.current[i] = subgoal_on_path(self.paths[i], poses[i, :2], self.cfg.horizon)

    def _replan(self, i: int, pose: FloatArray, goal: FloatArray, time: float) -> None:
        self.plan_time[i] = time
        start = Pose2D(float(pose[0]), float(pose[1]), float(pose[2]))
        end = Pose2D(float(goal[0]), float(goal[1]), 0.0)
        path: FloatArray | None
        try:
            path = self.planner.plan(self.inflated, start, end)
        except StartOccupied:
            path = self._plan_via_free_cell(start, end)
        except PlanningError:
            path = None
        if path is None:
            path = np.array([pose[:2], goal[:2]], dtype=np.float64)
        self.paths[i] = np.asarray(path, dtype=np.float64)

    def _plan_via_free_cell(self, start: Pose2D, end: Pose2D) -> FloatArray | None:
        grid = self.inflated
        cell = grid.world_to_cell(start.xy)
        if not bool(grid.in_bounds(cell)) or bool(grid.occupied.all()):
            return None
        if self._nearest is None:
            self._nearest = ndimage.distance_transform_edt(grid.occupied, return_indices=True)[1]
        free = grid.cell_to_world(self._nearest[:, int(cell[0]), int(cell[1])])
        try:
            path = self.planner.plan(grid, Pose2D(float(free[0]), float(free[1]), 0.0), end)
        except PlanningError:
            return None
        return np.vstack([start.xy[None, :], path])
