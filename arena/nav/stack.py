"""The navigation pipeline: a global planner feeding a local planner.

Data flow per episode: :meth:`NavigationStack.reset` inflates the static map once by
``robot_radius + inflation_margin`` and plans a global path; every control tick
:meth:`NavigationStack.step` checks the goal, replans when due, and asks the local planner for a
body-frame command. An intermediate planner (:mod:`arena.nav.intermediate`) sits between the two:
every ``intermediate_period`` seconds it sees the global path and the pedestrians (passed to
:meth:`NavigationStack.step`) and returns the path the local planner follows plus parameter
overrides (e.g. ``max_speed``). The default ``bypass`` leaves both untouched.

Policies (documented here because tasks and metrics depend on them):

- **Start inside the inflated zone.** A robot that got closer to a wall than the inflation radius
  has its own cell occupied in the inflated map. Rather than failing, the stack plans from the
  nearest free cell of the inflated map and prepends the robot's position, provided the straight
  segment from the robot to that cell crosses no occupied cell of the *uninflated* map. Only a
  robot whose position is blocked in the raw map (or walled off from free space) fails with
  :class:`~arena.core.errors.StartOccupied`.
- **Narrow passages.** The map is inflated by the robot's bounding circle (``robot_radius +
  inflation_margin``), which closes doors the robot fits through sideways-on: a jackal (0.267 m
  circle, 0.33 m wide) and Arena's 0.6 m doors. Where that map has no route (or the start or
  goal lies in its inflated zone), the stack plans on the map inflated by the footprint's
  inscribed radius instead (``footprint_radius + inflation_margin``): like a ROS costmap's
  lethal zone, cells where the footprint collides in every heading. :attr:`footprint_plan`
  says which one the path came from. Routes the circle fits through are always preferred, even
  when longer. (Not with a global costmap, which plans on its own inscribed radius.)
- **Coarse maps** are planned on their cells split to at most ``planning_resolution`` (0.1 m):
  distances are measured centre to centre, so on Arena's 0.4–0.5 m maps an inflation below one
  cell marked nothing and plans passed 0.25 m from walls, closer than the robot's radius.
- **Goal inside the inflated zone** fails with :class:`~arena.core.errors.GoalOccupied`: goals
  must be sampled with at least ``robot_radius + inflation_margin`` of clearance.
- **Failures.** If the plan made by :meth:`~NavigationStack.reset` fails, :attr:`status` becomes
  ``FAILED``, the typed error is kept in :attr:`last_error` and raised (never a ``None`` path);
  :meth:`~NavigationStack.step` then only brakes. A later replan that fails keeps the previous
  path (the static map has not changed, so the old path is still valid), records the error in
  :attr:`last_error` and retries after ``max(replan_period, 1 s)``.
- **Replanning** happens every ``replan_period`` seconds (0 = never) and whenever the robot is
  more than ``max_path_deviation`` from the path (pushed by a pedestrian, say).
- **Goal reached** when within ``goal_tolerance_xy`` and, if ``goal_tolerance_yaw`` is set, with
  the heading within it too; the stack then passes the tolerance to the local planner
  (``LocalObservation.goal_yaw_tolerance``), and planners that can turn on the spot (pure
  pursuit) align the heading at the goal. Car-like (Ackermann) robots cannot turn on the spot:
  they reach a goal heading only if the approach happens to end with it. The status then stays
  ``GOAL_REACHED``.
- **Parameter overrides** from the intermediate planner apply to the local planner when it has a
  pydantic ``params`` model with a field of that name (pure pursuit: ``max_speed``), else an
  attribute of that name; other keys are ignored. Each output replaces the previous overrides
  (values not overridden return to the configured ones); :meth:`NavigationStack.reset` restores
  the configured parameters.

move_base_flex-like features (all opt-in; with the defaults the stack behaves as before; the
``navigation`` keys in docs/navigation.md): the global planner runs at reset, every
``replan_period`` s, on deviation and at once when the path ahead is blocked
(``replan_on_blocked``, :mod:`arena.nav.planning`); the intermediate planner every
``intermediate_period`` s; the local planner every control tick. A **global costmap** plans on
a :class:`~arena.nav.costmap.GlobalCostmap` of the static map (inscribed radius ``robot_radius
+ inflation_margin``; cost-aware search with ``cost_weight > 0``, else the configured planner on
its lethal cells; ``use_scan`` folds every scan into its obstacle layer); a **local costmap** is
a rolling window updated every tick and given to the local planner; **oscillation and
recovery** are :mod:`arena.nav.stuck`'s.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import BaseModel

from arena.core.errors import ConfigError, PlanningError
from arena.core.geometry import point_segment_distance
from arena.core.types import Pose2D, wrap_angle_scalar
from arena.maps.grid import OccupancyGrid
from arena.nav.config import (
    DEFAULTS,
    GlobalCostmapConfig,
    LocalCostmapConfig,
    NavStatus,
)
from arena.nav.costmap import GlobalCostmap, LocalCostmap
from arena.nav.global_planners import GlobalPlanner
from arena.nav.intermediate import (
    INTERMEDIATE_PLANNERS,
    IntermediateInput,
    IntermediatePlanner,
    Pedestrians,
)
from arena.nav.local_planners import LocalObservation, LocalPlanner, limit_command
from arena.nav.planning import PathPlanning, subdivide
from arena.nav.recovery import OscillationMonitor, RecoveryName, RecoveryRun, sample_path
from arena.nav.stuck import StuckRecovery

_PATH_SAMPLE_STEP = 0.1
"""m, spacing of the path samples checked for blocking."""


def _ped_array(peds: Pedestrians) -> NDArray[np.float64]:
    """``(n, 4)`` ``[x, y, vx, vy]`` rows (m, m/s, world frame) of ``peds``."""
    pos = np.asarray(peds.positions, dtype=np.float64).reshape(-1, 2)
    vel = np.asarray(peds.velocities, dtype=np.float64).reshape(-1, 2)
    if len(vel) != len(pos):
        vel = np.zeros_like(pos)
    return np.hstack([pos, vel])


class NavigationStack(PathPlanning, StuckRecovery):
    """Global planner + local planner with replanning and goal checking, for one robot.

    Args:
        global_planner: plans on the inflated map.
        local_planner: turns the path into commands.
        robot_radius: radius of the robot's bounding circle (m).
        inflation_margin: clearance added to ``robot_radius`` when inflating the map (m).
        footprint_radius: inscribed radius of the robot's footprint (m): the largest disc about
            the robot origin inside it. Where the map inflated by ``robot_radius`` closes every
            route, the plan is made on the map inflated by ``footprint_radius +
            inflation_margin`` (see "Narrow passages" in the module docstring). ``None`` (or
            not below ``robot_radius``) plans with ``robot_radius`` only.
        planning_resolution: largest cell size planned on (m); coarser maps are subdivided.
        replan_period: seconds between replans; 0 plans only at reset (and on deviation).
        goal_tolerance: ``(xy m, yaw rad or None)``; ``None`` ignores the heading.
        max_path_deviation: distance from the path (m) that triggers an immediate replan.
        kinematics: the robot's kinematics name; checked against the local planner's
            ``supports`` and passed on in every observation. ``None`` lets the planner infer it.
        intermediate_planner: refines the path between the two; ``None`` = ``bypass``.
        intermediate_period: seconds between intermediate-planner calls; 0 = every tick.
        intermediate_window: radius (m) of the local window given to the intermediate planner.
        global_costmap: plan on a :class:`~arena.nav.costmap.GlobalCostmap` (``None``: on the
            inflated occupancy grid, as before).
        local_costmap: keep a :class:`~arena.nav.costmap.LocalCostmap` rolling window updated
            every tick (``None``: none).
        replan_on_blocked: replan at once, with the current scan marked on the planning grid,
            when a laser return (or a lethal local-costmap cell) blocks the path ahead.
        blocked_lookahead: length of path ahead checked for blocking (m).
        oscillation_timeout: seconds without ``oscillation_distance`` of motion before a
            recovery behaviour runs; 0 disables detection and recovery.
        oscillation_distance: motion that counts as progress (m).
        recovery_behaviors: the recovery behaviours in order (see :mod:`arena.nav.recovery`).
        back_up_distance: distance reversed by ``back_up`` (m).
        back_up_speed: reversing speed of ``back_up`` (m/s).
        rotate_speed: turn rate of ``rotate`` (rad/s), capped by the robot's ``omega_max``.
        scan_range_max: the laser's maximum range (m); readings at it count as no hit.

    Raises:
        ConfigError: the local planner cannot drive ``kinematics``, or an argument is invalid.
    """

    def __init__(
        self,
        global_planner: GlobalPlanner,
        local_planner: LocalPlanner,
        *,
        robot_radius: float,
        inflation_margin: float = DEFAULTS.inflation_margin,
        footprint_radius: float | None = None,
        planning_resolution: float = DEFAULTS.planning_resolution,
        replan_period: float = DEFAULTS.replan_period,
        goal_tolerance: tuple[float, float | None] = (
            DEFAULTS.goal_tolerance_xy,
            DEFAULTS.goal_tolerance_yaw,
        ),
        max_path_deviation: float = DEFAULTS.max_path_deviation,
        kinematics: str | None = None,
        intermediate_planner: IntermediatePlanner | None = None,
        intermediate_period: float = DEFAULTS.intermediate_period,
        intermediate_window: float = DEFAULTS.intermediate_window,
        global_costmap: GlobalCostmapConfig | None = None,
        local_costmap: LocalCostmapConfig | None = None,
        replan_on_blocked: bool = DEFAULTS.replan_on_blocked,
        blocked_lookahead: float = DEFAULTS.blocked_lookahead,
        oscillation_timeout: float = DEFAULTS.oscillation_timeout,
        oscillation_distance: float = DEFAULTS.oscillation_distance,
        recovery_behaviors: tuple[RecoveryName, ...] = DEFAULTS.recovery_behaviors,
        back_up_distance: float = DEFAULTS.back_up_distance,
        back_up_speed: float = DEFAULTS.back_up_speed,
        rotate_speed: float = DEFAULTS.rotate_speed,
        scan_range_max: float = math.inf,
    ) -> None:
        if not robot_radius > 0:
            raise ConfigError(f"robot_radius must be > 0 m, got {robot_radius}")
        if footprint_radius is not None and not footprint_radius > 0:
            raise ConfigError(f"footprint_radius must be > 0 m, got {footprint_radius}")
        if not planning_resolution > 0:
            raise ConfigError(f"planning_resolution must be > 0 m, got {planning_resolution}")
        if inflation_margin < 0 or replan_period < 0 or not max_path_deviation > 0:
            raise ConfigError(
                "inflation_margin and replan_period must be >= 0 and max_path_deviation > 0, got "
                f"{inflation_margin}, {replan_period}, {max_path_deviation}"
            )
        if intermediate_period < 0 or not intermediate_window > 0:
            raise ConfigError(
                "intermediate_period must be >= 0 and intermediate_window > 0, got "
                f"{intermediate_period}, {intermediate_window}"
            )
        supports: frozenset[str] = getattr(local_planner, "supports", frozenset())
        if kinematics is not None and kinematics not in supports:
            raise ConfigError(
                f"local planner {type(local_planner).__name__} cannot drive {kinematics!r} robots "
                f"(supports: {', '.join(sorted(supports)) or 'none'})"
            )
        self.global_planner = global_planner
        self.local_planner = local_planner
        self.robot_radius = float(robot_radius)
        self.inflation_margin = float(inflation_margin)
        self.footprint_radius = (
            None if footprint_radius is None or footprint_radius >= robot_radius
            else float(footprint_radius)
        )
        self.planning_resolution = float(planning_resolution)
        self.replan_period = float(replan_period)
        self.goal_tolerance_xy = float(goal_tolerance[0])
        self.goal_tolerance_yaw = None if goal_tolerance[1] is None else float(goal_tolerance[1])
        self.max_path_deviation = float(max_path_deviation)
        self.kinematics = kinematics
        self.grid: OccupancyGrid | None = None
        self.inflated: OccupancyGrid | None = None
        """The planning grid inflated by ``robot_radius + inflation_margin``."""
        self.inflated_footprint: OccupancyGrid | None = None
        """The planning grid inflated by ``footprint_radius + inflation_margin`` (or ``None``)."""
        self.footprint_plan = False
        """Whether the current path was planned with the footprint radius (a narrow passage)."""
        self.goal = Pose2D()
        self.status = NavStatus.FAILED
        self.last_error: PlanningError | None = None
        self.replans = 0
        self._path = np.zeros((0, 2))
        self._nearest_free: dict[int, NDArray[np.int64]] = {}
        self._wide_labels: NDArray[np.int32] | None = None
        self._time = 0.0
        self._last_plan_time = 0.0
        self._retry_after = -math.inf
        self.intermediate_planner: IntermediatePlanner = (
            intermediate_planner
            if intermediate_planner is not None
            else INTERMEDIATE_PLANNERS.build("bypass")
        )
        self.intermediate_period = float(intermediate_period)
        self.intermediate_window = float(intermediate_window)
        self.overrides: dict[str, float] = {}
        self._base_params = getattr(local_planner, "params", None)
        self._base_attrs: dict[str, Any] = {}
        self._inter_path: NDArray[np.float64] | None = None
        self._inter_time = -math.inf
        bad = [
            name
            for name in recovery_behaviors
            if name not in ("clear_costmap", "rotate", "back_up")
        ]
        if (
            bad or not blocked_lookahead > 0 or oscillation_timeout < 0
            or not (oscillation_distance > 0 and back_up_distance > 0)
            or not (back_up_speed > 0 and rotate_speed > 0)
        ):
            raise ConfigError(
                "invalid recovery settings: unknown behaviours "
                f"{bad}, or a non-positive distance, speed or lookahead"
            )
        self.global_costmap_config = global_costmap
        self.local_costmap_config = local_costmap
        self.global_costmap: GlobalCostmap | None = None
        """The global costmap (``None`` unless configured); built at :meth:`reset`."""
        self.local_costmap: LocalCostmap | None = None
        """The rolling local costmap (``None`` unless configured); updated every tick."""
        self.replan_on_blocked = bool(replan_on_blocked)
        self.blocked_lookahead = float(blocked_lookahead)
        self.oscillation = OscillationMonitor(oscillation_timeout, oscillation_distance)
        self.recovery_behaviors: tuple[RecoveryName, ...] = tuple(recovery_behaviors)
        self.back_up_distance = float(back_up_distance)
        self.back_up_speed = float(back_up_speed)
        self.rotate_speed = float(rotate_speed)
        self.scan_range_max = float(scan_range_max)
        self.blocked_replans = 0
        """Replans triggered by a blocked path since :meth:`reset`."""
        self.recoveries: list[RecoveryName] = []
        """Recovery behaviours run since :meth:`reset`, in order."""
        self._recovery_index = 0
        self._recovery: RecoveryRun | None = None
        self._stuck_xy: NDArray[np.float64] | None = None
        self._scan_world = np.zeros((0, 2))
        self._samples = np.zeros((0, 2))
        self._sample_s = np.zeros(0)
        self._last_blocked = -math.inf

    # -- state ----------------------------------------------------------------------------------
    @property
    def path(self) -> NDArray[np.float64]:
        """The current global path ``(k, 2)`` (m, world frame; read-only); ``(0, 2)`` if none."""
        return self._path

    @property
    def time(self) -> float:
        """``obs.time`` of the last :meth:`step`, or the reset time (s)."""
        return self._time

    def goal_reached(self, pose: Pose2D | ArrayLike) -> bool:
        """Whether ``pose`` satisfies the goal tolerances (position, and heading if set)."""
        p = pose if isinstance(pose, Pose2D) else Pose2D.from_array(np.asarray(pose).reshape(-1))
        if p.distance_to(self.goal) > self.goal_tolerance_xy:
            return False
        if self.goal_tolerance_yaw is None:
            return True
        return abs(wrap_angle_scalar(p.theta - self.goal.theta)) <= self.goal_tolerance_yaw

    def cross_track_error(self, xy: ArrayLike) -> float:
        """Distance (m) from the point ``(2,)`` to the current path (``inf`` without a path)."""
        path = self._path
        if len(path) == 0:
            return math.inf
        if len(path) == 1:
            return float(np.hypot(*(np.asarray(xy, dtype=np.float64) - path[0])))
        return float(np.min(point_segment_distance(np.asarray(xy)[None, :2], path[:-1], path[1:])))

    # -- episode --------------------------------------------------------------------------------
    def reset(
        self, grid: OccupancyGrid, start: Pose2D, goal: Pose2D, *, time: float = 0.0
    ) -> NavStatus:
        """Start a new run: inflate ``grid`` once, plan from ``start`` to ``goal``.

        Args:
            grid: the static map (uninflated).
            start: the robot's pose (m, rad).
            goal: the goal pose (m, rad).
            time: simulation time of the reset (s).

        Returns:
            The new :attr:`status`, ``ACTIVE``.

        Raises:
            StartOccupied: the robot cannot get out of the inflated zone (see module docstring).
            GoalOccupied: the goal lies in the inflated zone or off the map.
            NoPathFound: the goal is not reachable. Before any of these propagates,
                :attr:`status` is set to ``FAILED`` and the error kept in :attr:`last_error`, so
                a caller that catches it can still :meth:`step` (which then only brakes).
        """
        if grid is not self.grid or self.inflated is None:
            # Grids are immutable, so episodes on the same map share one inflation (an EDT).
            fine = subdivide(grid, self.planning_resolution)
            self.inflated = fine.inflate(self.robot_radius + self.inflation_margin)
            self.inflated_footprint = (
                None if self.footprint_radius is None
                else fine.inflate(self.footprint_radius + self.inflation_margin)
            )
            self._nearest_free = {}
            self._wide_labels = None
            self.global_costmap = None
        inscribed = self.robot_radius + self.inflation_margin
        gcfg, lcfg = self.global_costmap_config, self.local_costmap_config
        if gcfg is not None:
            if self.global_costmap is None:
                self.global_costmap = GlobalCostmap(
                    subdivide(grid, self.planning_resolution),
                    gcfg.params(inscribed, use_semantic=False),
                )
            else:  # same map: forget the previous episode's obstacles
                self.global_costmap.obstacles.costs[:] = 0
                self.global_costmap.update()
        if lcfg is not None:
            self.local_costmap = LocalCostmap(
                grid, lcfg.width, lcfg.height,
                lcfg.params(self.robot_radius, use_semantic=lcfg.use_pedestrians),
            )
        self.grid = grid
        self.goal = goal
        self.local_planner.reset()
        self.intermediate_planner.reset()
        self._apply_overrides({})
        self._inter_path = None
        self._inter_time = -math.inf
        self._path = np.zeros((0, 2))
        self._path.setflags(write=False)
        self._time = float(time)
        self._retry_after = -math.inf
        self.replans = 0
        self.last_error = None
        self.blocked_replans = 0
        self.recoveries = []
        self._recovery_index = 0
        self._recovery = None
        self._stuck_xy = None
        self._scan_world = np.zeros((0, 2))
        self._last_blocked = -math.inf
        self.oscillation.reset(start.xy, self._time)
        try:
            self._set_path(self._plan_from(start))
        except PlanningError as e:
            self.last_error = e
            self.status = NavStatus.FAILED
            raise
        self.status = NavStatus.ACTIVE
        return self.status

    def replan(self, pose: Pose2D, *, mark_scan: bool | None = None) -> bool:
        """Plan again from ``pose``; on failure keep the old path and record :attr:`last_error`.

        Args:
            pose: the robot's pose (m, rad).
            mark_scan: plan with the last scan's returns marked on the planning grid (inflated
                like the map); ``None`` = :attr:`replan_on_blocked`.

        Returns:
            Whether a new path was set.
        """
        self._require_reset()
        self.replans += 1
        if mark_scan is None:
            mark_scan = self.replan_on_blocked
        try:
            self._set_path(self._plan_from(pose, mark_scan=mark_scan))
        except PlanningError as e:
            self.last_error = e
            self._last_plan_time = self._time
            self._retry_after = self._time + max(self.replan_period, 1.0)
            return False
        return True

    def step(
        self, obs: LocalObservation, pedestrians: Pedestrians | None = None
    ) -> NDArray[np.float64]:
        """One control tick: check the goal, replan if due, return the local planner's command.

        Args:
            obs: the robot's observation this tick. Its ``path`` and ``goal`` are replaced by the
                stack's own (the caller may pass :attr:`path` or an empty array); ``kinematics``
                falls back to the stack's when ``None``. ``obs.time`` (s) drives the replanning
                period, so it must advance.
            pedestrians: pedestrians around the robot (world frame), for the intermediate
                planner; ``None`` means none known.

        Returns:
            ``(3,)`` body twist command ``[vx, vy, omega]``; a braking command (zero within the
            acceleration limits) once the goal is reached or when the initial plan failed.
        """
        self._require_reset()
        q = np.asarray(obs.pose, dtype=np.float64).reshape(3)
        v = np.asarray(obs.twist, dtype=np.float64).reshape(3)
        self._time = float(obs.time)
        running = (NavStatus.ACTIVE, NavStatus.RECOVERING)
        if self.status in running and self.goal_reached(Pose2D.from_array(q)):
            self.status = NavStatus.GOAL_REACHED
            self._recovery = None
        if self.status not in running:
            return limit_command(np.zeros(3), v, obs.limits, obs.dt)

        self._sense(obs, q, pedestrians)
        if self.status is NavStatus.RECOVERING:
            cmd = self._recover(obs, q, v)
            if cmd is not None:
                return cmd
        if self.oscillation.enabled and self._stuck(q):
            cmd = self._start_recovery(obs, q, v)
            if cmd is not None:
                return cmd

        due = self.replan_period > 0 and self._time - self._last_plan_time >= self.replan_period
        strayed = (
            self._time >= self._retry_after
            and self.cross_track_error(q[:2]) > self.max_path_deviation
        )
        if due or strayed:
            self.replan(Pose2D.from_array(q))
        elif self._path_blocked(q):
            self.blocked_replans += 1
            self._last_blocked = self._time
            self.replan(Pose2D.from_array(q), mark_scan=True)

        path = self._intermediate(obs, q, v, pedestrians)
        local_obs = dataclasses.replace(
            obs, path=path, goal=self.goal,
            kinematics=obs.kinematics if obs.kinematics is not None else self.kinematics,
            goal_yaw_tolerance=(
                obs.goal_yaw_tolerance
                if obs.goal_yaw_tolerance is not None
                else self.goal_tolerance_yaw
            ),
            goal_xy_tolerance=(
                obs.goal_xy_tolerance
                if obs.goal_xy_tolerance is not None
                else self.goal_tolerance_xy
            ),
            pedestrians=(
                _ped_array(pedestrians)
                if pedestrians is not None and len(pedestrians) and not np.size(obs.pedestrians)
                else obs.pedestrians
            ),
            costmap=(
                self.local_costmap.master if self.local_costmap is not None else obs.costmap
            ),
        )
        return np.asarray(self.local_planner.compute(local_obs), dtype=np.float64).reshape(3)

    @property
    def intermediate_path(self) -> NDArray[np.float64]:
        """The path the local planner followed at the last :meth:`step` (m, ``(m, 2)``)."""
        return self._inter_path if self._inter_path is not None else self._path

    # -- sensing, blocking, recovery ------------------------------------------------------------

    # -- internals ------------------------------------------------------------------------------
    def _base_speed(self, obs: LocalObservation) -> float:
        """The local planner's configured cruise speed (m/s): its ``max_speed`` or ``vx_max``."""
        configured = getattr(self._base_params, "max_speed", None)
        if configured is None:
            current = getattr(self.local_planner, "max_speed", None)
            configured = self._base_attrs.get("max_speed", current)
        vmax = float(obs.limits.vx_max)
        return min(vmax, float(configured)) if isinstance(configured, int | float) else vmax

    def _intermediate(
        self,
        obs: LocalObservation,
        q: NDArray[np.float64],
        v: NDArray[np.float64],
        pedestrians: Pedestrians | None,
    ) -> NDArray[np.float64]:
        """Call the intermediate planner when due; return the path for the local planner."""
        due = self._inter_path is None or (
            self._time - self._inter_time >= self.intermediate_period - 1e-9
        )
        if not due:
            assert self._inter_path is not None
            return self._inter_path
        points = obs.scan_points() if np.size(obs.scan_ranges) else np.zeros((0, 2))
        if len(points):
            c, s = math.cos(q[2]), math.sin(q[2])
            points = points @ np.array([[c, s], [-s, c]]) + q[:2]
        inp = IntermediateInput(
            pose=q, twist=v, path=self._path, goal=self.goal.as_array(),
            max_speed=self._base_speed(obs), robot_radius=self.robot_radius,
            pedestrians=pedestrians if pedestrians is not None else Pedestrians(),
            obstacle_points=points, window=self.intermediate_window, time=self._time,
            global_costmap=(
                self.global_costmap.master if self.global_costmap is not None else None
            ),
            local_costmap=self.local_costmap.master if self.local_costmap is not None else None,
        )
        out = self.intermediate_planner.plan(inp)
        if out.path is self._path:
            path = self._path
        else:
            path = np.array(out.path, dtype=np.float64).reshape(-1, 2)
            path.setflags(write=False)
        self._apply_overrides(dict(out.overrides))
        self._inter_path = path
        self._inter_time = self._time
        return path

    def _apply_overrides(self, overrides: dict[str, float]) -> None:
        """Set the local planner's parameters to the configured ones updated by ``overrides``."""
        if overrides == self.overrides:
            return
        lp = self.local_planner
        base = self._base_params
        fields = type(base).model_fields if isinstance(base, BaseModel) else {}
        in_params = {k: val for k, val in overrides.items() if k in fields}
        if isinstance(base, BaseModel):
            new = base.model_copy(update=in_params) if in_params else base
            lp.params = new  # type: ignore[attr-defined]
        for k in list(self._base_attrs):
            if k not in overrides:
                setattr(lp, k, self._base_attrs.pop(k))
        for k, val in overrides.items():
            if k not in fields and hasattr(lp, k) and not callable(getattr(lp, k)):
                self._base_attrs.setdefault(k, getattr(lp, k))
                setattr(lp, k, val)
        self.overrides = dict(overrides)

    def _require_reset(self) -> None:
        if self.inflated is None:
            raise RuntimeError("NavigationStack.reset(grid, start, goal) must be called first")

    def _set_path(self, path: NDArray[np.float64]) -> None:
        p = np.array(path, dtype=np.float64).reshape(-1, 2)
        p.setflags(write=False)
        self._path = p
        self._samples, self._sample_s = sample_path(p, _PATH_SAMPLE_STEP)
        self._last_plan_time = self._time
        self._retry_after = -math.inf


